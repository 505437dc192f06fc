// Frame bands: a frame whose buffers would pass the device's per-buffer limit is stored in bands
// of rows, and banding never changes a pixel: the same frame split differently (or not at all)
// is bit-identical. Large frames (4K, modern-hall's 13 lights at the paper's 800x600) render on
// lavapipe.
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "core/error.h"
#include "gpu_test.h"
#include "render/frame/frame_layout.h"
#include "render/obscurance_renderer.h"
#include "render/one_shot.h"
#include "render/path_tracer.h"
#include "render/scene_data/scene_buffers.h"
#include "render/test_scenes.h"
#include "scene/gltf_loader.h"

namespace obscura::test {
namespace {

TEST(FrameLayout, BandsCoverEveryRowOnceWithinTheLimit) {
  // 100 bytes per pixel, 1000 pixels wide: 100,000 bytes a row; a 350,000-byte limit holds 3 rows.
  const auto layout = render::FrameLayout::split(1000, 10, 100, 350000, "test");
  ASSERT_EQ(layout.bandCount(), 4u);
  std::uint32_t next = 0;
  for (const auto& band : layout.bands) {
    EXPECT_EQ(band.firstRow, next);
    EXPECT_LE(std::uint64_t(band.rows) * 1000 * 100, 350000u);
    next += band.rows;
  }
  EXPECT_EQ(next, 10u);
  EXPECT_EQ(render::FrameLayout::split(1000, 10, 100, 1u << 30, "test").bandCount(), 1u);
}

TEST(FrameLayout, ARowLargerThanTheLimitIsRefusedWithTheNeed) {
  try {
    render::FrameLayout::split(16384, 4, 32 * 300, 128u << 20, "the per-light basis buffers");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("MiB"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("merge"), std::string::npos) << e.what();
  }
}

bool bitIdentical(const io::Image& a, const io::Image& b, std::string* where) {
  if (a.channels != b.channels || a.pixels.size() != b.pixels.size()) {
    *where = "different channels or size";
    return false;
  }
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    if (std::memcmp(&a.pixels[i], &b.pixels[i], 4) != 0) {
      *where = "channel " + a.channels[i % a.channels.size()] + " of pixel " + std::to_string(i / a.channels.size());
      return false;
    }
  return true;
}

class FrameBands : public GpuTest {
protected:
  void SetUp() override {
    GpuTest::SetUp();
    cornell_ = scene::loadGltf(repoPath("scenes/cornell-box/cornell-box.gltf"));
    cornellBvh_ = bvh::build(render::triangleSoup(cornell_));
  }
  render::ObscuranceSettings cornellSettings(std::uint32_t w, std::uint32_t h) const {
    render::ObscuranceSettings s;
    s.width = w;
    s.height = h;
    s.spp = 2;
    s.seed = 5;
    s.camera = cornell_.cameras.at(0);
    return s;
  }
  scene::Scene cornell_;
  bvh::Bvh cornellBvh_;
};

TEST_F(FrameBands, BandedFrameIsBitIdenticalToTheWholeFrame) {
  auto settings = cornellSettings(48, 40);
  const auto whole = renderObscurances(context(), cornell_, cornellBvh_, settings);
  // A limit that holds 9 rows of the widest buffer (the AOV accumulators, 192 bytes a pixel):
  // 5 bands, the last one shorter.
  settings.maxBufferBytes = 48ull * 192 * 9;
  render::ObscuranceRenderer banded(context(), cornell_, cornellBvh_, settings);
  ASSERT_EQ(banded.layout().bandCount(), 5u);
  banded.render();
  std::string where;
  EXPECT_TRUE(bitIdentical(whole.image, banded.image(), &where)) << where;
}

// Every band's texel views within `maxTexels`: its G-buffer (kTexelsPerGBuffer a pixel) and its
// resolved transport (a word per light slot and pixel, plus A_t, rows padded to whole texels).
void expectTexelViewsWithin(const render::ObscuranceFrame& frame, std::uint64_t maxTexels) {
  const auto& layout = frame.layout();
  for (std::size_t i = 0; i < layout.bands.size(); ++i) {
    const auto& b = frame.band(i);
    // Every view is of 16-byte texels (RGBA32F or RGBA32UI) over its whole buffer.
    for (const gpu::TexelBuffer* view : {&b.gbuffer, &b.basis, &b.emissionBasis, &b.ambient, &b.specularBasis,
                                         &b.specularAmbient, &b.resolved})
      EXPECT_LE(view->buffer().size() / 16, maxTexels) << "band " << i << ": " << view->buffer().name();
  }
}

TEST_F(FrameBands, AFrameSplitByItsTexelViewLimitIsBitIdenticalToTheWholeFrame) {
  auto settings = cornellSettings(48, 40);
  const auto whole = renderObscurances(context(), cornell_, cornellBvh_, settings);
  // The G-buffer's 4 texels a pixel bind: 9 rows of 48 pixels a band, 5 bands.
  const std::uint64_t byGBuffer = 48ull * gpu::kTexelsPerGBuffer * 9;
  settings.maxTexelElements = byGBuffer;
  render::ObscuranceRenderer gbufferBound(context(), cornell_, cornellBvh_, settings);
  EXPECT_EQ(gbufferBound.layout().bandCount(), 5u);
  expectTexelViewsWithin(gbufferBound.frame(), byGBuffer);
  gbufferBound.render();
  std::string where;
  EXPECT_TRUE(bitIdentical(whole.image, gbufferBound.image(), &where)) << where;
  // With 31 light slots (spares for lights added later) the per-light Kahan sums bind instead (a
  // vec4 pair per slot and pixel): 3 rows of 48 pixels hold 8928 texels, 14 bands; the G-buffer
  // would take 46 rows, and the resolved transport's view (checked too) needs fewer texels.
  const std::uint64_t bySums = 48ull * gpu::kAccumulatorVec4s * 31 * 3;
  settings.maxTexelElements = bySums;
  settings.spareLightSlots = 30;
  render::ObscuranceRenderer sumsBound(context(), cornell_, cornellBvh_, settings);
  ASSERT_EQ(sumsBound.frame().lightCapacity(), 31u);
  EXPECT_EQ(sumsBound.layout().bandCount(), 14u);
  expectTexelViewsWithin(sumsBound.frame(), bySums);
  sumsBound.render();
  EXPECT_TRUE(bitIdentical(whole.image, sumsBound.image(), &where)) << where;
}

TEST_F(FrameBands, BandedGlossyFrameIsBitIdenticalToTheWholeFrame) {
  // Specular paths read pixel indices from a per-band queue.
  SceneBuilder b;
  auto mirror = b.glossy(glm::vec3(0.9f), 1.0f, 0.05f);
  auto white = b.lambertian(glm::vec3(0.7f));
  auto lamp = b.lambertian(glm::vec3(0.0f), glm::vec3(4.0f));
  b.quad({-2, 0, -2}, {0, 0, 4}, {4, 0, 0}, mirror);
  b.quad({-2, 0, -2}, {4, 0, 0}, {0, 3, 0}, white);
  b.quad({-0.5f, 2.5f, -0.5f}, {1, 0, 0}, {0, 0, 1}, lamp, "lamp");
  scene::Scene s = b.build();
  bvh::Bvh tree = bvh::build(render::triangleSoup(s));
  render::ObscuranceSettings settings;
  settings.width = 32;
  settings.height = 24;
  settings.spp = 2;
  settings.camera = lookCamera({0, 1.5f, 3}, glm::normalize(glm::vec3(0, -0.4f, -1)), {0, 1, 0}, 1.0f);
  const auto whole = renderObscurances(context(), s, tree, settings);
  settings.maxBufferBytes = 32ull * 192 * 7;
  render::ObscuranceRenderer banded(context(), s, tree, settings);
  ASSERT_GT(banded.layout().bandCount(), 2u);
  ASSERT_TRUE(banded.specular());
  banded.render();
  std::string where;
  EXPECT_TRUE(bitIdentical(whole.image, banded.image(), &where)) << where;
}

TEST_F(FrameBands, BandedPathTracingIsBitIdenticalToTheWholeFrame) {
  render::PathTraceSettings settings{.width = 40, .height = 30, .spp = 2, .seed = 3, .camera = cornell_.cameras.at(0)};
  const auto whole = renderPathTraced(context(), cornell_, cornellBvh_, settings);
  render::PathTracer banded(context(), cornell_, cornellBvh_, settings, 40ull * 32 * 7);
  banded.render();
  std::string where;
  EXPECT_TRUE(bitIdentical(whole.image, banded.image(), &where)) << where;
}

// Large frames render in as many bands as lavapipe's 128 MiB buffers need (at least `minBands`),
// and (where `resplit`) a different split (a quarter of the device's limit) gives the same bits. A
// 4K Cornell box needs 4 (its 64-byte G-buffer alone is 531 MB).
enum class Resplit { Yes, No };
void expectLargeFrameRenders(const gpu::Context& context, const scene::Scene& s, const bvh::Bvh& tree,
                             render::ObscuranceSettings settings, std::uint32_t minBands, Resplit resplitToo) {
  settings.spp = 1;
  settings.shadowRays = 1;
  settings.obscuranceRays = 1;
  settings.primaryAovs = false; // a PNG of combined: what `render -o out.png` keeps
  settings.composedAovs = false;
  io::Image image;
  std::uint32_t bands = 0;
  {
    render::ObscuranceRenderer renderer(context, s, tree, settings);
    bands = renderer.layout().bandCount();
    EXPECT_GE(bands, minBands);
    renderer.render();
    EXPECT_EQ(renderer.stats().truncatedTraversals, 0u);
    image = renderer.image();
  }
  double sum = 0.0;
  for (float v : image.pixels) {
    ASSERT_TRUE(std::isfinite(v));
    sum += v;
  }
  EXPECT_GT(sum, 0.0);
  if (resplitToo == Resplit::No) return;
  settings.maxBufferBytes = context.info().maxStorageBufferRange / 4;
  render::ObscuranceRenderer resplit(context, s, tree, settings);
  EXPECT_GT(resplit.layout().bandCount(), bands);
  resplit.render();
  std::string where;
  EXPECT_TRUE(bitIdentical(image, resplit.image(), &where)) << where;
}

TEST_F(FrameBands, CornellBoxRendersAt3840x2160) {
  // Split again (half of its 13 s on 2 cores), it would check what modern-hall's resplit below checks:
  // the bands' arithmetic does not depend on the frame's size. (A 1080p frame, one band split in
  // several, checked that too, for 6 s of the suite.) One camera ray per pixel: the probe of every
  // pixel's corners for the lamp's edge (--emission-samples auto) was four of the frame's five
  // primary rays, half its time, and the banded frames above probe in bands bit for bit.
  render::ObscuranceSettings settings = cornellSettings(3840, 2160);
  settings.emissionSamples = 1;
  settings.emissionAtEdges = false;
  expectLargeFrameRenders(context(), cornell_, cornellBvh_, settings, 4u, Resplit::No);
}

TEST_F(FrameBands, ModernHallRendersAtThePapers800x600WithAllItsLights) {
  scene::Scene s = scene::loadGltf(sharedScene("modern-hall/modern-hall.gltf"));
  bvh::Bvh tree = bvh::build(render::triangleSoup(s));
  render::ObscuranceSettings settings;
  settings.width = 800;
  settings.height = 600;
  settings.camera = s.cameras.at(0);
  settings.emissionSamples = 1; // as the 4K frame's (the small banded frames probe the edges)
  settings.emissionAtEdges = false;
  render::ObscuranceRenderer probe(context(), s, tree, [&] {
    auto small = settings;
    small.width = 8;
    small.height = 6;
    return small;
  }());
  EXPECT_EQ(probe.lights().size(), 13u);
  expectLargeFrameRenders(context(), s, tree, settings, 2u, Resplit::Yes); // 13 lights' sums: 200 MB
}

} // namespace
} // namespace obscura::test
