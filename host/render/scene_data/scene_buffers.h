// scene_buffers.h — the scene and its BVH on the GPU (set 0, bindings 0..5 of every tracing
// pass; see shaders/lib/scene_bindings.glsl). Uploaded once; lives as long as the scene.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "bvh/bvh.h"
#include "gpu/buffer.h"
#include "gpu/context.h"
#include "gpu/kernel.h"
#include "render/scene_data/bvh_layout.h"
#include "render/status_counters.h"
#include "scene/scene.h"

namespace obscura::render {

// The BVH input for a scene: its triangles' world-space vertices in scene order.
bvh::TriangleSoup triangleSoup(const scene::Scene& scene);

// The scale of the ray-origin offset (shaders/lib/ray.glsl): the scene's largest bounding-box
// extent, capped at 1 (the paper's constants are for unit scenes and only shrink for tiny ones).
float sceneScale(const scene::Bounds& bounds);

// a-bar of a material with its base colour factor [SPEC §1.2] (shading/bsdf.h meanAlbedo).
glm::vec3 materialMeanAlbedo(const scene::Material& material);

// Widens a box outward by one ulp on every face (conservative: never loses a hit). The GPU slab
// test needs it for rays with a zero direction component whose origin lies exactly on a face
// (see safeReciprocal in shaders/lib/intersect.glsl); the BVH's quantised boxes are built
// strictly outside their contents for the same reason (host/bvh/wide_node.cpp).
void widenBox(glm::vec4& lo, glm::vec4& hi);

// The GPU texel array of shared/host_device.h: the BVH's wide nodes (kTexelsPerNode texels),
// then its triangles (kTexelsPerTriangle texels), with each node's first triangle rebased from a
// triangle index to a texel index.
std::vector<gpu::vec4> bvhTexels(const bvh::Bvh& bvh);

// Throws DeviceError when the device's texel buffers cannot hold `texels` of the scene's `what`.
void checkTexelLimit(const gpu::Context& context, std::size_t texels, const char* what);

// A table of the scene as an RGBA32F texel buffer (whole texels per row), at least one row long
// (Vulkan has no empty buffers; a scene without lights still binds its light tables).
template <typename Row>
gpu::TexelBuffer tableTexels(const gpu::Context& context, const std::vector<Row>& rows, const char* what,
                             const std::string& name) {
  static_assert(sizeof(Row) % sizeof(gpu::vec4) == 0, "a row is whole RGBA32F texels");
  checkTexelLimit(context, rows.size() * (sizeof(Row) / sizeof(gpu::vec4)), what);
  const Row empty{};
  return rows.empty() ? gpu::TexelBuffer(context, &empty, sizeof(Row), name)
                      : gpu::TexelBuffer(context, rows.data(), rows.size() * sizeof(Row), name);
}

// tableTexels' rows into `table` through `uploads`, keeping the buffer where it holds them and
// else making it twice as large as they need (gpu::refillArray's rule); true when it made a new one.
template <typename Row>
bool refillTable(const gpu::Context& context, gpu::UploadBatch& uploads, gpu::TexelBuffer& table,
                 const std::vector<Row>& rows, const char* what, const std::string& name) {
  static_assert(sizeof(Row) % sizeof(gpu::vec4) == 0, "a row is whole RGBA32F texels");
  const std::size_t count = std::max<std::size_t>(rows.size(), 1);
  bool made = false;
  if (table.buffer().size() < count * sizeof(Row)) {
    checkTexelLimit(context, 2 * count * (sizeof(Row) / sizeof(gpu::vec4)), what);
    table = gpu::TexelBuffer(context, 2 * count * sizeof(Row), vk::Format::eR32G32B32A32Sfloat, {}, name);
    made = true;
  }
  if (rows.empty()) uploads.add(table.buffer(), std::vector<Row>(1));
  else uploads.add(table.buffer(), rows);
  return made;
}

// What the kernels that trace and shade a scene are specialised for, as the scene needs: the
// compact traversal stack of its BVH (kSpecConstantCompactStack; 0: the general stack with its
// second loop) and the kinds of texture none of its materials uses (kSpecConstantTexturesAbsent:
// their lookups compiled out). On lavapipe both cost every ray or hit even where unused.
struct SceneSpecialisation {
  std::uint32_t compactStackVectors = 0;
  std::uint32_t texturesAbsent = 0; // gpu::kTexturesAbsent* bits
  // The layout of the scene's BVH items and the loop that traverses them (kSpecConstantBvhLayout,
  // kSpecConstantBinaryLoop): a kernel reads one layout only.
  Traversal traversal = Traversal::Wide;
  // Whether kernels made for this specialisation trace and shade a scene that needs `scene` right.
  bool holds(const SceneSpecialisation& scene) const {
    return bvh::compactStackHolds(compactStackVectors, scene.compactStackVectors) &&
           (texturesAbsent & ~scene.texturesAbsent) == 0 && bvhLayoutOf(traversal) == bvhLayoutOf(scene.traversal);
  }
  // Appends its specialisation constants to `desc` (none where the general kernel's).
  void addTo(gpu::KernelDesc& desc) const;
  bool operator==(const SceneSpecialisation&) const = default;
};

class SceneBuffers {
public:
  // The BVH is uploaded in the layout of `traversal`, by default the context's request
  // (--traversal) or else the device's (traversalForDevice). A binary tree deeper than its traversal's stack keeps the wide layout
  // (noted in notes()), unless a binary traversal was asked for: then DeviceError.
  SceneBuffers(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
               std::optional<Traversal> traversal = {});

  // Binds bindings 0..5 of descriptor set `set` of `kernel`. Binding 5 (status counters) is the
  // scene's own unless `status` is given: a renderer counts its frame's rays in its own buffer.
  // Throws std::logic_error for a compact-stack kernel whose stack this BVH could overflow, or a
  // kernel without the lookups of a kind of texture this scene's materials use.
  void bindTo(gpu::Kernel& kernel, std::uint32_t set = 0, const gpu::Buffer* status = nullptr) const;

  // The compact register stack this BVH needs (bvh::compactStackVectors; 0: beyond it), kept up to
  // date by updateGeometry: the specialisation of the kernels that trace it.
  std::uint32_t compactStackVectors() const { return compactStackVectors_; }
  // The specialisation of the kernels that trace and shade this scene.
  SceneSpecialisation specialisation() const { return {compactStackVectors_, texturesAbsent_, traversal_}; }
  // The layout the BVH items are in and the loop that traverses them.
  Traversal traversal() const { return traversal_; }

  // After an edit that kept the materials and textures (a move or a removal): uploads the BVH items
  // and the triangles' shading data again, in place when their sizes stayed (the texel buffer's
  // view and every descriptor stay valid), else into new buffers (rebind the kernels then).
  // Returns true when the buffers were re-created. A caller with compact-stack kernels checks
  // compactStackVectors() after it: bound in place, they would not notice a deeper BVH.
  bool updateGeometry(const scene::Scene& scene, const bvh::Bvh& bvh);
  // After an edit that added materials but no texture (an emissive quad, an inserted object whose
  // materials use the scene's textures): the material table again, the textures kept (uploading
  // modern-hall's again cost an edit hundreds of ms). Call with updateGeometry; returns true
  // when the table's buffer was re-created (rebind). specialisation() may change: the kernels'
  // texture lookups follow the materials.
  bool updateMaterials(const scene::Scene& scene);

  // Marks the important secondary reflectors (one flag per triangle of `scene`, whose triangles
  // these buffers hold; secondary_reflectors.h). updateGeometry keeps the marks.
  void setSecondaryReflectors(const scene::Scene& scene, std::vector<std::uint8_t> marked);

  // Traversals cut off by kMaxTraversalSteps since the last reset (must stay 0).
  std::uint32_t truncatedTraversals() const;
  // All status words (kStatus*: truncations, rays per pass) since the last reset.
  std::vector<std::uint32_t> statusWords() const;
  void resetStatus();

  std::uint64_t bytes() const { return bytes_; }
  // The BVH's items buffer itself (also a storage buffer), for trace.comp's SSBO path.
  const gpu::Buffer& bvhItemsBuffer() const { return items_.buffer(); }
  // What the upload had to change (textures reduced to fit a device limit), for the log.
  const std::vector<std::string>& notes() const { return notes_; }

private:
  const gpu::Context* context_;
  gpu::TexelBuffer items_;
  gpu::TexelBuffer shading_;
  gpu::TexelBuffer materials_;
  gpu::TexelBuffer textures_;
  gpu::TexelBuffer texels_;
  StatusCounters status_;
  std::uint64_t bytes_ = 0;
  // The BVH's texels in the layout of traversal_ (falling back to the wide one, see the constructor).
  std::vector<gpu::vec4> itemTexels(const bvh::Bvh& bvh);

  std::optional<Traversal> requested_; // the traversal asked for; nullopt: the device's
  Traversal traversal_ = Traversal::Wide;
  std::uint32_t compactStackVectors_ = 0;
  std::uint32_t texturesAbsent_ = 0; // gpu::kTexturesAbsent* bits: the texture kinds no material uses
  std::vector<std::string> notes_;
  std::vector<std::uint8_t> reflectors_; // per triangle (empty: none marked)
};

// Every kernel that traces rays starts its binding list with the scene's.
std::vector<gpu::BindingKind> sceneBindingKinds();

} // namespace obscura::render
