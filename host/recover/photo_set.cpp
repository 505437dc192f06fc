// photo_set.cpp — see photo_set.h.
#include "recover/photo_set.h"

#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/image_io.h"
#include "io/json_fields.h"
#include "io/json_file.h"

namespace obscura::recover {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

int positiveInt(const json& j, const char* key, const std::string& where) {
  if (!j.contains(key) || !j.at(key).is_number_integer() || j.at(key).get<long long>() < 0)
    throw InputError(fmt::format("{}: '{}' must be an integer >= 0", where, key));
  return j.at(key).get<int>();
}

// The R, G, B channels: by name when the image names them, else the first three.
std::array<int, 3> rgbChannels(const io::Image& image, const std::string& path) {
  std::array<int, 3> rgb{image.channelIndex("R"), image.channelIndex("G"), image.channelIndex("B")};
  if (rgb[0] >= 0 && rgb[1] >= 0 && rgb[2] >= 0) return rgb;
  if (image.channelCount() < 3)
    throw InputError(fmt::format("{}: a photograph needs 3 colour channels, this image has {}", path,
                                 image.channelCount()));
  return {0, 1, 2};
}

} // namespace

float srgbToLinear(float encoded) {
  const float c = std::clamp(encoded, 0.0f, 1.0f);
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

std::vector<glm::vec3> readRadiance(const std::string& path, float exposure, int& width, int& height) {
  const io::Image image = io::readImage(path);
  const std::string ext = io::extensionOf(path);
  const bool encoded = ext == "png" || ext == "jpg" || ext == "jpeg";
  if (!encoded && ext != "exr")
    throw InputError(fmt::format("{}: photographs must be EXR (linear) or PNG/JPEG (sRGB)", path));
  const auto rgb = rgbChannels(image, path);
  width = image.width;
  height = image.height;
  std::vector<glm::vec3> out(std::size_t(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      glm::vec3 c;
      for (int k = 0; k < 3; ++k) {
        const float v = image.at(x, y, rgb[k]);
        c[k] = encoded ? srgbToLinear(v) : v;
      }
      if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z) || glm::any(glm::lessThan(c, glm::vec3(0.0f))))
        throw InputError(fmt::format("{}: pixel ({}, {}) is negative or not finite", path, x, y));
      out[std::size_t(y) * width + x] = c * exposure;
    }
  return out;
}

PhotoSet readPhotoSet(const std::string& jsonPath) {
  const json doc = io::readJsonFile(jsonPath, "cannot read the photographs' JSON");
  PhotoSet set;
  set.file = jsonPath;
  if (!doc.is_object()) throw InputError(fmt::format("{}: expected a JSON object", jsonPath));
  if (!doc.contains("camera") || !doc.at("camera").is_object())
    throw InputError(fmt::format("{}: 'camera' (gltf_camera, width, height) is missing", jsonPath));
  const json& camera = doc.at("camera");
  const std::string cameraWhere = jsonPath + ": camera";
  set.gltfCamera = positiveInt(camera, "gltf_camera", cameraWhere);
  set.width = positiveInt(camera, "width", cameraWhere);
  set.height = positiveInt(camera, "height", cameraWhere);
  if (set.width == 0 || set.height == 0) throw InputError(fmt::format("{}: width and height must be > 0", cameraWhere));
  if (camera.contains("yfov")) {
    if (!camera.at("yfov").is_number() || !(camera.at("yfov").get<float>() > 0.0f))
      throw InputError(fmt::format("{}: 'yfov' must be a positive number (radians)", cameraWhere));
    set.yfov = camera.at("yfov").get<float>();
  }
  if (!doc.contains("shots") || !doc.at("shots").is_array() || doc.at("shots").empty())
    throw InputError(fmt::format("{}: 'shots' must be a non-empty list", jsonPath));
  const fs::path folder = fs::path(jsonPath).parent_path();
  const json& shots = doc.at("shots");
  for (std::size_t i = 0; i < shots.size(); ++i) {
    const json& s = shots[i];
    const io::JsonEntry at{jsonPath + ": shots", i};
    if (!s.is_object()) at.fail("expected an object");
    Shot shot;
    const fs::path image = io::jsonText(s, "image", at);
    shot.image = (image.is_absolute() ? image : folder / image).string();
    shot.position = io::jsonVec3(s, "position", at);
    if (s.contains("radius")) shot.radius = io::jsonNumber(s, "radius", at);
    if (shot.radius < 0.0f) at.fail("'radius' must be >= 0");
    // The lamp in glTF KHR_lights_punctual terms: "gltf_light", or its fields on the shot itself.
    const json& lamp = s.contains("gltf_light") ? s.at("gltf_light") : s;
    if (s.contains("gltf_light")) {
      if (!lamp.is_object()) at.fail("'gltf_light' must be an object");
      if (lamp.contains("type") && lamp.at("type") != "point") at.fail("'gltf_light': only point lamps are supported");
    }
    shot.intensity = io::jsonNumber(lamp, "intensity", at);
    if (!(shot.intensity > 0.0f)) at.fail("'intensity' must be > 0");
    if (lamp.contains("color")) shot.color = io::jsonVec3(lamp, "color", at);
    if (glm::any(glm::lessThan(shot.color, glm::vec3(0.0f))) || shot.color == glm::vec3(0.0f))
      at.fail("'color' must be >= 0 and not black");
    if (s.contains("exposure")) shot.exposure = io::jsonNumber(s, "exposure", at);
    if (!(shot.exposure > 0.0f)) at.fail("'exposure' must be > 0");
    int w = 0, h = 0;
    shot.radiance = readRadiance(shot.image, shot.exposure, w, h);
    if (w != set.width || h != set.height)
      throw InputError(fmt::format("{}: the image is {}x{}, but {} gives the camera as {}x{} (and every photo must "
                                   "have that size)",
                                   shot.image, w, h, jsonPath, set.width, set.height));
    set.shots.push_back(std::move(shot));
  }
  return set;
}

} // namespace obscura::recover
