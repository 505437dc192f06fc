#include "scene/scene_edit.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"

namespace obscura::scene {
namespace {

// The vertices the object's triangles use (objects never share vertices).
std::vector<std::uint32_t> objectVertices(const Scene& scene, const SceneObject& o) {
  std::vector<std::uint32_t> vertices;
  for (std::uint32_t t = o.firstTriangle; t < o.firstTriangle + o.triangleCount; ++t)
    for (int k = 0; k < 3; ++k) vertices.push_back(scene.triangles[t][k]);
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  return vertices;
}

void recomputeBounds(Scene& scene) {
  scene.bounds = Bounds();
  for (const auto& t : scene.triangles)
    for (int k = 0; k < 3; ++k) scene.bounds.grow(scene.positions[t[k]]);
}

} // namespace

void makeObjectNamesUnique(Scene& scene) {
  UniqueNames names;
  for (auto& o : scene.objects) names.apply(o.name);
}

std::size_t objectIndex(const Scene& scene, const std::string& name, const std::string& where) {
  for (std::size_t i = 0; i < scene.objects.size(); ++i)
    if (!scene.objects[i].removed && scene.objects[i].name == name) return i;
  std::vector<std::string> names;
  for (const auto& o : scene.objects)
    if (!o.removed) names.push_back(o.name);
  throw InputError(fmt::format("{}: no object named '{}' (objects: {})", where, name, fmt::join(names, ", ")));
}

Bounds objectBounds(const Scene& scene, std::size_t index) {
  Bounds b;
  const SceneObject& o = scene.objects.at(index);
  for (std::uint32_t t = o.firstTriangle; t < o.firstTriangle + o.triangleCount; ++t)
    for (int k = 0; k < 3; ++k) b.grow(scene.positions[scene.triangles[t][k]]);
  return b;
}

void moveObject(Scene& scene, std::size_t index, glm::vec3 translate, glm::vec3 rotateDegrees) {
  SceneObject& o = scene.objects.at(index);
  glm::mat4 rotation(1.0f);
  rotation = glm::rotate(rotation, glm::radians(rotateDegrees.z), glm::vec3(0, 0, 1));
  rotation = glm::rotate(rotation, glm::radians(rotateDegrees.y), glm::vec3(0, 1, 0));
  rotation = glm::rotate(rotation, glm::radians(rotateDegrees.x), glm::vec3(1, 0, 0));
  const glm::vec3 origin(o.world[3]);
  const glm::mat3 r(rotation);
  for (std::uint32_t v : objectVertices(scene, o)) {
    scene.positions[v] = r * (scene.positions[v] - origin) + origin + translate;
    scene.normals[v] = glm::normalize(r * scene.normals[v]);
  }
  o.world = glm::translate(glm::mat4(1.0f), origin + translate) * rotation *
            glm::translate(glm::mat4(1.0f), -origin) * o.world;
  recomputeBounds(scene);
}

void removeObject(Scene& scene, std::size_t index) {
  SceneObject& o = scene.objects.at(index);
  o.removed = true;
  const std::vector<std::uint32_t> vertices = objectVertices(scene, o);
  if (vertices.empty()) return;
  const glm::vec3 point = scene.positions[vertices.front()];
  for (std::uint32_t v : vertices) scene.positions[v] = point; // zero-area triangles: never hit
  recomputeBounds(scene);
}

std::size_t insertObject(Scene& scene, const Scene& other, const std::string& name, glm::vec3 translate) {
  for (const auto& o : scene.objects)
    if (!o.removed && o.name == name) throw InputError(fmt::format("insert '{}': an object of that name exists", name));
  if (!other.lightGroups.empty() || !other.punctualLights.empty())
    throw InputError(fmt::format("insert '{}' from {}: it emits light; add lights with add_light edits", name,
                                 other.sourcePath));
  const auto vertexBase = static_cast<std::uint32_t>(scene.positions.size());
  const auto materialBase = static_cast<std::uint32_t>(scene.materials.size());
  const auto textureBase = static_cast<int>(scene.textures.size());
  for (std::size_t v = 0; v < other.positions.size(); ++v) {
    scene.positions.push_back(other.positions[v] + translate);
    scene.normals.push_back(other.normals[v]);
    scene.uvs.push_back(other.uvs[v]);
  }
  for (Material m : other.materials) {
    for (int* t : {&m.baseColorTexture, &m.metallicRoughnessTexture, &m.emissiveTexture})
      if (*t >= 0) *t += textureBase;
    scene.materials.push_back(m);
  }
  scene.textures.insert(scene.textures.end(), other.textures.begin(), other.textures.end());
  const auto first = static_cast<std::uint32_t>(scene.triangles.size());
  for (std::size_t t = 0; t < other.triangles.size(); ++t) {
    scene.triangles.push_back(other.triangles[t] + glm::uvec3(vertexBase));
    scene.triangleMaterial.push_back(other.triangleMaterial[t] + materialBase);
    scene.triangleLightGroup.push_back(~0u);
  }
  scene.objects.push_back({.name = name, .firstTriangle = first,
                           .triangleCount = static_cast<std::uint32_t>(other.triangles.size()),
                           .world = glm::translate(glm::mat4(1.0f), translate)});
  recomputeBounds(scene);
  return scene.objects.size() - 1;
}

std::size_t insertEmissiveQuad(Scene& scene, const EmissiveQuad& quad) {
  const glm::vec3 normal = glm::cross(quad.edge1, quad.edge2);
  if (!(glm::length(normal) > 0.0f) || !std::isfinite(glm::length(normal)))
    throw InputError(fmt::format("add quad '{}': its edges span no area", quad.name));
  if (glm::any(glm::lessThan(quad.emission, glm::vec3(0.0f))))
    throw InputError(fmt::format("add quad '{}': emission must not be negative", quad.name));
  for (const auto& o : scene.objects)
    if (!o.removed && o.name == quad.name)
      throw InputError(fmt::format("add quad '{}': an object of that name exists", quad.name));
  for (const auto& g : scene.lightGroups)
    if (g.name == quad.name) throw InputError(fmt::format("add quad '{}': a light of that name exists", quad.name));
  Material m;
  m.name = quad.name;
  m.baseColor = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  m.metallic = 0.0f;
  m.roughness = 1.0f;
  m.emission = quad.emission;
  scene.materials.push_back(m);
  const auto material = static_cast<std::uint32_t>(scene.materials.size() - 1);
  const auto group = static_cast<std::uint32_t>(scene.lightGroups.size());
  scene.lightGroups.push_back({.name = quad.name, .triangles = {}, .emission = quad.emission});
  const auto base = static_cast<std::uint32_t>(scene.positions.size());
  const glm::vec3 n = glm::normalize(normal);
  for (glm::vec3 p : {quad.corner, quad.corner + quad.edge1, quad.corner + quad.edge1 + quad.edge2, quad.corner + quad.edge2}) {
    scene.positions.push_back(p);
    scene.normals.push_back(n);
    scene.uvs.push_back(glm::vec2(0.0f));
  }
  const auto first = static_cast<std::uint32_t>(scene.triangles.size());
  for (glm::uvec3 t : {glm::uvec3(base, base + 1, base + 2), glm::uvec3(base, base + 2, base + 3)}) {
    scene.lightGroups.back().triangles.push_back(static_cast<std::uint32_t>(scene.triangles.size()));
    scene.triangles.push_back(t);
    scene.triangleMaterial.push_back(material);
    scene.triangleLightGroup.push_back(group);
  }
  scene.objects.push_back({.name = quad.name, .firstTriangle = first, .triangleCount = 2,
                           .world = glm::translate(glm::mat4(1.0f), quad.corner)});
  recomputeBounds(scene);
  return scene.objects.size() - 1;
}

} // namespace obscura::scene
