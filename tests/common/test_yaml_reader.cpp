// The strict YAML reader: every mistake is one error naming the file, the
// line, the full key, what was expected and what was found.
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/common/yaml_reader.hpp"

using namespace pvb;

namespace {

/// The what() of the ConfigError `fn` throws, or "(no error)".
std::string config_error(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

std::string io_error(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const IoError& e) {
    return e.what();
  }
  return "(no error)";
}

/// Reads camera: {fps, depth_noise: {axial_scale}} the way a scenario does.
void read_camera(const YAML::Node& root, const yaml::ReadContext& ctx) {
  yaml::MapReader top(root, ctx, "");
  yaml::with_map(top, "camera", [](yaml::MapReader& c) {
    c.integer("fps", 30, 1, 240);
    yaml::with_map(c, "depth_noise", [](yaml::MapReader& d) { d.number("axial_scale", 1.0, 0, 100); });
  });
  top.finish();
}

std::string camera_error(const std::string& text) {
  const yaml::ReadContext ctx{"cam.yaml"};
  return config_error([&] { read_camera(yaml::parse(text, ctx), ctx); });
}

/// Places every key on line 42 of "base.yaml", as a merged scenario does.
class LineFortyTwo : public yaml::KeyLocator {
 public:
  std::string locate(const std::string& key) const override { return "base.yaml:42"; }
};

}  // namespace

TEST(YamlReader, ADuplicateKeyNamesBothLinesAndTheFullKey) {
  EXPECT_EQ(
      camera_error("camera:\n  depth_noise:\n    axial_scale: 2\n    axial_scale: 3\n"),
      "cam.yaml:4: camera.depth_noise.axial_scale: expected each key once in its section (first given at "
      "line 3), got a second axial_scale");
  EXPECT_EQ(camera_error("camera: {fps: 15}\ncamera: {fps: 30}\n"),
            "cam.yaml:2: camera: expected each key once in its section (first given at line 1), got a second "
            "camera");
  EXPECT_EQ(
      camera_error("list:\n  - {a: 1, a: 2}\n"),
      "cam.yaml:2: list[0].a: expected each key once in its section (first given at line 2), got a second a");
  // The same key in two maps is no duplicate.
  EXPECT_EQ(camera_error("camera:\n  fps: 15\n  depth_noise: {fps: 1}\n"),
            "cam.yaml:3: camera.depth_noise.fps: expected a known key (axial_scale), got unknown key");
}

TEST(YamlReader, WrongTypesAndRangesNameTheLineOfTheValue) {
  EXPECT_EQ(camera_error("camera:\n  fps: 15\n  depth_noise:\n    axial_scale: lots\n"),
            "cam.yaml:4: camera.depth_noise.axial_scale: expected a number, got lots");
  EXPECT_EQ(camera_error("camera:\n  depth_noise:\n    axial_scale: [1]\n"),
            "cam.yaml:3: camera.depth_noise.axial_scale: expected a number, got a non-scalar");
  EXPECT_EQ(camera_error("\n\ncamera:\n  fps: 500\n"),
            "cam.yaml:4: camera.fps: expected a value in [1, 240], got 500");
  EXPECT_EQ(camera_error("camera:\n  fps: 2.5\n"), "cam.yaml:2: camera.fps: expected an integer, got 2.5");
  EXPECT_EQ(camera_error("camera: 3\n"), "cam.yaml:1: camera: expected a mapping of keys");
  EXPECT_EQ(camera_error("camera: {fps: 15}\n"), "(no error)");
}

TEST(YamlReader, UnknownKeysAreRefusedNamingTheKnownOnes) {
  EXPECT_EQ(camera_error("camera:\n  fps: 15\n  fsp: 15\n"),
            "cam.yaml:3: camera.fsp: expected a known key (depth_noise, fps), got unknown key");
  EXPECT_EQ(camera_error("camera: {}\nlight: {}\n"),
            "cam.yaml:2: light: expected a known key (camera), got unknown key");
  // keys() refuses an unknown key before any value is read.
  const yaml::ReadContext ctx{"c.yaml"};
  const YAML::Node root = yaml::parse("name: 3\nspeed: x\n", ctx);
  EXPECT_EQ(config_error([&] {
              yaml::MapReader r(root, ctx, "");
              r.keys({"name"});
            }),
            "c.yaml:2: speed: expected a known key (name), got unknown key");
}

TEST(YamlReader, RequiredTextAndSyntaxErrors) {
  const yaml::ReadContext ctx{"c.yaml"};
  const YAML::Node root = yaml::parse("s:\n  other: 1\n  empty: ''\n", ctx);
  yaml::MapReader top(root, ctx, "");
  const YAML::Node s = top.child("s");
  yaml::MapReader r(s, ctx, "s");
  EXPECT_EQ(config_error([&] { r.text("name", true); }), "c.yaml:2: s.name: expected a value (required)");
  EXPECT_EQ(config_error([&] { r.text("empty", false); }), "c.yaml:3: s.empty: expected a non-empty string");
  EXPECT_EQ(r.text("absent", false), "");
  EXPECT_EQ(
      config_error([] { yaml::parse("a: 1\nb: [1, 2\n", yaml::ReadContext{"s.yaml"}); }).rfind("s.yaml:", 0),
      0u);
  EXPECT_NE(config_error([] {
              yaml::parse("a: 1\nb: [1, 2\n", yaml::ReadContext{"s.yaml"});
            }).find(": (syntax): expected valid YAML, got "),
            std::string::npos);
}

// A document merged from several files places its keys itself; a key given
// twice is named at its own line in the file parsed.
TEST(YamlReader, AKeyLocatorPlacesTheKeysOfAMergedDocument) {
  const LineFortyTwo locator;
  const yaml::ReadContext ctx{"day.yaml", &locator};
  EXPECT_EQ(config_error([&] { read_camera(yaml::parse("camera: {fps: 0}\n", ctx), ctx); }),
            "base.yaml:42: camera.fps: expected a value in [1, 240], got 0");
  EXPECT_EQ(config_error([&] { yaml::parse("\na: 1\na: 2\n", ctx); }),
            "day.yaml:3: a: expected each key once in its section (first given at line 2), got a second a");
}

// JSON read back (metrics.json): IoError in the same format, a quoted
// number is a string, a key given twice is refused.
TEST(YamlReader, JsonIsReadStrictlyWithIoErrors) {
  const yaml::ReadContext json{"m.json", nullptr, yaml::ErrorKind::kIo, true};
  EXPECT_EQ(
      io_error([&] { yaml::parse("{\"frames\": 3,\n \"frames\": 4}\n", json); }),
      "m.json:2: frames: expected each key once in its section (first given at line 1), got a second frames");
  const YAML::Node root = yaml::parse("{\"a\": \"0.5\", \"b\": 0.5,\n \"c\": true}", json);
  double v = 0;
  EXPECT_FALSE(yaml::decode_number(root["a"], json, &v));
  EXPECT_TRUE(yaml::decode_number(root["b"], json, &v));
  EXPECT_EQ(yaml::shown(root["a"], json), "the string \"0.5\"");
  yaml::MapReader r(root, json, "x");
  EXPECT_EQ(io_error([&] { r.number("a", 0, 0, 1); }),
            "m.json:1: x.a: expected a number, got the string \"0.5\"");
  EXPECT_EQ(io_error([&] { r.text("d", true); }), "m.json:1: x.d: missing");
  EXPECT_EQ(io_error([&] { yaml::parse("{\"a\": [1,\n", json); }).rfind("m.json:", 0), 0u);
  EXPECT_NE(io_error([&] { yaml::parse("{\"a\": [1,\n", json); }).find("not valid JSON: "),
            std::string::npos);
}

TEST(YamlReader, ScalarDecodersRefuseWhatIsNotTheirType) {
  const yaml::ReadContext ctx{"d.yaml"};
  const YAML::Node root = yaml::parse("n: .nan\ni: 1e3\ns: -1\nb: maybe\nbig: 18446744073709551615\n", ctx);
  double d = 0;
  long long i = 0;
  std::uint64_t s = 0;
  bool b = false;
  EXPECT_FALSE(yaml::decode_number(root["n"], ctx, &d));
  EXPECT_FALSE(yaml::decode_integer(root["i"], ctx, &i));
  EXPECT_FALSE(yaml::decode_seed(root["s"], ctx, &s));
  EXPECT_FALSE(yaml::decode_boolean(root["b"], ctx, &b));
  EXPECT_TRUE(yaml::decode_seed(root["big"], ctx, &s));
  EXPECT_EQ(s, 18446744073709551615ull);
}
