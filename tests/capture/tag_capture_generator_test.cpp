// The capture generator against its own ground truth: the tag corners projected with the true pose
// land on the rendered tag's borders, libapriltag finds the tag there, and the trajectory keeps
// its promises (distance, tilt, tag in view, look-away frames).
#include "capture/sim/tag_capture_generator.h"

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "capture/recording/recording_reader.h"
#include "capture_test_support.h"
#include "core/image/pixel_convert.h"

namespace arpipe {
namespace {

using namespace arpipe::test;

// Luma of the rendered reflectances through the sRGB response and BT.601 limited range
// (paper 0.80 -> ~214, table 0.41 -> ~163, ink 0.025 -> ~54); thresholds sit between them.
constexpr int kDarkBelow = 100;
constexpr int kLightAbove = 130;
constexpr int kPaperAbove = 185;
// libapriltag puts pixel centres at +0.5 (pixel i spans [i, i+1]; see its quad_decimate
// rescaling); mrcal puts them at integers.
constexpr double kAprilTagPixelCentre = 0.5;

struct Luma {
  int width = 0, height = 0;
  std::vector<uint8_t> pixels;
  // Nearest pixel (mrcal's convention: pixel centres at integer coordinates); -1 outside.
  int at(const Vec2& p) const {
    const long u = std::lround(p[0]), v = std::lround(p[1]);
    if (u < 0 || v < 0 || u >= width || v >= height) return -1;
    return pixels[size_t(v) * width + size_t(u)];
  }
};

// One recording shared by the tests: 8 frames half a second apart (so the poses differ widely),
// the last two looking away from the tag.
class TagCapture : public ::testing::Test {
 public:
  static void SetUpTestSuite() {
    options_.frames = 8;
    options_.fps = 2.0;
    options_.look_away_frames = 2;
    dir_ = scratch_dir("tag-capture");
    fs::remove_all(dir_);
    ASSERT_EQ(generate_tag_capture(dir_, options_), 8);
  }

  static Luma luma(const RecordingReader& reader, size_t index) {
    Frame frame;
    reader.read(index, frame);
    Luma l{frame.width, frame.height, {}};
    to_grey(frame, l.pixels);
    return l;
  }

  // A point on the tag plane (tag-size units from the centre: the black border's corners are at +-0.5).
  static Vec2 project(const CameraModel& model, const SE3& T_cam_world, double x, double y) {
    const double s = options_.tag_size_m;
    auto p = model.project(T_cam_world * Vec3{x * s, y * s, 0.0});
    EXPECT_TRUE(p.has_value());
    return p.value_or(Vec2{-1, -1});
  }

  static inline TagCaptureOptions options_;
  static inline fs::path dir_;
};

// The black-border corners in libapriltag's order: bottom-left, bottom-right, top-right, top-left
// of the printed tag; the world y axis points to the tag's top.
constexpr double kCornerSigns[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};

void expect_documented_metadata(const RecordingReader& reader) {
  EXPECT_TRUE(reader.warnings().empty());
  EXPECT_EQ(reader.info().pixel_format, PixelFormat::YUYV);
  EXPECT_EQ(reader.info().width, 640);
  EXPECT_EQ(reader.info().height, 480);
  EXPECT_EQ(reader.camera_model().lensmodel(), "LENSMODEL_OPENCV4");
  ASSERT_EQ(reader.frame_count(), 8u);
  ASSERT_EQ(reader.ground_truth().size(), 8u);
  for (size_t i = 0; i < 8; ++i) {
    const FrameMetadata& m = reader.metadata(i);
    EXPECT_EQ(m.sequence, i);
    EXPECT_EQ(m.exposure_start_ns, 1'000'000'000 + int64_t(i) * 500'000'000);
    EXPECT_EQ(m.exposure_ns, 4'000'000);
    EXPECT_EQ(m.frame_duration_ns, 500'000'000);
    EXPECT_EQ(m.raw_timestamp_meaning, TimestampMeaning::StartOfExposure);
    EXPECT_EQ(reader.ground_truth()[i].sequence, i);
  }
}

// The true pose puts the projected tag exactly where the renderer drew it: just inside each
// black-border corner it is dark, on the white border light, and just outside the printed
// square (the table) light. A quarter cell is 2-4 px here (foreshortened by the tilt), more than
// the 0.5 px rounding to a pixel plus the 1 px of anti-aliasing.
void expect_borders_at_the_true_corners(const RecordingReader& reader) {
  const CameraModel& model = reader.camera_model();
  const double cell = 1.0 / 8;  // tag36h11: the black-border edge spans 8 cells
  for (size_t i = 0; i < 6; ++i) {
    const Luma image = TagCapture::luma(reader, i);
    const SE3& pose = reader.ground_truth()[i].T_cam_world_mid;
    for (const auto& sign : kCornerSigns) {
      auto at = [&](double offset) {
        const double d = 0.5 + offset;  // distance from the centre along each axis, tag-size units
        return image.at(TagCapture::project(model, pose, sign[0] * d, sign[1] * d));
      };
      EXPECT_LT(at(-cell / 4), kDarkBelow) << "frame " << i << " corner " << sign[0] << "," << sign[1];
      EXPECT_GT(at(cell / 2), kPaperAbove) << "frame " << i << " white border";
      EXPECT_GT(at(cell + cell / 4), kLightAbove) << "frame " << i << " table";
      EXPECT_LT(at(cell + cell / 4), kPaperAbove) << "frame " << i << " table is not paper";
    }
  }
}

// Every data cell's centre shows the bit that libapriltag's own image of the tag has there: the
// texture is neither mirrored nor rotated.
void expect_data_cells_of_the_family_image(const RecordingReader& reader) {
  apriltag_family_t* family = tag36h11_create();
  image_u8_t* tag = apriltag_to_image(family, 0);
  for (size_t i = 0; i < 6; i += 5) {
    const Luma image = TagCapture::luma(reader, i);
    for (int row = 0; row < tag->height; ++row)
      for (int col = 0; col < tag->width; ++col) {
        // Cell centres in tag-size units; the printed square is 10 cells of 1/8, row 0 at the top (+y).
        const double x = (col + 0.5 - tag->width / 2.0) / 8, y = (tag->height / 2.0 - row - 0.5) / 8;
        const int value =
            image.at(TagCapture::project(reader.camera_model(), reader.ground_truth()[i].T_cam_world_mid, x, y));
        if (tag->buf[row * tag->stride + col] > 127)
          EXPECT_GT(value, kLightAbove) << "frame " << i << " cell " << row << "," << col;
        else
          EXPECT_LT(value, kDarkBelow) << "frame " << i << " cell " << row << "," << col;
      }
  }
  image_u8_destroy(tag);
  tag36h11_destroy(family);
}

// One test for the three render checks, so that ctest (one process per test) renders the shared
// recording once for them.
TEST_F(TagCapture, RenderedFramesMatchTheirGroundTruth) {
  RecordingReader reader(dir_);
  {
    SCOPED_TRACE("metadata");
    expect_documented_metadata(reader);
  }
  {
    SCOPED_TRACE("borders at the true corners");
    expect_borders_at_the_true_corners(reader);
  }
  {
    SCOPED_TRACE("data cells");
    expect_data_cells_of_the_family_image(reader);
  }
}

// libapriltag, an independent detector, finds tag 0 with its corners on the true projections.
// Tolerance 0.5 px (the brief's): the detector's edge fit on an sRGB-encoded edge pulls corners
// inwards by about 0.2 px, and image noise adds a few hundredths.
TEST_F(TagCapture, AprilTagDetectorFindsTheTagAtTheTruePose) {
  RecordingReader reader(dir_);
  apriltag_family_t* family = tag36h11_create();
  apriltag_detector_t* detector = apriltag_detector_create();
  apriltag_detector_add_family(detector, family);
  detector->quad_decimate = 1.0;
  detector->nthreads = 1;
  for (size_t i = 0; i < 8; ++i) {
    Luma image = luma(reader, i);
    image_u8_t im{image.width, image.height, image.width, image.pixels.data()};
    zarray_t* detections = apriltag_detector_detect(detector, &im);
    if (i >= 6) {
      EXPECT_EQ(zarray_size(detections), 0) << "frame " << i << " looks away from the tag";
    } else {
      ASSERT_EQ(zarray_size(detections), 1) << "frame " << i;
      apriltag_detection_t* d = nullptr;
      zarray_get(detections, 0, &d);
      EXPECT_EQ(d->id, 0);
      const SE3& pose = reader.ground_truth()[i].T_cam_world_mid;
      for (int k = 0; k < 4; ++k) {
        const Vec2 truth = project(reader.camera_model(), pose, kCornerSigns[k][0] * 0.5, kCornerSigns[k][1] * 0.5);
        const double error =
            std::hypot(d->p[k][0] - kAprilTagPixelCentre - truth[0], d->p[k][1] - kAprilTagPixelCentre - truth[1]);
        EXPECT_LT(error, 0.5) << "frame " << i << " corner " << k;
      }
    }
    apriltag_detections_destroy(detections);
  }
  apriltag_detector_destroy(detector);
  tag36h11_destroy(family);
}

// The default capture keeps the brief's promises: 0.35-0.6 m from the tag, tilted at most 40
// degrees from its normal, looking near its centre, the whole printed tag (white border included)
// in view with a margin, smooth motion, and the last frames looking away with no part of the tag in view.
TEST(TagCaptureTrajectory, DefaultCaptureKeepsTheTagInViewUntilItLooksAway) {
  const TagCaptureOptions options;
  const CameraModel model = tag_capture_camera_model(options);
  const auto truth = tag_capture_ground_truth(options);
  ASSERT_EQ(truth.size(), size_t(options.frames));
  const double half_printed = options.tag_size_m * 10 / 8 / 2;
  const int visible = options.frames - options.look_away_frames;
  ASSERT_GE(options.look_away_frames, 2);
  for (int i = 0; i < options.frames; ++i) {
    const SE3& pose = truth[size_t(i)].T_cam_world_mid;
    const SE3 world_from_cam = pose.inverse();
    std::vector<Vec3> points{{0, 0, 0}};
    for (const auto& sign : kCornerSigns) points.push_back({sign[0] * half_printed, sign[1] * half_printed, 0});
    if (i < visible) {
      const double distance = norm(world_from_cam.translation());
      EXPECT_GE(distance, 0.35) << i;
      EXPECT_LE(distance, 0.6) << i;
      const Vec3 viewing = world_from_cam.rotate({0, 0, 1});
      EXPECT_LE(std::acos(-viewing[2]), 40 * std::numbers::pi / 180) << i;
      for (const Vec3& p : points) {
        const auto q = model.project(pose * p);
        ASSERT_TRUE(q.has_value()) << i;
        EXPECT_GE((*q)[0], 10) << i;
        EXPECT_GE((*q)[1], 10) << i;
        EXPECT_LE((*q)[0], options.width - 11) << i;
        EXPECT_LE((*q)[1], options.height - 11) << i;
      }
      const Vec2 centre = *model.project(pose * points[0]);
      EXPECT_LT(std::hypot(centre[0] - model.cx(), centre[1] - model.cy()), 60) << i;
      if (i > 0) {  // at 30 fps: about 1 degree and a few millimetres per frame
        const SE3& previous = truth[size_t(i - 1)].T_cam_world_mid;
        EXPECT_LT(rotation_angle_between(previous, pose), 2 * std::numbers::pi / 180) << i;
        EXPECT_LT(norm(previous.inverse().translation() - world_from_cam.translation()), 0.01) << i;
      }
    } else {
      for (const Vec3& p : points) {
        const Vec3 p_cam = pose * p;
        const auto q = p_cam[2] > 0 ? model.project(p_cam) : std::nullopt;
        const bool in_image = q && (*q)[0] >= -0.5 && (*q)[1] >= -0.5 && (*q)[0] <= options.width - 0.5 &&
                              (*q)[1] <= options.height - 0.5;
        EXPECT_FALSE(in_image) << "frame " << i << " should look away";
      }
    }
    // The camera moves while the shutter is open: start, mid and end differ, mid halfway between.
    const SE3& start = truth[size_t(i)].T_cam_world_start;
    const SE3& end = truth[size_t(i)].T_cam_world_end;
    EXPECT_GT(rotation_angle_between(start, end), 0.0) << i;
    const SE3 halfway = start.interpolate(end, 0.5);
    // Off the constant-velocity path by (dt^2 / 8) * acceleration: with dt = 4 ms, 1e-5 allows
    // angular accelerations up to 5 rad/s^2 and linear ones up to 5 m/s^2, far above this orbit's.
    EXPECT_LT(rotation_angle_between(halfway, pose), 1e-5) << i;
    EXPECT_LT(norm(halfway.translation() - pose.translation()), 1e-5) << i;
  }
}

TEST(TagCaptureTrajectory, SmallCapturesInEveryPixelFormatAreDeterministic) {
  for (PixelFormat format : {PixelFormat::GREY, PixelFormat::RGB24, PixelFormat::YUYV, PixelFormat::NV12}) {
    TagCaptureOptions options;
    options.width = 64;
    options.height = 48;
    options.frames = 2;
    options.look_away_frames = 0;
    options.pixel_format = format;
    const fs::path a = scratch_dir(fmt::format("tag-small-a-{}", pixel_format_name(format)));
    const fs::path b = scratch_dir(fmt::format("tag-small-b-{}", pixel_format_name(format)));
    const fs::path c = scratch_dir(fmt::format("tag-small-c-{}", pixel_format_name(format)));
    generate_tag_capture(a, options);
    generate_tag_capture(b, options);
    options.seed = 2;
    generate_tag_capture(c, options);
    EXPECT_EQ(read_file(a / "frames.bin"), read_file(b / "frames.bin")) << pixel_format_name(format);
    EXPECT_NE(read_file(a / "frames.bin"), read_file(c / "frames.bin")) << "the seed changes the noise";
    RecordingReader reader(a);
    EXPECT_EQ(reader.info().pixel_format, format);
    EXPECT_EQ(reader.frame_count(), 2u);
  }
}

TEST(TagCaptureTrajectory, RefusesToOverwriteARecording) {
  TagCaptureOptions options;
  options.width = 32;
  options.height = 24;
  options.frames = 1;
  const fs::path dir = scratch_dir("tag-overwrite");
  generate_tag_capture(dir, options);
  const std::string message = error_message([&] { generate_tag_capture(dir, options); });
  EXPECT_NE(message.find("refusing to overwrite"), std::string::npos) << message;
}

TEST(TagCaptureTrajectory, BadOptionsAreRefusedByName) {
  const fs::path dir = scratch_dir("tag-bad-options") / "never-written";
  auto refused = [&](auto change, const std::string& expected) {
    TagCaptureOptions options;
    change(options);
    const std::string message = error_message<std::invalid_argument>([&] { generate_tag_capture(dir, options); });
    EXPECT_NE(message.find(expected), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(dir));
  };
  refused([](auto& o) { o.frames = 0; }, "frames must be positive, got 0");
  refused([](auto& o) { o.fps = 0; }, "fps must be in (0, 1000], got 0");
  refused([](auto& o) { o.exposure_ns = 50'000'000; }, "exposure_ns must be in (0, 33333333]");
  refused([](auto& o) { o.family = "tag99h1"; }, "unknown tag family \"tag99h1\"");
  refused([](auto& o) { o.tag_id = 587; }, "tag id 587 is outside tag36h11's 0..586");
  refused([](auto& o) { o.lensmodel = "LENSMODEL_CAHVOR"; }, "lens model \"LENSMODEL_CAHVOR\" is not supported");
  refused([](auto& o) { o.width = 641; }, "YUYV needs an even width");
  refused([](auto& o) { o.tag_size_m = -1; }, "tag size must be in (0, 10) m");
}

}  // namespace
}  // namespace arpipe
