// optimization_inputs written from C++, byte-compatible with mrcal 2.2's Python: each value a numpy
// .npy array, all of them in a deflated .zip (numpy's .npz), the zip base-85 encoded as Python's
// base64.b85encode does. No Python is needed at run time, so every model arpipe writes carries them.
#include "calib/optimization_inputs.h"

#include <fmt/format.h>
#include <zlib.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "calib/mrcal_problem.h"

namespace arpipe::calib {

namespace {

// ---- numpy .npy (format version 1.0: numpy/lib/format.py) -------------------------------------

struct NpyArray {
  std::string name;     // the dict key
  std::string descr;    // numpy dtype string: '<f8', '<i4', '|b1', '<U12'
  std::vector<size_t> shape;
  std::string data;     // little-endian, C order
};

std::string npy_bytes(const NpyArray& array) {
  std::string shape = "(";
  for (size_t i = 0; i < array.shape.size(); ++i) shape += fmt::format("{}{}", i > 0 ? ", " : "", array.shape[i]);
  shape += array.shape.size() == 1 ? ",)" : ")";  // Python's one-element tuple
  std::string header = fmt::format("{{'descr': '{}', 'fortran_order': False, 'shape': {}, }}", array.descr, shape);
  // numpy pads the header with spaces and ends it with '\n' so that the data starts 64-byte aligned.
  const size_t preamble = 10;  // magic (6), version (2), header length (2)
  const size_t total = (preamble + header.size() + 1 + 63) / 64 * 64;
  header.append(total - preamble - header.size() - 1, ' ');
  header += '\n';
  std::string out = "\x93NUMPY";
  out += char(1);
  out += char(0);
  out += char(header.size() & 0xff);
  out += char(header.size() >> 8);
  out += header;
  out += array.data;
  return out;
}

template <typename T>
void append_le(std::string& out, T value) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));  // x86 and ARM Linux are little-endian, as numpy's '<' says
  out.append(reinterpret_cast<const char*>(bytes), sizeof(T));
}

NpyArray doubles(const std::string& name, std::vector<size_t> shape, const double* values) {
  size_t n = 1;
  for (size_t s : shape) n *= s;
  NpyArray a{name, "<f8", std::move(shape), {}};
  for (size_t i = 0; i < n; ++i) append_le(a.data, values[i]);
  return a;
}

NpyArray ints(const std::string& name, std::vector<size_t> shape, const std::vector<int32_t>& values) {
  NpyArray a{name, "<i4", std::move(shape), {}};
  for (int32_t v : values) append_le(a.data, v);
  return a;
}

NpyArray boolean(const std::string& name, bool value) { return {name, "|b1", {}, std::string(1, value ? '\1' : '\0')}; }

NpyArray scalar(const std::string& name, double value) { return doubles(name, {}, &value); }

// numpy's unicode strings: UTF-32LE, every element padded to the longest. Names are bytes here; a
// non-ASCII name is widened byte by byte (mrcal only shows it).
NpyArray strings(const std::string& name, std::vector<size_t> shape, const std::vector<std::string>& values) {
  size_t longest = 1;  // numpy gives '' the dtype '<U1'
  for (const std::string& v : values) longest = std::max(longest, v.size());
  NpyArray a{name, fmt::format("<U{}", longest), std::move(shape), {}};
  for (const std::string& v : values)
    for (size_t i = 0; i < longest; ++i) append_le(a.data, uint32_t(i < v.size() ? static_cast<unsigned char>(v[i]) : 0));
  return a;
}

// mrcal stores None as '' (a 0-d '<U1' array), since numpy cannot store None without pickling.
NpyArray none(const std::string& name) { return strings(name, {}, {""}); }

// ---- zip (PKWARE APPNOTE: local headers, central directory, end record), deflated ----------------

std::string deflate_raw(const std::string& in) {
  z_stream z{};
  if (deflateInit2(&z, Z_DEFAULT_COMPRESSION, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw std::runtime_error("optimization_inputs: zlib deflateInit2 failed");
  std::string out(deflateBound(&z, uLong(in.size())), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
  z.avail_in = uInt(in.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = uInt(out.size());
  const int status = deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  if (status != Z_STREAM_END) throw std::runtime_error("optimization_inputs: zlib deflate failed");
  return out;
}

std::string zip(const std::vector<NpyArray>& arrays) {
  std::string out, directory;
  constexpr uint16_t kVersion = 20, kDeflate = 8, kTime = 0, kDate = (1 << 5) | 1;  // 1980-01-01 00:00
  for (const NpyArray& array : arrays) {
    const std::string file = array.name + ".npy";
    const std::string raw = npy_bytes(array);
    const std::string packed = deflate_raw(raw);
    const uint32_t crc = uint32_t(crc32(0, reinterpret_cast<const Bytef*>(raw.data()), uInt(raw.size())));
    const uint32_t offset = uint32_t(out.size());
    append_le<uint32_t>(out, 0x04034b50);
    for (uint16_t v : {kVersion, uint16_t(0), kDeflate, kTime, kDate}) append_le(out, v);
    for (uint32_t v : {crc, uint32_t(packed.size()), uint32_t(raw.size())}) append_le(out, v);
    append_le(out, uint16_t(file.size()));
    append_le(out, uint16_t(0));
    out += file;
    out += packed;

    append_le<uint32_t>(directory, 0x02014b50);
    for (uint16_t v : {kVersion, kVersion, uint16_t(0), kDeflate, kTime, kDate}) append_le(directory, v);
    for (uint32_t v : {crc, uint32_t(packed.size()), uint32_t(raw.size())}) append_le(directory, v);
    for (uint16_t v : {uint16_t(file.size()), uint16_t(0), uint16_t(0), uint16_t(0), uint16_t(0)})
      append_le(directory, v);
    append_le(directory, uint32_t(0));  // external attributes
    append_le(directory, offset);
    directory += file;
  }
  const uint32_t directory_offset = uint32_t(out.size());
  out += directory;
  append_le<uint32_t>(out, 0x06054b50);
  for (uint16_t v : {uint16_t(0), uint16_t(0), uint16_t(arrays.size()), uint16_t(arrays.size())}) append_le(out, v);
  append_le(out, uint32_t(directory.size()));
  append_le(out, directory_offset);
  append_le(out, uint16_t(0));
  return out;
}

// ---- base-85 as Python's base64.b85encode (pad=False) -----------------------------------------

std::string base85(const std::string& in) {
  static constexpr char kAlphabet[] =
      "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz!#$%&()*+-;<=>?@^_`{|}~";
  std::string out;
  out.reserve((in.size() + 3) / 4 * 5);
  for (size_t i = 0; i < in.size(); i += 4) {
    uint32_t word = 0;
    for (size_t k = 0; k < 4; ++k)
      word = (word << 8) | (i + k < in.size() ? static_cast<unsigned char>(in[i + k]) : 0u);
    char chunk[5];
    for (int k = 4; k >= 0; --k) {
      chunk[k] = kAlphabet[word % 85];
      word /= 85;
    }
    // A final partial word of n bytes keeps n + 1 characters (the zero padding is dropped).
    out.append(chunk, in.size() - i >= 4 ? 5 : in.size() - i + 1);
  }
  return out;
}

}  // namespace

std::string optimization_inputs_base85(const CalibrationResult& result) {
  if (!result.problem) throw std::logic_error("optimization_inputs: the calibration result has no solved problem");
  const MrcalProblem& p = result.problem->problem;
  const mrcal_problem_selections_t& s = result.problem->selections;
  const size_t views = size_t(p.views());
  if (result.observations.size() != views)
    throw std::logic_error("optimization_inputs: the result's views do not match the solved problem's");

  std::vector<double> frames;
  for (const mrcal_pose_t& f : p.frames_toref)
    for (double v : {f.r.x, f.r.y, f.r.z, f.t.x, f.t.y, f.t.z}) frames.push_back(v);
  std::vector<double> pool;
  pool.reserve(p.pool.size() * 3);
  for (const mrcal_point3_t& point : p.pool)
    for (double v : {point.x, point.y, point.z}) pool.push_back(v);
  std::vector<int32_t> indices;  // frame, camera intrinsics, camera extrinsics (-1: the reference)
  for (const mrcal_observation_board_t& o : p.observations_board)
    for (int32_t v : {int32_t(o.iframe), int32_t(o.icam.intrinsics), int32_t(o.icam.extrinsics)}) indices.push_back(v);
  std::vector<std::string> imagepaths;
  for (const BoardObservation& o : result.observations) imagepaths.push_back(o.image);
  const double warp[2] = {p.calobject_warp.x2, p.calobject_warp.y2};

  // The keys and types of mrcal-calibrate-cameras' dict (mrcal 2.2), after its final optimize().
  const std::vector<NpyArray> arrays = {
      doubles("intrinsics", {1, p.intrinsics.size()}, p.intrinsics.data()),
      doubles("extrinsics_rt_fromref", {0, 6}, nullptr),  // one camera, at the reference
      doubles("frames_rt_toref", {views, 6}, frames.data()),
      none("points"),
      doubles("observations_board", {views, size_t(p.height_n), size_t(p.width_n), 3}, pool.data()),
      ints("indices_frame_camintrinsics_camextrinsics", {views, 3}, indices),
      none("observations_point"),
      none("indices_point_camintrinsics_camextrinsics"),
      strings("lensmodel", {}, {result.model.lensmodel()}),
      ints("imagersizes", {1, 2}, {int32_t(p.imagersize[0]), int32_t(p.imagersize[1])}),
      // arpipe always hands mrcal a warp (zero when not solved), so the flat board is stated, not None.
      doubles("calobject_warp", {2}, warp),
      boolean("do_optimize_intrinsics_core", s.do_optimize_intrinsics_core),
      boolean("do_optimize_intrinsics_distortions", s.do_optimize_intrinsics_distortions),
      boolean("do_optimize_extrinsics", s.do_optimize_extrinsics),
      boolean("do_optimize_frames", s.do_optimize_frames),
      boolean("do_optimize_calobject_warp", s.do_optimize_calobject_warp),
      scalar("calibration_object_spacing", p.spacing_m),
      boolean("do_apply_outlier_rejection", s.do_apply_outlier_rejection),
      boolean("do_apply_regularization", s.do_apply_regularization),
      boolean("verbose", false),
      strings("imagepaths", {views}, imagepaths),
  };
  return base85(zip(arrays));
}

std::string model_text_with_optimization_inputs(const CalibrationResult& result) {
  std::string text = result.model.to_string();
  const size_t end = text.rfind('}');
  if (end == std::string::npos) throw std::logic_error("optimization_inputs: the model text has no closing brace");
  text.erase(end);
  text += "\n    'icam_intrinsics': 0,\n\n";
  // mrcal's own comment (cameramodel.py _write), since mrcal's readers and people see the same file.
  text +=
      "    # The optimization inputs contain all the data used to compute this model.\n"
      "    # This contains ALL the observations for ALL the cameras in the solve. The uses of\n"
      "    # this are to be able to compute projection uncertainties, to visualize the\n"
      "    # calibration-time geometry and to re-run the original optimization for\n"
      "    # diagnostics. This is a big chunk of data that isn't useful for humans to\n"
      "    # interpret, so it's stored in binary, compressed, and encoded to ascii in\n"
      "    # base-85. Modifying the intrinsics of the model invalidates the optimization\n"
      "    # inputs: the optimum implied by the inputs would no longer match the stored\n"
      "    # parameters. Modifying the extrinsics is OK, however: if we move the camera\n"
      "    # elsewhere, the original solve can still be used to represent the camera-relative\n"
      "    # projection uncertainties\n";
  text += "    'optimization_inputs': b'" + optimization_inputs_base85(result) + "',\n\n}\n";
  return text;
}

void save_model_with_optimization_inputs(const CalibrationResult& result, const std::filesystem::path& path) {
  CameraModel::save_text(path, model_text_with_optimization_inputs(result));
}

}  // namespace arpipe::calib
