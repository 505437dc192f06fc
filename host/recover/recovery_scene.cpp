// recovery_scene.cpp — see recovery_scene.h.
#include "recover/recovery_scene.h"

#include <array>
#include <cmath>
#include <limits>
#include <map>

#include <fmt/format.h>

#include "core/error.h"

namespace obscura::recover {

std::vector<std::uint32_t> triangleObjects(const scene::Scene& scene) {
  std::vector<std::uint32_t> object(scene.triangles.size(), 0);
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const auto& obj = scene.objects[o];
    for (std::uint32_t t = 0; t < obj.triangleCount; ++t) object[obj.firstTriangle + t] = static_cast<std::uint32_t>(o);
  }
  return object;
}

std::vector<std::uint32_t> objectMaterials(const scene::Scene& room) {
  std::vector<std::uint32_t> material(room.objects.size(), 0);
  for (std::size_t o = 0; o < room.objects.size(); ++o) {
    const auto& obj = room.objects[o];
    std::map<std::uint32_t, double> area;
    for (std::uint32_t t = obj.firstTriangle; t < obj.firstTriangle + obj.triangleCount; ++t) {
      const glm::uvec3 tri = room.triangles[t];
      const glm::vec3 a = room.positions[tri.x];
      const glm::vec3 normal = glm::cross(room.positions[tri.y] - a, room.positions[tri.z] - a);
      area[room.triangleMaterial[t]] += 0.5 * double(glm::length(normal));
    }
    double largest = -1.0;
    for (const auto& [m, sum] : area)
      if (sum > largest) {
        largest = sum;
        material[o] = m;
      }
  }
  return material;
}

std::vector<bool> oneColourObjects(const scene::Scene& room) {
  std::vector<bool> one(room.objects.size(), false);
  for (std::size_t o = 0; o < room.objects.size(); ++o) {
    const auto& obj = room.objects[o];
    if (obj.triangleCount == 0) continue;
    const std::uint32_t m = room.triangleMaterial[obj.firstTriangle];
    bool same = room.materials.at(m).baseColorTexture < 0;
    for (std::uint32_t t = obj.firstTriangle; t < obj.firstTriangle + obj.triangleCount && same; ++t)
      same = room.triangleMaterial[t] == m;
    one[o] = same;
  }
  return one;
}

std::vector<std::optional<glm::vec3>> modelColours(const scene::Scene& room,
                                                   const std::vector<std::uint32_t>& objectMaterial) {
  std::vector<std::optional<glm::vec3>> colour(room.objects.size());
  for (std::size_t o = 0; o < room.objects.size(); ++o) {
    const scene::Material& m = room.materials.at(objectMaterial[o]);
    if (m.baseColorTexture < 0) colour[o] = glm::vec3(m.baseColor);
  }
  return colour;
}

scene::Scene recoveryScene(const scene::Scene& room, const std::vector<Shot>& shots,
                           const std::vector<glm::vec3>& objectReflectance) {
  scene::Scene s = room;
  s.materials.clear();
  for (std::size_t o = 0; o < room.objects.size(); ++o) {
    scene::Material m;
    m.name = "recovered." + room.objects[o].name;
    m.baseColor = glm::vec4(objectReflectance.at(o), 1.0f);
    m.metallic = 0.0f; // metallic 0, roughness 1: Lambertian of albedo = base colour [SPEC §5]
    m.roughness = 1.0f;
    m.doubleSided = true;
    s.materials.push_back(m);
  }
  if (s.materials.empty()) s.materials.emplace_back();
  s.triangleMaterial = triangleObjects(room);
  s.lightGroups.clear();
  s.triangleLightGroup.assign(s.triangles.size(), ~0u);
  s.background = glm::vec3(0.0f);
  s.punctualLights.clear();
  for (std::size_t i = 0; i < shots.size(); ++i) {
    scene::PunctualLight lamp;
    lamp.name = fmt::format("shot{}", i);
    lamp.type = scene::PunctualType::Point;
    lamp.position = shots[i].position;
    lamp.intensity = shots[i].intensity;
    lamp.color = shots[i].color;
    s.punctualLights.push_back(lamp);
  }
  return s;
}

// Closest point on a triangle, by its Voronoi regions (vertices, edges, face).
float pointTriangleDistance(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const glm::vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0f && d2 <= 0.0f) return glm::length(p - a);
  const glm::vec3 bp = p - b;
  const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0f && d4 <= d3) return glm::length(p - b);
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
  const glm::vec3 cp = p - c;
  const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0f && d5 <= d6) return glm::length(p - c);
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f)
    return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  const float denom = 1.0f / (va + vb + vc);
  return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

void checkLamps(const scene::Scene& room, const bvh::Bvh& bvh, const PhotoSet& photos) {
  // A point lamp (radius 0) still must not sit on a surface: a small part of the room's size.
  const float touching = 1e-4f * glm::length(room.bounds.extent());
  // Axis and diagonal directions: a lamp inside a closed object meets back faces in all of them.
  std::vector<glm::vec3> directions;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (x != 0 || y != 0 || z != 0) directions.push_back(glm::normalize(glm::vec3(x, y, z)));
  const std::vector<std::uint32_t> objects = triangleObjects(room);
  for (std::size_t i = 0; i < photos.shots.size(); ++i) {
    const Shot& shot = photos.shots[i];
    const float limit = std::max(shot.radius, touching);
    for (std::size_t t = 0; t < room.triangles.size(); ++t) {
      const glm::uvec3 tri = room.triangles[t];
      const float d = pointTriangleDistance(shot.position, room.positions[tri.x], room.positions[tri.y],
                                            room.positions[tri.z]);
      if (d < limit) {
        throw InputError(fmt::format("{}: shots entry {}: the lamp at ({}, {}, {}) is inside geometry: it is {:.4g} "
                                     "from object '{}', closer than its radius {}",
                                     photos.file, i, shot.position.x, shot.position.y, shot.position.z, d,
                                     room.objects[objects[t]].name, shot.radius));
      }
    }
    // Inside a closed object: at least 3/4 of the rays meet the back of one object first (an
    // object open at the bottom, standing on the floor, still counts). Walls that are separate
    // objects do not trip it whichever way they face.
    std::map<std::uint32_t, std::size_t> backFaces;
    for (const auto& dir : directions) {
      const bvh::Hit hit = bvh::closestHit(bvh, bvh::Ray{shot.position, dir});
      if (!hit.hit()) continue;
      const glm::uvec3 tri = room.triangles[hit.primitive];
      const glm::vec3 n = glm::cross(room.positions[tri.y] - room.positions[tri.x],
                                     room.positions[tri.z] - room.positions[tri.x]);
      if (glm::dot(n, dir) > 0.0f) ++backFaces[objects[hit.primitive]];
    }
    for (const auto& [object, count] : backFaces)
      if (4 * count >= 3 * directions.size())
        throw InputError(fmt::format("{}: shots entry {}: the lamp at ({}, {}, {}) is inside geometry: inside object "
                                     "'{}' (the rays from it meet its back faces first)",
                                     photos.file, i, shot.position.x, shot.position.y, shot.position.z,
                                     room.objects[object].name));
  }
}

} // namespace obscura::recover
