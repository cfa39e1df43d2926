// The JSON text of recording format v1: field names, types and units in one place (docs/FORMATS.md).
// Every decoding error names the place and the field, and says what was expected.
#include "capture/recording/recording_json.h"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <nlohmann/json.hpp>

namespace arpipe::recording_json {

namespace {

using nlohmann::json;

// in_line: the text is one line of a .jsonl file, so the byte position counts within the line.
json parse_object(const std::string& text, const std::string& where, const char* what, bool in_line) {
  json value;
  try {
    value = json::parse(text);
  } catch (const json::parse_error& e) {
    // e.byte counts from 1 at the character that broke the parse.
    throw RecordingError(fmt::format("{}: invalid JSON at byte {}{} ({} expected): {}", where, e.byte,
                                     in_line ? " of the line" : "", what, e.what()));
  } catch (const json::exception& e) {
    // out_of_range 406: a number such as 5e308 that no double holds.
    throw RecordingError(fmt::format("{}: invalid JSON ({} expected): {}", where, what, e.what()));
  }
  if (!value.is_object()) throw RecordingError(fmt::format("{}: expected a JSON object ({})", where, what));
  return value;
}

const json& field(const json& object, const char* name, const std::string& where, const char* expected) {
  auto it = object.find(name);
  if (it == object.end()) throw RecordingError(fmt::format("{}: missing field \"{}\" ({})", where, name, expected));
  return *it;
}

[[noreturn]] void wrong_type(const char* name, const json& value, const std::string& where, const char* expected) {
  throw RecordingError(fmt::format("{}: field \"{}\" is {}, expected {}", where, name, value.dump(), expected));
}

uint64_t get_unsigned(const json& object, const char* name, const std::string& where, const char* expected) {
  const json& value = field(object, name, where, expected);
  if (!value.is_number_unsigned()) wrong_type(name, value, where, expected);
  return value.get<uint64_t>();
}

int64_t get_signed(const json& object, const char* name, const std::string& where, const char* expected) {
  const json& value = field(object, name, where, expected);
  if (value.is_number_unsigned()) {
    if (value.get<uint64_t>() > uint64_t(std::numeric_limits<int64_t>::max())) wrong_type(name, value, where, expected);
    return int64_t(value.get<uint64_t>());
  }
  if (!value.is_number_integer()) wrong_type(name, value, where, expected);
  return value.get<int64_t>();
}

int get_int(const json& object, const char* name, const std::string& where, const char* expected) {
  const int64_t value = get_signed(object, name, where, expected);
  if (value < std::numeric_limits<int>::min() || value > std::numeric_limits<int>::max())
    wrong_type(name, field(object, name, where, expected), where, expected);
  return int(value);
}

double get_double(const json& object, const char* name, const std::string& where, const char* expected) {
  const json& value = field(object, name, where, expected);
  if (!value.is_number()) wrong_type(name, value, where, expected);
  return value.get<double>();
}

// An optional array of exactly N finite numbers, each at least `lowest` (or above it when `strictly`).
template <size_t N>
std::optional<std::array<double, N>> get_numbers(const json& object, const char* name, const std::string& where,
                                                 double lowest, bool strictly, const char* expected) {
  if (!object.contains(name)) return std::nullopt;
  const json& v = object[name];
  if (!v.is_array() || v.size() != N) wrong_type(name, v, where, expected);
  std::array<double, N> out{};
  for (size_t i = 0; i < N; ++i) {
    if (!v[i].is_number()) wrong_type(name, v, where, expected);
    out[i] = v[i].get<double>();
    if (!std::isfinite(out[i]) || out[i] < lowest || (strictly && out[i] == lowest))
      throw RecordingError(fmt::format("{}: {}[{}] is {}, expected {}", where, name, i, out[i], expected));
  }
  return out;
}

std::string get_string(const json& object, const char* name, const std::string& where, const char* expected) {
  const json& value = field(object, name, where, expected);
  if (!value.is_string()) wrong_type(name, value, where, expected);
  return value.get<std::string>();
}

// A part's name must stay inside the recording directory.
// prefix: how messages name the object holding the key ("files." for recording.json's files).
std::string get_file_name(const json& files, const char* name, const std::string& where, const char* prefix = "files.") {
  const char* expected = "a plain file name inside the recording directory";
  std::string value = get_string(files, name, where, expected);
  if (value.empty() || value == "." || value == ".." || value.find('/') != std::string::npos ||
      value.find('\0') != std::string::npos)
    throw RecordingError(fmt::format("{}: {}{} is \"{}\", expected {}", where, prefix, name, value, expected));
  return value;
}

json vec3_json(const Vec3& v) { return json::array({v[0], v[1], v[2]}); }

Vec3 get_vec3(const json& object, const char* name, const std::string& where) {
  const char* expected = "an array of 3 numbers";
  const json& value = field(object, name, where, expected);
  if (!value.is_array() || value.size() != 3) wrong_type(name, value, where, expected);
  Vec3 out{};
  for (size_t i = 0; i < 3; ++i) {
    if (!value[i].is_number()) wrong_type(name, value, where, expected);
    out[i] = value[i].get<double>();
  }
  return out;
}

json pose_json(const SE3& pose) {
  return json{{"r", vec3_json(pose.rotation_vector())}, {"t", vec3_json(pose.translation())}};
}

SE3 get_pose(const json& object, const char* name, const std::string& where) {
  const char* expected = "an object {\"r\": rotation vector [3], \"t\": translation in metres [3]}";
  const json& value = field(object, name, where, expected);
  if (!value.is_object()) wrong_type(name, value, where, expected);
  const std::string inner = fmt::format("{} (in \"{}\")", where, name);
  return SE3::from_rt(get_vec3(value, "r", inner), get_vec3(value, "t", inner));
}

constexpr double kDegreesPerRadian = 180.0 / 3.14159265358979323846;

json light_json(const GroundTruthLight& light) {
  nlohmann::ordered_json j = {{"name", light.name}, {"kind", light.kind}};
  if (light.kind == "directional") {
    j["direction_to_light"] = vec3_json(light.direction_to_light);
    j["irradiance"] = light.strength;
    j["angular_diameter_deg"] = light.angular_diameter_rad * kDegreesPerRadian;
  } else {
    j["position"] = vec3_json(light.position);
    j["intensity"] = light.strength;
    if (light.kind == "sphere") j["radius_m"] = light.radius_m;
  }
  j["color"] = json::array({light.color[0], light.color[1], light.color[2]});
  return j;
}

GroundTruthLight get_light(const json& object, const std::string& where) {
  if (!object.is_object()) wrong_type("lights", object, where, "a light object");
  GroundTruthLight light;
  light.name = get_string(object, "name", where, "the light's name");
  light.kind = get_string(object, "kind", where, "\"directional\", \"point\" or \"sphere\"");
  if (light.kind == "directional") {
    light.direction_to_light = get_vec3(object, "direction_to_light", where);
    light.strength = get_double(object, "irradiance", where, "irradiance in W/m^2");
    light.angular_diameter_rad = get_double(object, "angular_diameter_deg", where, "degrees") / kDegreesPerRadian;
  } else if (light.kind == "point" || light.kind == "sphere") {
    light.position = get_vec3(object, "position", where);
    light.strength = get_double(object, "intensity", where, "intensity in W/sr");
    if (light.kind == "sphere") light.radius_m = get_double(object, "radius_m", where, "the radius in metres");
  } else {
    throw RecordingError(fmt::format("{}: kind is \"{}\", expected \"directional\", \"point\" or \"sphere\"", where, light.kind));
  }
  light.color = get_vec3(object, "color", where);
  return light;
}

}  // namespace

std::string encode_info(const RecordingInfo& info, const FileNames& files) {
  nlohmann::ordered_json j = {
      {"format", kRecordingFormatName},
      {"version", info.version},
      {"pixel_format", std::string(pixel_format_name(info.pixel_format))},
      {"width", info.width},
      {"height", info.height},
      {"bytes_per_line", info.bytes_per_line},
      {"source", info.source},
      {"created_utc", info.created_utc},
      {"files",
       {{"camera_model", files.camera_model},
        {"frames", files.frames},
        {"metadata", files.metadata},
        {"ground_truth", files.ground_truth}}},
  };
  return j.dump(2) + "\n";
}

void decode_info(const std::string& text, const std::string& where, RecordingInfo& info, FileNames& files) {
  const json j = parse_object(text, where, "the recording description", false);
  const std::string format = get_string(j, "format", where, "\"arpipe-recording\"");
  if (format != kRecordingFormatName)
    throw RecordingError(fmt::format("{}: format is \"{}\", expected \"{}\"", where, format, kRecordingFormatName));
  // The version comes first: a newer format may change any other field.
  info.version = get_int(j, "version", where, "an integer format version");
  if (info.version != kRecordingFormatVersion)
    throw RecordingError(fmt::format("{}: format version {} is not supported (this build reads version {})", where,
                                     info.version, kRecordingFormatVersion));
  const std::string pixel_format = get_string(j, "pixel_format", where, "GREY, RGB24, YUYV or NV12");
  auto parsed = pixel_format_from_name(pixel_format);
  if (!parsed)
    throw RecordingError(fmt::format("{}: pixel_format \"{}\" is not supported (expected GREY, RGB24, YUYV or NV12)",
                                     where, pixel_format));
  info.pixel_format = *parsed;
  info.width = get_int(j, "width", where, "image width in pixels");
  info.height = get_int(j, "height", where, "image height in pixels");
  if (auto problem = check_image_size(info.pixel_format, info.width, info.height))
    throw RecordingError(fmt::format("{}: width/height: {}", where, *problem));
  info.bytes_per_line = get_unsigned(j, "bytes_per_line", where, "bytes per line of the first plane");
  const size_t min_stride = min_bytes_per_line(info.pixel_format, info.width);
  if (info.bytes_per_line < min_stride || info.bytes_per_line > 16 * min_stride)
    throw RecordingError(fmt::format("{}: bytes_per_line {} does not fit {} pixels of {} (expected {} to {})", where,
                                     info.bytes_per_line, info.width, pixel_format, min_stride, 16 * min_stride));
  info.source = get_string(j, "source", where, "a string");
  info.created_utc = get_string(j, "created_utc", where, "an ISO 8601 UTC time string");
  const json& f = field(j, "files", where, "an object naming the parts");
  if (!f.is_object()) wrong_type("files", f, where, "an object naming the parts");
  files.camera_model = get_file_name(f, "camera_model", where);
  files.frames = get_file_name(f, "frames", where);
  files.metadata = get_file_name(f, "metadata", where);
  files.ground_truth = get_file_name(f, "ground_truth", where);
}

std::string encode_frame_record(const FrameRecord& r) {
  const FrameMetadata& m = r.meta;
  // ordered_json keeps the documented field order, so a line reads well in a terminal.
  nlohmann::ordered_json j = {
      {"index", r.index},
      {"offset", r.offset},
      {"size", r.size},
      {"crc32", r.crc32},
      {"sequence", m.sequence},
      {"exposure_start_ns", m.exposure_start_ns},
      {"exposure_ns", m.exposure_ns},
      {"readout_ns", m.readout_ns},
      {"frame_duration_ns", m.frame_duration_ns},
      {"analogue_gain", m.analogue_gain},
      {"digital_gain", m.digital_gain},
      {"raw_timestamp_ns", m.raw_timestamp_ns},
      {"raw_timestamp_meaning", std::string(timestamp_meaning_name(m.raw_timestamp_meaning))},
      {"timestamp_offset_ns", m.timestamp_offset_ns},
  };
  // What the camera measured, only when it said (libcamera's Lux and ColourTemperature).
  if (m.lux > 0) j["lux"] = m.lux;
  if (m.colour_temperature_k > 0) j["colour_temperature_k"] = m.colour_temperature_k;
  // How a raw Bayer frame develops (core/raw_colour.h), as far as the camera or the source decided.
  if (m.raw.black_level) j["black_level"] = *m.raw.black_level;
  if (m.raw.white_level > 0) j["white_level"] = m.raw.white_level;
  if (m.raw.gains) j["colour_gains"] = *m.raw.gains;
  if (m.raw.colour_matrix) j["colour_matrix"] = *m.raw.colour_matrix;
  return j.dump();
}

FrameRecord decode_frame_record(const std::string& line, const std::string& where) {
  const json j = parse_object(line, where, "one frame's metadata", true);
  FrameRecord r;
  r.index = get_unsigned(j, "index", where, "the frame index, counting from 0");
  r.offset = get_unsigned(j, "offset", where, "byte offset in the frames file");
  r.size = get_unsigned(j, "size", where, "payload size in bytes");
  const uint64_t crc = get_unsigned(j, "crc32", where, "the payload's CRC-32 as an unsigned integer");
  if (crc > 0xffffffffu) wrong_type("crc32", j["crc32"], where, "an unsigned 32-bit integer");
  r.crc32 = uint32_t(crc);
  FrameMetadata& m = r.meta;
  m.sequence = get_unsigned(j, "sequence", where, "the source's sequence number");
  m.exposure_start_ns = get_signed(j, "exposure_start_ns", where, "integer nanoseconds, CLOCK_MONOTONIC");
  m.exposure_ns = get_signed(j, "exposure_ns", where, "integer nanoseconds");
  m.readout_ns = get_signed(j, "readout_ns", where, "integer nanoseconds");
  m.frame_duration_ns = get_signed(j, "frame_duration_ns", where, "integer nanoseconds");
  m.analogue_gain = get_double(j, "analogue_gain", where, "a number");
  m.digital_gain = get_double(j, "digital_gain", where, "a number");
  m.raw_timestamp_ns = get_signed(j, "raw_timestamp_ns", where, "integer nanoseconds");
  const char* meanings = "\"start_of_exposure\", \"end_of_frame\" or \"sensor\"";
  const std::string meaning = get_string(j, "raw_timestamp_meaning", where, meanings);
  if (!timestamp_meaning_from_name(meaning, m.raw_timestamp_meaning))
    throw RecordingError(fmt::format("{}: raw_timestamp_meaning is \"{}\", expected {}", where, meaning, meanings));
  m.timestamp_offset_ns = get_signed(j, "timestamp_offset_ns", where, "integer nanoseconds");
  if (j.contains("lux")) m.lux = get_double(j, "lux", where, "the scene's illuminance in lux");
  if (j.contains("colour_temperature_k"))
    m.colour_temperature_k = get_double(j, "colour_temperature_k", where, "a colour temperature in kelvin");
  if (m.lux < 0 || m.colour_temperature_k < 0)
    throw RecordingError(fmt::format("{}: lux and colour_temperature_k must not be negative", where));
  // Their fit to the frame's bit depth is checked where the frame is developed (capture/raw_colour_source.h).
  m.raw.black_level = get_numbers<4>(j, "black_level", where, 0, false, "4 raw codes (R, Gr, Gb, B), each >= 0");
  if (j.contains("white_level")) m.raw.white_level = get_double(j, "white_level", where, "the raw code of full scale");
  if (!(m.raw.white_level >= 0 && m.raw.white_level <= 65535))
    throw RecordingError(fmt::format("{}: white_level is {}, expected a raw code in [0, 65535]", where, m.raw.white_level));
  m.raw.gains = get_numbers<3>(j, "colour_gains", where, 0, true, "3 gains (R, G, B), each > 0");
  m.raw.colour_matrix = get_numbers<9>(j, "colour_matrix", where, -1e300, false, "9 finite numbers, row-major");
  if (m.exposure_ns < 0 || m.readout_ns < 0 || m.frame_duration_ns < 0)
    throw RecordingError(fmt::format("{}: exposure_ns, readout_ns and frame_duration_ns must not be negative", where));
  // Every later stage adds these (exposure end, next frame's start): the sum must stay in int64 ns.
  int64_t end_ns = 0;
  if (__builtin_add_overflow(m.exposure_start_ns, m.exposure_ns, &end_ns) ||
      __builtin_add_overflow(end_ns, m.readout_ns, &end_ns) ||
      __builtin_add_overflow(end_ns, m.frame_duration_ns, &end_ns))
    throw RecordingError(fmt::format("{}: exposure_start_ns {} + exposure_ns {} + readout_ns {} + frame_duration_ns {} "
                                     "overflows 64-bit nanoseconds",
                                     where, m.exposure_start_ns, m.exposure_ns, m.readout_ns, m.frame_duration_ns));
  return r;
}

std::string encode_ground_truth(const GroundTruthRecord& r) {
  const GroundTruthFrame& t = r.truth;
  nlohmann::ordered_json j = {
      {"index", r.index},
      {"sequence", t.sequence},
      {"T_cam_world_start", pose_json(t.T_cam_world_start)},
      {"T_cam_world_mid", pose_json(t.T_cam_world_mid)},
      {"T_cam_world_end", pose_json(t.T_cam_world_end)},
  };
  if (t.exposure_ns > 0) {
    j["exposure_ns"] = t.exposure_ns;
    j["analogue_gain"] = t.analogue_gain;
    j["digital_gain"] = t.digital_gain;
  }
  if (!t.rows.empty()) {
    json rows = json::array();
    for (const GroundTruthRowPose& row : t.rows) rows.push_back({{"row", row.row}, {"T_cam_world", pose_json(row.T_cam_world)}});
    j["rows"] = rows;
  }
  if (!t.lights.empty()) {
    json lights = json::array();
    for (const GroundTruthLight& light : t.lights) lights.push_back(light_json(light));
    j["lights"] = lights;
  }
  if (t.sun)
    j["sun"] = {{"azimuth_deg", t.sun->azimuth_rad * kDegreesPerRadian},
                {"elevation_deg", t.sun->elevation_rad * kDegreesPerRadian}};
  if (!t.linear_image.empty()) j["linear_image"] = t.linear_image;
  return j.dump();
}

GroundTruthRecord decode_ground_truth(const std::string& line, const std::string& where) {
  const json j = parse_object(line, where, "one frame's ground truth", true);
  GroundTruthRecord r;
  GroundTruthFrame& t = r.truth;
  r.index = get_unsigned(j, "index", where, "the frame index, counting from 0");
  t.sequence = get_unsigned(j, "sequence", where, "the frame's sequence number");
  t.T_cam_world_start = get_pose(j, "T_cam_world_start", where);
  t.T_cam_world_mid = get_pose(j, "T_cam_world_mid", where);
  t.T_cam_world_end = get_pose(j, "T_cam_world_end", where);
  if (j.contains("exposure_ns")) {
    t.exposure_ns = get_signed(j, "exposure_ns", where, "the exposure used, in ns");
    t.analogue_gain = get_double(j, "analogue_gain", where, "the analogue gain used");
    t.digital_gain = get_double(j, "digital_gain", where, "the digital gain used");
  }
  if (j.contains("rows")) {
    const json& rows = j["rows"];
    if (!rows.is_array()) wrong_type("rows", rows, where, "an array of {\"row\", \"T_cam_world\"}");
    for (size_t i = 0; i < rows.size(); ++i) {
      const std::string inner = fmt::format("{} (in \"rows\"[{}])", where, i);
      if (!rows[i].is_object()) wrong_type("rows", rows[i], inner, "an object {\"row\", \"T_cam_world\"}");
      t.rows.push_back({get_int(rows[i], "row", inner, "a row number"), get_pose(rows[i], "T_cam_world", inner)});
    }
  }
  if (j.contains("lights")) {
    const json& lights = j["lights"];
    if (!lights.is_array()) wrong_type("lights", lights, where, "an array of light objects");
    for (size_t i = 0; i < lights.size(); ++i)
      t.lights.push_back(get_light(lights[i], fmt::format("{} (in \"lights\"[{}])", where, i)));
  }
  if (j.contains("sun")) {
    const json& sun = j["sun"];
    const std::string inner = fmt::format("{} (in \"sun\")", where);
    if (!sun.is_object()) wrong_type("sun", sun, where, "an object {\"azimuth_deg\", \"elevation_deg\"}");
    t.sun = GroundTruthSun{get_double(sun, "azimuth_deg", inner, "degrees east of north") / kDegreesPerRadian,
                           get_double(sun, "elevation_deg", inner, "degrees above the horizon") / kDegreesPerRadian};
  }
  if (j.contains("linear_image"))
    t.linear_image = get_file_name(j, "linear_image", where, "");
  return r;
}

}  // namespace arpipe::recording_json
