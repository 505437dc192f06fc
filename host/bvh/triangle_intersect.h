// triangle_intersect.h — watertight ray/triangle intersection on the CPU.
//
// Woop, Benthin & Wald, "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013. The GLSL twin is
// shaders/lib/intersect.glsl; tests/shaders/intersect_test.* checks that both agree.
#pragma once
#include <glm/glm.hpp>

namespace obscura::bvh {

// Per-ray constants of the watertight test: the axis of largest |direction| becomes z, and the
// shear that maps the direction onto +z.
struct WatertightRay {
  glm::vec3 origin;
  int kx, ky, kz;   // permutation of the axes
  float sx, sy, sz; // shear constants
};

WatertightRay prepareWatertightRay(const glm::vec3& origin, const glm::vec3& direction);

// Returns true and sets t, u, v (barycentrics of v1, v2) if the ray hits the triangle with
// tmin < t <= tmax (closed at tmax, so a caller passing its best t can break ties by id).
// Edges and vertices are hit by at least one of the triangles sharing them; no absolute
// epsilon, so tiny triangles are never lost.
bool intersectTriangle(const WatertightRay& ray, const glm::vec3& v0, const glm::vec3& v1,
                       const glm::vec3& v2, float tmin, float tmax, float& t, float& u, float& v);

// Conservative bound on the absolute error of the t computed from these sheared coordinates
// (a*, b*, c*), edge functions e0..e2 and det [PBR3 §3.9.5]; hits with t <= it are rejected.
// zScale = |Sz|, the shear's z scale (to recover unscaled z for the x/y error terms).
float triangleTError(float ax, float ay, float az, float bx, float by, float bz, float cx, float cy, float cz,
                     float e0, float e1, float e2, float det, float zScale);

} // namespace obscura::bvh
