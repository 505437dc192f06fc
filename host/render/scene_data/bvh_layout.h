// bvh_layout.h — which BVH layout and traversal loop the kernels use on a device: the one place
// that decides it (SceneBuffers asks; `--traversal` overrides).
//
// lavapipe runs 8 lanes in lock-step through LLVM's vector units and pays for both sides of every
// branch, so its loop is the wide one of lib/bvh.glsl (8-wide compressed nodes, one loop that
// tests a triangle and visits a node per pass, a stack in registers). A GPU runs 32-wide warps
// with caches made for 64-byte fetches and branches that cost only where lanes diverge: there the
// binary layout (Aila & Laine's two-box nodes) with its while-while loop traced the same rays
// faster (docs/BENCHMARKS.md, "Traversal per device").
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bvh/bvh.h"
#include "core/names.h"
#include "gpu/context.h"

namespace obscura::render {

enum class Traversal : std::uint32_t {
  Wide,             // kBvhLayoutWide: lib/bvh.glsl traverseBvh's own loop
  Binary,           // kBvhLayoutBinary, one loop (exact against lavapipe's loop limiter)
  BinaryWhileWhile, // kBvhLayoutBinary, Aila & Laine's while-while (GPUs)
};

// The traversal for a device: Wide on a CPU (lavapipe), BinaryWhileWhile on a GPU.
Traversal traversalForDevice(const gpu::DeviceInfo& device);
// The traversal kernels use on `context`: its request (--traversal), else its device's.
Traversal traversalFor(const gpu::Context& context);

// The tree each traversal is fastest on: the binary layout over a tree with spatial splits
// (a budget of 10 % more references), the wide one without (measured: docs/BENCHMARKS.md,
// "Traversal per device"; on lavapipe the splits made shadow rays slower).
bvh::BuildOptions treeOptionsFor(Traversal traversal);

inline constexpr NameTable<Traversal, 3> kTraversalNames{{{"wide", Traversal::Wide},
                                                          {"binary", Traversal::Binary},
                                                          {"binary-while-while", Traversal::BinaryWhileWhile}}};
// A name of kTraversalNames; "auto" (or empty) is nullopt: the device's. Throws
// std::invalid_argument naming the accepted values otherwise.
std::optional<Traversal> parseTraversal(std::string_view name);
// The words --traversal takes: "auto" (the device's choice), then kTraversalNames' names.
std::vector<std::string> traversalRequestNames();
std::string traversalName(Traversal traversal);

std::uint32_t bvhLayoutOf(Traversal traversal); // gpu::kBvhLayoutWide or kBvhLayoutBinary
bool binaryWhileWhile(Traversal traversal);

// The GPU texel array of the binary layout (bvh/binary_layout.h): its nodes (kTexelsPerBinaryNode
// texels each), then the wide tree's triangles, the leaves' triangle indices made texel indices.
// nullopt where its tree is deeper than the binary traversal's stack (kBinaryStackSize).
std::optional<std::vector<gpu::vec4>> binaryBvhTexels(const bvh::Bvh& bvh);

} // namespace obscura::render
