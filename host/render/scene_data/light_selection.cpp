#include "render/scene_data/light_selection.h"

#include <algorithm>
#include <cmath>

#include "shading/bsdf.h"

namespace obscura::render {
namespace {

float cosOfClampedDifference(float cosA, float sinA, float cosB, float sinB) {
  return cosA >= cosB ? 1.0f : cosA * cosB + sinA * sinB;
}
float sinOfClampedDifference(float cosA, float sinA, float cosB, float sinB) {
  return cosA >= cosB ? 0.0f : sinA * cosB - cosA * sinB;
}

float nodeImportance(const std::vector<gpu::GpuLightNode>& tree, std::uint32_t row, glm::vec3 p, glm::vec3 n) {
  return boundsImportance(importanceBounds(tree[row]), p, n);
}

glm::vec2 lightTreeChildProbabilities(const std::vector<gpu::GpuLightNode>& tree, glm::uvec4 refs, glm::vec3 p,
                                      glm::vec3 n) {
  const float a = nodeImportance(tree, refs.x, p, n), b = nodeImportance(tree, refs.y, p, n);
  const float total = a + b;
  return total > 0.0f ? glm::vec2(a / total, b / total) : glm::vec2(0.0f);
}

float lightTreeShares(const std::vector<gpu::GpuLightNode>& tree, glm::vec3 p, glm::vec3 n, bool& lit) {
  const glm::uvec4 header = tree[0].refs;
  lit = header.x != gpu::kInvalidIndex && nodeImportance(tree, header.x, p, n) > 0.0f;
  return float(header.y) + (lit ? 1.0f : 0.0f);
}

} // namespace

bool isUnboundedLight(std::uint32_t type) { return type == gpu::kLightDirectional || type == gpu::kLightBackground; }

ImportanceBounds importanceBounds(const gpu::GpuLight& light) {
  ImportanceBounds b;
  const std::uint32_t type = light.info.x;
  if (isUnboundedLight(type)) return b;
  const bool area = type == gpu::kLightArea, spot = type == gpu::kLightSpot;
  b.power = light.params.y;
  b.centre = glm::vec3(light.position);
  b.radius = area ? light.position.w : 0.0f;
  b.axis = area || spot ? glm::vec3(light.direction) : glm::vec3(0.0f, 0.0f, 1.0f);
  b.cosO = area ? light.direction.w : spot ? light.params.w : -1.0f;
  b.cosE = spot ? gpu::kSpotConeSlack : 0.0f;
  b.uniformInCone = spot;
  return b;
}

ImportanceBounds importanceBounds(const gpu::GpuLightNode& node) {
  return {.power = node.emission.x,
          .centre = glm::vec3(node.sphere),
          .radius = node.sphere.w,
          .axis = glm::vec3(node.cone),
          .cosO = node.cone.w,
          .cosE = node.emission.y,
          .uniformInCone = node.emission.z != 0.0f};
}

float boundsImportance(const ImportanceBounds& b, glm::vec3 p, glm::vec3 n) {
  if (!(b.power > 0.0f)) return 0.0f;
  const glm::vec3 toLight = b.centre - p;
  const float d2 = glm::dot(toLight, toLight);
  const float r2 = b.radius * b.radius;
  if (d2 <= r2 * 1.0001f || d2 == 0.0f) return b.power / std::max(r2, 1e-12f);
  const float d = std::sqrt(d2);
  const glm::vec3 w = toLight / d;
  const float sinB = b.radius / d, cosB = std::sqrt(std::max(0.0f, 1.0f - sinB * sinB));
  const float cosI = glm::dot(n, w), sinI = std::sqrt(std::max(0.0f, 1.0f - cosI * cosI));
  const float cosIPrime = cosOfClampedDifference(cosI, sinI, cosB, sinB);
  if (cosIPrime <= 0.0f) return 0.0f;
  float importance = b.power * cosIPrime / d2;
  if (b.cosO > -1.0f) {
    const float sinO = std::sqrt(std::max(0.0f, 1.0f - b.cosO * b.cosO));
    const float cosW = glm::dot(b.axis, -w), sinW = std::sqrt(std::max(0.0f, 1.0f - cosW * cosW));
    const float cosX = cosOfClampedDifference(cosW, sinW, b.cosO, sinO);
    const float sinX = sinOfClampedDifference(cosW, sinW, b.cosO, sinO);
    const float cosPrime = cosOfClampedDifference(cosX, sinX, cosB, sinB);
    if (b.uniformInCone ? cosPrime < b.cosE : cosPrime <= b.cosE) return 0.0f;
    importance *= b.uniformInCone ? 1.0f : cosPrime;
  }
  return importance;
}

float lightImportance(const gpu::GpuLight& light, glm::vec3 p, glm::vec3 n) {
  return boundsImportance(importanceBounds(light), p, n);
}

LightPick selectLightFromTree(const std::vector<gpu::GpuLightNode>& tree, float u, glm::vec3 p, glm::vec3 n) {
  const glm::uvec4 header = tree[0].refs;
  bool lit = false;
  const float shares = lightTreeShares(tree, p, n, lit);
  LightPick pick;
  if (shares == 0.0f) return pick;
  const float scaled = u * shares;
  const std::uint32_t unbounded = header.y;
  if (!lit || scaled < float(unbounded)) {
    pick.probability = 1.0f / shares;
    pick.light = tree[1u + header.z + std::min(static_cast<std::uint32_t>(scaled), unbounded - 1u)].refs.x;
    return pick;
  }
  float v = std::min(scaled - float(unbounded), shading::kOneMinusEpsilon);
  float probability = 1.0f / shares;
  std::uint32_t row = header.x;
  for (std::uint32_t depth = 0; depth < gpu::kLightTreeMaxDepth; ++depth) {
    const glm::uvec4 refs = tree[row].refs;
    if (refs.y == gpu::kInvalidIndex) break;
    const glm::vec2 q = lightTreeChildProbabilities(tree, refs, p, n);
    const bool second = !(v < q.x);
    probability *= second ? q.y : q.x;
    if (!(probability > 0.0f)) return pick;
    v = std::min(second ? (v - q.x) / q.y : v / q.x, shading::kOneMinusEpsilon);
    row = second ? refs.y : refs.x;
  }
  pick.probability = probability;
  pick.light = tree[row].refs.x;
  return pick;
}

float lightTreePdf(const std::vector<gpu::GpuLightNode>& tree, const std::vector<gpu::GpuLight>& lights,
                   std::uint32_t light, glm::vec3 p, glm::vec3 n) {
  bool lit = false;
  const float shares = lightTreeShares(tree, p, n, lit);
  if (shares == 0.0f) return 0.0f;
  if (isUnboundedLight(lights[light].info.x)) return lights[light].params.y > 0.0f ? 1.0f / shares : 0.0f;
  const glm::uvec4 leaf = tree[1u + light].refs;
  if (!lit || leaf.w == gpu::kInvalidIndex) return 0.0f;
  float probability = 1.0f / shares;
  std::uint32_t row = tree[0].refs.x;
  for (std::uint32_t depth = 0; depth < leaf.w; ++depth) {
    const glm::uvec4 refs = tree[row].refs;
    const glm::vec2 q = lightTreeChildProbabilities(tree, refs, p, n);
    const bool second = ((leaf.z >> depth) & 1u) != 0u;
    probability *= second ? q.y : q.x;
    row = second ? refs.y : refs.x;
  }
  return probability;
}

} // namespace obscura::render
