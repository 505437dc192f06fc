#include "render/scene_data/light_tree.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>

#include <glm/glm.hpp>

#include "render/scene_data/light_selection.h"

namespace obscura::render {
namespace {

constexpr double kPiD = std::numbers::pi;
// Buckets per axis of the binned split search (pbrt-v4 and most SAH builders use 12).
constexpr int kSplitBuckets = 12;
// Angular slack added to a merged cone [rad], so rounding keeps every child's directions inside.
constexpr float kConeSlack = 1e-4f;

struct Box {
  glm::vec3 lo{std::numeric_limits<float>::max()};
  glm::vec3 hi{-std::numeric_limits<float>::max()};
  bool empty() const { return lo.x > hi.x; }
  void grow(const Box& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  glm::vec3 extent() const { return empty() ? glm::vec3(0.0f) : hi - lo; }
  double surfaceArea() const {
    const glm::dvec3 e(extent());
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
};

// The bounds of a set of lights, as they are merged on the way up.
struct NodeBounds {
  Box box;                 // holds every light's bounding sphere
  glm::vec3 axis{0.0f, 0.0f, 1.0f};
  float cosO = 1.0f;       // an empty set: a cone of no direction
  float cosE = 1.0f;
  bool uniformInCone = false;
  double power = 0.0;
  bool any = false;
};

// The smallest cone found here that holds cones (a, cosA) and (b, cosB): the cone whose edge
// touches the far edges of both, on the great circle through the two axes.
void mergeCones(glm::vec3 a, float cosA, glm::vec3 b, float cosB, glm::vec3& axis, float& cosTheta) {
  axis = a;
  cosTheta = -1.0f;
  if (cosA <= -1.0f || cosB <= -1.0f) return;
  const double thetaA = std::acos(std::clamp(double(cosA), -1.0, 1.0));
  const double thetaB = std::acos(std::clamp(double(cosB), -1.0, 1.0));
  const double between = std::acos(std::clamp(double(glm::dot(a, b)), -1.0, 1.0));
  if (between + thetaB <= thetaA) { // b inside a
    cosTheta = cosA;
    return;
  }
  if (between + thetaA <= thetaB) { // a inside b
    axis = b;
    cosTheta = cosB;
    return;
  }
  const double theta = 0.5 * (thetaA + between + thetaB) + kConeSlack;
  const glm::dvec3 da(a), db(b);
  const glm::dvec3 across = db - da * glm::dot(da, db);
  if (theta >= kPiD || glm::length(across) < 1e-9) return; // every direction
  const double turn = theta - thetaA; // rotate a towards b by this much
  axis = glm::vec3(glm::normalize(da * std::cos(turn) + glm::normalize(across) * std::sin(turn)));
  cosTheta = static_cast<float>(std::cos(theta));
}

NodeBounds merge(const NodeBounds& a, const NodeBounds& b) {
  if (!a.any) return b;
  if (!b.any) return a;
  NodeBounds m;
  m.any = true;
  m.box = a.box;
  m.box.grow(b.box);
  mergeCones(a.axis, a.cosO, b.axis, b.cosO, m.axis, m.cosO);
  m.cosE = std::min(a.cosE, b.cosE); // the wider spread
  m.uniformInCone = a.uniformInCone || b.uniformInCone;
  m.power = a.power + b.power;
  return m;
}

NodeBounds leafBounds(const ImportanceBounds& ib) {
  NodeBounds b;
  b.any = true;
  b.box.lo = ib.centre - glm::vec3(ib.radius);
  b.box.hi = ib.centre + glm::vec3(ib.radius);
  b.axis = ib.axis;
  b.cosO = ib.cosO;
  b.cosE = ib.cosE;
  b.uniformInCone = ib.uniformInCone;
  b.power = ib.power;
  return b;
}

// The split cost of one side: power x orientation measure x surface area, times the node's
// elongation along the split axis (pbrt-v4's Kr), which favours cuts across long nodes.
double splitCost(const NodeBounds& b, double elongation) {
  return b.power * orientationMeasure(b.cosO, b.cosE) * b.box.surfaceArea() * elongation;
}

int ceilLog2(std::size_t n) { return n <= 1 ? 0 : static_cast<int>(std::bit_width(n - 1)); }

struct Item {
  std::uint32_t light;
  NodeBounds bounds;
  glm::vec3 centroid;
};

struct TempNode {
  NodeBounds bounds;
  int children[2] = {-1, -1};
  std::uint32_t light = 0; // leaves
};

class Builder {
public:
  explicit Builder(std::size_t lightCount) : trails_(lightCount, {0u, gpu::kInvalidIndex}) {}

  int build(std::vector<Item>& items, std::size_t begin, std::size_t end, std::uint32_t depth, std::uint32_t bits) {
    const int index = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    depth_ = std::max(depth_, depth);
    if (end - begin == 1) {
      nodes_[index].bounds = items[begin].bounds;
      nodes_[index].light = items[begin].light;
      trails_[items[begin].light] = {bits, depth};
      return index;
    }
    const std::size_t middle = split(items, begin, end, depth);
    const int first = build(items, begin, middle, depth + 1, bits);
    const int second = build(items, middle, end, depth + 1, bits | (1u << depth));
    nodes_[index].children[0] = first;
    nodes_[index].children[1] = second;
    nodes_[index].bounds = merge(nodes_[first].bounds, nodes_[second].bounds);
    return index;
  }

  const std::vector<TempNode>& nodes() const { return nodes_; }
  const std::vector<std::array<std::uint32_t, 2>>& trails() const { return trails_; }
  std::uint32_t depth() const { return depth_; }

private:
  // Partitions [begin, end) and returns where the second child starts.
  std::size_t split(std::vector<Item>& items, std::size_t begin, std::size_t end, std::uint32_t depth) {
    Box centroids, all;
    for (std::size_t i = begin; i < end; ++i) {
      centroids.grow(Box{items[i].centroid, items[i].centroid});
      all.grow(items[i].bounds.box);
    }
    const glm::vec3 spread = centroids.extent();
    const int widest = spread.x >= spread.y && spread.x >= spread.z ? 0 : spread.y >= spread.z ? 1 : 2;
    auto median = [&] {
      const std::size_t middle = begin + (end - begin) / 2;
      std::nth_element(items.begin() + static_cast<std::ptrdiff_t>(begin),
                       items.begin() + static_cast<std::ptrdiff_t>(middle),
                       items.begin() + static_cast<std::ptrdiff_t>(end),
                       [&](const Item& a, const Item& b) { return a.centroid[widest] < b.centroid[widest]; });
      return middle;
    };
    // Near the depth limit (32 trail bits) only halving keeps every leaf within it.
    if (depth + static_cast<std::uint32_t>(ceilLog2(end - begin)) >= gpu::kLightTreeMaxDepth) return median();
    const glm::vec3 extent = all.extent();
    const float longest = std::max({extent.x, extent.y, extent.z});
    double bestCost = std::numeric_limits<double>::infinity();
    int bestAxis = -1, bestBucket = 0;
    for (int axis = 0; axis < 3; ++axis) {
      if (!(spread[axis] > 0.0f)) continue;
      std::array<NodeBounds, kSplitBuckets> buckets{};
      for (std::size_t i = begin; i < end; ++i) {
        const int b = bucketOf(items[i].centroid[axis], centroids.lo[axis], spread[axis]);
        buckets[b] = merge(buckets[b], items[i].bounds);
      }
      const double elongation = longest / std::max(extent[axis], std::numeric_limits<float>::min());
      // Sweep: below[k] = buckets [0, k] merged; the split after bucket k puts the rest above.
      std::array<NodeBounds, kSplitBuckets> below{};
      below[0] = buckets[0];
      for (int k = 1; k < kSplitBuckets; ++k) below[k] = merge(below[k - 1], buckets[k]);
      NodeBounds above;
      for (int k = kSplitBuckets - 1; k > 0; --k) {
        above = merge(above, buckets[k]);
        if (!below[k - 1].any || !above.any) continue;
        const double cost = splitCost(below[k - 1], elongation) + splitCost(above, elongation);
        if (cost < bestCost) {
          bestCost = cost;
          bestAxis = axis;
          bestBucket = k;
        }
      }
    }
    if (bestAxis < 0) return median(); // every centroid in one place: any halving will do
    const auto middle = std::partition(
        items.begin() + static_cast<std::ptrdiff_t>(begin), items.begin() + static_cast<std::ptrdiff_t>(end),
        [&](const Item& item) {
          return bucketOf(item.centroid[bestAxis], centroids.lo[bestAxis], spread[bestAxis]) < bestBucket;
        });
    return static_cast<std::size_t>(middle - items.begin());
  }

  static int bucketOf(float x, float lo, float spread) {
    const int b = static_cast<int>(float(kSplitBuckets) * ((x - lo) / spread));
    return std::clamp(b, 0, kSplitBuckets - 1);
  }

  std::vector<TempNode> nodes_;
  std::vector<std::array<std::uint32_t, 2>> trails_; // per light: bits, depth (kInvalidIndex: no leaf)
  std::uint32_t depth_ = 0;
};

gpu::GpuLightNode nodeRow(const NodeBounds& b) {
  gpu::GpuLightNode row{};
  const glm::vec3 centre = 0.5f * (b.box.lo + b.box.hi);
  // The sphere around the box holds every child's sphere; a hair larger for rounding.
  const float radius = 0.5f * glm::length(b.box.hi - b.box.lo) * 1.0001f;
  row.sphere = glm::vec4(centre, radius);
  row.cone = glm::vec4(b.axis, b.cosO);
  row.emission = glm::vec4(static_cast<float>(b.power), b.cosE, b.uniformInCone ? 1.0f : 0.0f, 0.0f);
  return row;
}

gpu::GpuLightNode leafRow(const ImportanceBounds& ib, std::uint32_t light) {
  gpu::GpuLightNode row{};
  row.sphere = glm::vec4(ib.centre, ib.radius);
  row.cone = glm::vec4(ib.axis, ib.cosO);
  row.emission = glm::vec4(ib.power, ib.cosE, ib.uniformInCone ? 1.0f : 0.0f, 0.0f);
  row.refs = glm::uvec4(light, gpu::kInvalidIndex, 0u, gpu::kInvalidIndex);
  return row;
}

} // namespace

double orientationMeasure(float cosO, float cosE) {
  // Integral over the sphere of cos(max(0, theta - theta_o)) for theta < theta_w =
  // min(theta_o + theta_e, pi), 0 beyond: 2 pi (1 - cos theta_o) inside the cone, and
  // 2 pi Int_{theta_o}^{theta_w} cos(theta - theta_o) sin(theta) dtheta
  //   = pi / 2 (cos theta_o - cos(2 theta_w - theta_o) + 2 (theta_w - theta_o) sin theta_o)
  // in the spread (sin(theta) cos(theta - theta_o) = (sin(2 theta - theta_o) + sin theta_o) / 2).
  const double thetaO = std::acos(std::clamp(double(cosO), -1.0, 1.0));
  const double thetaE = std::acos(std::clamp(double(cosE), -1.0, 1.0));
  const double thetaW = std::min(thetaO + thetaE, kPiD);
  const double sinO = std::sin(thetaO);
  return 2.0 * kPiD * (1.0 - std::cos(thetaO)) +
         0.5 * kPiD * (std::cos(thetaO) - std::cos(2.0 * thetaW - thetaO) + 2.0 * (thetaW - thetaO) * sinO);
}

std::vector<gpu::GpuLightNode> buildLightTree(const std::vector<gpu::GpuLight>& lights) {
  const auto lightCount = static_cast<std::uint32_t>(lights.size());
  std::vector<Item> items;
  std::vector<std::uint32_t> unbounded;
  std::vector<gpu::GpuLightNode> rows(1u + lightCount);
  for (std::uint32_t i = 0; i < lightCount; ++i) {
    const ImportanceBounds ib = importanceBounds(lights[i]);
    rows[1u + i] = leafRow(ib, i);
    if (isUnboundedLight(lights[i].info.x)) {
      if (lights[i].params.y > 0.0f) unbounded.push_back(i);
    } else if (ib.power > 0.0f) {
      items.push_back({.light = i, .bounds = leafBounds(ib), .centroid = ib.centre});
    }
  }
  for (std::uint32_t light : unbounded) {
    gpu::GpuLightNode row{};
    row.refs = glm::uvec4(light, gpu::kInvalidIndex, 0u, 0u);
    rows.push_back(row);
  }
  std::uint32_t root = gpu::kInvalidIndex, depth = 0;
  if (!items.empty()) {
    Builder builder(lightCount);
    builder.build(items, 0, items.size(), 0u, 0u);
    depth = builder.depth();
    // Rows of the internal nodes in the builder's (depth-first) order; leaves are the lights' rows.
    const auto& nodes = builder.nodes();
    std::vector<std::uint32_t> rowOf(nodes.size());
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      if (nodes[k].children[0] < 0) {
        rowOf[k] = 1u + nodes[k].light;
      } else {
        rowOf[k] = static_cast<std::uint32_t>(rows.size());
        rows.push_back(nodeRow(nodes[k].bounds));
      }
    }
    for (std::size_t k = 0; k < nodes.size(); ++k)
      if (nodes[k].children[0] >= 0)
        rows[rowOf[k]].refs = glm::uvec4(rowOf[nodes[k].children[0]], rowOf[nodes[k].children[1]], 0u, 0u);
    for (std::uint32_t i = 0; i < lightCount; ++i)
      if (builder.trails()[i][1] != gpu::kInvalidIndex)
        rows[1u + i].refs = glm::uvec4(i, gpu::kInvalidIndex, builder.trails()[i][0], builder.trails()[i][1]);
    root = rowOf[0];
  }
  rows[0].refs = glm::uvec4(root, static_cast<std::uint32_t>(unbounded.size()), lightCount, depth);
  return rows;
}

} // namespace obscura::render
