#include <algorithm>
#include <bit>
#include <limits>

#include "bvh/bvh.h"

namespace obscura::bvh {
namespace {

struct Box {
  glm::vec3 lo{std::numeric_limits<float>::infinity()};
  glm::vec3 hi{-std::numeric_limits<float>::infinity()};
  void grow(const glm::vec3& p) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
  void grow(const Box& b) { lo = glm::min(lo, b.lo); hi = glm::max(hi, b.hi); }
};

std::uint32_t childRef(const gpu::BvhNode& node, int which) {
  return std::bit_cast<std::uint32_t>(which == 0 ? node.lo0.w : node.hi0.w);
}

} // namespace

void refit(Bvh& bvh, const TriangleSoup& soup) {
  // The leaves keep their triangles; their vertices come from the soup again.
  for (std::size_t i = 0; i < bvh.triangles.size(); ++i) {
    const std::uint32_t id = bvh.order[i];
    bvh.triangles[i].v0 = gpu::vec4(soup.v0[id], bvh.triangles[i].v0.w);
    bvh.triangles[i].v1 = gpu::vec4(soup.v1[id], 0.0f);
    bvh.triangles[i].v2 = gpu::vec4(soup.v2[id], 0.0f);
  }
  // Nodes are in depth-first order (a child's index is above its parent's): from the last to the
  // first, every child box is the union of what lies below it, already refitted.
  std::vector<Box> nodeBox(bvh.nodes.size());
  for (std::size_t n = bvh.nodes.size(); n-- > 0;) {
    gpu::BvhNode& node = bvh.nodes[n];
    for (int c = 0; c < 2; ++c) {
      const std::uint32_t ref = childRef(node, c);
      if (ref == gpu::kInvalidIndex) continue; // the never-hit child keeps its inverted box
      Box box;
      if (ref & gpu::kLeafFlag) {
        const std::uint32_t first = ref & gpu::kLeafFirstMask;
        const std::uint32_t count = ((ref >> gpu::kLeafCountShift) & gpu::kLeafCountMask) + 1;
        for (std::uint32_t t = first; t < first + count; ++t)
          for (const gpu::vec4* v : {&bvh.triangles[t].v0, &bvh.triangles[t].v1, &bvh.triangles[t].v2})
            box.grow(glm::vec3(*v));
      } else {
        box = nodeBox[ref];
      }
      gpu::vec4& lo = c == 0 ? node.lo0 : node.lo1;
      gpu::vec4& hi = c == 0 ? node.hi0 : node.hi1;
      lo = gpu::vec4(box.lo, lo.w);
      hi = gpu::vec4(box.hi, hi.w);
      nodeBox[n].grow(box);
    }
  }
}

} // namespace obscura::bvh
