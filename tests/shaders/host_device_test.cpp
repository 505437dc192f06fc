// The one header shared by C++ and GLSL (shaders/shared/host_device.h): sizes and offsets on the
// host, and a GPU readback that proves GLSL lays the structs out the same way.
#include <cstddef>
#include <cstring>

#include <gtest/gtest.h>

#include "gpu/buffer.h"
#include "gpu/kernel.h"
#include "gpu_test.h"
#include "shared/host_device.h"
#include "layout_test.spv.h"
#include "shared/host_device.h"

namespace obscura::gpu {
static_assert(sizeof(BvhNode) == 80 && offsetof(BvhNode, qz) == 64 && sizeof(BvhNode) == kTexelsPerNode * 16);
static_assert(sizeof(BvhBinaryNode) == 64 && offsetof(BvhBinaryNode, rightHi) == 48 && sizeof(BvhBinaryNode) == kTexelsPerBinaryNode * 16);
static_assert(sizeof(BvhTriangle) == 48 && sizeof(BvhTriangle) == kTexelsPerTriangle * 16);
static_assert(sizeof(TriangleShading) == 80 && offsetof(TriangleShading, uv2) == 64);
static_assert(sizeof(GpuMaterial) == 80 && offsetof(GpuMaterial, textures) == 48 &&
              offsetof(GpuMaterial, meanAlbedo) == 64);
static_assert(sizeof(GpuLight) == 64 && offsetof(GpuLight, params) == 48);
static_assert(sizeof(GpuEmitter) == 64 && offsetof(GpuEmitter, radiance) == 48);
static_assert(sizeof(GpuLightNode) == 64 && offsetof(GpuLightNode, refs) == 48);
static_assert(sizeof(GpuTexture) == 16);
static_assert(sizeof(GpuRay) == 32);
static_assert(sizeof(GpuHit) == 16 && offsetof(GpuHit, primitive) == 12);
static_assert(sizeof(GpuCamera) == 64);
static_assert(sizeof(GBufferTexel) == 64 && offsetof(GBufferTexel, albedo) == 48);
static_assert(sizeof(PrimaryPush) == 112 && offsetof(PrimaryPush, firstSample) == 96 && sizeof(PrimaryPush) <= 128);
static_assert(sizeof(TracePush) == 16);
static_assert(sizeof(PathPush) == 128 && offsetof(PathPush, firstRow) == 96 && offsetof(PathPush, firstSample) == 116);
static_assert(sizeof(ShadePush) == 112 && offsetof(ShadePush, averageReflectance) == 48 && offsetof(ShadePush, pathDepth) == 60 &&
              offsetof(ShadePush, firstRow) == 80 && offsetof(ShadePush, kappa) == 96 && sizeof(ComposePush) == 32 &&
              offsetof(ComposePush, specular) == 28);
static_assert(sizeof(TonemapPush) == 24 && sizeof(ResolvePush) == 32 && sizeof(DirtyPush) == 224 && sizeof(ClearPush) == 16 &&
              sizeof(LightMixPush) == 32 && offsetof(LightMixPush, exposureScale) == 28 && sizeof(DirtyStagePush) == 4);
static_assert(kBvhStackSize >= kBvhMaxDepth, "the traversal stack must hold the deepest path");
static_assert(kMaxTraversalSteps < 65535u, "must stop before lavapipe's loop limiter");
} // namespace obscura::gpu

namespace obscura::test {
namespace {

struct LayoutBlock {
  gpu::BvhNode node;
  gpu::BvhTriangle triangle;
  gpu::TriangleShading shading;
  gpu::GpuMaterial material;
  gpu::GpuTexture texture;
  gpu::GpuRay ray;
  gpu::GpuHit hit;
  gpu::GpuCamera camera;
  gpu::GBufferTexel gtexel;
  gpu::PrimaryPush primaryPush;
  gpu::TracePush tracePush;
  gpu::GpuLight light;
  gpu::GpuEmitter emitter;
  gpu::ShadePush shadePush;
};
static_assert(sizeof(LayoutBlock) == 212 * 4);

class HostDeviceLayout : public GpuTest {};

TEST_F(HostDeviceLayout, GlslWritesEveryFieldWhereCppReadsIt) {
  using Usage = vk::BufferUsageFlagBits;
  gpu::Kernel kernel(context(), {.name = "layout_test", .spirv = kSpirv_layout_test,
                                 .bindings = {gpu::BindingKind::StorageBuffer}});
  gpu::Buffer out(context(), sizeof(LayoutBlock), Usage::eStorageBuffer, "test.layout");
  kernel.bind(0, out);
  context().submitAndWait([&](const vk::raii::CommandBuffer& cmd) { kernel.dispatch(cmd, 1, 1, 1); });
  LayoutBlock block{};
  out.download(context(), &block, sizeof(block));
  // Word i holds the value i (as float, int or uint as the field's type says).
  const auto* words = reinterpret_cast<const std::uint32_t*>(&block);
  const std::size_t intWords[] = {64,  65,  66,  67,  72,  73,  74,  75,  87,  136, 137, 138, 139, 140, 141, 142,
                                  143, 144, 145, 146, 147, 148, 149, 150, 151, 160, 161, 162, 163, 184, 185, 186,
                                  187, 188, 189, 190, 191, 204, 205, 206, 207};
  for (std::size_t i = 0; i < sizeof(LayoutBlock) / 4; ++i) {
    bool isInt = std::find(std::begin(intWords), std::end(intWords), i) != std::end(intWords);
    if (isInt) {
      EXPECT_EQ(words[i], i) << "word " << i;
    } else {
      float f;
      std::memcpy(&f, &words[i], 4);
      EXPECT_EQ(f, static_cast<float>(i)) << "word " << i;
    }
  }
  EXPECT_EQ(block.hit.primitive, 87u);
  EXPECT_EQ(block.material.textures.w, 67);
  EXPECT_EQ(block.material.meanAlbedo.x, 68.0f);
  EXPECT_EQ(block.primaryPush.width, 136u);
  EXPECT_EQ(block.gtexel.albedo.w, 119.0f);
  EXPECT_EQ(block.primaryPush.flags, 143u);
  EXPECT_EQ(block.primaryPush.firstSample, 144u);
  EXPECT_EQ(block.shadePush.renderFlags, 191u);
  EXPECT_EQ(block.shadePush.averageReflectance.z, 198.0f);
  EXPECT_EQ(block.shadePush.pathDepth, 199.0f);
  EXPECT_EQ(block.shadePush.sceneSize, 203.0f);
  EXPECT_EQ(block.shadePush.light, 207u);
  EXPECT_EQ(block.shadePush.unmarkedFirstBounce, 211.0f);
  EXPECT_EQ(block.light.info.x, 160u);
  EXPECT_EQ(block.emitter.radiance.w, 183.0f);
}

TEST_F(HostDeviceLayout, KernelRefusesPushConstantsOfAnotherSize) {
  // layout_test.comp declares no push constants: a 16-byte struct is a programming error, named.
  gpu::Kernel kernel(context(), {.name = "layout_test", .spirv = kSpirv_layout_test,
                                 .bindings = {gpu::BindingKind::StorageBuffer}});
  gpu::Buffer out(context(), sizeof(LayoutBlock), vk::BufferUsageFlagBits::eStorageBuffer, "test.layout");
  kernel.bind(0, out);
  try {
    context().submitAndWait([&](const vk::raii::CommandBuffer& cmd) { kernel.dispatch(cmd, 1, 1, 1, gpu::TracePush{}); });
    FAIL() << "a push-constant struct of the wrong size was recorded";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("layout_test: push constants of 16 bytes for a kernel that declares 0"),
              std::string::npos)
        << e.what();
  }
}

} // namespace
} // namespace obscura::test
