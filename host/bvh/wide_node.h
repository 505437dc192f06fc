// wide_node.h — the compressed 8-wide node of shaders/shared/host_device.h (gpu::BvhNode), on the
// host: writing a node from exact child boxes (outward quantisation), reading it back, and the
// ray/child-box test exactly as shaders/lib/bvh.glsl computes it.
#pragma once
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

#include "shared/host_device.h"

namespace obscura::bvh {

struct Box {
  glm::vec3 lo{std::numeric_limits<float>::infinity()};
  glm::vec3 hi{-std::numeric_limits<float>::infinity()};
  void grow(const glm::vec3& p) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
  void grow(const Box& b) { lo = glm::min(lo, b.lo); hi = glm::max(hi, b.hi); }
  bool empty() const { return !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z); }
};

// One slot of a wide node as the builder and refit describe it.
struct WideChild {
  enum class Kind : std::uint8_t { Empty, Leaf, Internal };
  Kind kind = Kind::Empty;
  Box box;                    // exact bounds of what lies below
  std::uint32_t triangleOffset = 0; // leaf: first triangle relative to the node's triangle base
  std::uint32_t triangleCount = 0;  // leaf: 1..gpu::kLeafMaxTriangles
};

// Writes `node` from its 8 slots: quantised boxes (each decoded plane strictly outside the exact
// box, so a ray starting exactly on a face still gets a non-zero distance to it), meta bytes and
// the internal-child mask. `firstChild` / `firstTriangle` go to refs.x / refs.y.
void writeWideNode(gpu::BvhNode& node, const std::array<WideChild, gpu::kBvhWidth>& slots,
                   std::uint32_t firstChild, std::uint32_t firstTriangle);

// The slots of `node` as it decodes: kind, leaf triangles, and the decoded (conservative) boxes.
std::array<WideChild, gpu::kBvhWidth> decodedSlots(const gpu::BvhNode& node);
// The slots of `node` as refit sees them, with exact boxes: an interior slot's from `nodeBox` (per
// node, filled by the caller bottom-up: children follow their parent), a leaf slot's from its
// triangles (`triangles`: Bvh::triangles, their whole boxes).
std::array<WideChild, gpu::kBvhWidth> exactSlots(const gpu::BvhNode& node, const std::vector<gpu::BvhTriangle>& triangles,
                                                 const std::vector<Box>& nodeBox);

// Decoded fields.
std::uint32_t internalMask(const gpu::BvhNode& node);   // bit s: slot s is an interior node
std::uint32_t firstChild(const gpu::BvhNode& node);
std::uint32_t firstTriangle(const gpu::BvhNode& node);
std::uint32_t slotMeta(const gpu::BvhNode& node, unsigned slot); // 0 = empty
// Node index of interior slot `slot`: the first child plus the interior slots before it.
std::uint32_t childNodeIndex(const gpu::BvhNode& node, unsigned slot);
// The decoded (quantised) box of a slot, exactly as the GPU decodes it.
Box decodedBox(const gpu::BvhNode& node, unsigned slot);

// Per-ray constants of the child-box test, as shaders/lib/bvh.glsl prepares them.
struct BoxRay {
  glm::vec3 origin;
  glm::vec3 invDir;  // safeReciprocal(direction) of shaders/lib/intersect.glsl
  glm::bvec3 negative; // direction < 0 per axis: the near plane is the box's hi side
  std::uint32_t octant; // negative.x | negative.y << 1 | negative.z << 2
};
BoxRay makeBoxRay(const glm::vec3& origin, const glm::vec3& direction);

// Bit s set: the ray meets slot s's decoded box within [tmin, tmax * (1 + 2 gamma(7))] (Ize,
// "Robust BVH Ray Traversal", JCGT 2013). Empty slots never hit.
std::uint32_t hitChildren(const gpu::BvhNode& node, const BoxRay& ray, float tmin, float tmax);

} // namespace obscura::bvh
