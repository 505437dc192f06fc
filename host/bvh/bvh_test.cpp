// bvh_test.cpp — watertight intersection, BVH structure, and BVH traversal against brute force.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "bvh/triangle_intersect.h"
#include "bvh/wide_node.h"

namespace obscura::bvh {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

struct TriHit {
  bool hit = false;
  float t = 0, u = 0, v = 0;
};

TriHit intersect(const glm::vec3& o, const glm::vec3& d, const glm::vec3& a, const glm::vec3& b,
                 const glm::vec3& c, float tmin = 0.0f, float tmax = kInf) {
  TriHit h;
  const WatertightRay r = prepareWatertightRay(o, d);
  h.hit = intersectTriangle(r, a, b, c, tmin, tmax, h.t, h.u, h.v);
  return h;
}

// ---------------------------------------------------------------- triangle intersection

TEST(TriangleIntersect, HitsMiddleWithKnownTuv) {
  const glm::vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const TriHit h = intersect({0.25f, 0.5f, 2.0f}, {0, 0, -1}, a, b, c);
  ASSERT_TRUE(h.hit);
  EXPECT_FLOAT_EQ(h.t, 2.0f);
  EXPECT_FLOAT_EQ(h.u, 0.25f); // barycentric of v1 = (1, 0, 0)
  EXPECT_FLOAT_EQ(h.v, 0.5f);  // barycentric of v2 = (0, 1, 0)
  // Both windings and both sides hit.
  EXPECT_TRUE(intersect({0.25f, 0.5f, 2.0f}, {0, 0, -1}, a, c, b).hit);
  EXPECT_TRUE(intersect({0.25f, 0.5f, -2.0f}, {0, 0, 1}, a, b, c).hit);
}

TEST(TriangleIntersect, BarycentricsReproduceTheHitPoint) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coord(-3.0f, 3.0f), unit(0.0f, 1.0f);
  int hits = 0;
  for (int i = 0; i < 10000; ++i) {
    const glm::vec3 a(coord(rng), coord(rng), coord(rng)), b(coord(rng), coord(rng), coord(rng)),
        c(coord(rng), coord(rng), coord(rng));
    float wb = unit(rng), wc = unit(rng);
    if (wb + wc > 1.0f) wb = 1.0f - wb, wc = 1.0f - wc;
    const glm::vec3 p = (1.0f - wb - wc) * a + wb * b + wc * c;
    const glm::vec3 o(coord(rng) * 3.0f, coord(rng) * 3.0f, coord(rng) * 3.0f);
    const glm::vec3 d = p - o;
    const TriHit h = intersect(o, d, a, b, c);
    if (!h.hit) continue; // grazing rays may miss by rounding when p is on an edge
    ++hits;
    const glm::vec3 q = (1.0f - h.u - h.v) * a + h.u * b + h.v * c;
    const glm::vec3 onRay = o + h.t * d;
    const float scale = glm::length(o) + glm::length(d) + 10.0f;
    EXPECT_LT(glm::length(q - onRay), 1e-4f * scale) << i;
    EXPECT_NEAR(h.t, 1.0f, 1e-3f) << i;
  }
  EXPECT_GT(hits, 9900);
}

TEST(TriangleIntersect, SharedEdgeIsHitByAtLeastOneTriangle) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> coord(-1.0f, 1.0f), unit(0.0f, 1.0f);
  int escapes = 0;
  for (int i = 0; i < 20000; ++i) {
    // Quad a b c d split along b-d; both triangles hold bit-identical b and d.
    const glm::vec3 a(coord(rng), coord(rng), coord(rng)), b(coord(rng), coord(rng), coord(rng)),
        d(coord(rng), coord(rng), coord(rng));
    const glm::vec3 c = b + d - a; // the far side, so the quad is a planar parallelogram
    const glm::vec3 target = glm::mix(b, d, unit(rng));
    const glm::vec3 o(coord(rng) * 5.0f, coord(rng) * 5.0f, coord(rng) * 5.0f);
    const glm::vec3 dir = target - o;
    const bool h0 = intersect(o, dir, a, b, d).hit;
    const bool h1 = intersect(o, dir, c, d, b).hit;
    if (!h0 && !h1) ++escapes;
  }
  EXPECT_EQ(escapes, 0);
}

TEST(TriangleIntersect, SharedVertexOfAFanIsHitByAtLeastOneTriangle) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> coord(-1.0f, 1.0f);
  int escapes = 0;
  for (int i = 0; i < 5000; ++i) {
    const glm::vec3 center(coord(rng), coord(rng), coord(rng));
    // A closed fan of 7 triangles around `center` (a pyramid-like cone, rim jittered).
    std::array<glm::vec3, 7> rim;
    for (int k = 0; k < 7; ++k) {
      const float phi = 6.2831853f * static_cast<float>(k) / 7.0f;
      rim[k] = center + glm::vec3(std::cos(phi), std::sin(phi), 0.3f * coord(rng)) +
               0.1f * glm::vec3(coord(rng), coord(rng), coord(rng));
    }
    const glm::vec3 o = center + glm::vec3(coord(rng), coord(rng), 2.0f + coord(rng));
    const glm::vec3 dir = center - o;
    bool any = false;
    for (int k = 0; k < 7; ++k)
      any = any || intersect(o, dir, center, rim[k], rim[(k + 1) % 7]).hit;
    if (!any) ++escapes;
  }
  EXPECT_EQ(escapes, 0);
}

TEST(TriangleIntersect, RayParallelToTriangleMisses) {
  const glm::vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  EXPECT_FALSE(intersect({-1, 0.2f, 0}, {1, 0, 0}, a, b, c).hit); // in the plane
  EXPECT_FALSE(intersect({-1, 0.2f, 0.1f}, {1, 0, 0}, a, b, c).hit); // above the plane
  EXPECT_FALSE(intersect({-1, -1, 0}, {1, 1, 0}, a, b, c).hit);
}

TEST(TriangleIntersect, DirectionsWithZeroComponents) {
  // An axis-aligned unit triangle in each plane, hit along each signed axis.
  for (int axis = 0; axis < 3; ++axis) {
    for (float sign : {-1.0f, 1.0f}) {
      const int ax = (axis + 1) % 3, ay = (axis + 2) % 3;
      glm::vec3 a(0), b(0), c(0);
      b[ax] = 1.0f;
      c[ay] = 1.0f;
      glm::vec3 o(0), d(0);
      o[ax] = 0.2f;
      o[ay] = 0.3f;
      o[axis] = -3.0f * sign;
      d[axis] = sign;
      const TriHit h = intersect(o, d, a, b, c);
      ASSERT_TRUE(h.hit) << axis << " " << sign;
      EXPECT_FLOAT_EQ(h.t, 3.0f);
      EXPECT_FLOAT_EQ(h.u, 0.2f);
      EXPECT_FLOAT_EQ(h.v, 0.3f);
    }
  }
  // Two zero components with the origin exactly on an edge's line.
  EXPECT_TRUE(intersect({0, 0.5f, 1}, {0, 0, -1}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}).hit);
  // Zero direction: never a hit, never NaN trouble.
  EXPECT_FALSE(intersect({0.2f, 0.2f, 1}, {0, 0, 0}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}).hit);
}

TEST(TriangleIntersect, TinyAndNeedleTriangles) {
  const float s = 1e-6f;
  const glm::vec3 a(0.3f, 0.4f, 1.0f);
  const TriHit tiny = intersect({0, 0, 0}, a + glm::vec3(s / 3, s / 3, 0), a,
                                a + glm::vec3(s, 0, 0), a + glm::vec3(0, s, 0));
  ASSERT_TRUE(tiny.hit);
  EXPECT_NEAR(tiny.t, 1.0f, 1e-5f);

  // Needle: length 1, width 1e-7, hit through its centroid from an oblique direction.
  const glm::vec3 n0(0, 0, 0), n1(1, 0, 0), n2(0.5f, 1e-7f, 0);
  const glm::vec3 centroid = (n0 + n1 + n2) / 3.0f;
  const glm::vec3 o(0.2f, -0.3f, 2.0f);
  const TriHit needle = intersect(o, centroid - o, n0, n1, n2);
  ASSERT_TRUE(needle.hit);
  EXPECT_NEAR(needle.t, 1.0f, 1e-5f);
  // Degenerate triangles (a point, a segment) never report a hit.
  EXPECT_FALSE(intersect({0, 0, 1}, {0, 0, -1}, n0, n0, n0).hit);
  EXPECT_FALSE(intersect({0.5f, 0, 1}, {0, 0, -1}, n0, n1, n1).hit);
}

TEST(TriangleIntersect, TminIsOpenTmaxIsClosed) {
  const glm::vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0), o(0.25f, 0.25f, 1.0f), d(0, 0, -1);
  EXPECT_TRUE(intersect(o, d, a, b, c, 0.0f, 1.0f).hit);
  EXPECT_FALSE(intersect(o, d, a, b, c, 0.0f, 0.999f).hit);
  EXPECT_FALSE(intersect(o, d, a, b, c, 1.0f, 2.0f).hit);
  EXPECT_TRUE(intersect(o, d, a, b, c, 0.999f, 2.0f).hit);
  EXPECT_FALSE(intersect(o, -d, a, b, c).hit); // behind the origin
}

// A closed icosphere: shared vertices are bit-identical across triangles.
TriangleSoup icosphere(int subdivisions, const glm::vec3& center, float radius,
                       std::vector<glm::vec3>* vertices, std::vector<glm::uvec3>* faces) {
  const float p = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<glm::vec3> v = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0},
                              {0, -1, p}, {0, 1, p}, {0, -1, -p}, {0, 1, -p},
                              {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  std::vector<glm::uvec3> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                               {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                               {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                               {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& x : v) x = glm::normalize(x);
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<unsigned, unsigned>, unsigned> mid;
    auto midpoint = [&](unsigned a, unsigned b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back(glm::normalize(v[a] + v[b]));
      return mid[key] = static_cast<unsigned>(v.size() - 1);
    };
    std::vector<glm::uvec3> next;
    for (const auto& t : f) {
      const unsigned ab = midpoint(t.x, t.y), bc = midpoint(t.y, t.z), ca = midpoint(t.z, t.x);
      next.push_back({t.x, ab, ca});
      next.push_back({t.y, bc, ab});
      next.push_back({t.z, ca, bc});
      next.push_back({ab, bc, ca});
    }
    f = std::move(next);
  }
  for (auto& x : v) x = center + radius * x;
  TriangleSoup soup;
  for (const auto& t : f) {
    soup.v0.push_back(v[t.x]);
    soup.v1.push_back(v[t.y]);
    soup.v2.push_back(v[t.z]);
  }
  if (vertices) *vertices = v;
  if (faces) *faces = f;
  return soup;
}

TEST(TriangleIntersect, ClosedIcosphereIsWatertight) {
  std::vector<glm::vec3> vertices;
  std::vector<glm::uvec3> faces;
  // Off-centre and not unit-sized, so that the vertex coordinates round in interesting ways.
  const glm::vec3 center(3.1f, -2.7f, 5.3f);
  const float radius = 1.7f;
  const TriangleSoup soup = icosphere(3, center, radius, &vertices, &faces);
  std::vector<glm::vec3> targets = vertices;
  for (const auto& f : faces) {
    targets.push_back(0.5f * (vertices[f.x] + vertices[f.y]));
    targets.push_back(0.5f * (vertices[f.y] + vertices[f.z]));
    targets.push_back(0.5f * (vertices[f.z] + vertices[f.x]));
  }
  const Bvh bvh = build(soup);
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> coord(-0.5f, 0.5f);
  int escapes = 0;
  const int kRays = 100000;
  for (int i = 0; i < kRays; ++i) {
    // Origins inside, half of them exactly at the centre (every ray is then a radius).
    const glm::vec3 o =
        i % 2 == 0 ? center : center + radius * glm::vec3(coord(rng), coord(rng), coord(rng));
    const glm::vec3 target = targets[static_cast<std::size_t>(i) % targets.size()];
    Ray ray;
    ray.origin = o;
    ray.direction = target - o;
    if (!closestHit(bvh, ray).hit()) ++escapes;
  }
  EXPECT_EQ(escapes, 0) << "of " << kRays << " rays";
}

// ---------------------------------------------------------------- BVH

bool strictlyInside(const Box& inner, const Box& outer) {
  return outer.lo.x < inner.lo.x && outer.lo.y < inner.lo.y && outer.lo.z < inner.lo.z &&
         inner.hi.x < outer.hi.x && inner.hi.y < outer.hi.y && inner.hi.z < outer.hi.z;
}

// Box of the points strictly inside both.
Box intersection(const Box& a, const Box& b) {
  Box both;
  both.lo = glm::max(a.lo, b.lo);
  both.hi = glm::min(a.hi, b.hi);
  return both;
}
bool strictlyContains(const Box& box, const glm::vec3& p) {
  return box.lo.x < p.x && box.lo.y < p.y && box.lo.z < p.z && p.x < box.hi.x && p.y < box.hi.y && p.z < box.hi.z;
}

// Points of triangle `id` a traversal must be able to reach: its corners, edge midpoints and
// centroid, and random points inside (each kept within the triangle's bounds, which float
// rounding of a centroid can leave by an ulp where the triangle is flat along an axis).
std::vector<glm::vec3> pointsOn(const TriangleSoup& soup, std::uint32_t id) {
  const glm::vec3 a = soup.v0[id], b = soup.v1[id], c = soup.v2[id];
  std::vector<glm::vec3> points = {a, b, c, 0.5f * (a + b), 0.5f * (b + c), 0.5f * (c + a), (a + b + c) / 3.0f};
  std::mt19937 rng(id);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int k = 0; k < 8; ++k) {
    float u = unit(rng), v = unit(rng);
    if (u + v > 1.0f) u = 1.0f - u, v = 1.0f - v;
    points.push_back(a + u * (b - a) + v * (c - a));
  }
  for (glm::vec3& p : points) p = glm::clamp(p, glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c)));
  return points;
}

// Checks everything the GPU relies on; returns the first problem found, or "".
//
// Without spatial splits every triangle is in exactly one leaf and every decoded box strictly
// contains the triangles below it. With them a triangle may be in several leaves, each holding a
// clipped piece of it, so the boxes are checked by what traversal needs instead: every point of
// every triangle lies strictly inside the decoded boxes on the whole path to some leaf holding it.
std::string validate(const Bvh& bvh, const TriangleSoup& soup, const BuildOptions& options) {
  const std::size_t n = soup.size();
  const bool spatial = options.spatialSplitBudget > 0.0f;
  const std::size_t stored = bvh.triangles.size();
  if (bvh.order.size() != stored || bvh.stats.references != stored) return "triangle/order/references size";
  const auto mostStored = n + static_cast<std::size_t>(static_cast<double>(options.spatialSplitBudget) * n);
  if (spatial ? stored < n || stored > mostStored : stored != n) return "stored triangles: " + std::to_string(stored);
  if (!spatial && bvh.stats.spatialSplits != 0) return "spatial splits without a budget";
  std::vector<int> seen(n, 0);
  for (std::size_t i = 0; i < stored; ++i) {
    const std::uint32_t id = bvh.order[i];
    if (id >= n) return "order out of range at " + std::to_string(i);
    if (seen[id]++ && !spatial) return "order is not a permutation at " + std::to_string(i);
    const gpu::BvhTriangle& t = bvh.triangles[i];
    if (std::bit_cast<std::uint32_t>(t.v0.w) != id) return "v0.w is not the original index";
    if (glm::vec3(t.v0) != soup.v0[id] || glm::vec3(t.v1) != soup.v1[id] ||
        glm::vec3(t.v2) != soup.v2[id])
      return "triangle vertices differ from the soup";
  }
  if (bvh.nodes.empty()) return "no root";
  if (bvh.stats.nodeCount != bvh.nodes.size()) return "stats.nodeCount";

  std::vector<int> leafOf(n, 0), nodeSeen(bvh.nodes.size(), 0);
  std::vector<std::vector<Box>> reach(spatial ? n : 0); // per triangle: the path boxes of its leaves
  std::uint32_t leaves = 0, maxDepth = 0;
  std::string problem;
  // Exact bounds of what lies below `index`, checking each slot's decoded box contains them
  // strictly (the GPU relies on that for rays starting on a face); `path`: the decoded boxes
  // above, intersected.
  std::function<Box(std::uint32_t, std::uint32_t, const Box&)> walk = [&](std::uint32_t index, std::uint32_t childDepth,
                                                                        const Box& path) {
    Box all;
    if (nodeSeen[index]++) {
      problem = "node reached twice";
      return all;
    }
    const gpu::BvhNode& node = bvh.nodes[index];
    const std::uint32_t imask = internalMask(node);
    std::uint32_t usedTriangleBits = 0;
    for (unsigned s = 0; s < gpu::kBvhWidth; ++s) {
      const std::uint32_t meta = slotMeta(node, s);
      const bool interior = (imask >> s & 1u) != 0;
      if (meta == 0) {
        if (interior) problem = "empty slot marked interior";
        continue;
      }
      const Box slotPath = intersection(path, decodedBox(node, s));
      Box exact;
      if (interior) {
        if (meta != 0x80u) problem = "interior slot with leaf meta";
        const std::uint32_t child = childNodeIndex(node, s);
        if (child >= bvh.nodes.size() || child <= index) {
          problem = "child index out of range or not after its parent";
          continue;
        }
        exact = walk(child, childDepth + 1, slotPath);
      } else {
        const std::uint32_t count = meta & 3u, offset = meta >> 2 & 31u;
        const std::uint32_t first = firstTriangle(node) + offset;
        if (count == 0 || count > options.maxLeafSize) problem = "leaf size outside 1..maxLeafSize";
        if (offset + count > 24 || first + count > stored) {
          problem = "leaf out of range";
          continue;
        }
        const std::uint32_t bits = ((1u << count) - 1u) << offset;
        if (usedTriangleBits & bits) problem = "leaves of one node overlap";
        usedTriangleBits |= bits;
        ++leaves;
        maxDepth = std::max(maxDepth, childDepth);
        for (std::uint32_t i = first; i < first + count; ++i) {
          const std::uint32_t id = bvh.order[i];
          for (std::uint32_t j = first; j < i; ++j)
            if (bvh.order[j] == id) problem = "a leaf holds one triangle twice";
          ++leafOf[id];
          if (spatial) reach[id].push_back(slotPath);
          for (const gpu::vec4& p : {bvh.triangles[i].v0, bvh.triangles[i].v1, bvh.triangles[i].v2})
            exact.grow(glm::vec3(p));
        }
      }
      if (!spatial && !strictlyInside(exact, decodedBox(node, s)))
        problem = "decoded box does not strictly contain its contents";
      all.grow(exact);
    }
    return all;
  };
  walk(0, 1, Box{glm::vec3(-kInf), glm::vec3(kInf)});
  if (!problem.empty()) return problem;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (spatial ? leafOf[i] < 1 : leafOf[i] != 1)
      return "triangle " + std::to_string(i) + " in " + std::to_string(leafOf[i]) + " leaves";
    if (!spatial) continue;
    for (const glm::vec3& p : pointsOn(soup, i))
      if (std::none_of(reach[i].begin(), reach[i].end(), [&](const Box& b) { return strictlyContains(b, p); }))
        return "a point of triangle " + std::to_string(i) + " lies outside every path to its leaves";
  }
  for (std::size_t i = 0; i < nodeSeen.size(); ++i)
    if (nodeSeen[i] != 1) return "node " + std::to_string(i) + " unreachable";
  if (leaves != bvh.stats.leafCount) return "stats.leafCount";
  if (maxDepth != bvh.stats.maxDepth) return "stats.maxDepth";
  if (bvh.stats.maxDepth > gpu::kBvhMaxDepth) return "depth above kBvhMaxDepth";
  if (n > 0 && !(bvh.stats.sahCost > 0.0)) return "sahCost";
  return "";
}

// Random rays around `box`: origins inside and outside, directions with some zero components,
// some finite tmax / non-zero tmin.
std::vector<Ray> randomRays(std::size_t count, glm::vec3 lo, glm::vec3 hi, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), sym(-1.0f, 1.0f);
  const glm::vec3 extent = glm::max(hi - lo, glm::vec3(1e-3f));
  std::vector<Ray> rays(count);
  for (auto& r : rays) {
    r.origin = lo - 0.25f * extent + 1.5f * extent * glm::vec3(unit(rng), unit(rng), unit(rng));
    if (unit(rng) < 0.5f) {
      // Aim at a random point of the box, so most rays hit something.
      const glm::vec3 target = lo + extent * glm::vec3(unit(rng), unit(rng), unit(rng));
      r.direction = target - r.origin;
    } else {
      r.direction = glm::vec3(sym(rng), sym(rng), sym(rng));
    }
    const float z = unit(rng);
    if (z < 0.05f) r.direction.x = 0.0f;
    else if (z < 0.10f) r.direction.x = r.direction.y = 0.0f;
    if (r.direction == glm::vec3(0.0f)) r.direction.z = 1.0f;
    if (unit(rng) < 0.2f) r.tmax = unit(rng) * 2.0f;
    if (unit(rng) < 0.1f) r.tmin = unit(rng) * 0.5f;
  }
  return rays;
}

// Traversal against brute force: exact agreement of primitive, t, u, v, and of anyHit.
//
// `nearTieScale` > 0 relaxes this for coplanar overlapping triangles: there a triangle's t has an
// absolute rounding error of about eps * (distance of its vertices from the origin), far more
// than the relative slack of the box test, so the BVH may cull a box whose triangle would win a
// near-tie by an ulp or two. Such a difference is accepted when both hit, the BVH's hit is
// genuine (same t when re-tested alone) and the two t differ by at most nearTieScale / |d|.
void expectAgreesWithBruteForce(const Bvh& bvh, const TriangleSoup& soup,
                                const std::vector<Ray>& rays, const std::string& what,
                                float nearTieScale = 0.0f) {
  int mismatches = 0, anyMismatches = 0, hits = 0, nearTies = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Ray& ray = rays[i];
    const Hit a = closestHit(bvh, ray);
    const Hit b = closestHitBruteForce(soup, ray);
    hits += b.hit() ? 1 : 0;
    bool same = a.primitive == b.primitive &&
                (!b.hit() || (a.t == b.t && a.u == b.u && a.v == b.v));
    if (!same && nearTieScale > 0.0f && a.hit() && b.hit()) {
      const WatertightRay wr = prepareWatertightRay(ray.origin, ray.direction);
      float t = 0, u = 0, v = 0;
      const bool genuine = intersectTriangle(wr, soup.v0[a.primitive], soup.v1[a.primitive],
                                             soup.v2[a.primitive], ray.tmin, ray.tmax, t, u, v) &&
                           t == a.t;
      if (genuine && std::abs(a.t - b.t) <= nearTieScale / glm::length(ray.direction)) {
        same = true;
        ++nearTies;
      }
    }
    if (!same && mismatches++ < 5)
      ADD_FAILURE() << what << " ray " << i << ": bvh prim " << a.primitive << " t " << a.t
                    << ", brute force prim " << b.primitive << " t " << b.t;
    const bool anyExpected = b.hit() && b.t < ray.tmax;
    if (anyHit(bvh, ray) != anyExpected && anyMismatches++ < 5)
      ADD_FAILURE() << what << " ray " << i << ": anyHit disagrees";
  }
  EXPECT_EQ(mismatches, 0) << what;
  EXPECT_EQ(anyMismatches, 0) << what;
  EXPECT_LE(nearTies, static_cast<int>(rays.size() / 100)) << what;
  if (soup.size() == 0) {
    EXPECT_EQ(hits, 0);
  }
}

void soupBounds(const TriangleSoup& soup, glm::vec3& lo, glm::vec3& hi) {
  lo = glm::vec3(kInf);
  hi = glm::vec3(-kInf);
  for (std::size_t i = 0; i < soup.size(); ++i)
    for (const glm::vec3& p : {soup.v0[i], soup.v1[i], soup.v2[i]}) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  if (soup.size() == 0) lo = glm::vec3(-1), hi = glm::vec3(1);
}

void add(TriangleSoup& soup, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  soup.v0.push_back(a);
  soup.v1.push_back(b);
  soup.v2.push_back(c);
}

// Random triangles with sizes spread over five decades (some around 1e-6 of the scene).
TriangleSoup randomSoup(std::size_t count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), sym(-1.0f, 1.0f);
  TriangleSoup soup;
  for (std::size_t i = 0; i < count; ++i) {
    const glm::vec3 c(10.0f * unit(rng), 10.0f * unit(rng), 10.0f * unit(rng));
    const float size = unit(rng) < 0.05f ? 1e-5f : std::pow(10.0f, -3.0f * unit(rng) + 0.3f);
    add(soup, c + size * glm::vec3(sym(rng), sym(rng), sym(rng)),
        c + size * glm::vec3(sym(rng), sym(rng), sym(rng)),
        c + size * glm::vec3(sym(rng), sym(rng), sym(rng)));
  }
  return soup;
}

void checkSoup(const TriangleSoup& soup, std::size_t rayCount, const std::string& what,
               BuildOptions options = {}, float nearTieScale = 0.0f) {
  const Bvh bvh = build(soup, options);
  const std::string problem = validate(bvh, soup, options);
  ASSERT_EQ(problem, "") << what;
  EXPECT_LE(bvh.stats.maxDepth, gpu::kBvhMaxDepth) << what;
  glm::vec3 lo, hi;
  soupBounds(soup, lo, hi);
  expectAgreesWithBruteForce(bvh, soup, randomRays(rayCount, lo, hi, 1234), what, nearTieScale);
}

TEST(Bvh, ClosestAndAnyHitMatchBruteForceOnRandomSoups) {
  // 4 soups x 30k rays; leaf sizes and bin counts varied too.
  const std::array<std::uint32_t, 4> leafSizes = {1, 2, 3, 3};
  for (std::uint32_t s = 0; s < 4; ++s) {
    const TriangleSoup soup = randomSoup(400 + 200 * s, 100 + s);
    BuildOptions options;
    options.maxLeafSize = leafSizes[s];
    options.bins = s == 2 ? 4 : 16;
    options.threads = s + 1;
    const Bvh bvh = build(soup, options);
    ASSERT_EQ(validate(bvh, soup, options), "");
    glm::vec3 lo, hi;
    soupBounds(soup, lo, hi);
    expectAgreesWithBruteForce(bvh, soup, randomRays(30000, lo, hi, 7 + s),
                               "soup " + std::to_string(s));
  }
}

TEST(Bvh, SharedCentroids) {
  // 100k triangles with exactly the same centroid (c = 3 p - a - b), of random shapes.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> sym(-1.0f, 1.0f);
  const glm::vec3 p(0.5f, 0.25f, -0.75f);
  TriangleSoup soup;
  for (int i = 0; i < 100000; ++i) {
    const glm::vec3 a = p + glm::vec3(sym(rng), sym(rng), sym(rng));
    const glm::vec3 b = p + glm::vec3(sym(rng), sym(rng), sym(rng));
    add(soup, a, b, 3.0f * p - a - b);
  }
  // Brute force over 100k triangles is the cost here: 300 rays.
  checkSoup(soup, 300, "shared centroids");
}

TEST(Bvh, GeometricSequenceOfSizes) {
  // Triangle i has size and position 1.02^-i: each binned split can only peel off the few
  // triangles of the top bins, so without the median fallback the depth would pass 48
  // (measured: the fallback is needed, and the depth ends at exactly 48).
  TriangleSoup soup;
  float s = 1.0f;
  for (int i = 0; i < 3000; ++i, s /= 1.02f)
    add(soup, glm::vec3(s, 0, 0), glm::vec3(2 * s, 0, 0), glm::vec3(s, s, s));
  BuildOptions options;
  options.maxLeafSize = 1;
  const Bvh bvh = build(soup, options);
  EXPECT_GT(bvh.stats.medianFallbacks, 0u);
  checkSoup(soup, 5000, "geometric sizes", options);
  checkSoup(soup, 5000, "geometric sizes, leaves of 3");
}

TEST(Bvh, AllTrianglesInOnePlane) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  TriangleSoup flat, tilted;
  for (int i = 0; i < 2000; ++i) {
    const glm::vec2 c(10 * unit(rng), 10 * unit(rng));
    glm::vec2 q[3];
    for (auto& x : q) x = c + 0.5f * glm::vec2(unit(rng), unit(rng));
    add(flat, {q[0], 1.0f}, {q[1], 1.0f}, {q[2], 1.0f});
    auto lift = [](glm::vec2 x) { return glm::vec3(x, 0.3f * x.x - 0.2f * x.y); };
    add(tilted, lift(q[0]), lift(q[1]), lift(q[2]));
  }
  // Overlapping coplanar triangles: near-ties within 1e-5 of the scene size are accepted.
  checkSoup(flat, 10000, "axis-aligned plane", {}, 1e-4f);
  checkSoup(tilted, 10000, "tilted plane", {}, 1e-4f);
}

TEST(Bvh, DegenerateTriangles) {
  TriangleSoup soup = randomSoup(500, 9);
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> unit(0.0f, 10.0f);
  for (int i = 0; i < 500; ++i) {
    const glm::vec3 a(unit(rng), unit(rng), unit(rng)), b(unit(rng), unit(rng), unit(rng));
    if (i % 2) add(soup, a, a, a); // a point
    else add(soup, a, b, 0.5f * (a + b)); // a segment
  }
  checkSoup(soup, 10000, "degenerate");
  // Only degenerate triangles, all at one point: a zero-area root.
  TriangleSoup points;
  for (int i = 0; i < 100; ++i) add(points, glm::vec3(1), glm::vec3(1), glm::vec3(1));
  checkSoup(points, 1000, "one point");
}

TEST(Bvh, SingleTriangleAndEmptySoup) {
  TriangleSoup one;
  add(one, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  const Bvh bvh = build(one);
  ASSERT_EQ(bvh.nodes.size(), 1u);
  EXPECT_EQ(bvh.stats.leafCount, 1u);
  EXPECT_EQ(bvh.stats.maxDepth, 1u);
  Ray ray;
  ray.origin = {0.25f, 0.25f, 1};
  ray.direction = {0, 0, -1};
  const Hit h = closestHit(bvh, ray);
  EXPECT_EQ(h.primitive, 0u);
  EXPECT_EQ(h.t, 1.0f);
  checkSoup(one, 10000, "one triangle");

  const TriangleSoup empty;
  const Bvh none = build(empty);
  ASSERT_EQ(none.nodes.size(), 1u);
  EXPECT_TRUE(none.triangles.empty());
  EXPECT_FALSE(closestHit(none, ray).hit());
  EXPECT_FALSE(anyHit(none, ray));
  checkSoup(empty, 10000, "empty");
}

TEST(Bvh, SmallSoupsOfEverySize) {
  // Sizes around the leaf size, where leaf-versus-split decisions and the one-leaf root meet.
  for (std::uint32_t n = 1; n <= 40; ++n)
    checkSoup(randomSoup(n, 50 + n), 500, "n=" + std::to_string(n));
}

// The compact traversal stack a BVH needs: one uvec4 of 4 entries per 4 levels of interior nodes
// below the root (a traversal pushes at most depth - 2 entries), none beyond depth 18 or 65,536
// nodes; a kernel may trace a BVH when it has at least as many registers, or the general stack.
TEST(Bvh, CompactStackVectorsFollowTheDepthAndTheNodeLimit) {
  Bvh b;
  b.nodes.resize(10);
  const std::map<std::uint32_t, std::uint32_t> expected = {{0, 1}, {1, 1}, {2, 1}, {3, 1}, {6, 1}, {7, 2},
                                                           {10, 2}, {11, 3}, {14, 3}, {15, 4}, {18, 4}, {19, 0}};
  for (const auto& [depth, vectors] : expected) {
    b.stats.maxDepth = depth;
    EXPECT_EQ(compactStackVectors(b), vectors) << "depth " << depth;
  }
  b.stats.maxDepth = 5;
  b.nodes.resize(gpu::kBvhCompactStackNodes);
  EXPECT_EQ(compactStackVectors(b), 1u);
  b.nodes.resize(gpu::kBvhCompactStackNodes + 1);
  EXPECT_EQ(compactStackVectors(b), 0u);

  EXPECT_TRUE(compactStackHolds(0, 0));  // the general kernel traces anything
  EXPECT_TRUE(compactStackHolds(0, 3));
  EXPECT_TRUE(compactStackHolds(3, 2));
  EXPECT_TRUE(compactStackHolds(2, 2));
  EXPECT_FALSE(compactStackHolds(1, 2));
  EXPECT_FALSE(compactStackHolds(4, 0)); // beyond the compact stack
}

TEST(Bvh, ThreadCountDoesNotChangeTheTree) {
  const TriangleSoup soup = randomSoup(50000, 77);
  BuildOptions one, many;
  one.threads = 1;
  many.threads = 8;
  const Bvh a = build(soup, one), b = build(soup, many);
  EXPECT_EQ(a.order, b.order);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  EXPECT_EQ(0, std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(gpu::BvhNode)));
  EXPECT_EQ(a.stats.sahCost, b.stats.sahCost);
}

// Long thin triangles crossing a cube in every direction, with small ones between them: the
// scene spatial splits are for (an object split cannot separate crossing slivers).
TriangleSoup crossingSlivers(std::size_t count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), sym(-1.0f, 1.0f);
  TriangleSoup soup;
  for (std::size_t i = 0; i < count; ++i) {
    const glm::vec3 a(10.0f * unit(rng), 10.0f * unit(rng), 10.0f * unit(rng));
    if (i % 4 == 0) {
      const glm::vec3 b(10.0f * unit(rng), 10.0f * unit(rng), 10.0f * unit(rng));
      add(soup, a, b, b + 0.05f * glm::vec3(sym(rng), sym(rng), sym(rng)));
    } else {
      add(soup, a, a + 0.2f * glm::vec3(sym(rng), sym(rng), sym(rng)), a + 0.2f * glm::vec3(sym(rng), sym(rng), sym(rng)));
    }
  }
  return soup;
}

TEST(Bvh, SpatialSplitsKeepTraversalExactAndCoverEveryTriangle) {
  const std::array<float, 3> budgets = {0.01f, 0.3f, 2.0f};
  for (std::uint32_t s = 0; s < budgets.size(); ++s) {
    const TriangleSoup soup = crossingSlivers(1500, 200 + s);
    BuildOptions options;
    options.spatialSplitBudget = budgets[s];
    options.maxLeafSize = s + 1;
    options.threads = s + 1;
    const Bvh bvh = build(soup, options);
    const std::string what = "budget " + std::to_string(budgets[s]);
    ASSERT_EQ(validate(bvh, soup, options), "") << what;
    EXPECT_GT(bvh.stats.spatialSplits, 0u) << what;
    EXPECT_GT(bvh.stats.references, soup.size()) << what;
    glm::vec3 lo, hi;
    soupBounds(soup, lo, hi);
    expectAgreesWithBruteForce(bvh, soup, randomRays(20000, lo, hi, 31 + s), what);
  }
}

TEST(Bvh, SpatialSplitsLowerTheSahCostOfCrossingSlivers) {
  // Measured: binary SAH cost 260 without, 116 with (34 spatial splits, 2,968 references);
  // 8-wide 103 and 46.
  const TriangleSoup soup = crossingSlivers(2000, 5);
  BuildOptions plain, spatial;
  spatial.spatialSplitBudget = 0.5f;
  const Bvh a = build(soup, plain), b = build(soup, spatial);
  EXPECT_EQ(a.stats.spatialSplits, 0u);
  EXPECT_EQ(a.stats.references, soup.size());
  EXPECT_LT(b.stats.sahCost, 0.6 * a.stats.sahCost);
  EXPECT_LT(b.stats.wideSahCost, 0.6 * a.stats.wideSahCost);
}

TEST(Bvh, SpatialSplitsOnHardSoups) {
  // Degenerate triangles, one plane, shared centroids and the geometric sequence that needs the
  // median fallback: still exact, still within the depth bound.
  BuildOptions options;
  options.spatialSplitBudget = 0.5f;
  TriangleSoup degenerate = randomSoup(300, 9);
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> unit(0.0f, 10.0f);
  for (int i = 0; i < 300; ++i) {
    const glm::vec3 a(unit(rng), unit(rng), unit(rng)), b(unit(rng), unit(rng), unit(rng));
    if (i % 2) add(degenerate, a, a, a);
    else add(degenerate, a, b, 0.5f * (a + b));
  }
  checkSoup(degenerate, 5000, "degenerate, spatial splits", options);
  TriangleSoup flat;
  for (int i = 0; i < 1000; ++i) {
    const glm::vec2 c(10.0f * unit(rng), 10.0f * unit(rng));
    add(flat, {c, 1.0f}, {c + glm::vec2(unit(rng), 0.1f * unit(rng)), 1.0f}, {c + glm::vec2(0.1f * unit(rng), unit(rng)), 1.0f});
  }
  checkSoup(flat, 5000, "one plane, spatial splits", options, 1e-4f);
  TriangleSoup shared;
  const glm::vec3 p(0.5f, 0.25f, -0.75f);
  for (int i = 0; i < 3000; ++i) {
    const glm::vec3 a = p + glm::vec3(unit(rng), unit(rng), unit(rng)) - 5.0f;
    const glm::vec3 b = p + glm::vec3(unit(rng), unit(rng), unit(rng)) - 5.0f;
    add(shared, a, b, 3.0f * p - a - b);
  }
  checkSoup(shared, 500, "shared centroids, spatial splits", options);
  TriangleSoup geometric;
  float size = 1.0f;
  for (int i = 0; i < 3000; ++i, size /= 1.02f)
    add(geometric, glm::vec3(size, 0, 0), glm::vec3(2 * size, 0, 0), glm::vec3(size, size, size));
  checkSoup(geometric, 3000, "geometric sizes, spatial splits", options);
}

TEST(Bvh, SpatialSplitsDoNotDependOnTheThreadCount) {
  const TriangleSoup soup = crossingSlivers(20000, 78);
  BuildOptions one, many;
  one.threads = 1;
  many.threads = 8;
  one.spatialSplitBudget = many.spatialSplitBudget = 0.2f;
  const Bvh a = build(soup, one), b = build(soup, many);
  EXPECT_GT(a.stats.spatialSplits, 0u);
  EXPECT_EQ(a.order, b.order);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  EXPECT_EQ(0, std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(gpu::BvhNode)));
  EXPECT_EQ(a.stats.sahCost, b.stats.sahCost);
}

} // namespace
} // namespace obscura::bvh
