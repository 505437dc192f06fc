// recovery_scene.h — the photographed room as the renderer sees it during reflectance recovery
// [IVR §4]: the glTF geometry with its own emitters off (the photographs were taken with them
// off), each shot's lamp as a glTF point light, and one Lambertian material per object whose
// reflectance is the current estimate (what the indirect term's R(Q) and I_a are computed with).
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "bvh/bvh.h"
#include "recover/photo_set.h"
#include "scene/scene.h"

namespace obscura::recover {

// `room` with no emission anywhere, the shots' lamps as point lights "shot<i>" (in shot order),
// and object o's triangles given a diffuse material of reflectance objectReflectance[o]. The
// triangles and their order stay, so the room's BVH serves it.
scene::Scene recoveryScene(const scene::Scene& room, const std::vector<Shot>& shots,
                           const std::vector<glm::vec3>& objectReflectance);

// The object of every triangle.
std::vector<std::uint32_t> triangleObjects(const scene::Scene& scene);
// Each object's material in the room's model: the one covering most of its area.
std::vector<std::uint32_t> objectMaterials(const scene::Scene& room);
// Whether the room's model gives each object one colour: every triangle of one material, which
// has no colour texture. Such objects of one material have the same reflectance.
std::vector<bool> oneColourObjects(const scene::Scene& room);
// The colour the room's model gives each object: its material's (`objectMaterial`, from
// objectMaterials) base colour, none where that material has a colour texture.
std::vector<std::optional<glm::vec3>> modelColours(const scene::Scene& room,
                                                   const std::vector<std::uint32_t>& objectMaterial);

// InputError naming `photos.file` and the shot when a lamp is inside geometry: its sphere (or,
// for radius 0, the point) touches a triangle, or it lies inside a closed object (3/4 of the rays
// from it first meet the back faces of one object).
void checkLamps(const scene::Scene& room, const bvh::Bvh& bvh, const PhotoSet& photos);

// The distance from p to triangle (a, b, c).
float pointTriangleDistance(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c);

} // namespace obscura::recover
