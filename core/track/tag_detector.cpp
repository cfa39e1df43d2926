// AprilTag detection: a thin owner of a libapriltag detector for one tag family chosen by name,
// run over an 8-bit grey image with any row stride.
#include "core/track/tag_detector.h"

#include <apriltag/apriltag.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/log.h"
#include "core/track/tag_family.h"

namespace arpipe {
namespace {

// libapriltag's decoder cannot correct more than 3 bits, and its quick-decode table holds every
// code with up to max_hamming flipped bits: measured here, 36h11 needs 36 MB at 2 bits but 1.2 GB
// (and 4 s) at 3; 52h13 needs 120 MB at 1 bit and 6 GB at 2. About 100 bytes per entry.
constexpr int kMaxHammingSupported = 3;
constexpr double kMaxDecodeTableEntries = 3.0e6;

double binomial(int n, int k) {
  double result = 1;
  for (int i = 1; i <= k; ++i) result = result * (n - k + i) / i;
  return result;
}

}  // namespace

struct TagDetector::Impl {
  TagFamilyPtr family{nullptr, nullptr};
  apriltag_detector_t* detector = nullptr;
  std::string family_name;

  ~Impl() {
    // The detector holds pointers into the family, so it goes first.
    if (detector) apriltag_detector_destroy(detector);
  }
};

TagDetector::TagDetector(const Config& config) : impl_(std::make_unique<Impl>()) {
  const TrackConfig& track = config.track;
  const std::string source = config_source_name(config);
  if (!is_tag_family(track.family)) {
    throw ConfigError(fmt::format("{}: track.family: unknown AprilTag family '{}' (expected one of: {})", source,
                                  track.family, joined_tag_family_names()));
  }
  if (!(track.quad_decimate >= 1.0) || !std::isfinite(track.quad_decimate)) {
    throw ConfigError(fmt::format("{}: track.quad_decimate: expected a number >= 1, got {}", source,
                                  track.quad_decimate));
  }
  if (!(track.quad_sigma >= 0.0) || !std::isfinite(track.quad_sigma)) {
    throw ConfigError(fmt::format("{}: track.quad_sigma: expected a number >= 0, got {}", source, track.quad_sigma));
  }
  if (track.threads < 1 || track.threads > 64) {
    throw ConfigError(fmt::format("{}: track.threads: expected 1 to 64, got {}", source, track.threads));
  }
  if (track.max_hamming < 0 || track.max_hamming > kMaxHammingSupported) {
    throw ConfigError(fmt::format("{}: track.max_hamming: expected 0 to {}, got {}", source, kMaxHammingSupported,
                                  track.max_hamming));
  }

  impl_->family_name = track.family;
  impl_->family = create_tag_family(track.family);

  double table_entries = 0;
  for (int bits = 0; bits <= track.max_hamming; ++bits) {
    table_entries += binomial(static_cast<int>(impl_->family->nbits), bits);
  }
  table_entries *= impl_->family->ncodes;
  if (table_entries > kMaxDecodeTableEntries) {
    throw ConfigError(fmt::format(
        "{}: track.max_hamming: {} corrected bits for family {} needs a decode table of {:.0f} entries "
        "(about {:.0f} MB); expected a smaller max_hamming",
        source, track.max_hamming, impl_->family_name, table_entries, table_entries * 100 / 1e6));
  }

  impl_->detector = apriltag_detector_create();
  impl_->detector->quad_decimate = static_cast<float>(track.quad_decimate);
  impl_->detector->quad_sigma = static_cast<float>(track.quad_sigma);
  impl_->detector->nthreads = track.threads;
  impl_->detector->refine_edges = true;
  apriltag_detector_add_family_bits(impl_->detector, impl_->family.get(), track.max_hamming);
}

TagDetector::~TagDetector() = default;


const std::string& TagDetector::family() const { return impl_->family_name; }

int TagDetector::code_count() const { return static_cast<int>(impl_->family->ncodes); }

int TagDetector::border_cells() const { return impl_->family->width_at_border; }

void TagDetector::detect(const uint8_t* grey, int width, int height, size_t stride,
                         std::vector<TagObservation>& out) noexcept {
  out.clear();
  if (!grey || width <= 0 || height <= 0 || stride < static_cast<size_t>(width)) return;
  // libapriltag takes a non-const buffer but copies before any blur or decimation.
  image_u8_t image{width, height, static_cast<int32_t>(stride), const_cast<uint8_t*>(grey)};
  zarray_t* detections = apriltag_detector_detect(impl_->detector, &image);
  if (!detections) return;
  try {
    out.reserve(static_cast<size_t>(zarray_size(detections)));
    for (int i = 0; i < zarray_size(detections); ++i) {
      apriltag_detection_t* detection = nullptr;
      zarray_get(detections, i, &detection);
      TagObservation observation;
      observation.id = detection->id;
      observation.hamming = detection->hamming;
      observation.decision_margin = detection->decision_margin;
      // libapriltag puts pixel centres at +0.5 (pixel i spans [i, i+1)); mrcal and OpenCV put them
      // at integers. Checked on rendered tags: without this shift every corner is half a pixel off.
      for (int c = 0; c < 4; ++c) observation.corners[c] = Vec2{detection->p[c][0] - 0.5, detection->p[c][1] - 0.5};
      out.push_back(observation);
    }
  } catch (const std::exception& e) {
    log::debug("track: dropping detections: {}", e.what());
    out.clear();
  }
  apriltag_detections_destroy(detections);
}

}  // namespace arpipe
