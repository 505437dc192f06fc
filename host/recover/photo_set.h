// photo_set.h — the photographs `obscura recover` reads: one fixed view, one lamp per shot
// [IVR §4.1], described by a JSON file (the format of shared/photos/cornell-box/lights.json):
//
//   { "camera": { "gltf_camera": N, "width": W, "height": H, "yfov": radians (optional) },
//     "shots": [ { "image": "photo-000.exr",              relative to the JSON
//                  "position": [x, y, z],                 world space of the glTF
//                  "radius": r,                           optional, 0 = a point
//                  "gltf_light": { "type": "point", "intensity": I, "color": [r, g, b] },
//                  "exposure": s } ... ] }                optional, default 1
//
// Camera response (the paper's T(C), IVR eq. 2): EXR values are linear radiance in the glTF's
// emission units; PNG and JPEG values are 8-bit sRGB-encoded (decoded with the IEC 61966-2-1
// curve). Either is then multiplied by the shot's `exposure` to give radiance.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace obscura::recover {

struct Shot {
  std::string image;       // the path as read (relative paths resolved against the JSON's folder)
  glm::vec3 position{0.0f};
  float radius = 0.0f;     // the lamp's radius (informative: the lamp is traced as a point, see recover.md)
  float intensity = 0.0f;  // glTF point-light intensity (W/sr in the glTF's units)
  glm::vec3 color{1.0f};
  float exposure = 1.0f;
  std::vector<glm::vec3> radiance; // the photograph, linear radiance, rows top to bottom
};

struct PhotoSet {
  std::string file;        // the JSON, for messages
  int gltfCamera = 0;
  float yfov = -1.0f;      // < 0 when the JSON does not give it
  int width = 0, height = 0;
  std::vector<Shot> shots;
  std::size_t pixels() const { return std::size_t(width) * height; }
};

// Reads the JSON and every photograph. InputError naming the JSON (and the shot and field) for a
// missing or bad field, naming the image for an unreadable image or one whose size is not the
// camera's.
PhotoSet readPhotoSet(const std::string& jsonPath);

// The linear radiance of an image's first three channels (R, G, B by name when present): EXR
// as stored, 8-bit formats sRGB-decoded; times `exposure`.
std::vector<glm::vec3> readRadiance(const std::string& path, float exposure, int& width, int& height);

// The inverse of the sRGB transfer curve (IEC 61966-2-1), for a value in [0, 1].
float srgbToLinear(float encoded);

} // namespace obscura::recover
