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
    const std::array<WideChild, gpu::kBvhWidth> slots = exactSlots(node, bvh.triangles, nodeBox);
    for (const WideChild& c : slots)
      if (c.kind != WideChild::Kind::Empty) nodeBox[n].grow(c.box);
    writeWideNode(node, slots, firstChild(node), firstTriangle(node));
  }
}

} // namespace obscura::bvh
