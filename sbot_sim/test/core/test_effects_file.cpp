// Effects files (effects_file.h): the format the workbench writes and the simulator loads; every
// bad file is a ConfigError naming the file and the field.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "sbot_sim/core/effects/effect_registry.h"
#include "sbot_sim/core/effects/effects_file.h"
#include "sbot_sim/core/errors.h"
#include "sbot_sim/core/world_config.h"

namespace sbot::test {
namespace {

std::string fieldOf(const std::string& yaml) {
  try {
    parseEffectsConfig(yaml, "effects.yaml");
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), "effects.yaml");
    return e.field();
  }
  return "<no error>";
}

TEST(EffectsFile, ParsesAndInstantiates) {
  const auto cfg = parseEffectsConfig(
      "format: sbot-effects/1\n"
      "effects:\n"
      "  - name: speed_scale\n"
      "    params: {scale: 1.04}\n"
      "    stderr: {scale: 0.002}\n"
      "  - {name: latency, params: {delay: 0.05}, note: fitted}\n",
      "effects.yaml");
  ASSERT_EQ(cfg.size(), 2u);
  EXPECT_EQ(cfg[0].name, "speed_scale");
  EXPECT_DOUBLE_EQ(cfg[0].params.at("scale"), 1.04);
  EXPECT_DOUBLE_EQ(cfg[0].stderr_.at("scale"), 0.002);
  EXPECT_EQ(cfg[1].note, "fitted");
  const auto effects = makeEffects(cfg);
  ASSERT_EQ(effects.size(), 2u);
  EXPECT_EQ(effects[0]->name(), "latency") << "pipeline order (the registry's), not the file's";
  EXPECT_EQ(effects[1]->name(), "speed_scale");
  auto* p = dynamic_cast<ParametricEffect*>(effects[0].get());
  ASSERT_NE(p, nullptr);
  EXPECT_DOUBLE_EQ(p->param("delay"), 0.05);
  EXPECT_TRUE(parseEffectsConfig("", "empty.yaml").empty()) << "an empty file means no effects";
  EXPECT_TRUE(parseEffectsConfig("effects: []", "e.yaml").empty());
}

TEST(EffectsFile, ErrorsNameTheField) {
  EXPECT_EQ(fieldOf("effects: [{name: warp_drive}]"), "effects[0].name");
  EXPECT_EQ(fieldOf("effects: [{name: speed_scale, params: {radius: 1}}]"), "effects[0].params.radius");
  EXPECT_EQ(fieldOf("effects: [{name: speed_scale, params: {scale: fast}}]"), "effects[0].params.scale");
  EXPECT_EQ(fieldOf("effects: [{name: speed_scale}, {name: latency, params: {delay: -1}}]"), "effects[1].params.delay");
  EXPECT_EQ(fieldOf("effects: [{params: {scale: 1}}]"), "effects[0].name");
  EXPECT_EQ(fieldOf("effects: [{name: latency}, {name: latency}]"), "effects[1].name");
  EXPECT_EQ(fieldOf("effects: [{name: latency, colour: red}]"), "effects[0].colour");
  EXPECT_EQ(fieldOf("effects: {name: latency}"), "effects");
  EXPECT_EQ(fieldOf("effect: []"), "effect");
  EXPECT_EQ(fieldOf("format: sbot-effects/9\neffects: []"), "format");
  EXPECT_EQ(fieldOf("effects: [{name: latency"), "") << "YAML syntax errors name the file";
  EXPECT_EQ(fieldOf("effects: [{name: [latency]}]"), "effects[0].name");
  EXPECT_EQ(fieldOf("effects: [{name: latency, params: {delay: 0.1}, stderr: {dleay: 0.01}}]"), "effects[0].stderr.dleay")
      << "a standard error for a value the file does not give";
  EXPECT_EQ(fieldOf("effects: [{name: latency, params: {delay: 0.1}}, {name: latency, delay: 1}]"), "effects[1].delay");
  EXPECT_EQ(fieldOf("effects:\n  - name: latency\n    name: speed_scale\n"), "") << "a repeated key names the file";
  EXPECT_THROW(loadEffectsFile("/nonexistent/effects.yaml"), ConfigError);
  // A folder is not an effects file (read as a stream it would be empty: "no effects").
  try {
    loadEffectsFile("/tmp");
    ADD_FAILURE() << "a folder was read as an effects file";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("is a folder, not an effects file"), std::string::npos) << e.what();
  }
  // A dimensionless parameter's unit "1" read as part of the value ("value -1 1 is outside").
  try {
    makeEffects(parseEffectsConfig("effects: [{name: speed_scale, params: {scale: -1}}]", "e.yaml"));
    ADD_FAILURE() << "scale -1 was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("value -1 is outside the physical bounds ["), std::string::npos) << e.what();
  }
}

// A per-surface parameter whose label names no surface would never act: the simulator node loaded
// `ir_reflectance: {whte_paper: 0.5}` and ran with white paper unchanged. Labels are the library's
// (knownSurfaces) and the world's own (a scenario box's surface).
TEST(EffectsFile, APerSurfaceParameterMustNameASurface) {
  const std::string path = testing::TempDir() + "effects_surfaces.yaml";
  std::ofstream(path) << "effects: [{name: ir_reflectance, params: {white_paper: 0.9, whte_paper: 0.5}}]\n";
  try {
    loadEffectsFile(path);
    FAIL() << "an unknown surface was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("effects[0].params.whte_paper"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("ir_reflectance: unknown surface 'whte_paper' (known: "), std::string::npos) << e.what();
  }
  // A label of the world's own boxes is a surface.
  TerrainConfig terrain;
  terrain.boxes.push_back({"sheet", Vec3(1, 0, 0.05), Vec3(0.1, 0.5, 0.1), 0, 0, "whte_paper"});
  EXPECT_EQ(surfaceLabels(terrain), (std::set<std::string>{"ground", "whte_paper"}));
  EXPECT_EQ(loadEffectsFile(path, surfaceLabels(terrain)).size(), 1u);
  // Effects with named parameters are not surface-checked (their names are checked by the registry).
  EXPECT_NO_THROW(checkEffectSurfaces({{"latency", {{"delay", 0.1}}, {}, ""}}, "test"));
}

TEST(EffectsFile, WriteThenReadRoundTrips) {
  const std::vector<EffectConfig> cfg{{"speed_scale", {{"scale", 1.0371}}, {{"scale", 0.0012}}, "note: with a colon"},
                                      {"motor_lag", {{"tau", 0.125}}, {}, ""}};
  const std::string path = testing::TempDir() + "effects_roundtrip.yaml";
  writeEffectsFile(path, cfg, "written by a test\nsecond line");
  const auto back = loadEffectsConfig(path);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_DOUBLE_EQ(back[0].params.at("scale"), 1.0371);
  EXPECT_DOUBLE_EQ(back[0].stderr_.at("scale"), 0.0012);
  EXPECT_EQ(back[0].note, "note: with a colon");
  EXPECT_DOUBLE_EQ(back[1].params.at("tau"), 0.125);
  std::remove(path.c_str());
}

// A fitted value is read back as the very double the fit ended with: a replay is chaotic enough
// that the 8 digits once written moved a Simple's error by 0.3 % (fit 2.3969, compare 2.4041).
TEST(EffectsFile, ParameterValuesReadBackBitForBitInTheirShortestForm) {
  // Within ir_reflectance's bounds [0.05, 5].
  const std::vector<double> values{0.1, 1.0 / 3.0, 0.084028028123456789, 1.1080143000000001, 4.9999999999999991, 0.7};
  std::map<std::string, double> params;
  for (std::size_t i = 0; i < values.size(); ++i) params["p" + std::to_string(i)] = values[i];
  const std::string yaml = effectsToYaml({{"ir_reflectance", params, {}, ""}});  // any parameter names
  EXPECT_NE(yaml.find("p0: 0.1,"), std::string::npos) << "shortest form, not 0.10000000000000001: " << yaml;
  const auto back = parseEffectsConfig(yaml, "roundtrip.yaml");
  ASSERT_EQ(back.size(), 1u);
  for (std::size_t i = 0; i < values.size(); ++i)
    EXPECT_EQ(back[0].params.at("p" + std::to_string(i)), values[i]) << "p" << i << " in " << yaml;
}

}  // namespace
}  // namespace sbot::test
