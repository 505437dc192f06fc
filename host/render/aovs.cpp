#include "render/aovs.h"

#include <algorithm>
#include <bit>

#include <fmt/format.h>

#include "core/error.h"
#include "shared/host_device.h"

namespace obscura::render {

const std::vector<std::string>& aovNames() {
  static const std::vector<std::string> names = {"preview", "albedo", "emission", "normal", "depth",
                                                 "position", "coverage", "primitive", "material"};
  return names;
}

std::vector<std::string> aovChannels(const std::string& aov) {
  if (aov == "normal" || aov == "position") return {aov + ".X", aov + ".Y", aov + ".Z"};
  if (aov == "depth") return {"depth.Z"};
  if (aov == "obscurance") return {"obscurance.Y"};
  if (aov == "coverage") return {"coverage.A"};
  if (aov == "primitive" || aov == "material") return {aov + ".id"};
  return {aov + ".R", aov + ".G", aov + ".B"};
}

io::Image selectAovs(const io::Image& image, const std::vector<std::string>& aovs) {
  if (aovs.empty()) return image;
  io::Image out;
  out.width = image.width;
  out.height = image.height;
  out.attributes = image.attributes;
  std::vector<int> source;
  for (const auto& aov : aovs)
    for (const auto& channel : aovChannels(aov)) {
      const int c = image.channelIndex(channel);
      if (c < 0) throw InputError(fmt::format("--aov {}: the image has no such AOV", aov));
      out.channels.push_back(channel);
      source.push_back(c);
    }
  out.pixels.resize(std::size_t(out.width) * out.height * out.channels.size());
  std::size_t k = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c : source) out.pixels[k++] = image.at(x, y, c);
  return out;
}

// Converts the accumulated AOV slots into image channels.
io::Image resolvePrimaryAovs(const std::vector<glm::vec4>& aov, std::uint32_t width, std::uint32_t height,
                             const std::vector<std::uint32_t>& samples) {
  io::Image image;
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  for (const auto& name : aovNames())
    for (const auto& channel : aovChannels(name)) image.channels.push_back(channel);
  image.pixels.resize(std::size_t(width) * height * image.channels.size());
  std::size_t k = 0;
  for (std::size_t p = 0; p < std::size_t(width) * height; ++p) {
    const float inv = 1.0f / static_cast<float>(std::max(samples[p], 1u));
    // Each accumulator is (sum, compensation): the sum of slot k is at k * kAccumulatorVec4s.
    auto sum = [&](std::uint32_t slot) { return aov[(p * gpu::kAovSlots + slot) * gpu::kAccumulatorVec4s]; };
    const glm::vec4 slot[gpu::kAovSlots] = {sum(0), sum(1), sum(2), sum(3), sum(4), sum(5)};
    glm::vec4 albedo = slot[gpu::kAovAlbedo] * inv;
    glm::vec4 normalDepth = slot[gpu::kAovNormal] * inv;
    glm::vec3 position = glm::vec3(slot[gpu::kAovPosition]) * inv;
    glm::vec3 emission = glm::vec3(slot[gpu::kAovEmission]) * inv;
    float normalLength = glm::length(glm::vec3(normalDepth));
    glm::vec3 normal = normalLength > 0.0f ? glm::vec3(normalDepth) / normalLength : glm::vec3(0.0f);
    glm::vec3 preview = glm::vec3(slot[gpu::kAovPreview]) * inv;
    auto put3 = [&](glm::vec3 v) { image.pixels[k++] = v.x; image.pixels[k++] = v.y; image.pixels[k++] = v.z; };
    put3(preview);
    put3(glm::vec3(albedo));
    put3(emission);
    put3(normal);
    image.pixels[k++] = normalDepth.w;
    put3(position);
    image.pixels[k++] = albedo.w;
    std::uint32_t primitive = std::bit_cast<std::uint32_t>(slot[gpu::kAovIds].x);
    std::uint32_t material = std::bit_cast<std::uint32_t>(slot[gpu::kAovIds].y);
    image.pixels[k++] = primitive == gpu::kInvalidIndex ? -1.0f : static_cast<float>(primitive);
    image.pixels[k++] = material == gpu::kInvalidIndex ? -1.0f : static_cast<float>(material);
  }
  return image;
}

} // namespace obscura::render
