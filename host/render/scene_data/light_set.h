// light_set.h — the scene's lights as the shading passes see them: one entry (and one basis
// buffer D_s) per emissive light group or punctual light [SPEC §3].
//
// Every light s has an emission scale E_s (RGB). The passes compute transport at unit scale, so
// the image is sum_s E_s * D_s + I_a(E) * A + emission, linear in every E_s: relighting changes
// E_s and recomposes without tracing a ray.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/names.h"
#include "scene/scene.h"
#include "shared/host_device.h"

namespace obscura::render {

// How shadow rays pick a light and a point on it (shaders/lib/lights.glsl) [SPEC §1.3]: Spatial
// (the default: importance at the point, solid angle, MIS on glossy lobes) or Area (the paper's:
// by power, uniform by area), kept for reproducing the paper.
enum class LightSampling : std::uint32_t { Spatial = gpu::kLightSamplingSpatial, Area = gpu::kLightSamplingArea };
inline constexpr NameTable<LightSampling, 2> kLightSamplingNames{
    {{"spatial", LightSampling::Spatial}, {"area", LightSampling::Area}}};

// What kind of light a light set's light is (GpuLight::info.x, read only by LightSet::type).
enum class LightType : std::uint32_t {
  Area = gpu::kLightArea,
  Point = gpu::kLightPoint,
  Spot = gpu::kLightSpot,
  Directional = gpu::kLightDirectional,
  Background = gpu::kLightBackground,
};
// `obscura info`, relighting states ("type").
inline constexpr NameTable<LightType, 5> kLightTypeNames{{{"area", LightType::Area},
                                                          {"point", LightType::Point},
                                                          {"spot", LightType::Spot},
                                                          {"directional", LightType::Directional},
                                                          {"background", LightType::Background}}};

struct LightSet {
  std::vector<gpu::GpuLight> lights;     // selection CDF filled in; probability 0 = never sampled
  std::vector<gpu::GpuEmitter> emitters; // area lights' triangles, grouped per light
  std::vector<std::string> names;        // light group or punctual light name
  std::vector<glm::vec3> emission;       // E_s: the scene's own emission scale of each light
  std::vector<glm::vec3> unitFlux;       // emitted flux of light s at E_s = 1 (W, per channel)
  std::vector<double> power;             // selection weight ("power", SPEC §5)
  LightType type(std::size_t light) const { return static_cast<LightType>(lights[light].info.x); }

  std::size_t size() const { return lights.size(); }
  bool anySampled() const;               // some light has positive power
};

// Builds the light set. Zero-area emitters and lights of zero power stay in the set (their basis
// buffer is simply 0) but are never sampled.
LightSet buildLightSet(const scene::Scene& scene);

// The background light's slot, or size() when the scene has none.
std::size_t backgroundLight(const LightSet& set);

// Appends a punctual light (glTF KHR_lights_punctual units); call updateSelection after.
void appendPunctual(LightSet& set, const scene::PunctualLight& light, const scene::Bounds& bounds);
// Removes punctual light `index` and updates the selection. Area lights are never removed from a
// set: their triangles name them by index (TriangleShading), so they are switched off instead.
void removePunctual(LightSet& set, std::size_t index);
// The selection CDF and probabilities from the lights' powers.
void updateSelection(LightSet& set);

// Emission scales E_s as the vec4 rows the shaders read (compose's emissions, the render-time
// normaliser, the path tracer's scales).
std::vector<glm::vec4> emissionRows(const std::vector<glm::vec3>& emissions);

// Scalar "brightness" of an RGB value for selection weights: the channel mean.
float luminanceWeight(const glm::vec3& rgb);

} // namespace obscura::render
