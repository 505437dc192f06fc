// scene.h — the scene model: world-space triangles, materials, lights, cameras.
//
// Only what the methods use [SPEC §5]: albedo (factor x texture), metallic/roughness (glossiness),
// emission (x emissive_strength), double-sidedness, punctual lights, perspective cameras.
// Geometry is flattened to world space at load time: the renderer never needs the hierarchy.
#pragma once
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/shared_bytes.h"

namespace obscura::scene {

struct Texture {
  std::string name;            // file name or "image[N]" for embedded data, for messages
  int width = 0, height = 0;
  SharedBytes rgba8;           // width * height * 4 bytes, rows top to bottom (shared by copies)
  bool srgb = false;           // true for base colour and emissive textures (glTF says so)
};

struct Material {
  std::string name;
  glm::vec4 baseColor{1.0f};   // linear RGBA factor
  int baseColorTexture = -1;   // index into Scene::textures, sRGB
  float metallic = 1.0f;       // glTF defaults
  float roughness = 1.0f;
  int metallicRoughnessTexture = -1;
  glm::vec3 emission{0.0f};    // emissiveFactor x KHR_materials_emissive_strength (radiance)
  int emissiveTexture = -1;
  bool doubleSided = false;
  float alphaCutoff = -1.0f;   // >= 0 when alphaMode == MASK, else -1
};

enum class PunctualType : std::uint32_t { Point = 0, Spot = 1, Directional = 2 };

struct PunctualLight {
  std::string name;
  PunctualType type = PunctualType::Point;
  glm::vec3 color{1.0f};
  float intensity = 1.0f;      // candela (point/spot) or lux (directional), as glTF defines
  glm::vec3 position{0.0f};    // world space (point/spot)
  glm::vec3 direction{0.0f, 0.0f, -1.0f}; // world space, unit: the direction light travels
  float range = 0.0f;          // 0 = infinite
  float innerConeAngle = 0.0f, outerConeAngle = 0.7853982f;
};

// A group of emissive triangles edited as one light (relighting's unit). By default one group
// per emissive mesh node.
struct LightGroup {
  std::string name;
  std::vector<std::uint32_t> triangles; // indices into Scene::triangles
  glm::vec3 emission{0.0f};             // the material emission of the group's first triangle
};

// One glTF mesh-node instance, kept through flattening so that edits can name and move it: its
// triangles are Scene::triangles[firstTriangle, firstTriangle + triangleCount), with vertices of
// their own (no vertex is shared with another object).
struct SceneObject {
  std::string name;                  // the node's name, object<N> without one; unique (#2, #3, ...)
  std::uint32_t firstTriangle = 0;
  std::uint32_t triangleCount = 0;
  glm::mat4 world{1.0f};             // the node's world transform at load (or after edits)
  // Removed by an edit (scene_edit.h removeObject): its triangles collapsed to a point, its index
  // kept (triangles and lights are addressed by index), its name no longer an object's.
  bool removed = false;
};

struct Camera {
  std::string name;
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f}; // unit
  glm::vec3 up{0.0f, 1.0f, 0.0f};       // unit, orthogonal to forward
  float yfov = 0.6911f;                 // radians
  float aspectRatio = 0.0f;             // 0 = take it from the image size
};

struct Bounds {
  glm::vec3 lo{std::numeric_limits<float>::max()};
  glm::vec3 hi{-std::numeric_limits<float>::max()};
  void grow(const glm::vec3& p) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
  bool empty() const { return lo.x > hi.x; }
  glm::vec3 extent() const { return empty() ? glm::vec3(0.0f) : hi - lo; }
};

struct LoadStats {
  std::size_t meshNodes = 0;
  std::size_t primitives = 0;
  std::size_t degenerateTrianglesDropped = 0; // zero area (or collapsed indices)
  std::size_t normalsComputed = 0;            // primitives whose normals we generated
  std::size_t invalidNormalsReplaced = 0;     // NaN/zero normals replaced by computed ones
};

// World-space, indexed triangle mesh of the whole scene.
struct Scene {
  std::string sourcePath;
  std::vector<glm::vec3> positions;  // per vertex, world space
  std::vector<glm::vec3> normals;    // per vertex, world space, unit
  std::vector<glm::vec2> uvs;        // per vertex (0,0 when the primitive has no TEXCOORD_0)
  std::vector<glm::uvec3> triangles; // vertex indices
  std::vector<std::uint32_t> triangleMaterial;   // per triangle, index into materials
  std::vector<std::uint32_t> triangleLightGroup; // per triangle, index into lightGroups or ~0u
  std::vector<Material> materials;   // never empty: a default material is appended when needed
  std::vector<Texture> textures;
  std::vector<PunctualLight> punctualLights;
  std::vector<LightGroup> lightGroups;
  std::vector<SceneObject> objects;  // in glTF node order; together they hold every triangle
  std::vector<Camera> cameras;       // in glTF node order
  // Constant radiance of the sky that rays leaving the scene see (`--background`; glTF has none):
  // one more light, "background", whose basis buffer relighting scales like any other.
  glm::vec3 background{0.0f};
  Bounds bounds;
  LoadStats stats;
  std::vector<std::string> warnings; // "<element>: <what was ignored or assumed>", for the log

  std::size_t triangleCount() const { return triangles.size(); }
};

// Makes names unique in the order they are given: a repeated name gets "#2", "#3", ...
class UniqueNames {
public:
  void apply(std::string& name) {
    const int n = ++seen_[name];
    if (n > 1) name.append("#").append(std::to_string(n)); // append: GCC 12 warns on += of a temporary
  }

private:
  std::map<std::string, int> seen_;
};

// The documented default camera when a scene has none: looks down -Z at the centre of the
// bounding box, yfov 45 degrees, from far enough back that the whole box fits in view.
Camera defaultCamera(const Bounds& bounds);

} // namespace obscura::scene
