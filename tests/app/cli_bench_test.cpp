// `obscura bench-rays --passes / --frame` as a smoke test on the Cornell box at a tiny size: the
// figures it prints are positive and consistent with each other (it is the speed benchmark of
// issue 10; speed itself is never asserted by a test, docs/BENCHMARKS.md records it).
#include <string>

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/cli_runner.h"
#include "gpu_test.h"

namespace obscura::test {
namespace {

using CliBench = CliTest;

// The last line of the output: --json prints one line (warnings may come before it).
nlohmann::json lastJsonLine(const std::string& output) {
  const auto end = output.find_last_not_of('\n');
  const auto start = output.rfind('\n', end);
  return nlohmann::json::parse(output.substr(start == std::string::npos ? 0 : start + 1, end + 1));
}

TEST_F(CliBench, PassesAndFrameFiguresArePositiveAndConsistent) {
  // Embree's threads flush denormals; the command runs in this process and must leave its mode
  // as it found it (left flushing, a later recovery merged other pixels).
  constexpr unsigned kFlushModes = _MM_FLUSH_ZERO_MASK | _MM_DENORMALS_ZERO_MASK;
  [[maybe_unused]] const unsigned modeBefore = _mm_getcsr() & kFlushModes;
  const auto r = runObscura("bench-rays " + cornellBox() +
                            " --rays 4096 --repeats 1 --verify 512 --json --passes 24x24 --frame 20x16 --frame-dmax 0.5"
                            " --frame-spp 4 --lanes 32x24 --baseline embree");
#ifndef OBSCURA_HAVE_EMBREE
  EXPECT_NE(r.exitCode, 0);
  EXPECT_CONTAINS(r.output, "without Embree");
#else
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_EQ(_mm_getcsr() & kFlushModes, modeBefore) << "bench-rays left this thread flushing denormals";
  const nlohmann::json j = lastJsonLine(r.output);

  // --passes: the paper's budget (8 spp, 5 shadow and 5 obscurance rays per hit) at 24x24, the
  // image as `render -o out.png` makes it: its passes, then compose and tonemap.
  const nlohmann::json& passes = j.at("passes");
  EXPECT_GT(passes.at("wall_s").get<double>(), 0.0);
  const nlohmann::json& perPass = passes.at("per_pass");
  double sumMs = 0.0;
  for (const char* pass : {"compose", "tonemap"}) {
    EXPECT_GT(perPass.at(pass).at("gpu_ms").get<double>(), 0.0) << pass;
    sumMs += perPass.at(pass).at("gpu_ms").get<double>();
  }
  for (const char* pass : {"primary", "shadow", "obscurance"}) {
    const nlohmann::json& p = perPass.at(pass);
    EXPECT_GT(p.at("gpu_ms").get<double>(), 0.0) << pass;
    EXPECT_GT(p.at("mrays_per_s").get<double>(), 0.0) << pass;
    EXPECT_GT(p.at("ratio_vs_bench_rays").get<double>(), 0.0) << pass;
    sumMs += p.at("gpu_ms").get<double>();
  }
  EXPECT_GE(passes.at("gpu_ms").get<double>(), sumMs * (1.0 - 1e-9));
  // One camera ray per pixel and sample, four emitter-edge probes per pixel, and 16 emission rays
  // a sample in each pixel the lamp's edge crosses (render --emission-samples auto, the default).
  const auto primaryRays = perPass.at("primary").at("rays").get<std::uint64_t>();
  const std::uint64_t budgetCameraRays = 24u * 24u * 8u, probes = 4u * 24u * 24u;
  EXPECT_GT(primaryRays, budgetCameraRays + probes) << "the lamp's edge crosses some pixels";
  EXPECT_EQ((primaryRays - budgetCameraRays - probes) % (16u * 8u), 0u) << primaryRays;
  EXPECT_EQ(perPass.at("shadow").at("bench_rays_kind"), "shadow");
  EXPECT_EQ(perPass.at("obscurance").at("bench_rays_kind"), "closest");
  // Each camera ray that hits (the box is open to the camera: not all) takes 5 shadow and 5
  // obscurance rays, and each obscurance ray that meets nothing within dMax one more (the box is
  // open: dark escapes, the default).
  const auto obscuranceRays = perPass.at("obscurance").at("rays").get<std::uint64_t>();
  const auto shadowRays = perPass.at("shadow").at("rays").get<std::uint64_t>();
  EXPECT_EQ(shadowRays % 5u, 0u);
  EXPECT_GT(shadowRays, 24u * 24u * 8u * 5u / 2u);
  EXPECT_LE(shadowRays, 24u * 24u * 8u * 5u);
  EXPECT_GT(obscuranceRays, shadowRays) << "some rays miss within dMax and are traced on";
  EXPECT_LE(obscuranceRays, 2u * shadowRays);
  // The ratio is the pass's rate over bench-rays' rate of its kind, printed in the same run.
  const nlohmann::json& shadow = perPass.at("shadow");
  EXPECT_NEAR(shadow.at("ratio_vs_bench_rays").get<double>(),
              shadow.at("mrays_per_s").get<double>() / j.at("shadow_mrays_per_s").get<double>(), 1e-9);

  // --frame: the obscurance-only frame by Obscura and by Embree, the same rays on both sides.
  ASSERT_EQ(j.at("frames").size(), 1u);
  const nlohmann::json& f = j.at("frames").at(0);
  const std::uint64_t cameraRays = 20u * 16u * 4u;
  EXPECT_EQ(f.at("obscura_primary_rays").get<std::uint64_t>(), cameraRays);
  EXPECT_EQ(f.at("embree_primary_rays").get<std::uint64_t>(), cameraRays);
  // 5 per hit on both sides; the hits are those of the same camera rays (Embree's triangle test is
  // not watertight, so an edge pixel could differ: 1 % leeway, far below the open front's share).
  const auto oursRays = f.at("obscura_obscurance_rays").get<std::uint64_t>();
  EXPECT_GT(oursRays, cameraRays * 5u / 2u);
  EXPECT_LE(oursRays, cameraRays * 5u);
  EXPECT_NEAR(static_cast<double>(f.at("embree_obscurance_rays").get<std::uint64_t>()), static_cast<double>(oursRays),
              0.01 * static_cast<double>(oursRays));
  for (const char* key : {"obscura_gpu_ms", "obscura_primary_ms", "obscura_obscurance_ms", "embree_ms",
                          "ratio_vs_embree", "cpu_ratio_vs_embree"})
    EXPECT_GT(f.at(key).get<double>(), 0.0) << key;
  EXPECT_NEAR(f.at("obscura_gpu_ms").get<double>(),
              f.at("obscura_primary_ms").get<double>() + f.at("obscura_obscurance_ms").get<double>(), 1e-6);
  EXPECT_NEAR(f.at("ratio_vs_embree").get<double>(),
              f.at("embree_ms").get<double>() / f.at("obscura_gpu_ms").get<double>(), 1e-9);
  // Both images are W = mean rho(d) over the same rays: the box is flat-shaded, so the shading
  // normal the GPU samples around is the geometric one Embree gives, and the directions agree up
  // to float rounding. Only a ray whose hit flips by rounding may differ: 0.005 of W's range
  // (linear instead of sqrt rho on Embree's side moves the mean by 0.027).
  const double wOurs = f.at("obscura_mean_obscurance").get<double>();
  EXPECT_GT(wOurs, 0.05);
  EXPECT_LT(wOurs, 0.95);
  EXPECT_NEAR(wOurs, f.at("embree_mean_obscurance").get<double>(), 0.005);

  // --lanes: the same rays in every order (camera: 32 x 24; obscurance: equal across orders), a
  // group's longest ray at least its mean, so utilisation in (0, 1].
  const nlohmann::json& lanes = j.at("lanes");
  ASSERT_EQ(lanes.size(), 6u);
  EXPECT_EQ(lanes.at(0).at("rays").get<std::uint64_t>(), 768u);
  EXPECT_EQ(lanes.at(1).at("rays").get<std::uint64_t>(), 768u);
  for (std::size_t k = 2; k < lanes.size(); ++k)
    EXPECT_EQ(lanes.at(k).at("rays"), lanes.at(2).at("rays")) << lanes.at(k).at("order");
  for (const auto& l : lanes) {
    EXPECT_GT(l.at("mean_steps").get<double>(), 0.0) << l.at("order");
    EXPECT_GT(l.at("utilisation").get<double>(), 0.0) << l.at("order");
    EXPECT_LE(l.at("utilisation").get<double>(), 1.0) << l.at("order");
  }
#endif
}

TEST_F(CliBench, BadPassesAndFrameOptionsAreRefusedByName) {
  auto r = runObscura("bench-rays " + cornellBox() + " --rays 64 --passes 24by24");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_CONTAINS(r.output, "--passes 24by24");
  r = runObscura("bench-rays " + cornellBox() + " --rays 64 --frame 20x0 --baseline embree");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_CONTAINS(r.output, "--frame 20x0");
  r = runObscura("bench-rays " + cornellBox() + " --rays 64 --frame 20x16");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_CONTAINS(r.output, "--baseline embree");
  r = runObscura("bench-rays " + cornellBox() + " --rays 64 --frame 20x16 --frame-dmax -1 --baseline embree");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_CONTAINS(r.output, "--frame-dmax");
}

// Another trace.comp shape (here a GPU's, one ray per invocation) traces the same answers.
TEST_F(CliBench, TraceShapeOptionTracesWithThatShapeAndVerifies) {
  const auto r = runObscura("bench-rays " + cornellBox() + " --rays 2048 --repeats 1 --verify 2048 --json --trace-shape 64x1");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const nlohmann::json j = lastJsonLine(r.output);
  EXPECT_EQ(j.at("trace_workgroup_size").get<int>(), 64);
  EXPECT_EQ(j.at("trace_rays_per_invocation").get<int>(), 1);
  EXPECT_EQ(j.at("mismatches").get<int>(), 0);
  EXPECT_EQ(j.at("float_precision_differences").get<int>(), 0); // lavapipe computes as the CPU does
  EXPECT_GT(j.at("closest_hit_fraction").get<double>(), 0.0);
}

// --stack-registers 0 traces with the general kernel, --bvh-items storage reads the BVH as an
// SSBO: the same answers; too few registers for the BVH is refused by name.
TEST_F(CliBench, StackAndBvhItemOptionsTraceTheSameAnswersAndTooFewRegistersAreRefused) {
  for (const char* option : {"--stack-registers 0", "--bvh-items storage"}) {
    const auto r = runObscura("bench-rays " + cornellBox() + " --rays 2048 --repeats 1 --verify 2048 --json " + option);
    ASSERT_EQ(r.exitCode, 0) << option << r.output;
    EXPECT_EQ(lastJsonLine(r.output).at("mismatches").get<int>(), 0) << option;
  }
  const auto r = runObscura("bench-rays " + sharedScene("modern-hall/modern-hall.gltf") + " --rays 64 --stack-registers 1");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_CONTAINS(r.output, "--stack-registers 1: this BVH (depth 9) needs 2");
}

TEST_F(CliBench, BadTraceShapeIsRefusedByName) {
  for (const char* shape : {"128", "100x1", "32x65", "1024x64"}) {
    const auto r = runObscura("bench-rays " + cornellBox() + " --rays 64 --trace-shape " + shape);
    EXPECT_NE(r.exitCode, 0) << shape;
    EXPECT_CONTAINS(r.output, std::string("--trace-shape ") + shape);
  }
}

} // namespace
} // namespace obscura::test
