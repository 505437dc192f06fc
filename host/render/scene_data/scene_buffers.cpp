#include "render/scene_data/scene_buffers.h"

#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <cstring>

#include <fmt/core.h>

#include "core/error.h"
#include "shading/bsdf.h"
#include "render/scene_data/texture_fit.h"

namespace obscura::render {

bvh::TriangleSoup triangleSoup(const scene::Scene& scene) {
  bvh::TriangleSoup soup;
  const std::size_t n = scene.triangles.size();
  soup.v0.resize(n);
  soup.v1.resize(n);
  soup.v2.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::uvec3& t = scene.triangles[i];
    soup.v0[i] = scene.positions[t.x];
    soup.v1[i] = scene.positions[t.y];
    soup.v2[i] = scene.positions[t.z];
  }
  return soup;
}

static_assert(sizeof(gpu::TriangleShading) == gpu::kTexelsPerShading * sizeof(gpu::vec4));
static_assert(sizeof(gpu::GpuMaterial) == gpu::kTexelsPerMaterial * sizeof(gpu::vec4));
static_assert(sizeof(gpu::GpuLight) == gpu::kTexelsPerLight * sizeof(gpu::vec4));
static_assert(sizeof(gpu::GpuEmitter) == gpu::kTexelsPerEmitter * sizeof(gpu::vec4));
static_assert(sizeof(gpu::GpuTexture) == sizeof(glm::uvec4));

std::vector<gpu::BindingKind> sceneBindingKinds() {
  using K = gpu::BindingKind;
  // Texel buffers for everything a ray's hit reads: lavapipe fetches a texel with one vector gather
  // where an SSBO field whose address differs between lanes is one scalar load per lane per word.
  return {K::UniformTexelBuffer, K::UniformTexelBuffer, K::UniformTexelBuffer,
          K::UniformTexelBuffer, K::UniformTexelBuffer, K::StorageBuffer};
}

float sceneScale(const scene::Bounds& bounds) {
  glm::vec3 e = bounds.extent();
  float largest = std::max(e.x, std::max(e.y, e.z));
  // Never above 1: for a large scene the paper's absolute step (1/65536 near the origin) is already
  // negligible, and growing it would lift rays off fine detail (a 1 m object on a 2 km floor).
  return largest > 0.0f && std::isfinite(largest) ? std::min(largest, 1.0f) : 1.0f;
}

void widenBox(glm::vec4& lo, glm::vec4& hi) {
  for (int k = 0; k < 3; ++k) {
    if (lo[k] > hi[k]) continue; // an empty child: left as it is (its ref is kInvalidIndex)
    lo[k] = std::nextafter(lo[k], -std::numeric_limits<float>::infinity());
    hi[k] = std::nextafter(hi[k], std::numeric_limits<float>::infinity());
  }
}

std::vector<gpu::vec4> bvhTexels(const bvh::Bvh& bvh) {
  const std::size_t nodeTexels = bvh.nodes.size() * gpu::kTexelsPerNode;
  const std::size_t total = nodeTexels + bvh.triangles.size() * gpu::kTexelsPerTriangle;
  if (total > 0x7FFFFFFFu) throw DeviceError("the scene has too many triangles for the BVH texel layout");
  std::vector<gpu::vec4> texels;
  texels.reserve(std::max<std::size_t>(total, 1));
  for (gpu::BvhNode node : bvh.nodes) {
    const auto first = std::bit_cast<std::uint32_t>(node.refs.y);
    node.refs.y = std::bit_cast<float>(static_cast<std::uint32_t>(nodeTexels + std::size_t{first} * gpu::kTexelsPerTriangle));
    for (const gpu::vec4& t : {node.origin, node.refs, node.qx, node.qy, node.qz}) texels.push_back(t);
  }
  for (const auto& t : bvh.triangles)
    for (const gpu::vec4& v : {t.v0, t.v1, t.v2}) texels.push_back(v);
  if (texels.empty()) texels.emplace_back(0.0f); // Vulkan buffers cannot be empty
  return texels;
}

namespace {

// `reflectors[t]` 1: triangle t is an important secondary reflector (n2.w = 1). At least one
// entry: Vulkan buffers cannot be empty.
std::vector<gpu::TriangleShading> shadingData(const scene::Scene& scene, const std::vector<std::uint8_t>& reflectors) {
  std::vector<gpu::TriangleShading> out(std::max<std::size_t>(scene.triangles.size(), 1));
  if (scene.triangles.empty()) return out;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const glm::uvec3& t = scene.triangles[i];
    std::uint32_t material = scene.triangleMaterial[i];
    std::uint32_t group = i < scene.triangleLightGroup.size() ? scene.triangleLightGroup[i] : gpu::kInvalidIndex;
    out[i].n0 = glm::vec4(scene.normals[t.x], std::bit_cast<float>(material));
    out[i].n1 = glm::vec4(scene.normals[t.y], std::bit_cast<float>(group));
    out[i].n2 = glm::vec4(scene.normals[t.z], i < reflectors.size() && reflectors[i] ? 1.0f : 0.0f);
    out[i].uv01 = glm::vec4(scene.uvs[t.x], scene.uvs[t.y]);
    out[i].uv2 = glm::vec4(scene.uvs[t.z], 0.0f, 0.0f);
  }
  return out;
}

} // namespace

glm::vec3 materialMeanAlbedo(const scene::Material& m) {
  // Remembered for the process: ~0.1 ms of integration a material, which every edit that adds a
  // material (an emissive quad, an insert) paid again for each of the scene's (modern-hall: ~15 ms
  // of an added quad's host work, twice: the material table and the reach's reflectances).
  using Key = std::array<std::uint32_t, 5>;
  static std::mutex mutex;
  static std::map<Key, glm::vec3> known;
  const Key key{std::bit_cast<std::uint32_t>(m.baseColor.x), std::bit_cast<std::uint32_t>(m.baseColor.y),
                std::bit_cast<std::uint32_t>(m.baseColor.z), std::bit_cast<std::uint32_t>(m.metallic),
                std::bit_cast<std::uint32_t>(m.roughness)};
  {
    const std::lock_guard lock(mutex);
    if (const auto it = known.find(key); it != known.end()) return it->second;
  }
  const glm::vec3 albedo = shading::meanAlbedo(glm::vec3(m.baseColor), m.metallic, m.roughness);
  const std::lock_guard lock(mutex);
  known.emplace(key, albedo);
  return albedo;
}

namespace {

std::vector<gpu::GpuMaterial> materialData(const scene::Scene& scene) {
  std::vector<gpu::GpuMaterial> out;
  for (const auto& m : scene.materials)
    out.push_back({.baseColor = m.baseColor,
                   .emission = glm::vec4(m.emission, m.doubleSided ? 1.0f : 0.0f),
                   .params = glm::vec4(m.metallic, m.roughness, m.alphaCutoff,
                                       shading::isGlossy(m.metallic, m.roughness) ? 1.0f : 0.0f),
                   .textures = glm::ivec4(m.baseColorTexture, m.metallicRoughnessTexture, m.emissiveTexture, -1),
                   .meanAlbedo = glm::vec4(materialMeanAlbedo(m), 0.0f)});
  return out;
}

// The kinds of texture (gpu::kTexturesAbsent* bits) that no material of `scene` uses.
std::uint32_t texturesAbsent(const scene::Scene& scene) {
  std::uint32_t absent = gpu::kTexturesAbsentBaseColor | gpu::kTexturesAbsentEmissive;
  for (const auto& m : scene.materials) {
    if (m.baseColorTexture >= 0) absent &= ~gpu::kTexturesAbsentBaseColor;
    if (m.emissiveTexture >= 0) absent &= ~gpu::kTexturesAbsentEmissive;
  }
  return absent;
}

} // namespace

void SceneSpecialisation::addTo(gpu::KernelDesc& desc) const {
  if (traversal != Traversal::Wide) {
    desc.specConstants.push_back({gpu::kSpecConstantBvhLayout, bvhLayoutOf(traversal)});
    desc.specConstants.push_back({gpu::kSpecConstantBinaryLoop, binaryWhileWhile(traversal) ? 1u : 0u});
  }
  if (compactStackVectors != 0) desc.specConstants.push_back({gpu::kSpecConstantCompactStack, compactStackVectors});
  if (texturesAbsent != 0) desc.specConstants.push_back({gpu::kSpecConstantTexturesAbsent, texturesAbsent});
}

void checkTexelLimit(const gpu::Context& context, std::size_t texels, const char* what) {
  if (texels > context.info().maxTexelBufferElements)
    throw DeviceError(fmt::format("the scene's {} need {} texels, more than the device's "
                                  "maxTexelBufferElements ({})", what, texels,
                                  context.info().maxTexelBufferElements));
}

std::vector<gpu::vec4> SceneBuffers::itemTexels(const bvh::Bvh& bvh) {
  traversal_ = requested_.value_or(traversalForDevice(context_->info()));
  if (traversal_ == Traversal::Wide) return bvhTexels(bvh);
  if (auto binary = binaryBvhTexels(bvh)) return *std::move(binary);
  const std::string why = fmt::format("the scene's binary BVH is deeper than the {}-entry stack of the binary traversal",
                                      gpu::kBinaryStackSize);
  if (requested_) throw DeviceError(fmt::format("--traversal {}: {}", traversalName(*requested_), why));
  notes_.push_back(why + ": the wide layout is traversed instead");
  traversal_ = Traversal::Wide;
  return bvhTexels(bvh);
}

SceneBuffers::SceneBuffers(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                           std::optional<Traversal> traversal)
    : context_(&context), requested_(traversal ? traversal : parseTraversal(context.traversalRequest())),
      compactStackVectors_(bvh::compactStackVectors(bvh)),
      texturesAbsent_(texturesAbsent(scene)) {
  auto items = itemTexels(bvh);
  checkTexelLimit(context, items.size(), "BVH nodes and triangles");
  items_ = gpu::TexelBuffer(context, items.data(), items.size() * sizeof(gpu::vec4), "scene.bvhItems",
                            vk::BufferUsageFlagBits::eStorageBuffer);

  shading_ = tableTexels(context, shadingData(scene, reflectors_), "triangles' shading data", "scene.shading");
  materials_ = tableTexels(context, materialData(scene), "materials", "scene.materials");

  std::vector<scene::Texture> fitted =
      fitTextures(scene.textures, context.info().maxStorageBufferRange, notes_);
  std::vector<gpu::GpuTexture> textureTable;
  std::size_t texelCount = 0;
  for (const auto& t : fitted) {
    textureTable.push_back({.info = glm::uvec4(static_cast<std::uint32_t>(texelCount), t.width, t.height,
                                               t.srgb ? gpu::kTextureSrgb : 0u)});
    texelCount += static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height);
  }
  if (textureTable.empty()) textureTable.emplace_back(); // Vulkan buffers cannot be empty
  textures_ = gpu::TexelBuffer(context, textureTable.size() * sizeof(gpu::GpuTexture), vk::Format::eR32G32B32A32Uint,
                               {}, "scene.textures");
  textures_.upload(context, textureTable.data(), textureTable.size() * sizeof(gpu::GpuTexture));
  checkTexelLimit(context, texelCount, "textures");
  texels_ = gpu::TexelBuffer(context, std::max<std::size_t>(texelCount, 1) * 4, vk::Format::eR8G8B8A8Unorm, {},
                             "scene.texels");
  std::size_t offset = 0;
  for (const auto& t : fitted) {
    texels_.upload(context, t.rgba8.data(), t.rgba8.size(), offset);
    offset += t.rgba8.size();
  }

  status_ = StatusCounters(context, "scene.status");
  bytes_ = items_.buffer().size() + shading_.buffer().size() + materials_.buffer().size() +
           textures_.buffer().size() + texels_.buffer().size() + status_.buffer().size();
}

void SceneBuffers::setSecondaryReflectors(const scene::Scene& scene, std::vector<std::uint8_t> marked) {
  reflectors_ = std::move(marked);
  auto shading = shadingData(scene, reflectors_);
  shading_.upload(*context_, shading.data(), shading.size() * sizeof(gpu::TriangleShading));
}

bool SceneBuffers::updateGeometry(const scene::Scene& scene, const bvh::Bvh& bvh) {
  auto items = itemTexels(bvh);
  auto shading = shadingData(scene, reflectors_);
  const std::size_t itemBytes = items.size() * sizeof(gpu::vec4);
  const std::size_t shadingBytes = shading.size() * sizeof(gpu::TriangleShading);
  compactStackVectors_ = bvh::compactStackVectors(bvh);
  if (itemBytes == items_.buffer().size() && shadingBytes == shading_.buffer().size()) {
    items_.upload(*context_, items.data(), itemBytes);
    shading_.upload(*context_, shading.data(), shadingBytes);
    return false;
  }
  checkTexelLimit(*context_, items.size(), "BVH nodes and triangles");
  bytes_ -= items_.buffer().size() + shading_.buffer().size();
  items_ =
      gpu::TexelBuffer(*context_, items.data(), itemBytes, "scene.bvhItems", vk::BufferUsageFlagBits::eStorageBuffer);
  shading_ = tableTexels(*context_, shading, "triangles' shading data", "scene.shading");
  bytes_ += items_.buffer().size() + shading_.buffer().size();
  return true;
}

bool SceneBuffers::updateMaterials(const scene::Scene& scene) {
  texturesAbsent_ = texturesAbsent(scene);
  const std::vector<gpu::GpuMaterial> table = materialData(scene);
  const std::size_t bytes = table.size() * sizeof(gpu::GpuMaterial);
  if (bytes == materials_.buffer().size()) {
    materials_.upload(*context_, table.data(), bytes);
    return false;
  }
  bytes_ -= materials_.buffer().size();
  materials_ = tableTexels(*context_, table, "materials", "scene.materials");
  bytes_ += materials_.buffer().size();
  return true;
}

void SceneBuffers::bindTo(gpu::Kernel& kernel, std::uint32_t set, const gpu::Buffer* status) const {
  const std::uint32_t kernelVectors = kernel.specConstant(gpu::kSpecConstantCompactStack);
  if (!bvh::compactStackHolds(kernelVectors, compactStackVectors_))
    throw std::logic_error(fmt::format("kernel '{}' is specialised for a compact traversal stack of {} vectors, "
                                       "which this scene's BVH could overflow (it needs {})",
                                       kernel.name(), kernelVectors,
                                       compactStackVectors_ == 0 ? "the general stack"
                                                                 : std::to_string(compactStackVectors_)));
  if (kernel.specConstant(gpu::kSpecConstantBvhLayout) != bvhLayoutOf(traversal_))
    throw std::logic_error(fmt::format("kernel '{}' traverses another BVH layout than this scene's ({})", kernel.name(),
                                       traversalName(traversal_)));
  const std::uint32_t kernelAbsent = kernel.specConstant(gpu::kSpecConstantTexturesAbsent);
  if ((kernelAbsent & ~texturesAbsent_) != 0)
    throw std::logic_error(fmt::format("kernel '{}' is specialised for a scene without {} textures, which this "
                                       "scene's materials use", kernel.name(),
                                       (kernelAbsent & ~texturesAbsent_ & gpu::kTexturesAbsentBaseColor) != 0
                                           ? "base-colour" : "emissive"));
  kernel.bind(gpu::kBindingBvhItems, items_, set);
  kernel.bind(gpu::kBindingShading, shading_, set);
  kernel.bind(gpu::kBindingMaterials, materials_, set);
  kernel.bind(gpu::kBindingTextures, textures_, set);
  kernel.bind(gpu::kBindingTexels, texels_, set);
  kernel.bind(gpu::kBindingStatus, status ? *status : status_.buffer(), set);
}

std::uint32_t SceneBuffers::truncatedTraversals() const { return statusWords()[gpu::kStatusTruncated]; }

std::vector<std::uint32_t> SceneBuffers::statusWords() const { return status_.words(); }

void SceneBuffers::resetStatus() { status_.reset(); }

} // namespace obscura::render
