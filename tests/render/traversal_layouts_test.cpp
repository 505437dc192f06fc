// Traversal per device (render/scene_data/bvh_layout.h): the binary layout a GPU traverses renders the
// frames lavapipe's wide layout renders, bit for bit in every AOV. Both find every hit with the
// same triangle test and the same tie rule (lower primitive id at equal t); only the order in
// which they visit boxes differs, and a shadow ray's answer does not depend on it. Run here on
// lavapipe, with one context asked for each traversal (as `--traversal` asks).
#include <bit>
#include <cstdint>
#include <string>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "gpu_test.h"
#include "render/obscurance_renderer.h"
#include "render/one_shot.h"
#include "render/path_tracer.h"
#include "render/scene_data/bvh_layout.h"
#include "render/scene_data/scene_buffers.h"
#include "render/test_scenes.h"
#include "scene/gltf_loader.h"

namespace obscura::test {
namespace {

// Pixels (over every channel) whose bits differ.
std::size_t differingValues(const io::Image& a, const io::Image& b) {
  EXPECT_EQ(a.channels, b.channels);
  EXPECT_EQ(a.pixels.size(), b.pixels.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < std::min(a.pixels.size(), b.pixels.size()); ++i)
    differ += std::bit_cast<std::uint32_t>(a.pixels[i]) != std::bit_cast<std::uint32_t>(b.pixels[i]);
  return differ;
}

class TraversalLayouts : public GpuTest {
protected:
  // A context on the same device that uploads scenes in `traversal`'s layout.
  static gpu::Context& contextFor(render::Traversal traversal) {
    static gpu::Context binary({.validate = true, .traversal = "binary"});
    static gpu::Context whileWhile({.validate = true, .traversal = "binary-while-while"});
    return traversal == render::Traversal::Binary ? binary : whileWhile;
  }
  static constexpr render::Traversal kBinaryTraversals[] = {render::Traversal::Binary,
                                                            render::Traversal::BinaryWhileWhile};
};

// Both binary loops over the same tree on the Cornell box; on modern-hall (glossy: specular paths)
// the GPU's default, the while-while over the tree a GPU builds for it (spatial splits: a triangle
// in several leaves, each leaf's box a piece of it); and the path tracer.
TEST_F(TraversalLayouts, BinaryLayoutRendersTheWideLayoutsFramesBitForBit) {
  for (const char* path : {"cornell-box/cornell-box.gltf", "modern-hall/modern-hall.gltf"}) {
    const bool hall = std::string(path).starts_with("modern-hall");
    const scene::Scene s = scene::loadGltf(sharedScene(path));
    const bvh::Bvh tree = bvh::build(render::triangleSoup(s));
    render::ObscuranceSettings settings;
    settings.width = 32;
    settings.height = 24;
    settings.spp = 2;
    settings.camera = s.cameras.at(0);
    const ObscuranceResult wide = renderObscurances(context(), s, tree, settings);
    const bvh::Bvh splitTree = bvh::build(render::triangleSoup(s), render::treeOptionsFor(render::Traversal::Binary));
    if (hall) {
      EXPECT_GT(splitTree.stats.spatialSplits, 0u);
    }
    for (const render::Traversal traversal : kBinaryTraversals) {
      if (hall && traversal != render::Traversal::BinaryWhileWhile) continue;
      ASSERT_EQ(render::SceneBuffers(contextFor(traversal), s, tree).traversal(), traversal);
      const ObscuranceResult binary = renderObscurances(contextFor(traversal), s, hall ? splitTree : tree, settings);
      EXPECT_EQ(binary.stats.truncatedTraversals, 0u);
      EXPECT_EQ(differingValues(wide.image, binary.image), 0u) << path << ", " << render::traversalName(traversal);
    }
    if (hall) continue;
    render::PathTraceSettings paths;
    paths.width = 32;
    paths.height = 24;
    paths.spp = 2;
    paths.camera = settings.camera;
    const PathTraceResult widePaths = renderPathTraced(context(), s, tree, paths);
    const PathTraceResult binaryPaths =
        renderPathTraced(contextFor(render::Traversal::BinaryWhileWhile), s, splitTree, paths);
    EXPECT_EQ(differingValues(widePaths.image, binaryPaths.image), 0u) << path << ", path tracer";
  }
}

// A moved object: the BVH refitted, the binary layout derived again from it and uploaded, the
// dirty pixels retraced. The same frame as the wide layout's after the same edit.
TEST_F(TraversalLayouts, GeometryEditOnTheBinaryLayoutGivesTheWideLayoutsFrame) {
  auto room = [](glm::vec3 object) {
    SceneBuilder b;
    auto white = b.lambertian(glm::vec3(0.7f));
    auto green = b.lambertian(glm::vec3(0.2f, 0.7f, 0.2f));
    auto lamp = b.lambertian(glm::vec3(0.0f), glm::vec3(6.0f));
    b.quad({-2, 0, -2}, {0, 0, 4}, {4, 0, 0}, white);
    b.quad({-2, 0, -2}, {4, 0, 0}, {0, 3, 0}, white);
    b.quad({-0.3f, 2.99f, -0.3f}, {0.6f, 0, 0}, {0, 0, 0.6f}, lamp, "lamp");
    b.quad(object, {0, 0, 0.5f}, {0.5f, 0, 0}, green);
    b.quad(object, {0.5f, 0, 0}, {0, 0, 0.5f}, green);
    return b.build();
  };
  const glm::vec3 from(0.0f, 0.8f, 0.0f), to(0.4f, 1.0f, 0.2f);
  const scene::Scene before = room(from), after = room(to);
  const bvh::Bvh beforeTree = bvh::build(render::triangleSoup(before));
  bvh::Bvh afterTree = beforeTree;
  bvh::refit(afterTree, render::triangleSoup(after));
  scene::Bounds changed;
  for (glm::vec3 corner : {from, from + glm::vec3(0.5f, 0, 0.5f), to, to + glm::vec3(0.5f, 0, 0.5f)}) changed.grow(corner);

  render::ObscuranceSettings settings;
  settings.width = 40;
  settings.height = 30;
  settings.spp = 2;
  settings.camera = lookCamera({0, 1.5f, 4.5f}, glm::normalize(glm::vec3(0, -0.25f, -1)), {0, 1, 0}, 0.9f);
  auto movedFrame = [&](const gpu::Context& context) {
    render::ObscuranceRenderer r(context, before, beforeTree, settings);
    r.render();
    EXPECT_GT(r.updateGeometry(after, afterTree, {changed}), 0u);
    r.compose();
    EXPECT_EQ(r.stats().truncatedTraversals, 0u);
    return r.image();
  };
  const io::Image wide = movedFrame(context());
  for (const render::Traversal traversal : kBinaryTraversals)
    EXPECT_EQ(differingValues(wide, movedFrame(contextFor(traversal))), 0u) << render::traversalName(traversal);
}

} // namespace
} // namespace obscura::test
