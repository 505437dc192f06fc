// test_scenes.h — scenes built in code for analytic tests: quads with Lambertian materials,
// emissive quads (light groups), punctual lights.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "bvh/bvh.h"
#include "render/scene_data/reached_surfaces.h"
#include "scene/scene.h"
#include "shared/host_device.h"

namespace obscura::test {

class SceneBuilder {
public:
  // A Lambertian material (metallic 0, roughness 1: no specular lobe [SPEC §5]).
  std::uint32_t lambertian(glm::vec3 albedo, glm::vec3 emission = glm::vec3(0.0f), bool doubleSided = false);
  std::uint32_t glossy(glm::vec3 baseColor, float metallic, float roughness, glm::vec3 emission = glm::vec3(0.0f));
  // Quad corner, edge u, edge v: two triangles, front face = the side cross(u, v) points to.
  void quad(glm::vec3 corner, glm::vec3 u, glm::vec3 v, std::uint32_t material, const std::string& group = "");
  void pointLight(glm::vec3 position, glm::vec3 color, float intensity, const std::string& name = "point");
  void directionalLight(glm::vec3 direction, glm::vec3 color, float intensity);
  scene::Scene build();

private:
  scene::Scene scene_;
};

// A scene made of a triangle soup, with one default material.
scene::Scene soupScene(const bvh::TriangleSoup& soup);

// The oracle of the traversal tests: brute force over every triangle, on all cores (each ray meets
// every triangle's padded box first; the answers are bvh::closestHitBruteForce's).
std::vector<bvh::Hit> bruteForce(const bvh::TriangleSoup& soup, const std::vector<gpu::GpuRay>& rays);
std::vector<bvh::Hit> bruteForce(const bvh::TriangleSoup& soup, const std::vector<bvh::Ray>& rays);

// A wide BVH built by hand over `soup` (n >= 2 triangles, every box the whole soup's), in which
// a ray along +x pushes one stack entry per level: "spine" node k has the next spine node in
// slot 0 and a "rib" node in slot 1, rib k holds triangle k, and the last spine node (depth
// n - 1) triangle n - 1. Depth n, 2n - 1 nodes, triangles in soup order.
bvh::Bvh combBvh(const bvh::TriangleSoup& soup);

// A camera at `position` looking along `forward` with the given vertical field of view.
scene::Camera lookCamera(glm::vec3 position, glm::vec3 forward, glm::vec3 up, float yfov);

// `scene` with object `name` translated by `by`, its BVH refitted from `tree`, and the object's
// old and new boxes padded by `padding` (what an edit tells a re-measurement it changed).
struct MovedObject {
  scene::Scene scene;
  bvh::Bvh tree;
  std::vector<scene::Bounds> changed;
};
// Asserts that `replayed` (a re-measurement after an edit) found exactly what `fresh` (the edited
// scene measured from scratch) found: every light ray's landing, every sample's first seen try,
// and the reach, escapes and landed triangles they make.
void expectReplayEqualsFresh(const render::LightReach& replayed, const render::LightReach& fresh);

MovedObject moveAndRefit(const scene::Scene& scene, const bvh::Bvh& tree, const std::string& name, glm::vec3 by,
                         float padding);

} // namespace obscura::test
