// Long progressive accumulation [issue: 100k iterations of a constant image stay within 1e-6
// relative]: the albedo AOV of a plane of albedo 0.3 (not exactly representable in binary), over
// 100,000 samples, against the float value of 0.3. A plain float sum drifts by ~1e-4 there. The
// plane's direct light from a directional light is the same number every sample too, so its mean
// over 100,000 samples must equal one sample's: the AOVs sum in SSBOs, the lights' bases in storage
// texel buffers (OBS_ACCUMULATE and OBS_ACCUMULATE_TEXEL), and both must carry the compensation.
#include <cmath>

#include <gtest/gtest.h>

#include "render/one_shot.h"
#include "bvh/bvh.h"
#include "gpu_test.h"
#include "render/aovs.h"
#include "render/scene_data/scene_buffers.h"
#include "render/test_scenes.h"

namespace obscura::test {
namespace {

class Accumulation : public GpuTest {};

TEST_F(Accumulation, HundredThousandSamplesOfAConstantStayWithin1e6) {
  SceneBuilder b;
  auto m = b.lambertian(glm::vec3(0.3f, 0.7f, 0.1f));
  b.quad({-100, 0, -100}, {0, 0, 200}, {200, 0, 0}, m);
  b.directionalLight(glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f)), glm::vec3(1.0f), 0.7f);
  scene::Scene s = b.build();
  bvh::Bvh tree = bvh::build(render::triangleSoup(s));
  // The primary pass and one shadow ray per hit (no obscurance ray): their accumulators are under test.
  render::ObscuranceSettings settings{.width = 8, .height = 8, .spp = 1, .seed = 3,
                                      .camera = lookCamera({0, 1, 0}, {0, -1, 0}, {0, 0, -1}, 0.5f),
                                      .shadowRays = 1, .obscuranceRays = 0};
  const io::Image oneSample = test::renderObscurances(context(), s, tree, settings).image;
  settings.spp = 100000;
  io::Image image = test::renderObscurances(context(), s, tree, settings).image;
  const int albedo = image.channelIndex("albedo.R");
  const float expected[3] = {0.3f, 0.7f, 0.1f};
  double worst = 0.0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 3; ++c) {
        float v = image.at(x, y, albedo + c);
        ASSERT_TRUE(std::isfinite(v));
        worst = std::max(worst, std::abs(double(v) - expected[c]) / expected[c]);
      }
  EXPECT_LT(worst, 1e-6) << "largest relative error over all pixels and channels";
  RecordProperty("worst_relative_error", std::to_string(worst));

  const int direct = image.channelIndex("direct.R");
  ASSERT_GE(direct, 0);
  double worstDirect = 0.0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 3; ++c) {
        const float one = oneSample.at(x, y, direct + c);
        ASSERT_GT(one, 0.0f) << "the plane is lit";
        worstDirect = std::max(worstDirect, std::abs(double(image.at(x, y, direct + c)) - one) / one);
      }
  EXPECT_LT(worstDirect, 1e-6) << "largest relative error of the direct light's mean";
  RecordProperty("worst_direct_relative_error", std::to_string(worstDirect));
}

} // namespace
} // namespace obscura::test
