#include "render/test_scenes.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <functional>
#include <map>
#include <mutex>
#include <string_view>
#include <thread>

#include <gtest/gtest.h>

#include "bvh/triangle_intersect.h"
#include "bvh/wide_node.h"
#include "render/scene_data/scene_buffers.h"
#include "scene/scene_edit.h"
#include "shared/host_device.h"

namespace obscura::test {

std::uint32_t SceneBuilder::lambertian(glm::vec3 albedo, glm::vec3 emission, bool doubleSided) {
  scene::Material m;
  m.name = "lambertian" + std::to_string(scene_.materials.size());
  m.baseColor = glm::vec4(albedo, 1.0f);
  m.metallic = 0.0f;
  m.roughness = 1.0f;
  m.emission = emission;
  m.doubleSided = doubleSided;
  scene_.materials.push_back(m);
  return static_cast<std::uint32_t>(scene_.materials.size() - 1);
}

std::uint32_t SceneBuilder::glossy(glm::vec3 baseColor, float metallic, float roughness, glm::vec3 emission) {
  scene::Material m;
  m.name = "glossy" + std::to_string(scene_.materials.size());
  m.baseColor = glm::vec4(baseColor, 1.0f);
  m.metallic = metallic;
  m.roughness = roughness;
  m.emission = emission;
  scene_.materials.push_back(m);
  return static_cast<std::uint32_t>(scene_.materials.size() - 1);
}

void SceneBuilder::quad(glm::vec3 corner, glm::vec3 u, glm::vec3 v, std::uint32_t material, const std::string& group) {
  auto base = static_cast<std::uint32_t>(scene_.positions.size());
  glm::vec3 n = glm::normalize(glm::cross(u, v));
  for (glm::vec3 p : {corner, corner + u, corner + u + v, corner + v}) {
    scene_.positions.push_back(p);
    scene_.normals.push_back(n);
    scene_.uvs.push_back(glm::vec2(0.0f));
    scene_.bounds.grow(p);
  }
  std::uint32_t lightGroup = gpu::kInvalidIndex;
  if (!group.empty()) {
    for (std::size_t g = 0; g < scene_.lightGroups.size(); ++g)
      if (scene_.lightGroups[g].name == group) lightGroup = static_cast<std::uint32_t>(g);
    if (lightGroup == gpu::kInvalidIndex) {
      scene_.lightGroups.push_back({.name = group, .triangles = {}, .emission = scene_.materials[material].emission});
      lightGroup = static_cast<std::uint32_t>(scene_.lightGroups.size() - 1);
    }
  }
  for (glm::uvec3 t : {glm::uvec3(base, base + 1, base + 2), glm::uvec3(base, base + 2, base + 3)}) {
    if (lightGroup != gpu::kInvalidIndex)
      scene_.lightGroups[lightGroup].triangles.push_back(static_cast<std::uint32_t>(scene_.triangles.size()));
    scene_.triangles.push_back(t);
    scene_.triangleMaterial.push_back(material);
    scene_.triangleLightGroup.push_back(lightGroup);
  }
}

void SceneBuilder::pointLight(glm::vec3 position, glm::vec3 color, float intensity, const std::string& name) {
  scene::PunctualLight l;
  l.name = name;
  l.type = scene::PunctualType::Point;
  l.position = position;
  l.color = color;
  l.intensity = intensity;
  scene_.punctualLights.push_back(l);
}

void SceneBuilder::directionalLight(glm::vec3 direction, glm::vec3 color, float intensity) {
  scene::PunctualLight l;
  l.name = "sun";
  l.type = scene::PunctualType::Directional;
  l.direction = glm::normalize(direction);
  l.color = color;
  l.intensity = intensity;
  scene_.punctualLights.push_back(l);
}

scene::Scene SceneBuilder::build() {
  if (scene_.materials.empty()) lambertian(glm::vec3(0.5f));
  return scene_;
}

scene::Scene soupScene(const bvh::TriangleSoup& soup) {
  scene::Scene s;
  for (std::size_t i = 0; i < soup.size(); ++i) {
    auto base = static_cast<std::uint32_t>(s.positions.size());
    for (glm::vec3 p : {soup.v0[i], soup.v1[i], soup.v2[i]}) {
      s.positions.push_back(p);
      s.normals.push_back(glm::vec3(0, 0, 1));
      s.uvs.push_back(glm::vec2(0));
      s.bounds.grow(p);
    }
    s.triangles.push_back(glm::uvec3(base, base + 1, base + 2));
    s.triangleMaterial.push_back(0);
    s.triangleLightGroup.push_back(gpu::kInvalidIndex);
  }
  s.materials.push_back({});
  return s;
}

namespace {

template <typename T> std::size_t hashOfBytes(const std::vector<T>& values) {
  return std::hash<std::string_view>{}(
      std::string_view(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T)));
}

} // namespace

namespace {

// Every triangle's box, padded, as arrays of each bound: the oracle meets each ray with every box
// first (a loop the compiler vectorises) and runs the watertight test only on the few triangles
// whose box the ray meets, which makes it ten times faster on modern-hall's 31k triangles. The
// padding (1e-4 of the box's largest coordinate) and the slab interval's widening (1e-4 of its
// ends) exceed float rounding by orders of magnitude, so no hit is culled and the answers are
// exactly bvh::closestHitBruteForce's (BruteForceOracle.BoxCullKeepsThePlainBruteForcesAnswers).
struct PaddedBoxes {
  std::array<std::vector<float>, 3> lo, hi;
  explicit PaddedBoxes(const bvh::TriangleSoup& soup) {
    for (int c = 0; c < 3; ++c) {
      lo[c].resize(soup.size());
      hi[c].resize(soup.size());
    }
    for (std::size_t i = 0; i < soup.size(); ++i) {
      const glm::vec3 l = glm::min(soup.v0[i], glm::min(soup.v1[i], soup.v2[i]));
      const glm::vec3 h = glm::max(soup.v0[i], glm::max(soup.v1[i], soup.v2[i]));
      const glm::vec3 magnitude = glm::max(glm::abs(l), glm::abs(h));
      const float pad = 1e-4f * std::max(magnitude.x, std::max(magnitude.y, magnitude.z)) + 1e-30f;
      for (int c = 0; c < 3; ++c) {
        lo[c][i] = l[c] - pad;
        hi[c][i] = h[c] + pad;
      }
    }
  }
};

bvh::Hit closestHitBoxCulled(const bvh::TriangleSoup& soup, const PaddedBoxes& boxes, const bvh::Ray& ray,
                             std::vector<std::uint8_t>& meets) {
  // 1/d with |d| raised to 1e-30: finite, of d's sign, so (bound - origin) * inverse is never 0 * inf.
  glm::vec3 inverse;
  for (int c = 0; c < 3; ++c) {
    const float d = ray.direction[c];
    inverse[c] = 1.0f / (std::abs(d) >= 1e-30f ? d : std::copysign(1e-30f, d));
  }
  const std::size_t n = soup.size();
  meets.resize(n);
  const float ox = ray.origin.x, oy = ray.origin.y, oz = ray.origin.z;
  const float ix = inverse.x, iy = inverse.y, iz = inverse.z, tmin = ray.tmin, tmax = ray.tmax;
  const float* lx = boxes.lo[0].data(), *ly = boxes.lo[1].data(), *lz = boxes.lo[2].data();
  const float* hx = boxes.hi[0].data(), *hy = boxes.hi[1].data(), *hz = boxes.hi[2].data();
  std::uint8_t* out = meets.data();
  for (std::size_t i = 0; i < n; ++i) {
    const float ax = (lx[i] - ox) * ix, bx = (hx[i] - ox) * ix;
    const float ay = (ly[i] - oy) * iy, by = (hy[i] - oy) * iy;
    const float az = (lz[i] - oz) * iz, bz = (hz[i] - oz) * iz;
    float near = std::max(std::max(std::min(ax, bx), std::min(ay, by)), std::min(az, bz));
    float far = std::min(std::min(std::max(ax, bx), std::max(ay, by)), std::max(az, bz));
    near -= 1e-4f * std::abs(near);
    far += 1e-4f * std::abs(far);
    out[i] = static_cast<std::uint8_t>((near <= far) & (far >= tmin) & (near <= tmax));
  }
  const bvh::WatertightRay wr = bvh::prepareWatertightRay(ray.origin, ray.direction);
  bvh::Hit best;
  float tLimit = ray.tmax;
  for (std::size_t i = 0; i < n; ++i) {
    if (!out[i]) continue;
    float t, u, v;
    if (!bvh::intersectTriangle(wr, soup.v0[i], soup.v1[i], soup.v2[i], ray.tmin, tLimit, t, u, v)) continue;
    const auto primitive = static_cast<std::uint32_t>(i);
    if (t < best.t || (t == best.t && primitive < best.primitive)) {
      best = bvh::Hit{t, u, v, primitive};
      tLimit = t;
    }
  }
  return best;
}

} // namespace

std::vector<bvh::Hit> bruteForce(const bvh::TriangleSoup& soup, const std::vector<bvh::Ray>& rays) {
  const PaddedBoxes boxes(soup);
  std::vector<bvh::Hit> out(rays.size());
  const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> pool;
  for (unsigned k = 0; k < threads; ++k)
    pool.emplace_back([&, k] {
      std::vector<std::uint8_t> meets;
      for (std::size_t i = k; i < rays.size(); i += threads) out[i] = closestHitBoxCulled(soup, boxes, rays[i], meets);
    });
  for (auto& t : pool) t.join();
  return out;
}

std::vector<bvh::Hit> bruteForce(const bvh::TriangleSoup& soup, const std::vector<gpu::GpuRay>& rays) {
  // The oracle's answers by their question. A suite runs in one process (CTest runs suites) and
  // traces the same soup and rays through several layouts, loops and trace shapes. Keyed by the
  // contents (four 64-bit hashes and the sizes), so a different soup or ray set is always computed
  // afresh.
  static std::mutex mutex;
  static std::map<std::array<std::size_t, 6>, std::vector<bvh::Hit>> answers;
  const std::array<std::size_t, 6> key{hashOfBytes(soup.v0), hashOfBytes(soup.v1), hashOfBytes(soup.v2),
                                       hashOfBytes(rays), soup.size(), rays.size()};
  {
    std::lock_guard lock(mutex);
    if (auto found = answers.find(key); found != answers.end()) return found->second;
  }
  std::vector<bvh::Ray> asRays;
  asRays.reserve(rays.size());
  for (const gpu::GpuRay& r : rays)
    asRays.push_back({glm::vec3(r.origin), glm::vec3(r.direction), r.origin.w, r.direction.w});
  std::vector<bvh::Hit> out = bruteForce(soup, asRays);
  std::lock_guard lock(mutex);
  answers.emplace(key, out);
  return out;
}

void expectReplayEqualsFresh(const render::LightReach& replayed, const render::LightReach& fresh) {
  EXPECT_EQ(replayed.rays.landingPrimitive, fresh.rays.landingPrimitive);
  EXPECT_EQ(replayed.rays.firstSeenTry, fresh.rays.firstSeenTry);
  ASSERT_EQ(replayed.rays.landingT.size(), fresh.rays.landingT.size());
  for (std::size_t i = 0; i < fresh.rays.landingT.size(); ++i)
    ASSERT_EQ(std::bit_cast<std::uint32_t>(replayed.rays.landingT[i]), std::bit_cast<std::uint32_t>(fresh.rays.landingT[i]))
        << "light ray " << i;
  EXPECT_EQ(replayed.area, fresh.area);
  EXPECT_EQ(replayed.escapeDirect, fresh.escapeDirect);
  EXPECT_EQ(replayed.escapeBounce, fresh.escapeBounce);
  EXPECT_EQ(replayed.landedTriangles, fresh.landedTriangles);
  // The rays kept for the next replay: the same rays (where a try was blocked may differ: any hit
  // along it will do).
  ASSERT_EQ(replayed.rays.lightRay.size(), fresh.rays.lightRay.size());
  for (std::size_t i = 0; i < fresh.rays.lightRay.size(); ++i) {
    ASSERT_EQ(replayed.rays.lightRay[i].origin, fresh.rays.lightRay[i].origin) << "light ray " << i;
    ASSERT_EQ(replayed.rays.lightRay[i].direction, fresh.rays.lightRay[i].direction) << "light ray " << i;
  }
  EXPECT_EQ(replayed.rays.bounceDirection, fresh.rays.bounceDirection);
  EXPECT_EQ(replayed.rays.landingTryDraws, fresh.rays.landingTryDraws);
}

MovedObject moveAndRefit(const scene::Scene& scene, const bvh::Bvh& tree, const std::string& name, glm::vec3 by,
                         float padding) {
  MovedObject moved{scene, tree, {}};
  const std::size_t object = scene::objectIndex(moved.scene, name, "test");
  moved.changed.push_back(scene::objectBounds(moved.scene, object));
  scene::moveObject(moved.scene, object, by, glm::vec3(0.0f));
  moved.changed.push_back(scene::objectBounds(moved.scene, object));
  for (scene::Bounds& b : moved.changed) b = {b.lo - padding, b.hi + padding};
  bvh::refit(moved.tree, render::triangleSoup(moved.scene));
  return moved;
}

scene::Camera lookCamera(glm::vec3 position, glm::vec3 forward, glm::vec3 up, float yfov) {
  scene::Camera c;
  c.position = position;
  c.forward = glm::normalize(forward);
  c.up = glm::normalize(up);
  c.yfov = yfov;
  return c;
}

bvh::Bvh combBvh(const bvh::TriangleSoup& soup) {
  const auto n = static_cast<std::uint32_t>(soup.size());
  const std::uint32_t levels = n - 1; // spine nodes with a rib
  bvh::Box all;
  for (std::size_t i = 0; i < soup.size(); ++i)
    for (const glm::vec3& p : {soup.v0[i], soup.v1[i], soup.v2[i]}) all.grow(p);
  // Node indices: spine k at 2k - 1 (the root is 0), rib k at 2k + 2.
  bvh::Bvh tree;
  tree.nodes.resize(2 * levels + 1);
  auto oneLeaf = [&] {
    std::array<bvh::WideChild, gpu::kBvhWidth> slots{};
    slots[0] = {.kind = bvh::WideChild::Kind::Leaf, .box = all, .triangleOffset = 0, .triangleCount = 1};
    return slots;
  };
  for (std::uint32_t k = 0; k <= levels; ++k) {
    const std::uint32_t spine = k == 0 ? 0 : 2 * k - 1;
    if (k == levels) {
      bvh::writeWideNode(tree.nodes[spine], oneLeaf(), 0, levels);
      continue;
    }
    std::array<bvh::WideChild, gpu::kBvhWidth> slots{};
    slots[0] = {.kind = bvh::WideChild::Kind::Internal, .box = all};
    slots[1] = {.kind = bvh::WideChild::Kind::Internal, .box = all};
    bvh::writeWideNode(tree.nodes[spine], slots, 2 * k + 1, 0);
    bvh::writeWideNode(tree.nodes[2 * k + 2], oneLeaf(), 0, k);
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    tree.order.push_back(i);
    tree.triangles.push_back({.v0 = glm::vec4(soup.v0[i], std::bit_cast<float>(i)),
                              .v1 = glm::vec4(soup.v1[i], 0.0f),
                              .v2 = glm::vec4(soup.v2[i], 0.0f)});
  }
  tree.stats.nodeCount = 2 * levels + 1;
  tree.stats.leafCount = n;
  tree.stats.maxDepth = n;
  return tree;
}

} // namespace obscura::test
