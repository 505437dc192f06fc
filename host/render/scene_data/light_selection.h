// light_selection.h — C++ twins of shaders/lib/lights.glsl's spatial light selection: the
// importance of a bound at a shading point, and the light tree's stochastic descent and pdf.
//
// Same names, arguments and float operations as the GLSL, so tests compare the GPU with them
// (tests/render/light_tree_test.cpp). The model and its citations are in lights.glsl.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "shared/host_device.h"

namespace obscura::render {

// What the importance needs to know of a light or of a tree node (GpuLightNode's fields).
struct ImportanceBounds {
  float power = 0.0f;         // selection weight (GpuLight.params.y, summed over a node)
  glm::vec3 centre{0.0f};     // bounding sphere
  float radius = 0.0f;
  glm::vec3 axis{0.0f, 0.0f, 1.0f}; // cone of emission normals / spot directions
  float cosO = -1.0f;         // its half-angle's cosine; -1 = no orientation bound
  float cosE = 0.0f;          // emission spread beyond theta_o (0: area lights' 90 degrees)
  bool uniformInCone = false; // spots: no cosine factor inside the cone
};

// The bounds lights.glsl's lightImportance gives light `light` (unbounded lights: power 0).
ImportanceBounds importanceBounds(const gpu::GpuLight& light);
ImportanceBounds importanceBounds(const gpu::GpuLightNode& node);

// Conty Estevez & Kulla 2018 eq. 3 (lights.glsl boundsImportance).
float boundsImportance(const ImportanceBounds& b, glm::vec3 p, glm::vec3 n);
float lightImportance(const gpu::GpuLight& light, glm::vec3 p, glm::vec3 n);

bool isUnboundedLight(std::uint32_t type);

// The light tree's selection at p, n (lights.glsl selectLightFromTree, lightTreePdf): the light
// and the probability of picking it (0: none can light p).
struct LightPick {
  std::uint32_t light = 0;
  float probability = 0.0f;
};
LightPick selectLightFromTree(const std::vector<gpu::GpuLightNode>& tree, float u, glm::vec3 p, glm::vec3 n);
float lightTreePdf(const std::vector<gpu::GpuLightNode>& tree, const std::vector<gpu::GpuLight>& lights,
                   std::uint32_t light, glm::vec3 p, glm::vec3 n);

} // namespace obscura::render
