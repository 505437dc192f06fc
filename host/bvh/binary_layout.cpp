// binary_layout.cpp — the wide tree as a binary one for GPUs (binary_layout.h).
#include "bvh/binary_layout.h"

#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "bvh/triangle_intersect.h"
#include "bvh/wide_node.h"

namespace obscura::bvh {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

float area(const Box& b) {
  if (b.empty()) return 0.0f;
  const glm::vec3 d = b.hi - b.lo;
  return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
}

Box unite(const Box& a, const Box& b) {
  Box u = a;
  u.grow(b);
  return u;
}

// The exact box of every slot of every wide node, bottom-up (a node's interior children follow
// it, so walking the nodes backwards meets children first). The quantised boxes of the wide
// nodes are looser; the binary nodes keep exact ones. A leaf's box is its triangles' box clipped
// to the slot's (decoded) box: with spatial splits a leaf holds a piece of a triangle that
// reaches far outside it, and the builder's box bounds the piece (without them, the clip
// changes nothing, the decoded box holding the triangles).
std::vector<std::array<Box, gpu::kBvhWidth>> exactSlotBoxes(const Bvh& bvh) {
  std::vector<std::array<Box, gpu::kBvhWidth>> slots(bvh.nodes.size());
  std::vector<Box> nodeBox(bvh.nodes.size());
  for (std::size_t n = bvh.nodes.size(); n-- > 0;) {
    const gpu::BvhNode& node = bvh.nodes[n];
    const std::array<WideChild, gpu::kBvhWidth> children = exactSlots(node, bvh.triangles, nodeBox);
    for (unsigned s = 0; s < gpu::kBvhWidth; ++s) {
      if (children[s].kind == WideChild::Kind::Empty) continue;
      Box& box = slots[n][s];
      box = children[s].box;
      if (children[s].kind == WideChild::Kind::Leaf) {
        const Box slot = decodedBox(node, s);
        box.lo = glm::max(box.lo, slot.lo);
        box.hi = glm::min(box.hi, slot.hi);
      }
      nodeBox[n].grow(box);
    }
  }
  return slots;
}

// One ulp outward on every face, so that a ray with a zero direction component whose origin lies
// exactly on a face still meets the box (render::widenBox; safeReciprocal in lib/intersect.glsl).
Box widened(Box b) {
  if (b.empty()) return b;
  for (int k = 0; k < 3; ++k) {
    b.lo[k] = std::nextafter(b.lo[k], -kInf);
    b.hi[k] = std::nextafter(b.hi[k], kInf);
  }
  return b;
}

class Deriver {
public:
  explicit Deriver(const Bvh& bvh) : bvh_(bvh), slotBoxes_(exactSlotBoxes(bvh)) {}

  BinaryBvh run() {
    out_.nodes.reserve(bvh_.nodes.size() * 2);
    out_.nodes.emplace_back(); // the root is node 0 whatever the wide root holds
    std::vector<Item> items = itemsOf(0);
    if (items.size() >= 2) {
      const std::vector<Cluster> clusters = cluster(items);
      const Cluster& top = clusters.back();
      fillNode(0, clusters[top.left], clusters[top.right], clusters, 1);
    } else {
      // A wide root of one leaf or none: a root with an absent child (or two).
      Cluster only{.box = items.empty() ? Box{} : items[0].box, .item = 0};
      Cluster absent{.box = Box{}, .item = -1};
      std::vector<Cluster> clusters;
      if (!items.empty()) items_.push_back(items[0]);
      fillNode(0, items.empty() ? absent : only, absent, clusters, 1);
    }
    return std::move(out_);
  }

private:
  // A child of a wide node: a leaf of its triangles, or an interior wide node.
  struct Item {
    Box box;
    bool leaf = false;
    std::uint32_t wideNode = 0;          // interior
    std::uint32_t first = 0, count = 0;  // leaf
  };
  // A node of the agglomerative tree over one wide node's items: an item (its index into items_),
  // or the union of two clusters.
  struct Cluster {
    Box box;
    int item = -1; // >= 0: items_[item]; else left / right
    int left = -1, right = -1;
  };

  std::vector<Item> itemsOf(std::uint32_t n) const {
    const gpu::BvhNode& node = bvh_.nodes[n];
    const std::uint32_t imask = internalMask(node);
    std::vector<Item> items;
    for (unsigned s = 0; s < gpu::kBvhWidth; ++s) {
      const std::uint32_t meta = slotMeta(node, s);
      if (meta == 0) continue;
      Item it;
      it.box = slotBoxes_[n][s];
      if (imask >> s & 1u) {
        it.wideNode = childNodeIndex(node, s);
      } else {
        it.leaf = true;
        it.first = firstTriangle(node) + (meta >> 2 & 31u);
        it.count = meta & 3u;
      }
      items.push_back(it);
    }
    return items;
  }

  // The agglomerative tree over `items` (>= 2), which are appended to items_: leaves first, then
  // each merge; the last cluster is the root.
  std::vector<Cluster> cluster(const std::vector<Item>& items) {
    std::vector<Cluster> clusters;
    std::vector<int> open;
    for (const Item& it : items) {
      clusters.push_back({.box = it.box, .item = static_cast<int>(items_.size())});
      items_.push_back(it);
      open.push_back(static_cast<int>(clusters.size()) - 1);
    }
    while (open.size() > 1) {
      std::size_t bestA = 0, bestB = 1;
      float best = kInf;
      for (std::size_t a = 0; a < open.size(); ++a)
        for (std::size_t b = a + 1; b < open.size(); ++b) {
          const float cost = area(unite(clusters[open[a]].box, clusters[open[b]].box));
          if (cost < best) {
            best = cost;
            bestA = a;
            bestB = b;
          }
        }
      const int a = open[bestA], b = open[bestB];
      clusters.push_back({.box = unite(clusters[a].box, clusters[b].box), .left = a, .right = b});
      open.erase(open.begin() + static_cast<std::ptrdiff_t>(bestB));
      open[bestA] = static_cast<int>(clusters.size()) - 1;
    }
    return clusters;
  }

  // The reference of a cluster at `depth` (nodes from the root), emitting what lies below it.
  std::uint32_t emit(const Cluster& c, const std::vector<Cluster>& clusters, std::uint32_t depth) {
    if (c.item >= 0) {
      const Item it = items_[static_cast<std::size_t>(c.item)];
      if (it.leaf) {
        out_.maxDepth = std::max(out_.maxDepth, depth);
        return binaryLeafRef(it.first, it.count);
      }
      return emitWide(it.wideNode, depth);
    }
    const auto index = static_cast<std::uint32_t>(out_.nodes.size());
    out_.nodes.emplace_back();
    fillNode(index, clusters[static_cast<std::size_t>(c.left)], clusters[static_cast<std::size_t>(c.right)], clusters,
             depth + 1);
    return index;
  }

  // A wide node's subtree, its binary nodes emitted from here; returns its reference.
  std::uint32_t emitWide(std::uint32_t n, std::uint32_t depth) {
    const std::size_t itemBase = items_.size();
    std::vector<Item> items = itemsOf(n);
    if (items.size() == 1) {
      items_.push_back(items[0]);
      return emit(Cluster{.box = items[0].box, .item = static_cast<int>(itemBase)}, {}, depth);
    }
    const std::vector<Cluster> clusters = cluster(items);
    return emit(clusters.back(), clusters, depth);
  }

  void fillNode(std::uint32_t index, const Cluster& left, const Cluster& right, const std::vector<Cluster>& clusters,
                std::uint32_t depth) {
    out_.maxDepth = std::max(out_.maxDepth, depth);
    const std::uint32_t leftRef = left.item == -1 && left.left == -1 ? gpu::kInvalidIndex : emit(left, clusters, depth);
    const std::uint32_t rightRef =
        right.item == -1 && right.left == -1 ? gpu::kInvalidIndex : emit(right, clusters, depth);
    auto corners = [](const Cluster& c, std::uint32_t ref) {
      if (ref == gpu::kInvalidIndex) return std::pair{glm::vec3(kInf), glm::vec3(kInf)}; // met by no ray
      const Box b = widened(c.box);
      return std::pair{b.lo, b.hi};
    };
    const auto [llo, lhi] = corners(left, leftRef);
    const auto [rlo, rhi] = corners(right, rightRef);
    gpu::BvhBinaryNode& node = out_.nodes[index]; // after the children: emitting them grew the vector
    node.leftLo = gpu::vec4(llo, std::bit_cast<float>(leftRef));
    node.leftHi = gpu::vec4(lhi, std::bit_cast<float>(rightRef));
    node.rightLo = gpu::vec4(rlo, 0.0f);
    node.rightHi = gpu::vec4(rhi, 0.0f);
  }

  const Bvh& bvh_;
  const std::vector<std::array<Box, gpu::kBvhWidth>> slotBoxes_;
  std::vector<Item> items_; // every wide node's items, as the clusters index them
  BinaryBvh out_;
};

// The slab test of intersectBox (shaders/lib/intersect.glsl), operation for operation.
bool meetsBox(const glm::vec3& lo, const glm::vec3& hi, const BoxRay& ray, float tmin, float tmax, float& tNear) {
  const glm::vec3 t0 = (lo - ray.origin) * ray.invDir;
  const glm::vec3 t1 = (hi - ray.origin) * ray.invDir;
  const glm::vec3 small = glm::min(t0, t1), big = glm::max(t0, t1);
  tNear = std::max(std::max(small.x, small.y), std::max(small.z, tmin));
  const float tFar = std::min(std::min(big.x, big.y), std::min(big.z, tmax)) * gpu::kBoxFarScale;
  return tNear <= tFar;
}

// The loop of traverseBinary: visit(first, count) tests a leaf's triangles and returns true to
// stop; tCull() is the current far limit for boxes.
template <class Visit, class Cull>
void traverseBinaryTree(const BinaryBvh& binary, const Ray& ray, Visit&& visit, Cull&& tCull) {
  if (binary.maxDepth > gpu::kBinaryStackSize)
    throw std::logic_error("binary BVH deeper than the binary traversal's stack");
  const BoxRay boxRay = makeBoxRay(ray.origin, ray.direction);
  std::array<std::uint32_t, gpu::kBinaryStackSize> stack;
  unsigned sp = 0;
  std::uint32_t ref = 0;
  for (;;) {
    while (!isBinaryLeaf(ref)) {
      const gpu::BvhBinaryNode& node = binary.nodes[ref];
      float nearL, nearR;
      const bool hitL = meetsBox(glm::vec3(node.leftLo), glm::vec3(node.leftHi), boxRay, ray.tmin, tCull(), nearL);
      const bool hitR = meetsBox(glm::vec3(node.rightLo), glm::vec3(node.rightHi), boxRay, ray.tmin, tCull(), nearR);
      const auto left = std::bit_cast<std::uint32_t>(node.leftLo.w);
      const auto right = std::bit_cast<std::uint32_t>(node.leftHi.w);
      if (hitL && hitR) {
        const bool rightFirst = nearR < nearL;
        stack[sp++] = rightFirst ? left : right;
        ref = rightFirst ? right : left;
      } else if (hitL || hitR) {
        ref = hitL ? left : right;
      } else {
        if (sp == 0) return;
        ref = stack[--sp];
      }
    }
    if (visit(binaryLeafFirst(ref), binaryLeafCount(ref))) return;
    if (sp == 0) return;
    ref = stack[--sp];
  }
}

} // namespace

std::uint32_t binaryLeafRef(std::uint32_t first, std::uint32_t count) {
  if (first > gpu::kBinaryLeafTexelMask || count == 0 || count > gpu::kLeafMaxTriangles)
    throw std::length_error("binary BVH leaf out of the layout's range");
  return gpu::kBinaryLeafBit | count << gpu::kBinaryLeafCountShift | first;
}
bool isBinaryLeaf(std::uint32_t ref) { return (ref & gpu::kBinaryLeafBit) != 0; }
std::uint32_t binaryLeafFirst(std::uint32_t ref) { return ref & gpu::kBinaryLeafTexelMask; }
std::uint32_t binaryLeafCount(std::uint32_t ref) { return ref >> gpu::kBinaryLeafCountShift & 7u; }

BinaryBvh binaryLayout(const Bvh& bvh) {
  if (bvh.nodes.empty()) throw std::logic_error("binaryLayout: a built BVH has a root");
  return Deriver(bvh).run();
}

Hit closestHitBinary(const Bvh& bvh, const BinaryBvh& binary, const Ray& ray) {
  const WatertightRay wr = prepareWatertightRay(ray.origin, ray.direction);
  Hit best;
  float tmax = ray.tmax;
  traverseBinaryTree(
      binary, ray,
      [&](std::uint32_t first, std::uint32_t count) {
        for (std::uint32_t i = first; i < first + count; ++i) {
          const gpu::BvhTriangle& tri = bvh.triangles[i];
          float t, u, v;
          if (!intersectTriangle(wr, glm::vec3(tri.v0), glm::vec3(tri.v1), glm::vec3(tri.v2), ray.tmin, tmax, t, u, v))
            continue;
          const auto primitive = std::bit_cast<std::uint32_t>(tri.v0.w);
          if (t < best.t || (t == best.t && primitive < best.primitive)) {
            best = Hit{t, u, v, primitive};
            tmax = t;
          }
        }
        return false;
      },
      [&] { return tmax; });
  return best;
}

bool anyHitBinary(const Bvh& bvh, const BinaryBvh& binary, const Ray& ray) {
  const WatertightRay wr = prepareWatertightRay(ray.origin, ray.direction);
  bool found = false;
  traverseBinaryTree(
      binary, ray,
      [&](std::uint32_t first, std::uint32_t count) {
        for (std::uint32_t i = first; i < first + count; ++i) {
          const gpu::BvhTriangle& tri = bvh.triangles[i];
          float t, u, v;
          if (intersectTriangle(wr, glm::vec3(tri.v0), glm::vec3(tri.v1), glm::vec3(tri.v2), ray.tmin, ray.tmax, t, u,
                                v) &&
              t < ray.tmax)
            return found = true;
        }
        return false;
      },
      [&] { return ray.tmax; });
  return found;
}

} // namespace obscura::bvh
