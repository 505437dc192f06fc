// builder.cpp — binned SAH BVH build, parallel over subtrees, written out in the GPU layout.
//
// Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies", IEEE RT 2007: bin the
// triangle centroids along each axis, sweep the bins for the cheapest split under the surface area
// heuristic (Goldsmith & Salmon 1987; MacDonald & Booth, "Heuristics for ray tracing using space
// subdivision", 1990), and compare it with the cost of a leaf.
//
// Shape of the code, top to bottom:
//   1. PrimRef per triangle (box, centroid), in parallel.
//   2. buildRange(): per node, decide leaf / SAH split / median split (depth bound) / index split
//      (no valid SAH split), or, with BuildOptions::spatialSplitBudget, a spatial split that clips
//      the triangles crossing its plane (SBVH); partition the refs, recurse; big subtrees run on
//      their own thread. Nodes go into a scratch array at indices that depend only on the range
//      and the room it owns for clipped references (no locks, the same tree on any thread count).
//   3. writeWide(): collapse into 8-wide compressed nodes (gpu::BvhNode, wide_node.h) by the
//      SAH-optimal programme of wide_collapse.h, the triangles in the order the wide leaves need
//      them, and the statistics.
#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <stdexcept>
#include <thread>
#include <vector>

#include "bvh/bvh.h"
#include "bvh/wide_collapse.h"
#include "bvh/wide_node.h"
#include "core/host_cpu_time.h"

namespace obscura::bvh {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

struct Aabb {
  glm::vec3 lo{kInf};
  glm::vec3 hi{-kInf};

  void grow(const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Aabb& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  bool empty() const { return !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z); }
  // Surface area; 0 for an empty (inverted) box. Flat boxes keep their non-zero area.
  float area() const {
    const glm::vec3 d = hi - lo;
    if (!(d.x >= 0.0f && d.y >= 0.0f && d.z >= 0.0f)) return 0.0f;
    return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
  }
};

// What the build moves around: 40 bytes, so partitioning touches one array and no indirection.
struct PrimRef {
  Aabb box;
  glm::vec3 centroid; // the triangle's centroid (v0 + v1 + v2) / 3
  std::uint32_t id;   // original triangle index
};

// Scratch node. A leaf has count > 0 and covers refs [first, first + count); an interior node has
// count == 0 and two children.
struct TempNode {
  Aabb box;
  std::uint32_t first = 0;
  std::uint32_t count = 0;
  std::uint32_t child[2] = {0, 0};
};

// Number of median splits a range of n refs needs until every piece fits in a leaf.
std::uint32_t medianLevels(std::uint32_t n, std::uint32_t maxLeaf) {
  std::uint32_t levels = 0;
  while (n > maxLeaf) {
    n = n - n / 2; // the larger half
    ++levels;
  }
  return levels;
}

struct Bin {
  Aabb box; // union of the triangle boxes whose centroid falls in the bin
  std::uint32_t count = 0;
};

// The mapping centroid -> bin along one axis (Wald 2007): k1 = bins * (1 - eps) / extent.
// The same object is used for binning and for partitioning, so the partition matches the bins
// exactly and the child boxes from the sweep are exact.
struct Binning {
  int axis = -1; // -1: no axis can be binned (all centroids coincide, or extents are denormal)
  float lo[3] = {0, 0, 0};
  float scale[3] = {0, 0, 0};
  bool usable[3] = {false, false, false};
  int bins = 0;

  int binOf(const glm::vec3& c, int a) const {
    const int b = static_cast<int>((c[a] - lo[a]) * scale[a]);
    return std::min(b, bins - 1);
  }
};

struct SplitChoice {
  bool valid = false;
  int axis = 0;
  int bin = 0; // refs with binOf(axis) <= bin go left
  float cost = kInf; // unnormalised: traversal * area(node) + intersection * sum(area * count)
  Aabb leftBox, rightBox;
};

class Builder {
public:
  Builder(const TriangleSoup& soup, const BuildOptions& options)
      : soup_(soup), options_(options) {
    threads_ = options.threads != 0 ? options.threads : std::thread::hardware_concurrency();
    threads_ = std::max(1u, threads_);
    bins_ = std::clamp(options.bins, 2, kMaxBins);
    maxLeaf_ = std::clamp(options.maxLeafSize, 1u, gpu::kLeafMaxTriangles);
    binaryLeaf_ = std::clamp(options.binaryLeafSize, 1u, maxLeaf_);
    // A few more tasks than threads so that uneven subtrees still keep every core busy.
    while ((1u << maxTaskDepth_) < 4 * threads_) ++maxTaskDepth_;
    if (threads_ == 1) maxTaskDepth_ = 0;
  }

  Bvh run() {
    const auto start = std::chrono::steady_clock::now();
    const std::uint32_t n = static_cast<std::uint32_t>(soup_.size());
    // A triangle's GPU texel index (host_device.h) must fit an int.
    if (soup_.size() > 0x1FFFFFFFu)
      throw std::length_error("bvh::build: too many triangles for the GPU layout");

    Bvh bvh;
    if (n == 0) {
      writeEmptyRoot(bvh);
    } else {
      Aabb box, centroids;
      makeRefs(box, centroids);
      // Room for the references spatial splits add (SBVH): the root range owns them all.
      const double extraShare = std::clamp(double{options_.spatialSplitBudget}, 0.0, 4.0);
      const auto extra = static_cast<std::uint32_t>(
          std::min<double>(extraShare * n, double{0x1FFFFFFFu} - n));
      refs_.resize(std::size_t{n} + extra);
      nodes_.resize(2 * (std::size_t{n} + extra) - 1);
      rootArea_ = box.area();
      buildRange(0, 0, n, extra, 0, box, centroids, 0);
      writeWide(bvh);
    }
    bvh.stats.medianFallbacks = medianFallbacks_.load();
    bvh.stats.spatialSplits = spatialSplits_.load();
    bvh.stats.references = static_cast<std::uint32_t>(bvh.triangles.size());
    bvh.stats.buildSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return bvh;
  }

private:
  static constexpr int kMaxBins = 256;
  // Below this many refs a subtree is built on the current thread, and binning is serial.
  static constexpr std::uint32_t kParallelSubtreeMin = 4096;
  static constexpr std::uint32_t kParallelBinMin = 65536;

  // Runs body(chunk, begin, end) over [0, n) cut into `chunks` pieces, one thread each.
  template <class Body> void parallelChunks(std::uint32_t n, unsigned chunks, Body&& body) {
    chunks = std::max(1u, std::min(chunks, n));
    std::vector<std::future<void>> futures;
    for (unsigned i = 1; i < chunks; ++i) {
      const std::uint32_t b = static_cast<std::uint32_t>(std::uint64_t{n} * i / chunks);
      const std::uint32_t e = static_cast<std::uint32_t>(std::uint64_t{n} * (i + 1) / chunks);
      futures.push_back(std::async(std::launch::async, [&body, i, b, e] {
        const HelperThreadCpu counted; // an edit's host work (core/host_cpu_time.h)
        body(i, b, e);
      }));
    }
    body(0u, 0u, static_cast<std::uint32_t>(std::uint64_t{n} / chunks));
    for (auto& f : futures) f.get();
  }

  // ---- 1. References: box and centroid of every triangle, and the bounds of both.
  void makeRefs(Aabb& box, Aabb& centroids) {
    const std::uint32_t n = static_cast<std::uint32_t>(soup_.size());
    refs_.resize(n);
    const unsigned chunks = n >= kParallelBinMin ? threads_ : 1u;
    std::vector<Aabb> boxes(chunks), cboxes(chunks);
    parallelChunks(n, chunks, [&](unsigned chunk, std::uint32_t b, std::uint32_t e) {
      Aabb bb, cb;
      for (std::uint32_t i = b; i < e; ++i) {
        PrimRef& r = refs_[i];
        r.box = Aabb{};
        r.box.grow(soup_.v0[i]);
        r.box.grow(soup_.v1[i]);
        r.box.grow(soup_.v2[i]);
        r.centroid = (soup_.v0[i] + soup_.v1[i] + soup_.v2[i]) * (1.0f / 3.0f);
        r.id = i;
        bb.grow(r.box);
        cb.grow(r.centroid);
      }
      boxes[chunk] = bb;
      cboxes[chunk] = cb;
    });
    for (unsigned c = 0; c < chunks; ++c) {
      box.grow(boxes[c]);
      centroids.grow(cboxes[c]);
    }
  }

  // ---- 2. Recursive build of the `count` refs at refs_[begin, begin + count) into scratch node
  // `slot`.
  //
  // `depth` is the depth of the leaves this range would produce if it became a leaf now: the
  // number of GPU interior nodes above it (the root range is 0, but a root leaf still gets a root
  // node above it, so it ends up at depth 1). A range owns the refs_ entries
  // [begin, begin + count + extra): `extra` is room for the references its spatial splits may
  // add, shared between its children in proportion to their refs (so the tree does not depend
  // on which thread splits first). Scratch slots: a range owning m = count + extra entries owns
  // 2m - 1 slots from `slot`; its left child, owning ml, gets slot + 1, its right slot + 2 ml.
  // Without spatial splits extra is 0 everywhere and the children are the two halves in place.
  void buildRange(std::uint32_t slot, std::uint32_t begin, std::uint32_t count, std::uint32_t extra,
                  std::uint32_t depth, const Aabb& box, const Aabb& centroids, unsigned taskDepth) {
    TempNode& node = nodes_[slot];
    node.box = box;
    const std::uint32_t end = begin + count;

    auto makeLeaf = [&] {
      node.first = begin;
      node.count = count;
    };
    if (count == 1) return makeLeaf();

    // Depth guarantee. A SAH split may peel off a single triangle, leaving count - 1 refs one
    // level down; it is allowed only while the median splits could still finish that worst
    // case within kBvhMaxDepth. Otherwise split at the median (or make a leaf if it fits).
    // A spatial split keeps each side below count refs too.
    const bool sahAllowed = depth + 1 + medianLevels(count - 1, maxLeaf_) <= gpu::kBvhMaxDepth;

    std::uint32_t leftCount = 0;
    std::uint32_t leftExtra = 0;
    Aabb leftBox, rightBox, leftCentroids, rightCentroids;
    if (!sahAllowed) {
      if (count <= maxLeaf_) return makeLeaf();
      ++medianFallbacks_;
      leftCount = medianSplit(begin, end, centroids) - begin;
      bounds(begin, begin + leftCount, leftBox, leftCentroids);
      bounds(begin + leftCount, end, rightBox, rightCentroids);
    } else {
      // Bin, sweep, and compare the best split with a leaf.
      const Binning binning = makeBinning(centroids, count);
      const SplitChoice split = binning.axis >= 0 ? bestSplit(begin, end, binning, box)
                                                  : SplitChoice{};
      // A spatial split is tried where the object split's children overlap (Stich et al. 2009,
      // §4.3: overlap area > alpha * root area), and taken where the SAH says it is cheaper.
      SpatialChoice spatial;
      if (extra > 0 && (!split.valid || overlapArea(split.leftBox, split.rightBox) >
                                            options_.spatialSplitOverlap * rootArea_))
        spatial = bestSpatialSplit(begin, count, extra, box);
      const float bestCost = std::min(split.valid ? split.cost : kInf, spatial.valid ? spatial.cost : kInf);
      const float leafCost = options_.intersectionCost * static_cast<float>(count) * box.area();
      if (count <= binaryLeaf_ && (bestCost == kInf || leafCost <= bestCost)) return makeLeaf();

      if (spatial.valid && spatial.cost < (split.valid ? split.cost : kInf)) {
        std::vector<PrimRef> left, right;
        spatialPartition(begin, count, spatial, left, right);
        // Unsplitting may have emptied a side; then the object split (or the index split) does.
        if (!left.empty() && !right.empty() && left.size() < count && right.size() < count) {
          ++spatialSplits_;
          leftCount = static_cast<std::uint32_t>(left.size());
          const auto rightCount = static_cast<std::uint32_t>(right.size());
          const std::uint32_t room = extra - (leftCount + rightCount - count); // for the children's splits
          leftExtra = static_cast<std::uint32_t>(std::uint64_t{room} * leftCount / (leftCount + rightCount));
          const std::uint32_t rightBegin = begin + leftCount + leftExtra;
          std::copy(left.begin(), left.end(), refs_.begin() + begin);
          std::copy(right.begin(), right.end(), refs_.begin() + rightBegin);
          bounds(begin, begin + leftCount, leftBox, leftCentroids);
          bounds(rightBegin, rightBegin + rightCount, rightBox, rightCentroids);
          return buildChildren(slot, begin, leftCount, leftExtra, rightCount, room - leftExtra, depth,
                               leftBox, leftCentroids, rightBox, rightCentroids, taskDepth);
        }
      }
      if (split.valid) {
        leftCount = partition(begin, end, binning, split, leftCentroids, rightCentroids) - begin;
        leftBox = split.leftBox;
        rightBox = split.rightBox;
      } else {
        // No SAH split exists (every centroid in one bin, e.g. all centroids equal): any
        // partition is as good as another, so cut the index range in the middle.
        leftCount = count / 2;
        bounds(begin, begin + leftCount, leftBox, leftCentroids);
        bounds(begin + leftCount, end, rightBox, rightCentroids);
      }
    }
    // An object split: the right refs move up past the left child's share of the room.
    const std::uint32_t rightCount = count - leftCount;
    leftExtra = static_cast<std::uint32_t>(std::uint64_t{extra} * leftCount / count);
    if (leftExtra > 0)
      std::move_backward(refs_.begin() + begin + leftCount, refs_.begin() + end,
                         refs_.begin() + end + leftExtra);
    buildChildren(slot, begin, leftCount, leftExtra, rightCount, extra - leftExtra, depth, leftBox,
                  leftCentroids, rightBox, rightCentroids, taskDepth);
  }

  // The two children of interior `slot`: the left owning refs_[begin, begin + leftCount +
  // leftExtra), the right the rightCount + rightExtra entries after it.
  void buildChildren(std::uint32_t slot, std::uint32_t begin, std::uint32_t leftCount, std::uint32_t leftExtra,
                     std::uint32_t rightCount, std::uint32_t rightExtra, std::uint32_t depth,
                     const Aabb& leftBox, const Aabb& leftCentroids, const Aabb& rightBox,
                     const Aabb& rightCentroids, unsigned taskDepth) {
    TempNode& node = nodes_[slot];
    const std::uint32_t leftOwned = leftCount + leftExtra;
    const std::uint32_t leftSlot = slot + 1;
    const std::uint32_t rightSlot = slot + 2 * leftOwned;
    const std::uint32_t rightBegin = begin + leftOwned;
    node.count = 0;
    node.child[0] = leftSlot;
    node.child[1] = rightSlot;

    // Subtrees: the right one on a new thread while the task tree is shallow and both are big.
    const bool spawn = taskDepth < maxTaskDepth_ && leftCount >= kParallelSubtreeMin &&
                       rightCount >= kParallelSubtreeMin;
    if (spawn) {
      auto right = std::async(std::launch::async, [&, rightSlot, rightBegin, rightCount, rightExtra, depth, taskDepth] {
        const HelperThreadCpu counted;
        buildRange(rightSlot, rightBegin, rightCount, rightExtra, depth + 1, rightBox, rightCentroids, taskDepth + 1);
      });
      buildRange(leftSlot, begin, leftCount, leftExtra, depth + 1, leftBox, leftCentroids, taskDepth + 1);
      right.get();
    } else {
      buildRange(leftSlot, begin, leftCount, leftExtra, depth + 1, leftBox, leftCentroids, taskDepth);
      buildRange(rightSlot, rightBegin, rightCount, rightExtra, depth + 1, rightBox, rightCentroids, taskDepth);
    }
  }

  static float overlapArea(const Aabb& a, const Aabb& b) {
    Aabb both;
    both.lo = glm::max(a.lo, b.lo);
    both.hi = glm::min(a.hi, b.hi);
    return both.area();
  }

  // ---- Spatial splits (Stich, Friedrich & Dietrich, "Spatial Splits in Bounding Volume
  // Hierarchies", HPG 2009, §4): the node's box is cut into equal slabs along each axis; a
  // reference spanning several slabs is clipped into each (the box of the part of its triangle
  // inside the slab and inside its own, possibly already clipped, box), counted where it enters
  // and where it leaves. The sweep prices every slab boundary as a split plane; a reference that
  // straddles the chosen plane goes to both sides, clipped, or whole to one side where that is
  // cheaper (reference unsplitting, §4.4).

  // The box of the part of triangle `id` inside `box` on either side of the plane x_axis = pos.
  void clipReference(std::uint32_t id, const Aabb& box, int axis, float pos, Aabb& left, Aabb& right) const {
    const glm::vec3 v[3] = {soup_.v0[id], soup_.v1[id], soup_.v2[id]};
    left = Aabb{};
    right = Aabb{};
    for (int i = 0; i < 3; ++i) {
      const glm::vec3& a = v[i];
      const glm::vec3& b = v[(i + 1) % 3];
      if (a[axis] <= pos) left.grow(a);
      if (a[axis] >= pos) right.grow(a);
      if ((a[axis] < pos && b[axis] > pos) || (a[axis] > pos && b[axis] < pos)) {
        // Where the edge crosses the plane, computed with a few ulps of error (of the larger
        // end): padded by that, so that the piece's box holds the exact crossing (a clipped box
        // must not lose a sliver of the triangle that a ray could hit).
        const float t = (pos - a[axis]) / (b[axis] - a[axis]);
        glm::vec3 p = a + (b - a) * std::clamp(t, 0.0f, 1.0f);
        p[axis] = pos;
        const glm::vec3 pad = 4.0f * std::numeric_limits<float>::epsilon() * glm::max(glm::abs(a), glm::abs(b)) +
                              glm::vec3(std::numeric_limits<float>::denorm_min());
        for (const glm::vec3& q : {p - pad, p + pad}) {
          left.grow(q);
          right.grow(q);
        }
      }
    }
    left.lo = glm::max(left.lo, box.lo);
    left.hi = glm::min(left.hi, box.hi);
    left.hi[axis] = std::min(left.hi[axis], pos);
    right.lo = glm::max(right.lo, box.lo);
    right.hi = glm::min(right.hi, box.hi);
    right.lo[axis] = std::max(right.lo[axis], pos);
  }

  struct SpatialBin {
    Aabb box;
    std::uint32_t enter = 0, exit = 0;
  };
  struct SpatialSlabs {
    float lo = 0.0f, width = 0.0f, scale = 0.0f;
    int bins = 0;
    int binOf(float x) const { return std::clamp(static_cast<int>((x - lo) * scale), 0, bins - 1); }
    float plane(int bin) const { return lo + width * static_cast<float>(bin + 1); } // after `bin`
  };
  struct SpatialChoice {
    bool valid = false;
    int axis = 0;
    int bin = 0; // the plane after this slab
    float cost = kInf;
    SpatialSlabs slabs;
    Aabb leftBox, rightBox;
    std::uint32_t leftCount = 0, rightCount = 0;
  };

  SpatialChoice bestSpatialSplit(std::uint32_t begin, std::uint32_t count, std::uint32_t extra, const Aabb& box) {
    SpatialChoice best;
    const int nb = std::min(bins_, static_cast<int>(count / 2 + 4));
    std::vector<SpatialBin> bins(static_cast<std::size_t>(nb));
    const float nodeCost = options_.traversalCost * box.area();
    for (int a = 0; a < 3; ++a) {
      SpatialSlabs slabs;
      slabs.lo = box.lo[a];
      slabs.bins = nb;
      slabs.width = (box.hi[a] - box.lo[a]) / static_cast<float>(nb);
      slabs.scale = 1.0f / slabs.width;
      if (!(slabs.width > 0.0f) || !std::isfinite(slabs.scale)) continue;
      std::fill(bins.begin(), bins.end(), SpatialBin{});
      for (std::uint32_t i = begin; i < begin + count; ++i) {
        const PrimRef& r = refs_[i];
        const int first = slabs.binOf(r.box.lo[a]);
        const int last = slabs.binOf(r.box.hi[a]);
        ++bins[static_cast<std::size_t>(first)].enter;
        ++bins[static_cast<std::size_t>(last)].exit;
        Aabb rest = r.box;
        for (int b = first; b < last; ++b) {
          Aabb piece, after;
          clipReference(r.id, rest, a, slabs.plane(b), piece, after);
          bins[static_cast<std::size_t>(b)].box.grow(piece);
          rest = after;
        }
        bins[static_cast<std::size_t>(last)].box.grow(rest);
      }
      std::array<float, kMaxBins> rightCost{};
      std::array<std::uint32_t, kMaxBins> rightN{};
      Aabb acc;
      std::uint32_t n = 0;
      for (int i = nb - 1; i > 0; --i) {
        acc.grow(bins[static_cast<std::size_t>(i)].box);
        n += bins[static_cast<std::size_t>(i)].exit;
        rightN[static_cast<std::size_t>(i)] = n;
        rightCost[static_cast<std::size_t>(i)] = acc.area() * static_cast<float>(n);
      }
      acc = Aabb{};
      n = 0;
      for (int i = 0; i < nb - 1; ++i) {
        acc.grow(bins[static_cast<std::size_t>(i)].box);
        n += bins[static_cast<std::size_t>(i)].enter;
        const std::uint32_t nr = rightN[static_cast<std::size_t>(i + 1)];
        if (n == 0 || nr == 0 || n >= count || nr >= count || n + nr - count > extra) continue;
        const float cost = nodeCost + options_.intersectionCost * (acc.area() * static_cast<float>(n) +
                                                                   rightCost[static_cast<std::size_t>(i + 1)]);
        if (cost < best.cost) {
          best = SpatialChoice{.valid = true, .axis = a, .bin = i, .cost = cost, .slabs = slabs,
                               .leftCount = n, .rightCount = nr};
          best.leftBox = acc;
        }
      }
      if (best.valid && best.axis == a) {
        best.rightBox = Aabb{};
        for (int i = best.bin + 1; i < nb; ++i) best.rightBox.grow(bins[static_cast<std::size_t>(i)].box);
      }
    }
    return best;
  }

  // The node's refs on either side of `split`'s plane, a straddling one clipped into both.
  void spatialPartition(std::uint32_t begin, std::uint32_t count, const SpatialChoice& split,
                        std::vector<PrimRef>& left, std::vector<PrimRef>& right) const {
    const int a = split.axis;
    const float pos = split.slabs.plane(split.bin);
    left.reserve(split.leftCount);
    right.reserve(split.rightCount);
    Aabb leftBox = split.leftBox, rightBox = split.rightBox;
    std::uint32_t nl = split.leftCount, nr = split.rightCount;
    for (std::uint32_t i = begin; i < begin + count; ++i) {
      const PrimRef& r = refs_[i];
      const int first = split.slabs.binOf(r.box.lo[a]);
      const int last = split.slabs.binOf(r.box.hi[a]);
      if (last <= split.bin) {
        left.push_back(r);
        continue;
      }
      if (first > split.bin) {
        right.push_back(r);
        continue;
      }
      // Straddling. Reference unsplitting (§4.4): whole to one side where the SAH says so.
      Aabb withLeft = leftBox, withRight = rightBox;
      withLeft.grow(r.box);
      withRight.grow(r.box);
      const float both = leftBox.area() * static_cast<float>(nl) + rightBox.area() * static_cast<float>(nr);
      const float toLeft = withLeft.area() * static_cast<float>(nl) + rightBox.area() * static_cast<float>(nr - 1);
      const float toRight = leftBox.area() * static_cast<float>(nl - 1) + withRight.area() * static_cast<float>(nr);
      Aabb l, rr;
      clipReference(r.id, r.box, a, pos, l, rr);
      if (rr.empty() || (toLeft < both && toLeft <= toRight)) {
        left.push_back(r);
        leftBox = withLeft;
        --nr;
      } else if (l.empty() || toRight < both) {
        right.push_back(r);
        rightBox = withRight;
        --nl;
      } else {
        left.push_back(PrimRef{.box = l, .centroid = 0.5f * (l.lo + l.hi), .id = r.id});
        right.push_back(PrimRef{.box = rr, .centroid = 0.5f * (rr.lo + rr.hi), .id = r.id});
      }
    }
  }

  // Bin parameters from the centroid bounds. An axis whose extent is zero (or so small that
  // bins / extent overflows) cannot separate anything and is skipped.
  Binning makeBinning(const Aabb& centroids, std::uint32_t count) const {
    Binning b;
    // A node of n refs gets at most n / 2 + 4 bins: more would mostly stay empty, and for the
    // many small nodes near the leaves the fixed cost of clearing and sweeping the bins
    // dominates (measured: about -25% build time on 262k random triangles, SAH cost +0.03%).
    b.bins = static_cast<int>(
        std::min<std::uint32_t>(static_cast<std::uint32_t>(bins_), count / 2 + 4));
    float bestExtent = 0.0f;
    for (int a = 0; a < 3; ++a) {
      const float extent = centroids.hi[a] - centroids.lo[a];
      const float scale = static_cast<float>(b.bins) * (1.0f - 1e-6f) / extent;
      b.lo[a] = centroids.lo[a];
      b.scale[a] = scale;
      b.usable[a] = extent > 0.0f && std::isfinite(extent) && std::isfinite(scale);
      if (b.usable[a] && extent > bestExtent) {
        bestExtent = extent;
        b.axis = a;
      }
    }
    return b;
  }

  // Bin every ref on all usable axes, then sweep each axis from both ends (Wald 2007):
  // cost(split after bin i) = C_trav * A(node) + C_int * (A_left * N_left + A_right * N_right),
  // i.e. the SAH multiplied through by A(node), so that flat or point-sized nodes need no
  // division.
  SplitChoice bestSplit(std::uint32_t begin, std::uint32_t end, const Binning& binning,
                        const Aabb& box) {
    const std::uint32_t count = end - begin;
    const int nb = binning.bins;
    // bins[a * nb + i]: bin i along axis a.
    auto binRange = [&](Bin* bins, std::uint32_t b, std::uint32_t e) {
      std::fill(bins, bins + 3 * nb, Bin{});
      for (std::uint32_t i = b; i < e; ++i) {
        const PrimRef& r = refs_[i];
        for (int a = 0; a < 3; ++a) {
          if (!binning.usable[a]) continue;
          Bin& bin = bins[a * nb + binning.binOf(r.centroid, a)];
          bin.box.grow(r.box);
          ++bin.count;
        }
      }
    };

    // Per-thread scratch, so small nodes cost no allocation. Big nodes (the top of the tree,
    // before subtree tasks take over) are binned in parallel, one set of bins per chunk.
    thread_local std::vector<Bin> scratch;
    const unsigned chunks = count >= kParallelBinMin ? threads_ : 1u;
    scratch.resize(static_cast<std::size_t>(3 * nb) * chunks);
    Bin* const bins = scratch.data();
    if (chunks == 1) {
      binRange(bins, begin, end);
    } else {
      parallelChunks(count, chunks, [&](unsigned c, std::uint32_t b, std::uint32_t e) {
        binRange(bins + c * 3 * nb, begin + b, begin + e);
      });
      for (unsigned c = 1; c < chunks; ++c)
        for (int i = 0; i < 3 * nb; ++i) {
          const Bin& other = bins[c * 3 * nb + i];
          bins[i].box.grow(other.box);
          bins[i].count += other.count;
        }
    }

    SplitChoice best;
    const float nodeCost = options_.traversalCost * box.area();
    for (int a = 0; a < 3; ++a) {
      if (!binning.usable[a]) continue;
      // Right-to-left sweep: cost of the right side of the split after bin i - 1.
      std::array<float, kMaxBins> rightCost{};
      Aabb acc;
      std::uint32_t n = 0;
      for (int i = nb - 1; i > 0; --i) {
        acc.grow(bins[a * nb + i].box);
        n += bins[a * nb + i].count;
        rightCost[i] = n > 0 ? acc.area() * static_cast<float>(n) : kInf;
      }
      // Left-to-right sweep, combining with the right side.
      acc = Aabb{};
      n = 0;
      for (int i = 0; i < nb - 1; ++i) {
        acc.grow(bins[a * nb + i].box);
        n += bins[a * nb + i].count;
        if (n == 0 || n == count) continue; // one side empty: not a split
        const float cost =
            nodeCost + options_.intersectionCost * (acc.area() * static_cast<float>(n) +
                                                    rightCost[i + 1]);
        if (cost < best.cost) {
          best.valid = true;
          best.cost = cost;
          best.axis = a;
          best.bin = i;
        }
      }
    }
    if (!best.valid) return best;

    // Children's boxes from the bins, exact because partition() uses the same bin mapping.
    for (int i = 0; i < nb; ++i) {
      const Bin& bin = bins[best.axis * nb + i];
      (i <= best.bin ? best.leftBox : best.rightBox).grow(bin.box);
    }
    return best;
  }

  // In-place partition (Hoare) by the split's bin; it also gathers the children's centroid
  // bounds, which the next level's binning needs, while the refs pass by anyway.
  std::uint32_t partition(std::uint32_t begin, std::uint32_t end, const Binning& binning,
                          const SplitChoice& split, Aabb& leftCentroids, Aabb& rightCentroids) {
    auto goesLeft = [&](const PrimRef& r) {
      return binning.binOf(r.centroid, split.axis) <= split.bin;
    };
    std::uint32_t l = begin, r = end;
    for (;;) {
      while (l < r && goesLeft(refs_[l])) leftCentroids.grow(refs_[l++].centroid);
      while (l < r && !goesLeft(refs_[r - 1])) rightCentroids.grow(refs_[--r].centroid);
      if (l == r) return l;
      std::swap(refs_[l], refs_[r - 1]);
    }
  }

  // Object median along the largest centroid extent; when all centroids coincide the order is
  // arbitrary and the index middle is the median.
  std::uint32_t medianSplit(std::uint32_t begin, std::uint32_t end, const Aabb& centroids) {
    const std::uint32_t mid = begin + (end - begin) / 2;
    const glm::vec3 extent = centroids.hi - centroids.lo;
    int axis = 0;
    if (extent.y > extent[axis]) axis = 1;
    if (extent.z > extent[axis]) axis = 2;
    if (extent[axis] > 0.0f) {
      std::nth_element(refs_.begin() + begin, refs_.begin() + mid, refs_.begin() + end,
                       [axis](const PrimRef& a, const PrimRef& b) {
                         return a.centroid[axis] < b.centroid[axis];
                       });
    }
    return mid;
  }

  void bounds(std::uint32_t begin, std::uint32_t end, Aabb& box, Aabb& centroids) const {
    for (std::uint32_t i = begin; i < end; ++i) {
      box.grow(refs_[i].box);
      centroids.grow(refs_[i].centroid);
    }
  }

  // ---- 3. Wide layout: collapse the binary tree into 8-wide nodes by the SAH-optimal programme
  // of Ylitie, Karras & Laine 2017, §3.1 (wide_collapse.h), which also merges subtrees of at most
  // maxLeaf triangles into one leaf slot. Wide nodes are emitted breadth-first, so a node's
  // interior children are consecutive and come after it (refit walks them backwards), and the
  // triangles of a node's leaf children are consecutive, in the order the traversal's bit masks
  // need them.
  void writeWide(Bvh& bvh) {
    const TempNode& root = nodes_[0];
    sah_ = 0.0;
    bvh.triangles.reserve(refs_.size());
    bvh.order.reserve(refs_.size());
    if (root.count > 0) {
      // A one-leaf tree: a root whose only child is the leaf.
      std::array<WideChild, gpu::kBvhWidth> slots{};
      slots[0] = leafChild(0, root.box, bvh);
      bvh.nodes.emplace_back();
      writeWideNode(bvh.nodes[0], slots, 0, 0);
      bvh.stats.leafCount = 1;
      bvh.stats.maxDepth = 1;
      sah_ = double{options_.traversalCost} * areaRatio(root.box) +
             double{options_.intersectionCost} * root.count * areaRatio(root.box);
      bvh.stats.sahCost = bvh.stats.wideSahCost = sah_;
      bvh.stats.nodeCount = 1;
      return;
    }
    const std::vector<CollapseInput> binary = collapseInput();
    const WideCollapse collapse(binary, CollapseCosts{.node = options_.wideNodeCost,
                                                      .triangle = options_.intersectionCost,
                                                      .maxLeafTriangles = maxLeaf_});
    std::vector<std::uint32_t> pending = {0}; // binary slot of each wide node, by wide index
    std::vector<std::uint32_t> depth = {0};
    for (std::size_t w = 0; w < pending.size(); ++w) {
      const std::vector<CollapsedSlot> children = collapse.slots(pending[w]);
      const std::array<int, gpu::kBvhWidth> slotOf = assignOctantSlots(pending[w], children);
      std::array<WideChild, gpu::kBvhWidth> slots{};
      const auto firstTriangle = static_cast<std::uint32_t>(bvh.triangles.size());
      const auto firstChild = static_cast<std::uint32_t>(pending.size());
      for (unsigned s = 0; s < gpu::kBvhWidth; ++s) {
        if (slotOf[s] < 0) continue;
        const CollapsedSlot& child = children[static_cast<std::size_t>(slotOf[s])];
        const TempNode& c = nodes_[child.node];
        if (child.leaf) {
          slots[s] = leafChild(child.node, c.box, bvh);
          slots[s].triangleOffset = slots[s].triangleOffset - firstTriangle;
          ++bvh.stats.leafCount;
          bvh.stats.maxDepth = std::max(bvh.stats.maxDepth, depth[w] + 1);
        } else {
          slots[s].kind = WideChild::Kind::Internal;
          slots[s].box = toBox(c.box);
          pending.push_back(child.node);
          depth.push_back(depth[w] + 1);
        }
      }
      if (bvh.nodes.size() < pending.size()) bvh.nodes.resize(pending.size());
      writeWideNode(bvh.nodes[w], slots, firstChild, firstTriangle);
    }
    addBinarySah(0);
    bvh.stats.nodeCount = static_cast<std::uint32_t>(bvh.nodes.size());
    bvh.stats.sahCost = sah_;
    bvh.stats.wideSahCost = collapse.cost();
  }

  static Box toBox(const Aabb& a) { return Box{a.lo, a.hi}; }

  // The binary tree as the collapse reads it (unused scratch slots stay zero: never reached).
  std::vector<CollapseInput> collapseInput() const {
    std::vector<CollapseInput> in(nodes_.size());
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      const TempNode& t = nodes_[i];
      in[i].area = t.box.area();
      in[i].triangles = t.count;
      in[i].child[0] = t.child[0];
      in[i].child[1] = t.child[1];
    }
    return in;
  }

  // Appends the triangles of the binary subtree at `slot` as one leaf, each once (spatial splits
  // may put two pieces of one triangle below it); returns its slot (triangleOffset = absolute
  // first index). Leaves left to right, so without spatial splits the triangles keep the order
  // of the refs.
  WideChild leafChild(std::uint32_t slot, const Aabb& box, Bvh& bvh) const {
    WideChild c;
    c.kind = WideChild::Kind::Leaf;
    c.box = toBox(box);
    c.triangleOffset = static_cast<std::uint32_t>(bvh.triangles.size());
    c.triangleCount = 0;
    std::vector<std::uint32_t> todo = {slot};
    while (!todo.empty()) {
      const TempNode& t = nodes_[todo.back()];
      todo.pop_back();
      if (t.count == 0) {
        todo.push_back(t.child[1]);
        todo.push_back(t.child[0]);
        continue;
      }
      for (std::uint32_t i = t.first; i < t.first + t.count; ++i) {
        const std::uint32_t id = refs_[i].id;
        const auto stored = bvh.order.end() - c.triangleCount;
        if (std::find(stored, bvh.order.end(), id) != bvh.order.end()) continue;
        ++c.triangleCount;
        bvh.order.push_back(id);
        bvh.triangles.push_back({.v0 = gpu::vec4(soup_.v0[id], std::bit_cast<float>(id)),
                                 .v1 = gpu::vec4(soup_.v1[id], 0.0f),
                                 .v2 = gpu::vec4(soup_.v2[id], 0.0f)});
      }
    }
    return c;
  }

  // slotOf[s] = index into `children` placed in slot s, or -1. Slot bit k means "on the + side of
  // axis k" (host_device.h): greedily, the (child, slot) pair whose slot direction best matches
  // the child's offset from the parent's centre is placed first (Ylitie et al. 2017, §3.2).
  std::array<int, gpu::kBvhWidth> assignOctantSlots(std::uint32_t parent,
                                                   const std::vector<CollapsedSlot>& children) const {
    const Aabb& p = nodes_[parent].box;
    const glm::vec3 centre = 0.5f * (p.lo + p.hi);
    struct Pair { float cost; int child; int slot; };
    std::vector<Pair> pairs;
    for (std::size_t i = 0; i < children.size(); ++i) {
      const Aabb& b = nodes_[children[i].node].box;
      const glm::vec3 offset = 0.5f * (b.lo + b.hi) - centre;
      for (int s = 0; s < static_cast<int>(gpu::kBvhWidth); ++s) {
        const glm::vec3 dir((s & 1) ? 1.0f : -1.0f, (s & 2) ? 1.0f : -1.0f, (s & 4) ? 1.0f : -1.0f);
        pairs.push_back({-glm::dot(offset, dir), static_cast<int>(i), s});
      }
    }
    std::stable_sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.cost < b.cost; });
    std::array<int, gpu::kBvhWidth> slotOf;
    slotOf.fill(-1);
    std::vector<bool> placed(children.size(), false);
    for (const Pair& pr : pairs) {
      if (placed[static_cast<std::size_t>(pr.child)] || slotOf[static_cast<std::size_t>(pr.slot)] >= 0) continue;
      placed[static_cast<std::size_t>(pr.child)] = true;
      slotOf[static_cast<std::size_t>(pr.slot)] = pr.child;
    }
    return slotOf;
  }

  // SAH cost of the binary tree below interior `slot` (the statistic; root area = 1).
  void addBinarySah(std::uint32_t slot) {
    std::vector<std::uint32_t> todo = {slot};
    while (!todo.empty()) {
      const TempNode& t = nodes_[todo.back()];
      todo.pop_back();
      if (t.count > 0) {
        sah_ += double{options_.intersectionCost} * t.count * areaRatio(t.box);
        continue;
      }
      sah_ += double{options_.traversalCost} * areaRatio(t.box);
      todo.push_back(t.child[0]);
      todo.push_back(t.child[1]);
    }
  }

  void writeEmptyRoot(Bvh& bvh) const {
    bvh.nodes.emplace_back();
    writeWideNode(bvh.nodes[0], {}, 0, 0);
    bvh.stats.nodeCount = 1;
    bvh.stats.maxDepth = 0;
  }

  // Area relative to the root for the SAH statistic; a zero-area root (all triangles on one line
  // or point) makes every ratio 0/0, counted as 1.
  double areaRatio(const Aabb& b) const {
    return rootArea_ > 0.0 ? static_cast<double>(b.area()) / rootArea_ : 1.0;
  }

  const TriangleSoup& soup_;
  const BuildOptions& options_;
  unsigned threads_ = 1;
  int bins_ = 16;
  std::uint32_t maxLeaf_ = 3;    // triangles of a wide leaf slot
  std::uint32_t binaryLeaf_ = 1; // of a binary leaf, where the SAH may still split
  unsigned maxTaskDepth_ = 0;
  std::vector<PrimRef> refs_;
  std::vector<TempNode> nodes_;
  std::atomic<std::uint32_t> medianFallbacks_{0};
  std::atomic<std::uint32_t> spatialSplits_{0};
  // The root's surface area: the spatial splits' overlap test and the SAH statistic divide by it.
  double rootArea_ = 0.0;

  // writeWide() state
  double sah_ = 0.0;
};

} // namespace

std::uint32_t compactStackVectors(const Bvh& bvh) {
  if (bvh.nodes.size() > gpu::kBvhCompactStackNodes || bvh.stats.maxDepth > gpu::kBvhCompactStackMaxDepth) return 0;
  const std::uint32_t entries = bvh.stats.maxDepth > 2 ? bvh.stats.maxDepth - 2 : 0;
  return std::max(1u, (entries + 3) / 4);
}

Bvh build(const TriangleSoup& soup, const BuildOptions& options) {
  return Builder(soup, options).run();
}

} // namespace obscura::bvh
