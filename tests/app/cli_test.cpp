// The `obscura` command as a user runs it: good input renders; bad input gets a message naming
// the file and the problem, a non-zero exit, and no output or temporary file left behind.
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <tuple>
#include <map>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/cli_runner.h"
#include "gpu_test.h"

namespace obscura::test {
namespace {
namespace fs = std::filesystem;

class Cli : public CliTest {
protected:
  // Files in the test folder other than `allowed`.
  std::vector<std::string> strayFiles(const std::string& allowed = "") const {
    return allowed.empty() ? CliTest::strayFiles() : CliTest::strayFiles({allowed});
  }
};

TEST_F(Cli, RendersTheDefaultSceneToPngAndExrWithMetrics) {
  auto r = runObscura("render " + repoPath("scenes/cornell-box/cornell-box.gltf") + " -o " + path("c.exr") +
                      " --width 32 --height 32 --spp 2 --metrics " + path("m.json"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_TRUE(fs::exists(path("c.exr")));
  EXPECT_TRUE(fs::exists(path("m.json")));
  std::ifstream metrics(path("m.json"));
  std::string text((std::istreambuf_iterator<char>(metrics)), std::istreambuf_iterator<char>());
  for (const char* key : {"\"device\"", "\"bvh\"", "\"build_s\"", "\"gpu_ms\"", "\"mrays_per_s\"", "\"rays\""})
    EXPECT_NE(text.find(key), std::string::npos) << key;
  r = runObscura("render " + repoPath("scenes/cornell-box/cornell-box.gltf") + " -o " + path("c.png") +
                 " --width 32 --spp 1 --aov albedo");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_TRUE(fs::exists(path("c.png")));
}

// A small study end to end: every method's curve in the CSV, each obscurance method's speed-up in
// three error measures and the bias floor in the summary, the equal-time PNGs, and a second run
// that takes both references from the cache. With emission rays, the same method without them too.
TEST_F(Cli, ConvergeReportsEveryMethodInEveryMeasure) {
  const std::string args = "converge " + cornellBox() + " -o " + path("study") +
                           " --width 16 --max-spp 16 --pt-max-spp 8 --reference-factor 4 --secondary-reflectors 1"
                           " --emission-samples 4 --pt-emission-samples 2";
  auto r = runObscura(args);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  for (const char* part : {"equal-noise speed-up", "bias floor", "crossover", "rmse_trimmed", "equal time",
                           "bias floor with secondary reflectors", "total error against path tracing's at equal time"})
    EXPECT_CONTAINS(r.output, part);
  std::ifstream csv(path("study/cornell-box.convergence.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_CONTAINS(line, "mae_noise");
  std::map<std::string, int> rows;
  while (std::getline(csv, line)) ++rows[line.substr(0, line.find(','))];
  const std::map<std::string, int> expected = { // 1 ... 16 spp; path tracing 1 ... 8
      {"obscurance", 5}, {"obscurance-uncorrected", 5}, {"obscurance-primary-emission", 5}, {"obscurance-paper", 5},
      {"obscurance-5+5", 5}, {"obscurance-per-hit-vertices", 5}, {"obscurance-realtime", 5},
      {"obscurance-reflectors", 5}, {"obscurance-denoised", 5}, {"obscurance-realtime-denoised", 5}, {"pathtrace", 4}};
  EXPECT_EQ(rows, expected);
  std::ifstream json(path("study/cornell-box.convergence.json"));
  std::string text((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  for (const char* key : {"\"obscurance-paper\"", "\"obscurance-realtime\"", "\"obscurance-reflectors\"",
                          "\"obscurance-denoised\"", "\"obscurance-realtime-denoised\"",
                          "\"bias_floor_obscurance-reflectors\"", "\"equal_noise_speedup\"",
                          "\"mean_ratio\"", "\"crossover_ms\"", "\"rmse_trimmed\"", "\"obscurance-uncorrected\"",
                          "\"worst_total_error_ratio_at_equal_time\""})
    EXPECT_CONTAINS(text, key);
  for (const char* png : {"study/cornell-box.obscurance-budget.png", "study/cornell-box.pathtrace-equal-time.png",
                          "study/cornell-box.convergence.png"})
    EXPECT_TRUE(fs::exists(path(png))) << png;
  // Each reference's own noise (its two halves' difference) is stated, and every curve point within
  // twice it, in a measure, is marked at the floor in that measure and in no other.
  EXPECT_CONTAINS(r.output, "own noise (from its two halves)");
  const nlohmann::json summary = nlohmann::json::parse(text);
  EXPECT_TRUE(summary.at("methods").at("obscurance-denoised").contains("undenoised_at_equal_time"));
  const nlohmann::json& floors = summary.at("reference_noise");
  ASSERT_TRUE(floors.contains("obscurance") && floors.contains("pathtrace")) << floors.dump();
  std::ifstream rowsAgain(path("study/cornell-box.convergence.csv"));
  std::getline(rowsAgain, line);
  EXPECT_CONTAINS(line, "noise_at_reference_floor");
  int marked = 0; // points at the floor (0 or more: the references have 4x the curves' samples)
  while (std::getline(rowsAgain, line)) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    if (line.back() == ',') cells.emplace_back();
    ASSERT_EQ(cells.size(), 13u) << line;
    if (cells[0] == "obscurance-reflectors") continue; // measured against a reference of its own
    // The defaults' 16-spp frame is corrected by 8 paths: it converges to path tracing's image, and
    // is measured against its reference.
    const bool againstPaths = cells[0] == "pathtrace" || (cells[0] == "obscurance" && cells[1] == "16");
    const nlohmann::json& own = floors.at(againstPaths ? "pathtrace" : "obscurance");
    std::string expected;
    for (const auto& [key, column, measure] : {std::tuple{"rmse", 4, "rmse"}, std::tuple{"trimmed", 7, "rmse_trimmed"},
                                               std::tuple{"mae", 6, "mae"}})
      if (std::stod(cells[column]) < 2.0 * own.at(measure).get<double>())
        expected += expected.empty() ? key : std::string("+") + key;
    EXPECT_EQ(cells[12], expected) << line;
    marked += !expected.empty();
  }
  (void)marked;
  // References no more converged than the curves' last points: the budget's noise is named as the
  // reference's, no speed-up read from it.
  const auto flat = runObscura("converge " + cornellBox() + " -o " + path("flat") +
                               " --width 16 --max-spp 8 --pt-max-spp 8 --reference-factor 1");
  ASSERT_EQ(flat.exitCode, 0) << flat.output;
  EXPECT_CONTAINS(flat.output, "of its reference's own noise");
  EXPECT_CONTAINS(flat.output, "no speed-up is read");
  r = runObscura(args);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_CONTAINS(r.output, "reference obscurance: cached");
  EXPECT_CONTAINS(r.output, "reference pathtrace: cached");
  EXPECT_CONTAINS(r.output, "reference obscurance-reflectors: cached");
}

TEST_F(Cli, MissingSceneNamesTheFile) {
  auto r = runObscura("render " + path("nope.gltf") + " -o " + path("out.png"));
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("nope.gltf"), std::string::npos) << r.output;
  EXPECT_TRUE(strayFiles().empty());
}

TEST_F(Cli, MalformedSceneIsRejectedWithoutOutput) {
  std::ofstream(path("bad.gltf")) << "{ \"asset\": { \"version\": \"2.0\" }, \"meshes\": [ ";
  auto r = runObscura("render " + path("bad.gltf") + " -o " + path("out.exr"));
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("bad.gltf"), std::string::npos) << r.output;
  EXPECT_EQ(strayFiles("bad.gltf"), std::vector<std::string>{});
}

TEST_F(Cli, BadFlagsAreRefused) {
  const std::string scene = repoPath("scenes/cornell-box/cornell-box.gltf");
  for (const std::string flags : {"--spp 0", "--spp -3", "--width 0", "--height 0", "--aov nonsense", "--camera 7"}) {
    auto r = runObscura("render " + scene + " -o " + path("out.png") + " " + flags);
    EXPECT_NE(r.exitCode, 0) << flags << "\n" << r.output;
    EXPECT_FALSE(r.output.empty()) << flags;
    EXPECT_TRUE(strayFiles().empty()) << flags;
  }
  auto r = runObscura("render " + scene + " -o " + path("out.jpg"));
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.output.find("out.jpg"), std::string::npos) << r.output;
}

TEST_F(Cli, UnwritableOutputLeavesNothingBehind) {
  auto r = runObscura("render " + repoPath("scenes/cornell-box/cornell-box.gltf") + " --width 16 --spp 1 -o " +
                      path("missing-folder/out.png"));
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("missing-folder"), std::string::npos) << r.output;
  EXPECT_TRUE(strayFiles().empty());
}

TEST_F(Cli, ResolutionBeyondDeviceMemoryIsRefusedUpFront) {
  auto r = runObscura("render " + repoPath("scenes/cornell-box/cornell-box.gltf") + " --width 16384 --height 16384 -o " +
                      path("huge.exr"));
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("MiB"), std::string::npos) << r.output;
  EXPECT_TRUE(strayFiles().empty());
}

TEST_F(Cli, DeviceSelection) {
  const std::string scene = repoPath("scenes/cornell-box/cornell-box.gltf");
  auto r = runObscura("render " + scene + " --width 16 --spp 1 -o " + path("a.png") + " --device 0");
  EXPECT_EQ(r.exitCode, 0) << r.output;
  r = runObscura("render " + scene + " --width 16 --spp 1 -o " + path("b.png") + " --device no-such-gpu");
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("no-such-gpu"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path("b.png")));
}

TEST_F(Cli, NoVulkanDeviceIsAClearError) {
  // Point the loader at a driver manifest that does not exist: no device at all.
  auto r = runObscura("render " + repoPath("scenes/cornell-box/cornell-box.gltf") + " -o " + path("x.png") +
                      " --width 16 --spp 1");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  std::string command = "env VK_ICD_FILENAMES=/nonexistent.json VK_DRIVER_FILES=/nonexistent.json OBSCURA_VALIDATE=0 ";
  FILE* pipe = popen((command + OBSCURA_BINARY_PATH + " render " + repoPath("scenes/cornell-box/cornell-box.gltf") +
                      " -o " + path("y.png") + " 2>&1").c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) output += buffer.data();
  int status = pclose(pipe);
  EXPECT_EQ(WEXITSTATUS(status), 3) << output;
  EXPECT_NE(output.find("Vulkan"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(path("y.png")));
}

TEST_F(Cli, InfoListsTheChosenDevice) {
  auto r = runObscura("info");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("chosen"), std::string::npos) << r.output;
}

TEST_F(Cli, BenchRaysPrintsJson) {
  auto r = runObscura("bench-rays " + repoPath("scenes/cornell-box/cornell-box.gltf") +
                      " --rays 20000 --repeats 1 --verify 2000 --json");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  for (const char* key : {"closest_mrays_per_s", "shadow_mrays_per_s", "build_s", "closest_hit_fraction",
                          "\"mismatches\":0"})
    EXPECT_NE(r.output.find(key), std::string::npos) << key << "\n" << r.output;
}

// With Embree, the same rays traced by it agree with ours and the ratio is printed; without, the
// option is refused with a message that says why.
TEST_F(Cli, BenchRaysEmbreeBaseline) {
  auto r = runObscura("bench-rays " + repoPath("scenes/cornell-box/cornell-box.gltf") +
                      " --rays 20000 --repeats 1 --json --baseline embree");
#ifdef OBSCURA_HAVE_EMBREE
  ASSERT_EQ(r.exitCode, 0) << r.output;
  for (const char* key : {"embree_closest_mrays_per_s", "embree_shadow_mrays_per_s", "embree_build_s",
                          "closest_ratio_vs_embree", "shadow_ratio_vs_embree"})
    EXPECT_NE(r.output.find(key), std::string::npos) << key << "\n" << r.output;
#else
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.output.find("without Embree"), std::string::npos) << r.output;
#endif
}

} // namespace
} // namespace obscura::test
