// Config findings of issue 18: the timestamp offset is range-checked, a --set value is exactly one
// TOML value on one line, numbers beyond 64 bits are "out of range" with key and line, and the
// files a config names are checked (arpipe config --check) with the key that names them.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/config/config.h"
#include "core/config/config_files.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

std::string config_error(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    parse_config(text, "test.toml", overrides);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(ConfigHardening, TimestampOffsetIsRangeChecked) {
  // INT64_MAX would overflow every exposure time it is added to.
  EXPECT_EQ(config_error("[source]\ntimestamp_offset_ns = 9223372036854775807\n"),
            "test.toml:2:23: source.timestamp_offset_ns: expected an integer in [-3600000000000, 3600000000000], found "
            "9223372036854775807");
  const std::string from_override = config_error("", {"source.timestamp_offset_ns=-9223372036854775808"});
  EXPECT_TRUE(contains(from_override, "override 'source.timestamp_offset_ns=-9223372036854775808': "
                                      "source.timestamp_offset_ns: expected an integer in [-3600000000000, "
                                      "3600000000000], found -9223372036854775808"))
      << from_override;
  EXPECT_EQ(parse_config("[source]\ntimestamp_offset_ns = -3600000000000\n", "t").source.timestamp_offset_ns,
            -3'600'000'000'000);
}

TEST(ConfigHardening, AnOverrideWithANewlineCannotInjectTables) {
  // Before: the newline ended the value and [sinks.png] became a table of the config.
  const std::string message =
      config_error("", {"pipeline.log_level=\"info\"\n[sinks.png]\ndir = \"/etc/cron.d\""});
  EXPECT_EQ(message,
            "override 'pipeline.log_level=\"info\"\\n[sinks.png]\\ndir = \"/etc/cron.d\"': the value of "
            "'pipeline.log_level' contains a newline; an override is exactly one TOML value on one line (escape it "
            "inside a quoted string, e.g. \"a\\nb\")");
  EXPECT_TRUE(contains(config_error("", {"source.path=a\rb"}), "contains a control character")) << config_error("", {"source.path=a\rb"});
  // Escaped inside a quoted string, a newline is just a character of the value.
  EXPECT_EQ(parse_config("", "t", {"source.path=\"a\\nb\""}).source.path, fs::path("a\nb"));
  // An inline table is still one value.
  EXPECT_EQ(parse_config("", "t", {"render.objects=[{mesh = \"builtin:pyramid\"}]"}).render.objects.at(0).mesh,
            "builtin:pyramid");
}

TEST(ConfigHardening, NumbersBeyond64BitsAreOutOfRangeWithKeyAndLine) {
  // Before: a syntax error from the file, and "got a string" from an override (1e400 was taken as a bare word).
  EXPECT_EQ(config_error("[render]\nlens = \"map\"\nlens_canvas_scale = 1e400\n"),
            "test.toml:3:21: render.lens_canvas_scale: expected a number within a 64-bit float (magnitude at most "
            "about 1.8e308), found 1e400");
  EXPECT_EQ(config_error("", {"render.lens_canvas_scale=1e400"}),
            "override 'render.lens_canvas_scale=1e400': render.lens_canvas_scale: expected a number within a 64-bit "
            "float (magnitude at most about 1.8e308), found 1e400");
  const std::string integer =
      config_error("[[render.objects]]\nscale = 1\n[[render.objects]]\nscale = 99999999999999999999\n");
  EXPECT_TRUE(contains(integer, "test.toml:4:"));
  EXPECT_TRUE(contains(integer, "render.objects[1].scale: expected an integer within 64 bits"))
      << integer;
  EXPECT_TRUE(contains(integer, "found 99999999999999999999"))
      << integer;
}

TEST(ConfigHardening, AHugeArrayIndexInAnOverrideIsNotAnIndex) {
  // Before: std::stoul's bare "stoul" (std::out_of_range) reached the user.
  EXPECT_EQ(config_error("[[render.objects]]\nscale = 1\n", {"render.objects.99999999999999999999999.scale=2"}),
            "override 'render.objects.99999999999999999999999.scale=2': 'render.objects' has 1 elements; "
            "'99999999999999999999999' is not an index into it");
}

class ConfigFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("arpipe_config_files_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "rec");
    std::ofstream(dir_ / "rec" / "recording.json") << "{}";
    std::ofstream(dir_ / "mesh.gltf") << "{}";
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string files_error(const std::string& text) {
    try {
      Config config = parse_config(text, "c.toml");
      check_config_files(config);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  }
  std::string source() const { return "[source]\npath = \"" + (dir_ / "rec").string() + "\"\n"; }

  fs::path dir_;
};

TEST_F(ConfigFiles, EveryNamedInputMustExistAndBeARegularFile) {
  EXPECT_EQ(files_error(source()), "");
  EXPECT_EQ(files_error(source() + "[[render.objects]]\nmesh = \"" + (dir_ / "mesh.gltf").string() + "\"\n"), "");
  // Before: arpipe config --check said "ok" for a mesh that does not exist.
  EXPECT_EQ(files_error(source() + "[[render.objects]]\nmesh = \"builtin:cube\"\n[[render.objects]]\nmesh = \"" +
                        (dir_ / "absent.gltf").string() + "\"\n"),
            "c.toml: render.objects[1].mesh: " + (dir_ / "absent.gltf").string() + ": No such file or directory");
  EXPECT_EQ(files_error(source() + "camera_model = \"" + dir_.string() + "\"\n"),
            "c.toml: source.camera_model: " + dir_.string() + ": it is a directory, expected a regular file");
  EXPECT_EQ(files_error("[source]\npath = \"" + (dir_ / "nothing").string() + "\"\n"),
            "c.toml: source.path: " + (dir_ / "nothing").string() + ": no such directory, expected a recording directory");
  EXPECT_EQ(files_error(source() + "[light]\nsource = \"environment\"\n[light.environment]\nfile = \"/dev/zero\"\n"),
            "c.toml: light.environment.file: /dev/zero: it is a character device, expected a regular file");
  // A panorama source: its still, every viewpoint's and the head track; the scene's lights file.
  const std::string panorama = "[source]\ntype = \"panorama\"\n[source.panorama]\nfile = \"" + (dir_ / "mesh.gltf").string() + "\"\n";
  EXPECT_EQ(files_error(panorama), "");
  EXPECT_EQ(files_error("[source]\ntype = \"panorama\"\n[source.panorama]\nfile = \"" + (dir_ / "absent.png").string() + "\"\n"),
            "c.toml: source.panorama.file: " + (dir_ / "absent.png").string() + ": No such file or directory");
  EXPECT_EQ(files_error(panorama + "[[source.panorama.viewpoints]]\nfile = \"" + dir_.string() +
                        "\"\n[source.panorama.view]\ndwell_s = 1.0\n"),
            "c.toml: source.panorama.viewpoints[0].file: " + dir_.string() + ": it is a directory, expected a regular file");
  EXPECT_EQ(files_error(panorama + "[source.panorama.view]\ntrack = \"" + (dir_ / "absent.csv").string() + "\"\n"),
            "c.toml: source.panorama.view.track: " + (dir_ / "absent.csv").string() + ": No such file or directory");
  EXPECT_EQ(files_error(panorama + "[light]\nsource = \"panorama\"\n[light.panorama]\nlights_file = \"/dev/zero\"\n"),
            "c.toml: light.panorama.lights_file: /dev/zero: it is a character device, expected a regular file");
  // The defaults name no recording: nothing to check (starting the replay says source.path is empty).
  EXPECT_EQ(files_error(""), "");
  // A disabled renderer loads no meshes.
  EXPECT_EQ(files_error(source() + "[render]\nenabled = false\n[[render.objects]]\nmesh = \"absent.gltf\"\n"), "");
}

TEST_F(ConfigFiles, ASymlinkLoopIsNamedWithItsKey) {
  fs::create_symlink(dir_ / "loop_b", dir_ / "loop_a");
  fs::create_symlink(dir_ / "loop_a", dir_ / "loop_b");
  EXPECT_EQ(files_error("[source]\npath = \"" + (dir_ / "loop_a").string() + "\"\n"),
            "c.toml: source.path: " + (dir_ / "loop_a").string() + ": Too many levels of symbolic links");
}

}  // namespace
}  // namespace arpipe
