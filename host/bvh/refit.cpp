// refit.cpp — new boxes for moved triangles, same topology (bvh.h).
#include <array>

#include "bvh/bvh.h"
#include "bvh/wide_node.h"

namespace obscura::bvh {

void refit(Bvh& bvh, const TriangleSoup& soup) {
  // The leaves keep their triangles; their vertices come from the soup again.
  for (std::size_t i = 0; i < bvh.triangles.size(); ++i) {
    const std::uint32_t id = bvh.order[i];
    bvh.triangles[i].v0 = gpu::vec4(soup.v0[id], bvh.triangles[i].v0.w);
    bvh.triangles[i].v1 = gpu::vec4(soup.v1[id], 0.0f);
    bvh.triangles[i].v2 = gpu::vec4(soup.v2[id], 0.0f);
  }
  // Nodes are in breadth-first order (a node's children have larger indices): from the last to
  // the first, every slot's box is the union of what lies below it, already refitted; then the
  // node is quantised again on a grid fitted to the new boxes.
  std::vector<Box> nodeBox(bvh.nodes.size());
  for (std::size_t n = bvh.nodes.size(); n-- > 0;) {
    gpu::BvhNode& node = bvh.nodes[n];
    const std::uint32_t imask = internalMask(node);
    std::array<WideChild, gpu::kBvhWidth> slots{};
    for (unsigned s = 0; s < gpu::kBvhWidth; ++s) {
      const std::uint32_t meta = slotMeta(node, s);
      if (meta == 0) continue;
      WideChild& c = slots[s];
      if (imask >> s & 1u) {
        c.kind = WideChild::Kind::Internal;
        c.box = nodeBox[childNodeIndex(node, s)];
      } else {
        c.kind = WideChild::Kind::Leaf;
        c.triangleCount = meta & 3u;
        c.triangleOffset = meta >> 2 & 31u;
        const std::uint32_t first = firstTriangle(node) + c.triangleOffset;
        for (std::uint32_t t = first; t < first + c.triangleCount; ++t)
          for (const gpu::vec4* v : {&bvh.triangles[t].v0, &bvh.triangles[t].v1, &bvh.triangles[t].v2})
            c.box.grow(glm::vec3(*v));
      }
      nodeBox[n].grow(c.box);
    }
    writeWideNode(node, slots, firstChild(node), firstTriangle(node));
  }
}

} // namespace obscura::bvh
