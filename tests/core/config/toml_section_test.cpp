// TomlSection: the one TOML section reader. Typed reads with their fallbacks, ranges, choices,
// sections, and the one message shape "file:line:col: dotted.key: expected X, found Y".
#include "core/config/toml_section.h"

#include <gtest/gtest.h>

#include <string>

namespace arpipe {
namespace {

enum class Pace { Timestamps, Fast };
constexpr ChoiceName<Pace> kPaceNames[] = {
    {"timestamps", Pace::Timestamps}, {"fast", Pace::Fast}, {"realtime", Pace::Timestamps, true}};

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const TomlInputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(TomlSection, ReadsTypedValuesAndFallbacks) {
  const toml::table root = parse_toml(
      "flag = true\ncount = 7\nscale = 2\nname = \"x\"\nv = [1, 2.5, 3]\npace = \"realtime\"\n"
      "[sub]\nk = 1.5\n[[items]]\na = 1\n[[items]]\na = 2\n",
      "a.toml");
  const TomlSection file(root, "a.toml");
  EXPECT_TRUE(file.boolean("flag", false));
  EXPECT_EQ(file.integer("count", 0, {0, 10}), 7);
  EXPECT_EQ(file.integer_as<int>("missing", 4), 4);
  EXPECT_EQ(file.number("scale", 0, NumberRange::closed(1, 4)), 2.0);  // an integer is a number
  EXPECT_EQ(file.string("name", ""), "x");
  EXPECT_EQ(file.vec3("v", {0, 0, 0}), (std::array<double, 3>{1, 2.5, 3}));
  EXPECT_EQ(file.choice("pace", Pace::Fast, kPaceNames), Pace::Timestamps);  // an alias
  const auto sub = file.section("sub");
  ASSERT_TRUE(sub.has_value());
  EXPECT_EQ(sub->dotted(), "sub");
  EXPECT_EQ(sub->number("k", 0), 1.5);
  const auto items = file.sections("items");
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(items[0].integer("a", 0), 1);
  EXPECT_EQ(items[1].integer("a", 0), 2);
  EXPECT_EQ(items[1].dotted(), "items[1]");
  EXPECT_TRUE(file.sections("absent").empty());
  EXPECT_FALSE(file.section("absent").has_value());
  EXPECT_NO_THROW(file.reject_stray_keys());
}

TEST(TomlSection, KeysOfArrayTablesMustBeReadToo) {
  const toml::table root = parse_toml("[[items]]\na = 1\n[[items]]\na = 2\nb = 3\n", "a.toml");
  const TomlSection file(root, "a.toml");
  for (const TomlSection& item : file.sections("items")) item.integer("a", 0);
  EXPECT_EQ(error_of([&] { file.reject_stray_keys(); }),
            "a.toml:5:1: items[1].b: unknown key; allowed keys in [[items]]: a");
}

TEST(TomlSection, OneMessageShape) {
  const toml::table root = parse_toml("[render]\nlens_canvas_scale = 7.0\nlens = 3\nk = \"seed\"\n", "a.toml");
  const TomlSection file(root, "a.toml");
  const TomlSection render = *file.section("render");
  EXPECT_EQ(error_of([&] { render.number("lens_canvas_scale", 1.5, NumberRange::closed(1, 4)); }),
            "a.toml:2:21: render.lens_canvas_scale: expected a number in [1, 4], found 7.0");
  EXPECT_EQ(error_of([&] { render.string("lens", ""); }), "a.toml:3:8: render.lens: expected a string, found an integer");
  EXPECT_EQ(error_of([&] { render.choice("k", Pace::Fast, kPaceNames); }),
            "a.toml:4:5: render.k: expected one of \"timestamps\", \"fast\", found \"seed\"");
  EXPECT_EQ(error_of([&] { render.integer("lens", 0, {4, 32}); }),
            "a.toml:3:8: render.lens: expected an integer in [4, 32], found 3");
  EXPECT_EQ(error_of([&] { render.number("lens", 0, NumberRange::above(0).in("m")); }), "no error");
}

TEST(TomlSection, RejectsTheFirstStrayKeyInFileOrder) {
  const toml::table root = parse_toml("[render]\nlens = \"map\"\nzeta = 1\nalpha = 2\n[other]\n", "a.toml");
  const TomlSection file(root, "a.toml");
  const TomlSection render = *file.section("render");
  render.string("lens", "");
  render.allow("enabled");
  EXPECT_EQ(error_of([&] { file.reject_stray_keys(); }),
            "a.toml:3:1: render.zeta: unknown key; allowed keys in [render]: lens, enabled");
}

TEST(TomlSection, NumbersBeyond64BitsNameTheKey) {
  EXPECT_EQ(error_of([] { parse_toml("[render]\nlens_canvas_scale = 1e400\n", "a.toml"); }),
            "a.toml:2:21: render.lens_canvas_scale: expected a number within a 64-bit float (magnitude at most "
            "about 1.8e308), found 1e400");
  EXPECT_EQ(error_of([] { parse_toml("x = [\n", "a.toml"); }).rfind("a.toml:", 0), 0u);
}

TEST(TomlSection, RangesSayWhatTheyAccept) {
  EXPECT_EQ(NumberRange::closed(0, 1e6).in("m").phrase(), "a number in [0, 1e6] (m)");
  EXPECT_EQ(NumberRange::closed_open(0, 0.95).phrase(), "a number in [0, 0.95)");
  EXPECT_EQ(NumberRange::at_least(1).phrase(), "a number >= 1");
  EXPECT_EQ(NumberRange::any().phrase(), "a number");
  EXPECT_EQ((IntRange{1}).phrase(), "an integer >= 1");
  EXPECT_EQ((IntRange{}).phrase(), "an integer");
}

}  // namespace
}  // namespace arpipe
