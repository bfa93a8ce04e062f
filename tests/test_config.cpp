// Scene configuration against the real scene registry: a scene file and
// `--set` overrides are checked before anything runs, and every mistake is
// one ConfigError naming the file and line (or the override), the key and
// the allowed range.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "tools/app/config.hpp"
#include "tools/app/scene/scene.hpp"

namespace {

namespace fs = std::filesystem;
using mpmvv::app::Config;
using mpmvv::app::ConfigError;
using mpmvv::app::KeySpec;

std::optional<std::vector<KeySpec>> registered_keys(const std::string& scene) {
  const mpmvv::app::SceneType* type = mpmvv::app::find_scene_type(scene);
  if (!type) return std::nullopt;
  return type->keys();
}

Config load(const std::string& path, const std::vector<std::string>& overrides = {}) {
  return mpmvv::app::load_scene_file(path, registered_keys, overrides);
}

Config ring_defaults() { return Config("ring", *registered_keys("ring")); }

// The message of the ConfigError `action` throws; fails the test if it
// throws nothing.
template <class Action>
std::string config_error(Action action) {
  try {
    action();
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no ConfigError";
  return "";
}

#define EXPECT_MENTIONS(message, text) EXPECT_NE((message).find(text), std::string::npos) << (message)

class SceneFile : public ::testing::Test {
 protected:
  void SetUp() override {
    directory_ = fs::temp_directory_path() /
                 ("mpmvv_test_config_" + std::to_string(::getpid()) + "_" +
                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(directory_);
  }
  void TearDown() override { fs::remove_all(directory_); }

  // Writes `text` to a file of that name in the test's own directory.
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path path = directory_ / name;
    std::ofstream(path) << text;
    return path.string();
  }

  fs::path directory_;
};

// ---------------------------------------------------------------- scene files

// A valid file sets its keys and records the line each came from; keys it
// does not name keep their declared defaults.
TEST_F(SceneFile, ValidFileSetsKeysWithTheirOrigin) {
  const std::string path = write("ring.toml", "scene = \"ring\"\nmethod = \"gimp\"\ncells = 48\namplitude = 1\n");
  const Config c = load(path);
  EXPECT_EQ(c.scene(), "ring");
  EXPECT_EQ(c.text("method"), "gimp");
  EXPECT_EQ(c.integer("cells"), 48);
  EXPECT_EQ(c.real("amplitude"), 1.0);  // an integer given for a real key
  EXPECT_EQ(c.origin("cells").source, path + ":3");
  EXPECT_EQ(c.text("scheme"), "usl");
  EXPECT_EQ(c.origin("scheme").source, "default");
}

// An unknown key names the file, the line and the key.
TEST_F(SceneFile, UnknownKeyNamesFileLineAndKey) {
  const std::string path = write("typo.toml", "scene = \"ring\"\ncells = 32\nceIls = 64\n");
  const std::string message = config_error([&] { load(path); });
  EXPECT_MENTIONS(message, path + ":3");
  EXPECT_MENTIONS(message, "'ceIls'");
  EXPECT_MENTIONS(message, "known keys");
}

// Out-of-range values and values of the wrong kind name the file and line,
// the key and its allowed range.
TEST_F(SceneFile, BadValueNamesKeyAndAllowedRange) {
  struct Case {
    const char* line;
    const char* key;
    const char* range;
  };
  const Case cases[] = {
      {"cells = 2", "'cells'", "an integer in [4, 20000]"},
      {"cells = \"abc\"", "'cells'", "an integer in [4, 20000]"},
      {"cells = 64.5", "'cells'", "an integer in [4, 20000]"},
      {"density = -1", "'density'", "a number > 0"},
      {"density = 0.0", "'density'", "a number > 0"},
      {"cfl = 1.5", "'cfl'", "a number in (0, 1]"},
      {"method = \"foo\"", "'method'", "one of linear, gimp, cpdi"},
      {"time_function = \"cos\"", "'time_function'", "one of cosine, sine"},
      {"end_time = \"one\"", "'end_time'", "a number > 0"},
      {"output_times = [0.5, -0.25]", "'output_times'", "a list of numbers, each > 0"},
      {"output_times = []", "'output_times'", "a list of numbers, each > 0"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.line);
    const std::string path = write("bad.toml", std::string("scene = \"ring\"\n\n") + c.line + "\n");
    const std::string message = config_error([&] { load(path); });
    EXPECT_MENTIONS(message, path + ":3");
    EXPECT_MENTIONS(message, c.key);
    EXPECT_MENTIONS(message, c.range);
  }
}

// Values TOML can hold but no key accepts name the key and the line.
TEST_F(SceneFile, UnsupportedValueTypesNameTheKey) {
  for (const char* line : {"cells = true", "output_times = [0.5, \"x\"]", "cfl = { value = 0.3 }"}) {
    SCOPED_TRACE(line);
    const std::string path = write("odd.toml", std::string("scene = \"ring\"\n") + line + "\n");
    const std::string message = config_error([&] { load(path); });
    EXPECT_MENTIONS(message, path + ":2");
    EXPECT_MENTIONS(message, std::string(line).substr(0, std::string(line).find(' ')));
  }
}

// A missing file is named.
TEST_F(SceneFile, MissingFileIsNamed) {
  const std::string path = (directory_ / "absent.toml").string();
  const std::string message = config_error([&] { load(path); });
  EXPECT_MENTIONS(message, path);
  EXPECT_MENTIONS(message, "no such scene file");
}

// A TOML syntax error gives file:line of the mistake.
TEST_F(SceneFile, SyntaxErrorGivesFileAndLine) {
  const std::string path = write("broken.toml", "scene = \"ring\"\ncells = 32\nmethod = = \"cpdi\"\n");
  const std::string message = config_error([&] { load(path); });
  EXPECT_MENTIONS(message, path + ":3:");
  EXPECT_MENTIONS(message, "TOML syntax error");
}

// A key given twice is a syntax error at its second line.
TEST_F(SceneFile, RepeatedKeyIsASyntaxError) {
  const std::string path = write("twice.toml", "scene = \"ring\"\ncells = 32\ncells = 64\n");
  EXPECT_MENTIONS(config_error([&] { load(path); }), path + ":3:");
}

// A file without a scene, or naming one the registry lacks, says so.
TEST_F(SceneFile, SceneMustBeNamedAndKnown) {
  const std::string no_scene = write("none.toml", "cells = 32\n");
  EXPECT_MENTIONS(config_error([&] { load(no_scene); }), "missing key 'scene'");
  const std::string unknown = write("other.toml", "cells = 32\nscene = \"square\"\n");
  const std::string message = config_error([&] { load(unknown); });
  EXPECT_MENTIONS(message, unknown + ":2");
  EXPECT_MENTIONS(message, "unknown scene 'square'");
}

// The shipped ring scene is valid and every key it names comes from it.
TEST_F(SceneFile, ShippedRingScenesLoad) {
  // ring.toml sets nothing but its scene: every key comes from its default.
  const Config ring = load(std::string(MPMVV_SOURCE_DIR) + "/suites/scenes/ring.toml");
  EXPECT_EQ(ring.scene(), "ring");
  EXPECT_EQ(ring.origin("cells").source, "default");
  // stiff-vortex.toml is the ring with the keys it sets, each from its line.
  const Config vortex = load(std::string(MPMVV_SOURCE_DIR) + "/suites/scenes/stiff-vortex.toml");
  EXPECT_EQ(vortex.scene(), "ring");
  EXPECT_MENTIONS(vortex.origin("cells").source, "stiff-vortex.toml:");
  EXPECT_MENTIONS(vortex.origin("output_times").source, "stiff-vortex.toml:");
  EXPECT_EQ(vortex.integer("cells"), 30);
}

// The resolved configuration a run stores (to_toml) reads back to the same
// values: every run keeps its full configuration.
TEST_F(SceneFile, ResolvedConfigurationReadsBack) {
  const std::string path = write("ring.toml", "scene = \"ring\"\nmethod = \"linear\"\namplitude = 0.3\n");
  const Config original = load(path, {"cells=40", "output_times=0.125,0.5,1", "cfl=0.2"});
  const Config reread = load(write("resolved.toml", original.to_toml()));
  for (const KeySpec& k : original.specs())
    EXPECT_EQ(mpmvv::app::format_value(reread.value(k.name)), mpmvv::app::format_value(original.value(k.name)))
        << k.name;
}

// A text value with quotes, a backslash, a tab, a newline and a non-ASCII
// letter is written escaped: the resolved configuration stays TOML, one line
// a key, and reads back to the same text.
TEST(ConfigText, AnyTextReadsBackFromTheResolvedConfiguration) {
  const std::string text = "a \"quoted\" \\ path\twith\nlines \u00e9";
  Config c("free", {KeySpec{"label", mpmvv::app::KeyKind::text, std::string("plain"), "a label"},
                    KeySpec{"size", mpmvv::app::KeyKind::real, 1.0, "a size"}});
  c.set("label", text, {"test"});
  const std::string resolved = c.to_toml();
  EXPECT_EQ(std::count(resolved.begin(), resolved.end(), '\n'), 3) << resolved;
  const toml::table t = toml::parse(resolved);
  EXPECT_EQ(t["scene"].value<std::string>(), "free");
  EXPECT_EQ(t["label"].value<std::string>(), text) << resolved;
  EXPECT_EQ(t["size"].value<double>(), 1.0) << resolved;
}

// ---------------------------------------------------------------- --set overrides

// `--set key=value` parses the value for the key's kind, trims spaces,
// overrides the file, and records where the value came from.
TEST_F(SceneFile, OverridesParseAndWin) {
  const std::string path = write("ring.toml", "scene = \"ring\"\ncells = 32\n");
  const Config c = load(path, {"cells=128", " method = gimp ", "cfl=0.25", "cfl=1"});
  EXPECT_EQ(c.integer("cells"), 128);
  EXPECT_EQ(c.origin("cells").source, "--set cells=128");
  EXPECT_EQ(c.text("method"), "gimp");
  EXPECT_EQ(c.real("cfl"), 1.0);  // the last one wins; 1 is inside (0, 1]
}

// A list override takes comma-separated numbers, with or without brackets.
TEST(ConfigOverride, OutputTimesListParses) {
  Config c = ring_defaults();
  c.set_from_text("output_times=0.25,1.0");
  EXPECT_EQ(c.reals("output_times"), (std::vector<double>{0.25, 1.0}));
  c.set_from_text("output_times=[0.1, 0.2, 0.3]");
  EXPECT_EQ(c.reals("output_times"), (std::vector<double>{0.1, 0.2, 0.3}));
  c.set_from_text("output_times=0.5");
  EXPECT_EQ(c.reals("output_times"), (std::vector<double>{0.5}));
}

// Bad overrides fail with the assignment, the key and the allowed range;
// the configuration keeps its previous value.
TEST(ConfigOverride, BadOverridesNameKeyAndRange) {
  struct Case {
    const char* assignment;
    std::vector<std::string> mentions;
  };
  const Case cases[] = {
      {"cells=abc", {"--set cells=abc", "'cells'", "an integer in [4, 20000]"}},
      {"cells=1e3", {"'cells'", "an integer in [4, 20000]"}},
      {"cells=2", {"--set cells=2", "'cells'", "[4, 20000]", "got 2"}},
      {"cells=", {"'cells'", "an integer"}},
      {"nokey=1", {"unknown key 'nokey'", "known keys"}},
      {"cells", {"--set cells", "expected key=value"}},
      {"=5", {"expected key=value"}},
      {"cfl=nan", {"'cfl'", "(0, 1]"}},
      {"cfl=0", {"'cfl'", "(0, 1]"}},
      {"method=foo", {"'method'", "one of linear, gimp, cpdi"}},
      {"output_times=0.25,abc", {"'output_times'", "a list of numbers"}},
      {"output_times=0,1", {"'output_times'", "each > 0"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.assignment);
    Config config = ring_defaults();
    const std::string before = config.to_toml();
    const std::string message = config_error([&] { config.set_from_text(c.assignment); });
    for (const std::string& m : c.mentions) EXPECT_MENTIONS(message, m);
    EXPECT_EQ(config.to_toml(), before);
  }
}

// ---------------------------------------------------------------- rules across keys

// Rules that tie keys together are checked when the case is built, before
// anything runs, and name the key and where its value came from.
TEST(SceneRules, CrossKeyRulesNameTheKey) {
  struct Case {
    std::vector<std::string> overrides;
    std::vector<std::string> mentions;
  };
  const Case cases[] = {
      // The rule is stated on outer_radius, still at its default, and names
      // where the conflicting inner_radius came from.
      {{"inner_radius=1.3"}, {"'outer_radius'", "inner_radius = 1.3 (from --set inner_radius=1.3)"}},
      {{"domain=2.6"}, {"'domain'", "--set domain=2.6"}},
      {{"lambda=-300"}, {"'lambda'", "--set lambda=-300"}},
      // h = 1 m is wider than the 0.5 m ring, with room to the walls.
      {{"domain=8", "cells=8"}, {"'cells'", "--set cells=8"}},
      {{"output_times=0.5,0.25"}, {"'output_times'", "--set output_times=0.5,0.25", "strictly increasing"}},
      // The stable step is measured on a symmetric linearization only.
      {{"time_step=stable"}, {"'time_step'", "formulation = \"total\"", "formulation = \"updated\""}},
  };
  const mpmvv::app::SceneType* ring = mpmvv::app::find_scene_type("ring");
  ASSERT_NE(ring, nullptr);
  for (const Case& c : cases) {
    SCOPED_TRACE(c.overrides.back());
    Config config = ring_defaults();
    for (const std::string& o : c.overrides) config.set_from_text(o);
    const std::string message = config_error([&] { ring->build(config); });
    for (const std::string& m : c.mentions) EXPECT_MENTIONS(message, m);
  }
}

}  // namespace

// A scene's defaults are written once, in its keys (tools/app/scenes/): a
// shipped scene file sets a key only to a value other than its default, so
// that a default changed in the code is the default every file runs with.
TEST(SceneFiles, SetOnlyWhatDiffersFromTheDefaults) {
  int files = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(std::string(MPMVV_SOURCE_DIR) + "/suites/scenes")) {
    if (entry.path().extension() != ".toml") continue;
    ++files;
    const Config file = load(entry.path().string());
    const Config defaults(file.scene(), *registered_keys(file.scene()));
    const toml::table table = toml::parse_file(entry.path().string());
    for (const auto& [key, node] : table) {
      if (key.str() == "scene") continue;
      EXPECT_NE(file.value(std::string(key.str())), defaults.value(std::string(key.str())))
          << entry.path().filename().string() << " sets " << key.str() << " to its default";
    }
  }
  EXPECT_GE(files, 12);
}
