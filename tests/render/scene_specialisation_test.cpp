// The kernels that trace and shade a scene are specialised for it (SceneSpecialisation): the
// texture kinds no material uses are compiled out of their lookups, and a kernel made without a
// kind refuses a scene that uses it rather than render it without its textures.
#include <stdexcept>

#include <gtest/gtest.h>

#include "gpu_test.h"
#include "render/passes/shading_inputs.h"
#include "render/scene_data/scene_buffers.h"
#include "render/test_scenes.h"
#include "shadow.spv.h"

namespace obscura::test {
namespace {

class SceneSpecialisationTest : public GpuTest {};

// A lit floor whose material has a base-colour texture (2 x 2 texels), emission none.
scene::Scene texturedFloor() {
  SceneBuilder b;
  const std::uint32_t floor = b.lambertian(glm::vec3(1.0f));
  b.quad(glm::vec3(-1.0f, 0.0f, -1.0f), glm::vec3(0.0f, 0.0f, 2.0f), glm::vec3(2.0f, 0.0f, 0.0f), floor);
  b.pointLight(glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(1.0f), 1.0f);
  scene::Scene s = b.build();
  s.textures.push_back({.name = "checker", .width = 2, .height = 2,
                        .rgba8 = {255, 255, 255, 255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255, 255}, .srgb = true});
  s.materials[floor].baseColorTexture = 0;
  return s;
}

TEST_F(SceneSpecialisationTest, TheTextureKindsNoMaterialUsesAreLeftOut) {
  scene::Scene plain = texturedFloor();
  for (auto& m : plain.materials) m.baseColorTexture = -1;
  const render::SceneBuffers plainBuffers(context(), plain, bvh::build(render::triangleSoup(plain)));
  EXPECT_EQ(plainBuffers.specialisation().texturesAbsent, gpu::kTexturesAbsentBaseColor | gpu::kTexturesAbsentEmissive);

  const scene::Scene textured = texturedFloor();
  const render::SceneBuffers texturedBuffers(context(), textured, bvh::build(render::triangleSoup(textured)));
  EXPECT_EQ(texturedBuffers.specialisation().texturesAbsent, gpu::kTexturesAbsentEmissive);

  // Kernels for the plain scene do not hold the textured one; the general kernels hold both.
  EXPECT_FALSE(plainBuffers.specialisation().holds(texturedBuffers.specialisation()));
  EXPECT_TRUE(texturedBuffers.specialisation().holds(plainBuffers.specialisation()));
  EXPECT_TRUE(render::SceneSpecialisation{}.holds(texturedBuffers.specialisation()));
}

TEST_F(SceneSpecialisationTest, AKernelWithoutBaseColourLookupsRefusesATexturedScene) {
  const scene::Scene textured = texturedFloor();
  const render::SceneBuffers buffers(context(), textured, bvh::build(render::triangleSoup(textured)));
  render::ShadingSpecialisation withoutTextures{
      .scene = {.texturesAbsent = gpu::kTexturesAbsentBaseColor | gpu::kTexturesAbsentEmissive}};
  gpu::Kernel refused(context(), render::shadingKernelDesc("shadow", kSpirv_shadow, withoutTextures));
  EXPECT_THROW(buffers.bindTo(refused), std::logic_error);
  render::ShadingSpecialisation forTheScene{.scene = buffers.specialisation()};
  gpu::Kernel accepted(context(), render::shadingKernelDesc("shadow", kSpirv_shadow, forTheScene));
  EXPECT_NO_THROW(buffers.bindTo(accepted));
}

} // namespace
} // namespace obscura::test
