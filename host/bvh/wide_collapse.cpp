// wide_collapse.cpp — the dynamic programme of wide_collapse.h.
#include "bvh/wide_collapse.h"

#include <limits>
#include <stdexcept>

namespace obscura::bvh {
namespace {
constexpr float kInf = std::numeric_limits<float>::infinity();
} // namespace

WideCollapse::WideCollapse(std::span<const CollapseInput> nodes, const CollapseCosts& costs)
    : nodes_(nodes), costs_(costs) {
  if (nodes.empty() || nodes[0].leaf()) throw std::invalid_argument("WideCollapse: the root must be interior");
  subtreeTriangles_.assign(nodes.size(), 0);
  cost_.assign(nodes.size() * kWidth, kInf);
  choice_.assign(nodes.size() * kWidth, 0);
  nodeSplit_.assign(nodes.size(), 0);
  // Pre-order over the reachable nodes; solved in reverse, so every child before its parent.
  std::vector<std::uint32_t> order, todo = {0};
  while (!todo.empty()) {
    const std::uint32_t n = todo.back();
    todo.pop_back();
    order.push_back(n);
    if (nodes[n].leaf()) continue;
    for (const std::uint32_t c : nodes[n].child) {
      if (c <= n || c >= nodes.size()) throw std::invalid_argument("WideCollapse: a child must follow its parent");
      todo.push_back(c);
    }
  }
  for (auto it = order.rbegin(); it != order.rend(); ++it) solve(*it);
}

void WideCollapse::solve(std::uint32_t n) {
  const CollapseInput& node = nodes_[n];
  float* c = &cost_[std::size_t{n} * kWidth];
  std::uint8_t* how = &choice_[std::size_t{n} * kWidth];
  if (node.leaf()) {
    subtreeTriangles_[n] = node.triangles;
    const float leaf = costs_.triangle * node.area * static_cast<float>(node.triangles);
    for (int i = 0; i < kWidth; ++i) c[i] = leaf; // C(n, i) = C(n, 1), as a leaf
    return;
  }
  const std::uint32_t l = node.child[0], r = node.child[1];
  subtreeTriangles_[n] = subtreeTriangles_[l] + subtreeTriangles_[r];
  const float* cl = &cost_[std::size_t{l} * kWidth];
  const float* cr = &cost_[std::size_t{r} * kWidth];
  // The two children sharing i slots (i = 2..8): the best k for the left one.
  float shared[kWidth + 1];
  std::uint8_t sharedSplit[kWidth + 1] = {};
  for (int i = 2; i <= kWidth; ++i) {
    // k = 1 first, so that a split is recorded even when every sum is infinite.
    shared[i] = cl[0] + cr[i - 2];
    sharedSplit[i] = 1;
    for (int k = 2; k < i; ++k) {
      const float s = cl[k - 1] + cr[i - k - 1];
      if (s < shared[i]) {
        shared[i] = s;
        sharedSplit[i] = static_cast<std::uint8_t>(k);
      }
    }
  }
  const float asNode = costs_.node * node.area + shared[kWidth];
  nodeSplit_[n] = sharedSplit[kWidth];
  const float asLeaf = subtreeTriangles_[n] <= costs_.maxLeafTriangles
                           ? costs_.triangle * node.area * static_cast<float>(subtreeTriangles_[n])
                           : kInf;
  // Ties go to the leaf: the same cost with one node fewer.
  c[0] = asLeaf <= asNode ? asLeaf : asNode;
  how[0] = asLeaf <= asNode ? 0 : 1;
  for (int i = 2; i <= kWidth; ++i) {
    const bool split = shared[i] < c[i - 2];
    c[i - 1] = split ? shared[i] : c[i - 2];
    how[i - 1] = split ? sharedSplit[i] : 0;
  }
}

void WideCollapse::collect(std::uint32_t n, int i, std::vector<CollapsedSlot>& out) const {
  // C(n, i) taken as C(n, i - 1) until it was a split or i = 1.
  while (i > 1 && choice_[std::size_t{n} * kWidth + i - 1] == 0) --i;
  if (i == 1) {
    const bool leaf = nodes_[n].leaf() || choice_[std::size_t{n} * kWidth] == 0;
    out.push_back({n, leaf});
    return;
  }
  const int k = choice_[std::size_t{n} * kWidth + i - 1];
  collect(nodes_[n].child[0], k, out);
  collect(nodes_[n].child[1], i - k, out);
}

std::vector<CollapsedSlot> WideCollapse::slots(std::uint32_t n) const {
  if (nodes_[n].leaf()) throw std::invalid_argument("WideCollapse::slots: a leaf has no slots");
  std::vector<CollapsedSlot> out;
  out.reserve(kWidth);
  const int k = nodeSplit_[n];
  collect(nodes_[n].child[0], k, out);
  collect(nodes_[n].child[1], kWidth - k, out);
  return out;
}

double WideCollapse::cost() const {
  const CollapseInput& root = nodes_[0];
  const float* cl = &cost_[std::size_t{root.child[0]} * kWidth];
  const float* cr = &cost_[std::size_t{root.child[1]} * kWidth];
  const int k = nodeSplit_[0];
  const double c = double{costs_.node} * root.area + double{cl[k - 1]} + double{cr[kWidth - k - 1]};
  return root.area > 0.0f ? c / root.area : c;
}

} // namespace obscura::bvh
