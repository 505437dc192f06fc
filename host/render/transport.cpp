#include "render/transport.h"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "core/error.h"
#include "render/aovs.h"

namespace obscura::render {
namespace {

void putRgb(io::Image& image, std::size_t pixel, std::size_t channel, const glm::vec3& v) {
  for (int c = 0; c < 3; ++c) image.pixels[pixel * image.channels.size() + channel + c] = v[c];
}

int requireChannel(const io::Image& image, const std::string& name, const std::string& file) {
  const int c = image.channelIndex(name);
  if (c < 0) throw InputError(fmt::format("{}: channel '{}' is missing", file, name));
  return c;
}

std::vector<glm::vec3> readRgb(const io::Image& image, const std::string& prefix, const std::string& file) {
  const int r = requireChannel(image, prefix + ".R", file), g = requireChannel(image, prefix + ".G", file),
            b = requireChannel(image, prefix + ".B", file);
  std::vector<glm::vec3> out(std::size_t(image.width) * image.height);
  const std::size_t n = image.channels.size();
  for (std::size_t p = 0; p < out.size(); ++p)
    out[p] = glm::vec3(image.pixels[p * n + r], image.pixels[p * n + g], image.pixels[p * n + b]);
  return out;
}

glm::vec3 indirectIntensity(const std::vector<glm::vec3>& emissions, const std::vector<glm::vec3>& weights) {
  glm::vec3 ia(0.0f);
  for (std::size_t s = 0; s < emissions.size(); ++s) ia += emissions[s] * weights[s];
  return ia;
}

} // namespace

Transport resolveSums(Transport t, const std::vector<std::uint32_t>& counts) {
  if (counts.size() != t.pixels()) throw std::logic_error("resolveSums: one count per pixel");
  for (std::size_t p = 0; p < t.pixels(); ++p) {
    const float inv = 1.0f / static_cast<float>(std::max(counts[p], 1u)); // compose.comp's divisor
    t.ambient[p] *= inv;
    if (t.specular) t.specularAmbient[p] *= inv;
    for (std::size_t l = 0; l < t.lights.size(); ++l) {
      t.direct[l][p] *= inv;
      t.seen[l][p] *= inv;
      if (t.specular) t.specularDirect[l][p] *= inv;
      if (t.hasOwnIndirect()) t.ownIndirect[l][p] *= inv;
    }
  }
  return t;
}

io::Image Transport::toImage() const {
  io::Image image;
  image.width = width;
  image.height = height;
  auto rgb = [&](const std::string& prefix) {
    for (const char* c : {"R", "G", "B"}) image.channels.push_back(prefix + "." + c);
  };
  for (const auto& name : lights) {
    rgb("D." + name);
    rgb("M." + name);
    if (specular) rgb("S." + name);
    if (hasOwnIndirect()) rgb("I." + name);
  }
  rgb("A");
  image.channels.push_back("A.W");
  if (specular) rgb("SA");
  image.pixels.assign(pixels() * image.channels.size(), 0.0f);
  for (std::size_t p = 0; p < pixels(); ++p) {
    std::size_t c = 0;
    for (std::size_t s = 0; s < lights.size(); ++s) {
      putRgb(image, p, c, direct[s][p]);
      putRgb(image, p, c + 3, seen[s][p]);
      c += 6;
      if (specular) {
        putRgb(image, p, c, specularDirect[s][p]);
        c += 3;
      }
      if (hasOwnIndirect()) {
        putRgb(image, p, c, ownIndirect[s][p]);
        c += 3;
      }
    }
    putRgb(image, p, c, glm::vec3(ambient[p]));
    image.pixels[p * image.channels.size() + c + 3] = ambient[p].w;
    if (specular) putRgb(image, p, c + 4, specularAmbient[p]);
  }
  return image;
}

Transport Transport::fromImage(const io::Image& image, const std::vector<std::string>& lights, bool specular,
                               const std::string& file) {
  Transport t;
  t.width = image.width;
  t.height = image.height;
  t.lights = lights;
  t.specular = specular;
  const bool ownIndirect = !lights.empty() && image.channelIndex("I." + lights.front() + ".R") >= 0;
  for (const auto& name : lights) {
    t.direct.push_back(readRgb(image, "D." + name, file));
    t.seen.push_back(readRgb(image, "M." + name, file));
    if (specular) t.specularDirect.push_back(readRgb(image, "S." + name, file));
    if (ownIndirect) t.ownIndirect.push_back(readRgb(image, "I." + name, file));
  }
  const auto a = readRgb(image, "A", file);
  const int w = requireChannel(image, "A.W", file);
  t.ambient.resize(a.size());
  for (std::size_t p = 0; p < a.size(); ++p)
    t.ambient[p] = glm::vec4(a[p], image.pixels[p * image.channels.size() + w]);
  if (specular) t.specularAmbient = readRgb(image, "SA", file);
  return t;
}

io::Image composeTransport(const Transport& t, const std::vector<glm::vec3>& emissions,
                           const std::vector<glm::vec3>& ambientWeights) {
  io::Image image;
  image.width = t.width;
  image.height = t.height;
  for (const char* aov : {"combined", "direct", "indirect", "specular", "obscurance", "emission"})
    for (const auto& c : aovChannels(aov)) image.channels.push_back(c);
  const std::size_t nc = image.channels.size();
  image.pixels.assign(t.pixels() * nc, 0.0f);
  const glm::vec3 ia = indirectIntensity(emissions, ambientWeights);
  for (std::size_t p = 0; p < t.pixels(); ++p) {
    glm::vec3 direct(0.0f), seen(0.0f), specular(0.0f), indirect = ia * glm::vec3(t.ambient[p]);
    for (std::size_t s = 0; s < t.lights.size(); ++s) {
      direct += emissions[s] * t.direct[s][p];
      seen += emissions[s] * t.seen[s][p];
      if (t.specular) specular += emissions[s] * t.specularDirect[s][p];
      if (t.hasOwnIndirect()) indirect += emissions[s] * t.ownIndirect[s][p];
    }
    if (t.specular) specular += ia * t.specularAmbient[p];
    putRgb(image, p, 0, direct + indirect + seen + specular);
    putRgb(image, p, 3, direct);
    putRgb(image, p, 6, indirect);
    putRgb(image, p, 9, specular);
    image.pixels[p * nc + 12] = t.ambient[p].w;
    putRgb(image, p, 13, seen);
  }
  return image;
}

io::Image lightLayers(const Transport& t, const std::vector<glm::vec3>& emissions,
                      const std::vector<glm::vec3>& ambientWeights) {
  io::Image image;
  image.width = t.width;
  image.height = t.height;
  for (const auto& name : t.lights)
    for (const char* c : {"R", "G", "B"}) image.channels.push_back(fmt::format("light.{}.{}", name, c));
  image.pixels.assign(t.pixels() * image.channels.size(), 0.0f);
  for (std::size_t s = 0; s < t.lights.size(); ++s) {
    const glm::vec3 share = emissions[s] * ambientWeights[s];
    for (std::size_t p = 0; p < t.pixels(); ++p) {
      glm::vec3 own = t.direct[s][p] + t.seen[s][p];
      glm::vec3 a = glm::vec3(t.ambient[p]);
      if (t.specular) {
        own += t.specularDirect[s][p];
        a += t.specularAmbient[p];
      }
      if (t.hasOwnIndirect()) own += t.ownIndirect[s][p];
      putRgb(image, p, s * 3, emissions[s] * own + share * a);
    }
  }
  return image;
}

} // namespace obscura::render
