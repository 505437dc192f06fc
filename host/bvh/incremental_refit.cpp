#include "bvh/incremental_refit.h"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace obscura::bvh {

IncrementalRefit::IncrementalRefit(const Bvh& bvh)
    : parent_(bvh.nodes.size(), 0), leafNode_(bvh.triangles.size(), 0), nodeBox_(bvh.nodes.size()),
      marked_(bvh.nodes.size(), 0) {
  // Children follow their parent (breadth-first): from the last node up, every child's box is known.
  for (std::size_t n = bvh.nodes.size(); n-- > 0;) {
    const gpu::BvhNode& node = bvh.nodes[n];
    const std::uint32_t imask = internalMask(node);
    for (unsigned s = 0; s < gpu::kBvhWidth; ++s) {
      const std::uint32_t meta = slotMeta(node, s);
      if (meta == 0) continue;
      if (imask >> s & 1u) {
        parent_[childNodeIndex(node, s)] = static_cast<std::uint32_t>(n);
      } else {
        const std::uint32_t first = firstTriangle(node) + (meta >> 2 & 31u);
        for (std::uint32_t t = first; t < first + (meta & 3u); ++t) leafNode_[t] = static_cast<std::uint32_t>(n);
      }
    }
    for (const WideChild& c : exactSlots(node, bvh.triangles, nodeBox_))
      if (c.kind != WideChild::Kind::Empty) nodeBox_[n].grow(c.box);
  }
  // Where each original triangle lies (counting sort of `order`).
  std::uint32_t originals = 0;
  for (std::uint32_t id : bvh.order) originals = std::max(originals, id + 1);
  placesFrom_.assign(originals + 1, 0);
  for (std::uint32_t id : bvh.order) ++placesFrom_[id + 1];
  for (std::size_t i = 1; i < placesFrom_.size(); ++i) placesFrom_[i] += placesFrom_[i - 1];
  places_.resize(bvh.order.size());
  std::vector<std::uint32_t> next(placesFrom_.begin(), placesFrom_.end() - 1);
  for (std::uint32_t p = 0; p < bvh.order.size(); ++p) places_[next[bvh.order[p]]++] = p;
}

std::span<const std::uint32_t> IncrementalRefit::refit(Bvh& bvh, std::span<const std::uint32_t> ids, const TriangleSoup& moved) {
  if (bvh.nodes.size() != parent_.size() || bvh.triangles.size() != leafNode_.size() || moved.size() != ids.size())
    throw std::logic_error("IncrementalRefit: not the tree it was made for, or a soup that does not match the ids");
  refitted_.clear();
  auto mark = [&](std::uint32_t n) { // n and its ancestors, up to one marked already
    while (!marked_[n]) {
      marked_[n] = 1;
      refitted_.push_back(n);
      if (n == 0) break;
      n = parent_[n];
    }
  };
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const std::uint32_t id = ids[k];
    if (id + 1 >= placesFrom_.size()) continue; // not in the tree (never placed)
    for (std::uint32_t i = placesFrom_[id]; i < placesFrom_[id + 1]; ++i) {
      const std::uint32_t p = places_[i];
      gpu::BvhTriangle& t = bvh.triangles[p];
      t.v0 = gpu::vec4(moved.v0[k], t.v0.w);
      t.v1 = gpu::vec4(moved.v1[k], 0.0f);
      t.v2 = gpu::vec4(moved.v2[k], 0.0f);
      mark(leafNode_[p]);
    }
  }
  // Children before parents: the highest index first.
  std::sort(refitted_.begin(), refitted_.end(), std::greater<>());
  for (const std::uint32_t n : refitted_) {
    gpu::BvhNode& node = bvh.nodes[n];
    const std::array<WideChild, gpu::kBvhWidth> slots = exactSlots(node, bvh.triangles, nodeBox_);
    nodeBox_[n] = Box{};
    for (const WideChild& c : slots)
      if (c.kind != WideChild::Kind::Empty) nodeBox_[n].grow(c.box);
    writeWideNode(node, slots, firstChild(node), firstTriangle(node));
    marked_[n] = 0;
  }
  return refitted_;
}

} // namespace obscura::bvh
