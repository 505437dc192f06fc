#include "bvh/insert.h"

#include <algorithm>
#include <array>
#include <bit>
#include <limits>

#include "bvh/wide_node.h"

namespace obscura::bvh {
namespace {

// One past the last triangle the node's leaf slots address, relative to its first triangle (from
// the meta bytes alone: every node is looked at).
std::uint32_t leafRangeEnd(const gpu::BvhNode& node) {
  std::uint32_t end = 0;
  const std::uint32_t imask = internalMask(node);
  for (unsigned s = 0; s < gpu::kBvhWidth; ++s) {
    const std::uint32_t meta = slotMeta(node, s);
    if (meta == 0 || (imask >> s & 1u)) continue;
    end = std::max(end, (meta >> 2 & 31u) + (meta & 3u));
  }
  return end;
}

} // namespace

bool insertTriangles(Bvh& bvh, std::span<const std::uint32_t> ids, const TriangleSoup& added) {
  const auto count = static_cast<std::uint32_t>(ids.size());
  if (count == 0 || count > gpu::kLeafMaxTriangles || added.size() != ids.size() || bvh.nodes.empty()) return false;
  Box box;
  for (std::size_t k = 0; k < added.size(); ++k)
    for (const glm::vec3& v : {added.v0[k], added.v1[k], added.v2[k]}) box.grow(v);

  // The node with room (a free slot, and the leaf's offset within 5 bits) whose box grows least,
  // in surface area, to hold the new triangles: a wide tree's nodes are mostly full, so every
  // node is looked at (through its parent's decoded, so conservative, box of it), not only those
  // on the way down.
  auto hasRoom = [&](const gpu::BvhNode& node) {
    bool freeSlot = false;
    for (unsigned s = 0; s < gpu::kBvhWidth; ++s) freeSlot = freeSlot || slotMeta(node, s) == 0;
    return freeSlot && leafRangeEnd(node) <= 31u;
  };
  auto area = [](const Box& b) {
    const glm::vec3 e = glm::max(b.hi - b.lo, glm::vec3(0.0f));
    return e.x * e.y + e.y * e.z + e.z * e.x;
  };
  std::uint32_t chosen = ~0u;
  float best = std::numeric_limits<float>::infinity(), bestArea = best;
  auto consider = [&](std::uint32_t n, const Box& nodeBox) {
    if (!hasRoom(bvh.nodes[n])) return;
    Box grown = nodeBox;
    grown.grow(box);
    const float cost = area(grown) - area(nodeBox);
    if (cost < best || (cost == best && area(nodeBox) < bestArea)) {
      chosen = n;
      best = cost;
      bestArea = area(nodeBox);
    }
  };
  Box rootBox;
  for (unsigned s = 0; s < gpu::kBvhWidth; ++s)
    if (slotMeta(bvh.nodes[0], s) != 0) rootBox.grow(decodedBox(bvh.nodes[0], s));
  consider(0, rootBox);
  for (std::uint32_t n = 0; n < bvh.nodes.size(); ++n) {
    const gpu::BvhNode& node = bvh.nodes[n];
    const std::uint32_t imask = internalMask(node);
    for (unsigned s = 0; s < gpu::kBvhWidth; ++s)
      if (imask >> s & 1u) consider(childNodeIndex(node, s), decodedBox(node, s));
  }
  if (chosen == ~0u) return false;

  gpu::BvhNode& node = bvh.nodes[chosen];
  // The node written again with its slots as they decode, and the new leaf in its first free slot.
  std::array<WideChild, gpu::kBvhWidth> slots = decodedSlots(node);
  const std::uint32_t oldFirst = firstTriangle(node), rangeEnd = leafRangeEnd(node);
  const auto newFirst = static_cast<std::uint32_t>(bvh.triangles.size());
  for (std::uint32_t t = 0; t < rangeEnd; ++t) { // the node's leaves, copied to the end
    bvh.triangles.push_back(bvh.triangles[oldFirst + t]);
    bvh.order.push_back(bvh.order[oldFirst + t]);
  }
  for (std::size_t k = 0; k < added.size(); ++k) {
    gpu::BvhTriangle t;
    t.v0 = gpu::vec4(added.v0[k], std::bit_cast<float>(ids[k]));
    t.v1 = gpu::vec4(added.v1[k], 0.0f);
    t.v2 = gpu::vec4(added.v2[k], 0.0f);
    bvh.triangles.push_back(t);
    bvh.order.push_back(ids[k]);
  }
  for (WideChild& c : slots)
    if (c.kind == WideChild::Kind::Empty) {
      c = {.kind = WideChild::Kind::Leaf, .box = box, .triangleOffset = rangeEnd, .triangleCount = count};
      break;
    }
  writeWideNode(node, slots, firstChild(node), newFirst);
  // Its ancestors' boxes for that slot still hold the old box: grown exactly by the refit after.
  return true;
}

} // namespace obscura::bvh
