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
static_assert(sizeof(PrimaryPush) == 112 && offsetof(PrimaryPush, accumulation) == 96 && sizeof(PrimaryPush) <= 128);
static_assert(sizeof(TracePush) == 16);
static_assert(sizeof(PathPush) == 112 && offsetof(PathPush, band) == 96 && sizeof(PathPush) <= 128);
static_assert(sizeof(ShadePush) == 112 && offsetof(ShadePush, reflectors) == 96 && sizeof(ComposePush) == 48);
static_assert(sizeof(TonemapPush) == 48 && sizeof(ResolvePush) == 48 && sizeof(DirtyPush) == 224 && sizeof(ClearPush) == 16 && sizeof(LightMixPush) == 32);
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
};
static_assert(sizeof(LayoutBlock) == 184 * 4);

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
  const std::size_t intWords[] = {64, 65, 66, 67, 72, 73, 74, 75, 87, 136, 137, 138, 139, 140, 141, 142, 143,
                                  144, 145, 146, 147, 148, 149, 150, 151, 160, 161, 162, 163};
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
  EXPECT_EQ(block.primaryPush.frame.x, 136u);
  EXPECT_EQ(block.gtexel.albedo.w, 119.0f);
  EXPECT_EQ(block.primaryPush.band.w, 143u);
  EXPECT_EQ(block.primaryPush.accumulation.x, 144u);
  EXPECT_EQ(block.light.info.x, 160u);
  EXPECT_EQ(block.emitter.radiance.w, 183.0f);
}

} // namespace
} // namespace obscura::test
