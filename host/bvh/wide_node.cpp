// wide_node.cpp — quantisation and decoding of the compressed wide node (see wide_node.h).
//
// Ylitie, Karras & Laine 2017, §3.1: child boxes as 8-bit offsets on a grid of spacing 2^e per
// axis from a per-node origin. Our decoding is plane = fma(q, 2^e, origin), one rounding of an
// exact sum (q * 2^e is exact), so the host can evaluate it bit for bit as the GPU does and
// pick the q that puts every decoded plane strictly outside the exact box.
#include "bvh/wide_node.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace obscura::bvh {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

float decodePlane(float origin, float scale, std::uint32_t q) {
  return std::fma(static_cast<float>(q), scale, origin);
}

float scaleOf(std::uint32_t exponentByte) { return std::bit_cast<float>(exponentByte << 23); }

// The grid of one axis for planes in [lo, hi]: origin strictly below lo, and the smallest
// power-of-two spacing whose plane 255 lies strictly above hi. Returns the biased exponent byte.
std::uint32_t chooseGrid(float lo, float hi, float& origin) {
  origin = std::nextafter(lo, -kInf);
  const float magnitude = std::max(std::abs(origin), std::abs(hi));
  // Start near the answer: 255 * 2^e ~ extent, but not below the spacing of floats at this
  // magnitude (a flat axis), nor below the smallest normal power of two.
  int e = std::ilogb(std::max(hi - origin, std::numeric_limits<float>::min())) - 8;
  if (magnitude > 0.0f) e = std::max(e, std::ilogb(magnitude) - 24 - 8);
  e = std::max(e, -126);
  while (e < 127 && !(decodePlane(origin, scaleOf(static_cast<std::uint32_t>(e + 127)), 255) > hi)) ++e;
  return static_cast<std::uint32_t>(e + 127);
}

// Largest q whose plane lies strictly below `lo` (q = 0 always does: origin < node lo <= lo).
std::uint32_t quantiseLow(float lo, float origin, float scale) {
  float guess = std::floor((lo - origin) / scale);
  std::uint32_t q = static_cast<std::uint32_t>(std::clamp(guess, 0.0f, 255.0f));
  while (q > 0 && !(decodePlane(origin, scale, q) < lo)) --q;
  while (q < 255 && decodePlane(origin, scale, q + 1) < lo) ++q;
  return q;
}

// Smallest q whose plane lies strictly above `hi` (q = 255 always does, by chooseGrid).
std::uint32_t quantiseHigh(float hi, float origin, float scale) {
  float guess = std::ceil((hi - origin) / scale);
  std::uint32_t q = static_cast<std::uint32_t>(std::clamp(guess, 0.0f, 255.0f));
  while (q < 255 && !(decodePlane(origin, scale, q) > hi)) ++q;
  while (q > 0 && decodePlane(origin, scale, q - 1) > hi) --q;
  return q;
}

std::uint32_t byteOf(std::uint32_t word, unsigned index) { return (word >> (8 * index)) & 0xFFu; }
std::uint32_t bits(float f) { return std::bit_cast<std::uint32_t>(f); }
float asFloat(std::uint32_t u) { return std::bit_cast<float>(u); }

// The q word of `axis` (qx, qy or qz) as uints.
glm::uvec4 qWords(const gpu::BvhNode& node, int axis) {
  const gpu::vec4& q = axis == 0 ? node.qx : axis == 1 ? node.qy : node.qz;
  return {bits(q.x), bits(q.y), bits(q.z), bits(q.w)};
}

} // namespace

void writeWideNode(gpu::BvhNode& node, const std::array<WideChild, gpu::kBvhWidth>& slots,
                   std::uint32_t firstChildIndex, std::uint32_t firstTriangleIndex) {
  Box all;
  std::uint32_t imask = 0, meta[2] = {0, 0};
  for (unsigned s = 0; s < gpu::kBvhWidth; ++s) {
    const WideChild& c = slots[s];
    if (c.kind == WideChild::Kind::Empty) continue;
    all.grow(c.box);
    std::uint32_t m = 0x80u;
    if (c.kind == WideChild::Kind::Leaf) m = c.triangleCount | c.triangleOffset << 2;
    else imask |= 1u << s;
    meta[s / 4] |= m << (8 * (s % 4));
  }
  if (all.empty()) all = Box{glm::vec3(0.0f), glm::vec3(0.0f)}; // no children: any grid will do

  std::uint32_t exponents = 0;
  glm::uvec4 q[3] = {};
  for (int a = 0; a < 3; ++a) {
    float origin = 0.0f;
    const std::uint32_t e = chooseGrid(all.lo[a], all.hi[a], origin);
    node.origin[a] = origin;
    exponents |= e << (8 * a);
    const float scale = scaleOf(e);
    for (unsigned s = 0; s < gpu::kBvhWidth; ++s) {
      if (slots[s].kind == WideChild::Kind::Empty) continue;
      const std::uint32_t lo = quantiseLow(slots[s].box.lo[a], origin, scale);
      const std::uint32_t hi = quantiseHigh(slots[s].box.hi[a], origin, scale);
      q[a][s / 4] |= lo << (8 * (s % 4));
      q[a][2 + s / 4] |= hi << (8 * (s % 4));
    }
  }
  node.origin.w = asFloat(exponents | imask << 24);
  node.refs = gpu::vec4(asFloat(firstChildIndex), asFloat(firstTriangleIndex), asFloat(meta[0]), asFloat(meta[1]));
  node.qx = gpu::vec4(asFloat(q[0].x), asFloat(q[0].y), asFloat(q[0].z), asFloat(q[0].w));
  node.qy = gpu::vec4(asFloat(q[1].x), asFloat(q[1].y), asFloat(q[1].z), asFloat(q[1].w));
  node.qz = gpu::vec4(asFloat(q[2].x), asFloat(q[2].y), asFloat(q[2].z), asFloat(q[2].w));
}

std::array<WideChild, gpu::kBvhWidth> decodedSlots(const gpu::BvhNode& node) {
  const std::uint32_t imask = internalMask(node);
  std::array<WideChild, gpu::kBvhWidth> slots{};
  for (unsigned s = 0; s < gpu::kBvhWidth; ++s) {
    const std::uint32_t meta = slotMeta(node, s);
    if (meta == 0) continue;
    WideChild& c = slots[s];
    c.box = decodedBox(node, s);
    if (imask >> s & 1u) {
      c.kind = WideChild::Kind::Internal;
    } else {
      c.kind = WideChild::Kind::Leaf;
      c.triangleCount = meta & 3u;
      c.triangleOffset = meta >> 2 & 31u;
    }
  }
  return slots;
}

std::array<WideChild, gpu::kBvhWidth> exactSlots(const gpu::BvhNode& node, const std::vector<gpu::BvhTriangle>& triangles,
                                                 const std::vector<Box>& nodeBox) {
  std::array<WideChild, gpu::kBvhWidth> slots = decodedSlots(node);
  for (unsigned s = 0; s < gpu::kBvhWidth; ++s) {
    WideChild& c = slots[s];
    if (c.kind == WideChild::Kind::Internal) {
      c.box = nodeBox[childNodeIndex(node, s)];
    } else if (c.kind == WideChild::Kind::Leaf) {
      c.box = Box{};
      const std::uint32_t first = firstTriangle(node) + c.triangleOffset;
      for (std::uint32_t t = first; t < first + c.triangleCount; ++t)
        for (const gpu::vec4* v : {&triangles[t].v0, &triangles[t].v1, &triangles[t].v2}) c.box.grow(glm::vec3(*v));
    }
  }
  return slots;
}

std::uint32_t internalMask(const gpu::BvhNode& node) { return bits(node.origin.w) >> 24; }
std::uint32_t firstChild(const gpu::BvhNode& node) { return bits(node.refs.x); }
std::uint32_t firstTriangle(const gpu::BvhNode& node) { return bits(node.refs.y); }
std::uint32_t slotMeta(const gpu::BvhNode& node, unsigned slot) {
  return byteOf(bits(slot < 4 ? node.refs.z : node.refs.w), slot % 4);
}

std::uint32_t childNodeIndex(const gpu::BvhNode& node, unsigned slot) {
  return firstChild(node) + static_cast<std::uint32_t>(std::popcount(internalMask(node) & ((1u << slot) - 1u)));
}

Box decodedBox(const gpu::BvhNode& node, unsigned slot) {
  Box b;
  for (int a = 0; a < 3; ++a) {
    const float scale = scaleOf(byteOf(bits(node.origin.w), static_cast<unsigned>(a)));
    const glm::uvec4 w = qWords(node, a);
    b.lo[a] = decodePlane(node.origin[a], scale, byteOf(w[slot / 4], slot % 4));
    b.hi[a] = decodePlane(node.origin[a], scale, byteOf(w[2 + slot / 4], slot % 4));
  }
  return b;
}

BoxRay makeBoxRay(const glm::vec3& origin, const glm::vec3& direction) {
  BoxRay r;
  r.origin = origin;
  r.octant = 0;
  for (int a = 0; a < 3; ++a) {
    // safeReciprocal() of shaders/lib/intersect.glsl: a zero component gives a huge finite value.
    constexpr float kTiny = 1e-37f;
    const float m = std::max(std::abs(direction[a]), kTiny);
    r.negative[a] = direction[a] < 0.0f;
    r.invDir[a] = (r.negative[a] ? -1.0f : 1.0f) / m;
    r.octant |= (r.negative[a] ? 1u : 0u) << a;
  }
  return r;
}

std::uint32_t hitChildren(const gpu::BvhNode& node, const BoxRay& ray, float tmin, float tmax) {
  // gpu::kBoxFarScale covers a GPU's 2.5-ulp reciprocal; the CPU's bound would be gamma(3), but
  // the same boxes are tested on both.
  std::uint32_t hits = 0;
  for (unsigned s = 0; s < gpu::kBvhWidth; ++s) {
    if (slotMeta(node, s) == 0) continue;
    const Box b = decodedBox(node, s);
    float tNear = tmin, tFar = tmax;
    for (int a = 0; a < 3; ++a) {
      const float nearPlane = ray.negative[a] ? b.hi[a] : b.lo[a];
      const float farPlane = ray.negative[a] ? b.lo[a] : b.hi[a];
      const float t0 = (nearPlane - ray.origin[a]) * ray.invDir[a];
      const float t1 = (farPlane - ray.origin[a]) * ray.invDir[a];
      tNear = std::max(tNear, t0);
      tFar = std::min(tFar, t1);
    }
    if (tNear <= tFar * gpu::kBoxFarScale) hits |= 1u << s;
  }
  return hits;
}

} // namespace obscura::bvh
