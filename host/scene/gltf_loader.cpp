// gltf_loader.cpp — glTF 2.0 to Scene. tinygltf parses the JSON and loads the buffers; everything
// that reads binary data (accessors, indices, images) is done here with explicit bounds checks,
// because tinygltf trusts counts and offsets.
//
// Every failure is an obscura::InputError "<path>: <element>: <problem>".

// tinygltf and stb_image are single-header libraries: their implementations live in this file
// only. External images are not loaded by tinygltf (TINYGLTF_NO_EXTERNAL_IMAGE) so that a
// missing or corrupt image gets our own message, and images are decoded only when a material
// uses them. stb_image is static so that it cannot clash with another copy in the process.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wtype-limits"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#include <stb/stb_image.h> // Debian installs stb under include/stb
#include <tiny_gltf.h>
#pragma GCC diagnostic pop

#include "scene/gltf_loader.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <optional>
#include <sstream>
#include <thread>
#include <utility>

#include <glm/gtc/quaternion.hpp>

#include "core/error.h"

namespace obscura::scene {
namespace {

constexpr std::uint32_t kNoLightGroup = ~0u;
constexpr int kMaxImageSide = 32768;                      // larger images are not textures
constexpr std::uint64_t kMaxImagePixels = 1ull << 28;     // 1 GiB of RGBA8
constexpr std::uint64_t kMaxVertices = 0xffffffffull;     // vertex indices are uint32

// Extensions whose meaning we implement; any other one in extensionsRequired is rejected,
// and any other one in extensionsUsed is noted (ignoring it only loses appearance).
const std::set<std::string> kSupportedExtensions = {"KHR_lights_punctual",
                                                    "KHR_materials_emissive_strength"};

// ---- Messages -----------------------------------------------------------------------------

std::string indexed(const std::string& array, std::size_t i) {
  return array + "[" + std::to_string(i) + "]";
}

std::string primitiveName(std::size_t mesh, std::size_t primitive) {
  return indexed("meshes", mesh) + "." + indexed("primitives", primitive);
}

// What every conversion step needs: the file (for messages) and the parsed model.
struct Context {
  std::string path;
  std::filesystem::path baseDir;
  const tinygltf::Model& model;
  std::vector<std::string>& warnings;

  [[noreturn]] void fail(const std::string& element, const std::string& problem) const {
    throw InputError(path + ": " + element + ": " + problem);
  }
  void note(const std::string& element, const std::string& what) const {
    warnings.push_back(element + ": " + what);
  }
};

// Checks that an index into one of the model's arrays exists.
template <typename T>
std::size_t checkedIndex(const Context& ctx, int index, const std::vector<T>& array,
                         const std::string& arrayName, const std::string& referrer) {
  if (index < 0 || static_cast<std::size_t>(index) >= array.size()) {
    ctx.fail(referrer, "refers to " + arrayName + "[" + std::to_string(index) + "], but the file has " +
                           std::to_string(array.size()));
  }
  return static_cast<std::size_t>(index);
}

float finiteFloat(const Context& ctx, double value, const std::string& element,
                  const std::string& what) {
  const auto f = static_cast<float>(value);
  if (!std::isfinite(f)) {
    ctx.fail(element, what + " is not a finite float (" + std::to_string(value) + ")");
  }
  return f;
}

// ---- Files --------------------------------------------------------------------------------

bool readFile(const std::filesystem::path& file, std::vector<unsigned char>& bytes) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return false;
  bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return !in.bad();
}

// glTF URIs are percent-encoded ("my%20file.png").
std::string decodeUri(const std::string& uri) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
      out += static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

// ---- Parsing (tinygltf) -------------------------------------------------------------------

// tinygltf hands embedded images (data URIs and bufferViews) to this callback; we keep the
// encoded bytes and decode later, only for images a material uses. For a bufferView image
// tinygltf does not check the view against its buffer, so we do it before reading.
struct ImageCallbackState {
  tinygltf::Model* model = nullptr;
  std::string error; // our own message, reported instead of tinygltf's
};

bool keepEncodedImage(tinygltf::Image* image, const int imageIndex, std::string* err, std::string*,
                      int, int, const unsigned char* bytes, int size, void* user) {
  auto* state = static_cast<ImageCallbackState*>(user);
  if (image->bufferView >= 0) {
    const tinygltf::BufferView& view = state->model->bufferViews.at(static_cast<std::size_t>(image->bufferView));
    const tinygltf::Buffer& buffer = state->model->buffers.at(static_cast<std::size_t>(view.buffer));
    const std::size_t available = buffer.data.size();
    if (view.byteOffset > available || view.byteLength > available - view.byteOffset) {
      state->error = indexed("images", static_cast<std::size_t>(imageIndex)) + ": " +
                     indexed("bufferViews", static_cast<std::size_t>(image->bufferView)) +
                     " (byteOffset " + std::to_string(view.byteOffset) + ", byteLength " +
                     std::to_string(view.byteLength) + ") runs past " +
                     indexed("buffers", static_cast<std::size_t>(view.buffer)) + " (length " +
                     std::to_string(available) + ")";
      if (err) *err += state->error;
      return false;
    }
  }
  if (size < 0 || (size > 0 && bytes == nullptr)) return false;
  image->image.assign(bytes, bytes + size);
  image->as_is = true; // image->image holds the encoded file, not pixels
  return true;
}

// The GLB container, checked before tinygltf sees it: tinygltf 2.7's LoadBinaryFromMemory checks
// the BIN chunk's length against the file without its 8-byte chunk header, so a chunk that claims
// up to 8 bytes more than the file holds is read past the end of the buffer (found by
// tests/fuzz, regression tests/fuzz/regressions/glb_bin_chunk_header_not_counted.glb).
void checkGlbChunks(const std::string& path, const std::vector<unsigned char>& bytes) {
  auto word = [&](std::size_t at) {
    std::uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v; // GLB is little-endian, like every platform we build for
  };
  const auto fail = [&](const std::string& problem) { throw InputError(path + ": GLB: " + problem); };
  if (bytes.size() < 20) fail("the file is shorter than the 20-byte GLB header and JSON chunk header");
  const std::uint64_t length = word(8); // the header's total length
  if (length > bytes.size()) {
    fail("the header's length " + std::to_string(length) + " exceeds the file (" + std::to_string(bytes.size()) + " bytes)");
  }
  const std::uint64_t jsonEnd = 20ull + word(12);
  if (jsonEnd > length) {
    fail("the JSON chunk (" + std::to_string(word(12)) + " bytes) runs past the end (length " + std::to_string(length) + ")");
  }
  if (jsonEnd == length) return; // no BIN chunk
  if (jsonEnd + 8 > length) fail("truncated chunk header after the JSON chunk");
  const std::uint64_t binEnd = jsonEnd + 8 + word(static_cast<std::size_t>(jsonEnd));
  if (binEnd > length) {
    fail("the BIN chunk (" + std::to_string(word(static_cast<std::size_t>(jsonEnd))) + " bytes at offset " +
         std::to_string(jsonEnd + 8) + ") runs past the end (length " + std::to_string(length) + ")");
  }
}

tinygltf::Model parseModel(const std::string& path, std::vector<std::string>& warnings) {
  std::vector<unsigned char> bytes;
  if (!readFile(path, bytes)) {
    throw InputError(path + ": file: cannot open or read the file");
  }
  if (bytes.size() > std::numeric_limits<unsigned int>::max()) {
    throw InputError(path + ": file: larger than 4 GiB, which glTF does not allow");
  }
  const std::string baseDir = std::filesystem::path(path).parent_path().string();
  tinygltf::Model model;
  tinygltf::TinyGLTF parser;
  ImageCallbackState imageState;
  imageState.model = &model;
  parser.SetImageLoader(&keepEncodedImage, &imageState);

  std::string err, warn;
  bool ok = false;
  const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  if (binary) checkGlbChunks(path, bytes);
  try {
    const auto size = static_cast<unsigned int>(bytes.size());
    ok = binary ? parser.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), size, baseDir)
                : parser.LoadASCIIFromString(&model, &err, &warn,
                                             reinterpret_cast<const char*>(bytes.data()), size,
                                             baseDir);
  } catch (const std::exception& e) { // tinygltf and nlohmann json may throw on odd input
    throw InputError(path + ": tinygltf: " + e.what());
  }
  if (!imageState.error.empty()) throw InputError(path + ": " + imageState.error);
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    std::replace(err.begin(), err.end(), '\n', ';');
    throw InputError(path + ": tinygltf: " + (err.empty() ? "cannot parse the file" : err));
  }
  std::istringstream lines(warn);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty()) warnings.push_back("tinygltf: " + line);
  }
  return model;
}

// ---- Accessors ----------------------------------------------------------------------------

// A bounds-checked view of one accessor. The constructor proves that every element lies inside
// the accessor's bufferView and the bufferView inside its buffer; element reads are then safe.
class AccessorReader {
public:
  AccessorReader(const Context& ctx, int accessorIndex, const std::string& usage,
                 int expectedType, std::initializer_list<int> allowedComponentTypes)
      : ctx_(ctx) {
    const std::size_t index = checkedIndex(ctx, accessorIndex, ctx.model.accessors, "accessors", usage);
    element_ = indexed("accessors", index) + " (" + usage + ")";
    const tinygltf::Accessor& accessor = ctx.model.accessors[index];
    if (accessor.sparse.isSparse) ctx.fail(element_, "sparse accessors are not supported");
    if (accessor.type != expectedType) {
      ctx.fail(element_, "type " + std::to_string(accessor.type) + " where " +
                             std::to_string(expectedType) + " (tinygltf type code) is required");
    }
    if (std::find(allowedComponentTypes.begin(), allowedComponentTypes.end(),
                  accessor.componentType) == allowedComponentTypes.end()) {
      ctx.fail(element_, "componentType " + std::to_string(accessor.componentType) +
                             " is not supported here");
    }
    componentType_ = accessor.componentType;
    components_ = static_cast<std::size_t>(tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(accessor.type)));
    componentSize_ = static_cast<std::size_t>(tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(accessor.componentType)));
    count_ = accessor.count;
    if (accessor.bufferView < 0) {
      // glTF means "all zeros" here; only sparse accessors use that, and we support neither.
      ctx.fail(element_, "has no bufferView (all-zero accessors are not supported)");
    }
    locate(accessor);
  }

  std::size_t count() const { return count_; }
  const std::string& element() const { return element_; }

  float component(std::size_t i, std::size_t c) const {
    const unsigned char* p = data_ + i * stride_ + c * componentSize_;
    switch (componentType_) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, p, 4); return f; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return static_cast<float>(*p) / 255.0f;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t u; std::memcpy(&u, p, 2); return static_cast<float>(u) / 65535.0f;
    }
    default: return 0.0f; // the constructor admits no other type for float reads
    }
  }
  glm::vec3 vec3(std::size_t i) const { return {component(i, 0), component(i, 1), component(i, 2)}; }
  glm::vec2 vec2(std::size_t i) const { return {component(i, 0), component(i, 1)}; }

  std::uint32_t index(std::size_t i) const {
    const unsigned char* p = data_ + i * stride_;
    switch (componentType_) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return *p;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { std::uint16_t u; std::memcpy(&u, p, 2); return u; }
    default: { std::uint32_t u; std::memcpy(&u, p, 4); return u; }
    }
  }

private:
  // Finds the first element and the stride, checking bufferView and accessor ranges without
  // ever multiplying a count from the file (which could overflow).
  void locate(const tinygltf::Accessor& accessor) {
    const tinygltf::Model& m = ctx_.model;
    const std::size_t viewIndex = checkedIndex(ctx_, accessor.bufferView, m.bufferViews, "bufferViews", element_);
    const tinygltf::BufferView& view = m.bufferViews[viewIndex];
    const std::string viewName = indexed("bufferViews", viewIndex);
    const std::size_t bufferIndex = checkedIndex(ctx_, view.buffer, m.buffers, "buffers", viewName);
    const std::size_t bufferLength = m.buffers[bufferIndex].data.size();
    if (view.byteOffset > bufferLength || view.byteLength > bufferLength - view.byteOffset) {
      ctx_.fail(viewName, "byteOffset " + std::to_string(view.byteOffset) + " + byteLength " +
                              std::to_string(view.byteLength) + " runs past " +
                              indexed("buffers", bufferIndex) + " (length " +
                              std::to_string(bufferLength) + ")");
    }
    const std::size_t elementSize = components_ * componentSize_;
    stride_ = view.byteStride != 0 ? view.byteStride : elementSize;
    if (stride_ < elementSize) {
      ctx_.fail(element_, viewName + " byteStride " + std::to_string(stride_) +
                              " is smaller than one element (" + std::to_string(elementSize) + " bytes)");
    }
    const std::size_t viewLength = view.byteLength;
    const bool fits = count_ == 0 ||
                      (accessor.byteOffset <= viewLength && elementSize <= viewLength - accessor.byteOffset &&
                       count_ - 1 <= (viewLength - accessor.byteOffset - elementSize) / stride_);
    if (!fits) {
      ctx_.fail(element_, "byteOffset " + std::to_string(accessor.byteOffset) + " + " +
                              std::to_string(count_) + " elements x " + std::to_string(stride_) +
                              " bytes runs past " + viewName + " (length " +
                              std::to_string(viewLength) + ")");
    }
    data_ = m.buffers[bufferIndex].data.data() + view.byteOffset + accessor.byteOffset;
  }

  const Context& ctx_;
  std::string element_;
  const unsigned char* data_ = nullptr;
  std::size_t stride_ = 0, count_ = 0, components_ = 0, componentSize_ = 0;
  int componentType_ = 0;
};

// ---- Materials and textures ---------------------------------------------------------------

// One Texture per glTF image that a material uses, decoded after all materials are read.
class TextureTable {
public:
  explicit TextureTable(const Context& ctx) : ctx_(ctx) {}

  // Returns the Scene::textures index for a material's texture reference.
  int use(const tinygltf::TextureInfo& info, bool srgb, const std::string& element) {
    if (info.index < 0) return -1;
    const tinygltf::Model& m = ctx_.model;
    const std::size_t t = checkedIndex(ctx_, info.index, m.textures, "textures", element);
    const int source = m.textures[t].source;
    if (source < 0) {
      ctx_.fail(indexed("textures", t), "has no source image (only PNG/JPEG sources are supported)");
    }
    const std::size_t image = checkedIndex(ctx_, source, m.images, "images", indexed("textures", t));
    if (info.texCoord != 0) ctx_.note(element, "texCoord " + std::to_string(info.texCoord) + " ignored, TEXCOORD_0 used");
    if (info.extensions.count("KHR_texture_transform")) ctx_.note(element, "KHR_texture_transform ignored");
    auto [it, added] = imageToTexture_.try_emplace(image, static_cast<int>(images_.size()));
    if (added) {
      images_.push_back(image);
      srgb_.push_back(srgb);
    } else if (srgb_[static_cast<std::size_t>(it->second)] != srgb) {
      ctx_.note(indexed("images", image), "used as both colour (sRGB) and data (linear); treated as sRGB");
      srgb_[static_cast<std::size_t>(it->second)] = true;
    }
    return it->second;
  }

  // Decodes every used image to RGBA8, in parallel (JPEG decoding dominates load time).
  std::vector<Texture> decodeAll() const {
    std::vector<Texture> textures(images_.size());
    std::vector<std::exception_ptr> errors(images_.size());
    std::atomic<std::size_t> next{0};
    auto worker = [&] {
      for (std::size_t i; (i = next++) < images_.size();) {
        try {
          textures[i] = decode(images_[i]);
          textures[i].srgb = srgb_[i];
        } catch (...) {
          errors[i] = std::current_exception();
        }
      }
    };
    const std::size_t threadCount =
        std::min<std::size_t>(images_.size(), std::max(1u, std::thread::hardware_concurrency()));
    std::vector<std::thread> threads;
    for (std::size_t t = 1; t < threadCount; ++t) threads.emplace_back(worker);
    worker();
    for (auto& thread : threads) thread.join();
    for (const auto& error : errors) {
      if (error) std::rethrow_exception(error); // the first failing image in material order
    }
    return textures;
  }

private:
  Texture decode(std::size_t imageIndex) const {
    const tinygltf::Image& image = ctx_.model.images[imageIndex];
    Texture texture;
    std::string element = indexed("images", imageIndex);
    std::vector<unsigned char> fileBytes;
    const std::vector<unsigned char>* encoded = &image.image;
    std::string source;
    if (image.as_is) { // embedded: data URI or bufferView, kept by keepEncodedImage
      texture.name = indexed("image", imageIndex); // scene.h's name for embedded images
      source = "embedded data";
    } else {
      const std::filesystem::path file = ctx_.baseDir / decodeUri(image.uri);
      element += " (uri \"" + image.uri + "\")";
      texture.name = file.filename().string();
      source = file.string();
      if (!readFile(file, fileBytes)) ctx_.fail(element, "cannot read image file " + source);
      encoded = &fileBytes;
    }
    if (encoded->empty() || encoded->size() > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
      ctx_.fail(element, "image " + source + " is empty or too large");
    }
    const int length = static_cast<int>(encoded->size());
    int width = 0, height = 0, channels = 0;
    if (!stbi_info_from_memory(encoded->data(), length, &width, &height, &channels)) {
      ctx_.fail(element, "cannot decode image " + source + " (" + stbi_failure_reason() + ")");
    }
    if (width <= 0 || height <= 0 || width > kMaxImageSide || height > kMaxImageSide ||
        static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) > kMaxImagePixels) {
      ctx_.fail(element, "image " + source + " has unsupported size " + std::to_string(width) + "x" +
                             std::to_string(height));
    }
    unsigned char* pixels = stbi_load_from_memory(encoded->data(), length, &width, &height, &channels, 4);
    if (pixels == nullptr) {
      ctx_.fail(element, "cannot decode image " + source + " (" + stbi_failure_reason() + ")");
    }
    texture.width = width;
    texture.height = height;
    texture.rgba8.assign(pixels, pixels + static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4);
    stbi_image_free(pixels);
    return texture;
  }

  const Context& ctx_;
  std::map<std::size_t, int> imageToTexture_;
  std::vector<std::size_t> images_; // glTF image index per Scene texture
  std::vector<bool> srgb_;
};

float emissiveStrength(const Context& ctx, const tinygltf::Material& material, const std::string& element) {
  const auto it = material.extensions.find("KHR_materials_emissive_strength");
  if (it == material.extensions.end() || !it->second.IsObject() || !it->second.Has("emissiveStrength")) {
    return 1.0f;
  }
  const tinygltf::Value& value = it->second.Get("emissiveStrength");
  if (!value.IsNumber()) ctx.fail(element, "emissiveStrength is not a number");
  const float strength = finiteFloat(ctx, value.GetNumberAsDouble(), element, "emissiveStrength");
  if (strength < 0.0f) ctx.fail(element, "emissiveStrength is negative");
  return strength;
}

Material convertMaterial(const Context& ctx, std::size_t index, TextureTable& textures) {
  const tinygltf::Material& in = ctx.model.materials[index];
  const std::string element = indexed("materials", index);
  const tinygltf::PbrMetallicRoughness& pbr = in.pbrMetallicRoughness;
  Material out;
  out.name = in.name.empty() ? element : in.name;
  if (!pbr.baseColorFactor.empty()) {
    if (pbr.baseColorFactor.size() != 4) ctx.fail(element, "baseColorFactor must have 4 numbers");
    for (int c = 0; c < 4; ++c) {
      out.baseColor[c] = finiteFloat(ctx, pbr.baseColorFactor[static_cast<std::size_t>(c)], element, "baseColorFactor");
    }
  }
  out.metallic = std::clamp(finiteFloat(ctx, pbr.metallicFactor, element, "metallicFactor"), 0.0f, 1.0f);
  out.roughness = std::clamp(finiteFloat(ctx, pbr.roughnessFactor, element, "roughnessFactor"), 0.0f, 1.0f);
  out.baseColorTexture = textures.use(pbr.baseColorTexture, true, element + ".baseColorTexture");
  out.metallicRoughnessTexture =
      textures.use(pbr.metallicRoughnessTexture, false, element + ".metallicRoughnessTexture");

  const float strength = emissiveStrength(ctx, in, element);
  if (in.emissiveFactor.size() == 3) { // tinygltf rejects any other length
    for (int c = 0; c < 3; ++c) {
      const float factor = finiteFloat(ctx, in.emissiveFactor[static_cast<std::size_t>(c)], element, "emissiveFactor");
      out.emission[c] = std::max(0.0f, factor) * strength;
    }
  }
  out.emissiveTexture = textures.use(in.emissiveTexture, true, element + ".emissiveTexture");
  out.doubleSided = in.doubleSided;
  if (in.alphaMode == "MASK") {
    out.alphaCutoff = std::max(0.0f, finiteFloat(ctx, in.alphaCutoff, element, "alphaCutoff"));
  } else if (in.alphaMode == "BLEND") {
    ctx.note(element, "alphaMode BLEND treated as OPAQUE");
  }
  return out;
}

// ---- Node hierarchy -----------------------------------------------------------------------

struct NodeInstance {
  std::size_t node;
  glm::dmat4 world;
};

glm::dmat4 localTransform(const Context& ctx, std::size_t index) {
  const tinygltf::Node& node = ctx.model.nodes[index];
  const std::string element = indexed("nodes", index);
  auto number = [&](double v, const char* what) -> double {
    if (!std::isfinite(v)) ctx.fail(element, std::string(what) + " is not finite");
    return v;
  };
  if (!node.matrix.empty()) {
    if (node.matrix.size() != 16) ctx.fail(element, "matrix must have 16 numbers");
    glm::dmat4 m(1.0);
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 4; ++r) m[c][r] = number(node.matrix[static_cast<std::size_t>(c * 4 + r)], "matrix"); // column-major
    }
    return m;
  }
  glm::dvec3 t(0.0), s(1.0);
  glm::dquat q(1.0, 0.0, 0.0, 0.0); // (w, x, y, z)
  if (!node.translation.empty()) {
    if (node.translation.size() != 3) ctx.fail(element, "translation must have 3 numbers");
    for (int i = 0; i < 3; ++i) t[i] = number(node.translation[static_cast<std::size_t>(i)], "translation");
  }
  if (!node.scale.empty()) {
    if (node.scale.size() != 3) ctx.fail(element, "scale must have 3 numbers");
    for (int i = 0; i < 3; ++i) s[i] = number(node.scale[static_cast<std::size_t>(i)], "scale");
  }
  if (!node.rotation.empty()) {
    if (node.rotation.size() != 4) ctx.fail(element, "rotation must have 4 numbers (x, y, z, w)");
    const auto& r = node.rotation;
    q = glm::dquat(number(r[3], "rotation"), number(r[0], "rotation"), number(r[1], "rotation"),
                   number(r[2], "rotation"));
    const double length = glm::length(q);
    if (!(length > 0.0)) ctx.fail(element, "rotation is a zero quaternion");
    q /= length; // glTF requires unit quaternions; exporters round
  }
  const glm::dmat3 rs = glm::mat3_cast(q) * glm::dmat3(glm::dvec3(s.x, 0, 0), glm::dvec3(0, s.y, 0), glm::dvec3(0, 0, s.z));
  glm::dmat4 m(rs);
  m[3] = glm::dvec4(t, 1.0);
  return m;
}

// The default scene's nodes in depth-first pre-order with world transforms. Iterative, so a
// deep hierarchy cannot overflow the stack; a node reached twice (a cycle or a shared child,
// both invalid glTF) is an error, which also bounds the work by the node count.
std::vector<NodeInstance> flattenHierarchy(const Context& ctx) {
  const tinygltf::Model& m = ctx.model;
  if (m.scenes.empty()) ctx.fail("scenes", "the file defines no scene");
  const int sceneIndex = m.defaultScene < 0 ? 0 : m.defaultScene;
  const std::size_t scene = checkedIndex(ctx, sceneIndex, m.scenes, "scenes", "scene");
  std::vector<bool> reached(m.nodes.size(), false);
  std::vector<NodeInstance> order;
  std::vector<std::pair<int, glm::dmat4>> stack; // (node, parent world)
  const std::vector<int>& roots = m.scenes[scene].nodes;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(*it, glm::dmat4(1.0));
  while (!stack.empty()) {
    const auto [nodeIndex, parent] = stack.back();
    stack.pop_back();
    const std::size_t node = checkedIndex(ctx, nodeIndex, m.nodes, "nodes", indexed("scenes", scene));
    if (reached[node]) ctx.fail(indexed("nodes", node), "is reached twice in the hierarchy (cycle or shared child)");
    reached[node] = true;
    const glm::dmat4 world = parent * localTransform(ctx, node);
    order.push_back({node, world});
    const std::vector<int>& children = m.nodes[node].children;
    for (auto it = children.rbegin(); it != children.rend(); ++it) stack.emplace_back(*it, world);
  }
  return order;
}

// ---- Geometry -----------------------------------------------------------------------------

// Node-level data shared by all primitives of one mesh instance.
struct MeshInstance {
  std::size_t node;
  glm::dmat4 world;
  glm::dmat3 normalMatrix; // inverse transpose of the linear part, up to a positive scale
  bool flipWinding;        // det < 0: a mirror turns counter-clockwise into clockwise
  std::uint32_t* lightGroup; // index into Scene::lightGroups, created on first emissive triangle
};

// Inverse transpose up to the factor 1/|det|: the cofactor matrix times sign(det). It needs no
// division, so a singular transform (scale 0) gives finite normals and only degenerate triangles.
glm::dmat3 normalMatrixOf(const glm::dmat3& m, double det) {
  glm::dmat3 cofactor(glm::cross(m[1], m[2]), glm::cross(m[2], m[0]), glm::cross(m[0], m[1]));
  return det < 0.0 ? -cofactor : cofactor;
}

class PrimitiveBuilder {
public:
  PrimitiveBuilder(const Context& ctx, Scene& scene, const MeshInstance& instance,
                   std::size_t mesh, std::size_t primitive)
      : ctx_(ctx), scene_(scene), instance_(instance),
        prim_(ctx.model.meshes[mesh].primitives[primitive]), name_(primitiveName(mesh, primitive)) {}

  void build() {
    if (prim_.mode != TINYGLTF_MODE_TRIANGLES) {
      ctx_.fail(name_, "primitive mode " + std::to_string(prim_.mode) + " (" + modeName(prim_.mode) +
                           ") is not supported, only TRIANGLES (4)");
    }
    const std::uint32_t material = materialIndex();
    readPositions();
    readTriangles();
    if (kept_.empty()) return;
    emitVertices();
    emitTriangles(material);
  }

private:
  static const char* modeName(int mode) {
    switch (mode) {
    case 0: return "POINTS"; case 1: return "LINES"; case 2: return "LINE_LOOP";
    case 3: return "LINE_STRIP"; case 5: return "TRIANGLE_STRIP"; case 6: return "TRIANGLE_FAN";
    default: return "unknown";
    }
  }

  int attribute(const char* name) const {
    const auto it = prim_.attributes.find(name);
    return it == prim_.attributes.end() ? -1 : it->second;
  }

  std::uint32_t materialIndex() {
    if (prim_.material < 0) return defaultMaterial();
    return static_cast<std::uint32_t>(checkedIndex(ctx_, prim_.material, ctx_.model.materials, "materials", name_));
  }

  // glTF's default material, appended once after the file's materials.
  std::uint32_t defaultMaterial() {
    const std::size_t fileMaterials = ctx_.model.materials.size();
    if (scene_.materials.size() == fileMaterials) {
      Material fallback;
      fallback.name = "default";
      scene_.materials.push_back(fallback);
      ctx_.note(name_, "has no material; the glTF default material (white, metallic 1, roughness 1) is used");
    }
    return static_cast<std::uint32_t>(fileMaterials);
  }

  void readPositions() {
    const int index = attribute("POSITION");
    if (index < 0) ctx_.fail(name_, "has no POSITION attribute");
    AccessorReader reader(ctx_, index, name_ + ".POSITION", TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT});
    world_.resize(reader.count());
    for (std::size_t i = 0; i < reader.count(); ++i) {
      const glm::vec3 p = reader.vec3(i);
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        ctx_.fail(reader.element(), "element " + std::to_string(i) + " is not finite (" + std::to_string(p.x) +
                                        ", " + std::to_string(p.y) + ", " + std::to_string(p.z) + ")");
      }
      const glm::dvec3 w = glm::dvec3(instance_.world * glm::dvec4(glm::dvec3(p), 1.0));
      world_[i] = glm::vec3(w);
      if (!std::isfinite(world_[i].x) || !std::isfinite(world_[i].y) || !std::isfinite(world_[i].z)) {
        ctx_.fail(indexed("nodes", instance_.node), "transform takes vertex " + std::to_string(i) + " of " +
                                                        name_ + " out of float range");
      }
    }
  }

  // Reads the triangle list (indexed or not), checks indices, fixes winding, drops degenerates.
  void readTriangles() {
    std::size_t indexCount = world_.size();
    std::optional<AccessorReader> indices;
    if (prim_.indices >= 0) {
      indices.emplace(ctx_, prim_.indices, name_ + ".indices", TINYGLTF_TYPE_SCALAR,
                      std::initializer_list<int>{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                                 TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                                 TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT});
      indexCount = indices->count();
    }
    if (indexCount % 3 != 0) {
      ctx_.fail(name_, std::to_string(indexCount) + " vertex indices is not a multiple of 3");
    }
    kept_.reserve(indexCount / 3);
    for (std::size_t t = 0; t < indexCount / 3; ++t) {
      glm::uvec3 tri;
      for (int k = 0; k < 3; ++k) {
        const std::size_t at = 3 * t + static_cast<std::size_t>(k);
        const std::uint32_t v = indices ? indices->index(at) : static_cast<std::uint32_t>(at);
        if (v >= world_.size()) {
          ctx_.fail(name_, "index " + std::to_string(v) + " at position " + std::to_string(at) + " of " +
                               (indices ? indices->element() : std::string("POSITION")) + " is out of range (POSITION has " +
                               std::to_string(world_.size()) + " vertices)");
        }
        tri[k] = v;
      }
      if (instance_.flipWinding) std::swap(tri.y, tri.z);
      // Exact test in double: only truly zero-area triangles go, tiny ones are kept.
      const glm::dvec3 a(world_[tri.x]), b(world_[tri.y]), c(world_[tri.z]);
      if (glm::cross(b - a, c - a) == glm::dvec3(0.0)) {
        ++scene_.stats.degenerateTrianglesDropped;
        continue;
      }
      kept_.push_back(tri);
    }
  }

  // Appends the vertices that kept triangles use, in first-use order, with normals and UVs.
  void emitVertices() {
    remap_.assign(world_.size(), kNoLightGroup);
    const std::size_t base = scene_.positions.size();
    std::size_t used = 0;
    for (const glm::uvec3& tri : kept_) {
      for (int k = 0; k < 3; ++k) {
        if (remap_[tri[k]] == kNoLightGroup) remap_[tri[k]] = static_cast<std::uint32_t>(used++);
      }
    }
    if (base + used > kMaxVertices) ctx_.fail(name_, "the scene has more than 2^32 - 1 vertices");
    std::vector<std::uint32_t> source(used); // primitive vertex per emitted vertex
    for (std::size_t v = 0; v < remap_.size(); ++v) {
      if (remap_[v] != kNoLightGroup) source[remap_[v]] = static_cast<std::uint32_t>(v);
    }
    for (std::uint32_t v : source) {
      scene_.positions.push_back(world_[v]);
      scene_.bounds.grow(world_[v]);
    }
    appendNormals(source);
    appendUvs(source);
    for (std::uint32_t& r : remap_) {
      if (r != kNoLightGroup) r += static_cast<std::uint32_t>(base);
    }
  }

  // Area-weighted vertex normals of the kept (world-space, winding-fixed) triangles.
  std::vector<glm::dvec3> computedNormals() const {
    std::vector<glm::dvec3> sum(world_.size(), glm::dvec3(0.0));
    for (const glm::uvec3& tri : kept_) {
      const glm::dvec3 a(world_[tri.x]), b(world_[tri.y]), c(world_[tri.z]);
      const glm::dvec3 n = glm::cross(b - a, c - a); // length = 2 x area
      for (int k = 0; k < 3; ++k) sum[tri[k]] += n;
    }
    return sum;
  }

  static glm::vec3 unitOr(const glm::dvec3& n, const glm::dvec3& fallback) {
    const double length = glm::length(n);
    if (length > 0.0 && std::isfinite(length)) return glm::vec3(n / length);
    const double fallbackLength = glm::length(fallback);
    if (fallbackLength > 0.0 && std::isfinite(fallbackLength)) return glm::vec3(fallback / fallbackLength);
    return {0.0f, 0.0f, 1.0f}; // unreachable for kept triangles, kept for safety
  }

  void appendNormals(const std::vector<std::uint32_t>& source) {
    const std::vector<glm::dvec3> computed = computedNormals();
    const int index = attribute("NORMAL");
    if (index < 0) {
      ++scene_.stats.normalsComputed;
      for (std::uint32_t v : source) scene_.normals.push_back(unitOr(computed[v], computed[v]));
      return;
    }
    AccessorReader reader(ctx_, index, name_ + ".NORMAL", TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT});
    checkSameCount(reader);
    for (std::uint32_t v : source) {
      const glm::vec3 n = reader.vec3(v);
      const glm::dvec3 transformed = instance_.normalMatrix * glm::dvec3(n);
      const bool valid = std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z) && glm::length(transformed) > 0.0;
      if (!valid) ++scene_.stats.invalidNormalsReplaced;
      scene_.normals.push_back(valid ? unitOr(transformed, computed[v]) : unitOr(computed[v], computed[v]));
    }
  }

  void appendUvs(const std::vector<std::uint32_t>& source) {
    const int index = attribute("TEXCOORD_0");
    if (index < 0) {
      scene_.uvs.insert(scene_.uvs.end(), source.size(), glm::vec2(0.0f));
      return;
    }
    AccessorReader reader(ctx_, index, name_ + ".TEXCOORD_0", TINYGLTF_TYPE_VEC2,
                          {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                           TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
    checkSameCount(reader);
    for (std::uint32_t v : source) {
      glm::vec2 uv = reader.vec2(v);
      if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) uv = glm::vec2(0.0f); // harmless to fix
      scene_.uvs.push_back(uv);
    }
  }

  void checkSameCount(const AccessorReader& reader) const {
    if (reader.count() != world_.size()) {
      ctx_.fail(reader.element(), "has " + std::to_string(reader.count()) + " elements but POSITION has " +
                                      std::to_string(world_.size()));
    }
  }

  void emitTriangles(std::uint32_t material) {
    const bool emissive = glm::any(glm::greaterThan(scene_.materials[material].emission, glm::vec3(0.0f)));
    std::uint32_t group = kNoLightGroup;
    if (emissive) group = lightGroupForNode(material);
    for (const glm::uvec3& tri : kept_) {
      if (group != kNoLightGroup) {
        scene_.lightGroups[group].triangles.push_back(static_cast<std::uint32_t>(scene_.triangles.size()));
      }
      scene_.triangles.emplace_back(remap_[tri.x], remap_[tri.y], remap_[tri.z]);
      scene_.triangleMaterial.push_back(material);
      scene_.triangleLightGroup.push_back(group);
    }
  }

  std::uint32_t lightGroupForNode(std::uint32_t material) {
    if (*instance_.lightGroup == kNoLightGroup) {
      const tinygltf::Node& node = ctx_.model.nodes[instance_.node];
      LightGroup group;
      group.name = node.name.empty() ? "light" + std::to_string(scene_.lightGroups.size()) : node.name;
      group.emission = scene_.materials[material].emission;
      *instance_.lightGroup = static_cast<std::uint32_t>(scene_.lightGroups.size());
      scene_.lightGroups.push_back(std::move(group));
    }
    return *instance_.lightGroup;
  }

  const Context& ctx_;
  Scene& scene_;
  const MeshInstance& instance_;
  const tinygltf::Primitive& prim_;
  std::string name_;
  std::vector<glm::vec3> world_;       // world-space positions of all the primitive's vertices
  std::vector<glm::uvec3> kept_;       // non-degenerate triangles, primitive vertex indices
  std::vector<std::uint32_t> remap_;   // primitive vertex -> Scene vertex (~0u: unused)
};

void appendMesh(const Context& ctx, Scene& scene, const NodeInstance& instance) {
  const tinygltf::Node& node = ctx.model.nodes[instance.node];
  const std::size_t mesh = checkedIndex(ctx, node.mesh, ctx.model.meshes, "meshes", indexed("nodes", instance.node));
  const glm::dmat3 linear(instance.world);
  const double det = glm::determinant(linear);
  std::uint32_t lightGroup = kNoLightGroup;
  const MeshInstance meshInstance{instance.node, instance.world, normalMatrixOf(linear, det), det < 0.0, &lightGroup};
  ++scene.stats.meshNodes;
  const auto first = static_cast<std::uint32_t>(scene.triangles.size());
  const auto& primitives = ctx.model.meshes[mesh].primitives;
  for (std::size_t p = 0; p < primitives.size(); ++p) {
    PrimitiveBuilder(ctx, scene, meshInstance, mesh, p).build();
    ++scene.stats.primitives;
  }
  // The node's primitives were appended together: that range is the object edits name.
  scene.objects.push_back({.name = node.name.empty() ? "object" + std::to_string(scene.objects.size()) : node.name,
                           .firstTriangle = first,
                           .triangleCount = static_cast<std::uint32_t>(scene.triangles.size()) - first,
                           .world = glm::mat4(instance.world)});
}

// ---- Cameras and punctual lights ----------------------------------------------------------

glm::vec3 unitAxis(const Context& ctx, const glm::dvec3& axis, const std::string& element) {
  const double length = glm::length(axis);
  if (!(length > 0.0) || !std::isfinite(length)) ctx.fail(element, "world transform is degenerate (zero scale)");
  return glm::vec3(axis / length);
}

void appendCamera(const Context& ctx, Scene& scene, const NodeInstance& instance) {
  const tinygltf::Node& node = ctx.model.nodes[instance.node];
  const std::string nodeName = indexed("nodes", instance.node);
  const std::size_t index = checkedIndex(ctx, node.camera, ctx.model.cameras, "cameras", nodeName);
  const tinygltf::Camera& in = ctx.model.cameras[index];
  const std::string element = indexed("cameras", index);
  if (in.type != "perspective") {
    ctx.note(element, "camera type \"" + in.type + "\" skipped (only perspective cameras are used)");
    return;
  }
  Camera out;
  out.name = !in.name.empty() ? in.name : !node.name.empty() ? node.name : element;
  out.position = glm::vec3(instance.world[3]);
  out.forward = unitAxis(ctx, -glm::dvec3(instance.world[2]), nodeName);
  const glm::dvec3 f(out.forward);
  const glm::dvec3 y(instance.world[1]);
  out.up = unitAxis(ctx, y - glm::dot(y, f) * f, nodeName); // Gram-Schmidt against forward
  out.yfov = finiteFloat(ctx, in.perspective.yfov, element, "yfov");
  if (!(out.yfov > 0.0f && out.yfov < 3.1415926f)) ctx.fail(element, "yfov must be in (0, pi)");
  out.aspectRatio = std::max(0.0f, finiteFloat(ctx, in.perspective.aspectRatio, element, "aspectRatio"));
  scene.cameras.push_back(out);
}

int lightIndexOf(const Context& ctx, const tinygltf::Node& node, const std::string& element) {
  const auto it = node.extensions.find("KHR_lights_punctual");
  if (it == node.extensions.end()) return -1;
  if (!it->second.IsObject() || !it->second.Has("light") || !it->second.Get("light").IsInt()) {
    ctx.fail(element, "KHR_lights_punctual.light must be an integer");
  }
  return it->second.Get("light").GetNumberAsInt();
}

PunctualType lightType(const Context& ctx, const std::string& type, const std::string& element) {
  if (type == "point") return PunctualType::Point;
  if (type == "spot") return PunctualType::Spot;
  if (type == "directional") return PunctualType::Directional;
  ctx.fail(element, "light type \"" + type + "\" is not point, spot or directional");
}

void appendLight(const Context& ctx, Scene& scene, const NodeInstance& instance, int lightIndex) {
  const std::string nodeName = indexed("nodes", instance.node);
  const std::size_t index = checkedIndex(ctx, lightIndex, ctx.model.lights, "KHR_lights_punctual.lights", nodeName);
  const tinygltf::Light& in = ctx.model.lights[index];
  const std::string element = indexed("KHR_lights_punctual.lights", index);
  PunctualLight out;
  out.name = !in.name.empty() ? in.name : element;
  out.type = lightType(ctx, in.type, element);
  if (!in.color.empty()) {
    if (in.color.size() != 3) ctx.fail(element, "color must have 3 numbers");
    for (int c = 0; c < 3; ++c) out.color[c] = std::max(0.0f, finiteFloat(ctx, in.color[static_cast<std::size_t>(c)], element, "color"));
  }
  out.intensity = std::max(0.0f, finiteFloat(ctx, in.intensity, element, "intensity"));
  out.range = std::max(0.0f, finiteFloat(ctx, in.range, element, "range"));
  out.position = glm::vec3(instance.world[3]);
  out.direction = unitAxis(ctx, -glm::dvec3(instance.world[2]), nodeName);
  if (out.type == PunctualType::Spot) {
    out.innerConeAngle = finiteFloat(ctx, in.spot.innerConeAngle, element, "innerConeAngle");
    out.outerConeAngle = finiteFloat(ctx, in.spot.outerConeAngle, element, "outerConeAngle");
    if (!(out.innerConeAngle >= 0.0f && out.innerConeAngle < out.outerConeAngle && out.outerConeAngle <= 1.5707964f)) {
      ctx.fail(element, "spot cone angles need 0 <= inner < outer <= pi/2");
    }
  }
  scene.punctualLights.push_back(out);
}

// ---- Whole file ---------------------------------------------------------------------------

void checkExtensions(const Context& ctx) {
  for (const std::string& name : ctx.model.extensionsRequired) {
    if (!kSupportedExtensions.count(name)) ctx.fail("extensionsRequired", name + " is not supported");
  }
  for (const std::string& name : ctx.model.extensionsUsed) {
    if (!kSupportedExtensions.count(name)) ctx.note("extensionsUsed", name + " ignored");
  }
}

} // namespace

Scene loadGltf(const std::string& path) {
  Scene scene;
  const tinygltf::Model model = parseModel(path, scene.warnings);
  scene.sourcePath = path;
  const Context ctx{path, std::filesystem::path(path).parent_path(), model, scene.warnings};
  checkExtensions(ctx);

  TextureTable textures(ctx);
  for (std::size_t m = 0; m < model.materials.size(); ++m) scene.materials.push_back(convertMaterial(ctx, m, textures));

  for (const NodeInstance& instance : flattenHierarchy(ctx)) {
    const tinygltf::Node& node = model.nodes[instance.node];
    if (node.mesh >= 0) appendMesh(ctx, scene, instance);
    if (node.camera >= 0) appendCamera(ctx, scene, instance);
    const int light = lightIndexOf(ctx, node, indexed("nodes", instance.node));
    if (light >= 0) appendLight(ctx, scene, instance, light);
  }
  if (scene.materials.empty()) scene.materials.emplace_back().name = "default"; // never empty
  if (scene.cameras.empty()) {
    scene.cameras.push_back(defaultCamera(scene.bounds));
    ctx.note("cameras", "the scene has no perspective camera; the default camera is used");
  }
  // Decoded last: the geometry errors are cheaper to find than decoding every image first.
  scene.textures = textures.decodeAll();
  return scene;
}

} // namespace obscura::scene
