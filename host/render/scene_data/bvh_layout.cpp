// bvh_layout.cpp — the traversal per device and the binary layout's texels (bvh_layout.h).
#include "render/scene_data/bvh_layout.h"

#include <bit>
#include <stdexcept>

#include <fmt/core.h>
#include <fmt/ranges.h>

#include "bvh/binary_layout.h"
#include "core/error.h"

namespace obscura::render {

Traversal traversalForDevice(const gpu::DeviceInfo& device) {
  return device.type == "cpu" ? Traversal::Wide : Traversal::BinaryWhileWhile;
}

Traversal traversalFor(const gpu::Context& context) {
  return parseTraversal(context.traversalRequest()).value_or(traversalForDevice(context.info()));
}

bvh::BuildOptions treeOptionsFor(Traversal traversal) {
  bvh::BuildOptions options;
  if (traversal != Traversal::Wide) options.spatialSplitBudget = 0.1f;
  return options;
}

std::optional<Traversal> parseTraversal(std::string_view name) {
  if (name.empty() || name == "auto") return std::nullopt;
  if (const auto traversal = valueNamed(kTraversalNames, name)) return traversal;
  throw std::invalid_argument(
      fmt::format("unknown traversal '{}' (expected one of: {})", name, fmt::join(traversalRequestNames(), ", ")));
}

std::vector<std::string> traversalRequestNames() {
  std::vector<std::string> names = namesOf(kTraversalNames);
  names.insert(names.begin(), "auto");
  return names;
}

std::string traversalName(Traversal traversal) { return std::string(nameOf(kTraversalNames, traversal)); }

std::uint32_t bvhLayoutOf(Traversal traversal) {
  return traversal == Traversal::Wide ? gpu::kBvhLayoutWide : gpu::kBvhLayoutBinary;
}

bool binaryWhileWhile(Traversal traversal) { return traversal == Traversal::BinaryWhileWhile; }

std::optional<std::vector<gpu::vec4>> binaryBvhTexels(const bvh::Bvh& bvh) {
  const bvh::BinaryBvh binary = bvh::binaryLayout(bvh);
  if (binary.maxDepth > gpu::kBinaryStackSize) return std::nullopt;
  const std::size_t nodeTexels = binary.nodes.size() * gpu::kTexelsPerBinaryNode;
  const std::size_t total = nodeTexels + bvh.triangles.size() * gpu::kTexelsPerTriangle;
  if (total > gpu::kBinaryLeafTexelMask)
    throw DeviceError("the scene has too many triangles for the binary BVH layout's leaf references");
  // A leaf reference's triangle index becomes the texel of that triangle's v0.
  auto rebased = [&](float refBits) {
    const auto ref = std::bit_cast<std::uint32_t>(refBits);
    if (ref == gpu::kInvalidIndex || !bvh::isBinaryLeaf(ref)) return refBits;
    const auto texel = static_cast<std::uint32_t>(nodeTexels + std::size_t{bvh::binaryLeafFirst(ref)} * gpu::kTexelsPerTriangle);
    return std::bit_cast<float>(gpu::kBinaryLeafBit | bvh::binaryLeafCount(ref) << gpu::kBinaryLeafCountShift | texel);
  };
  std::vector<gpu::vec4> texels;
  texels.reserve(total);
  for (gpu::BvhBinaryNode node : binary.nodes) {
    node.leftLo.w = rebased(node.leftLo.w);
    node.leftHi.w = rebased(node.leftHi.w);
    for (const gpu::vec4& t : {node.leftLo, node.leftHi, node.rightLo, node.rightHi}) texels.push_back(t);
  }
  for (const auto& t : bvh.triangles)
    for (const gpu::vec4& v : {t.v0, t.v1, t.v2}) texels.push_back(v);
  return texels;
}

} // namespace obscura::render
