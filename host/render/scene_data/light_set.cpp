#include "render/scene_data/light_set.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace obscura::render {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

float triangleArea(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  return 0.5f * glm::length(glm::cross(b - a, c - a));
}

// Per-channel ratio that makes a group's emission "unit": e / E, and 1 where E is 0 so a channel
// switched on later by relighting still has transport in D_s.
glm::vec3 unitRadiance(const glm::vec3& e, const glm::vec3& scale) {
  glm::vec3 out;
  for (int c = 0; c < 3; ++c) out[c] = scale[c] > 0.0f ? e[c] / scale[c] : 1.0f;
  return out;
}

// Area of the scene's bounding box seen along `direction`: a directional light's "power" is its
// irradiance times the cross-section it lights. OURS [SPEC §5 defines power for area and
// punctual lights only].
float projectedBoxArea(const scene::Bounds& b, const glm::vec3& direction) {
  glm::vec3 e = b.extent();
  glm::vec3 d = glm::abs(direction);
  return d.x * e.y * e.z + d.y * e.x * e.z + d.z * e.x * e.y;
}

// The bounds lights.glsl's importance needs of an area light: the bounding sphere of its
// triangles (position = centre, w = radius) and the cone holding their normals (direction = axis,
// w = cos of its half-angle; -1 when the normals span too much or a triangle emits both ways).
void setAreaLightBounds(gpu::GpuLight& light, const std::vector<gpu::GpuEmitter>& emitters, std::size_t first) {
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  glm::vec3 axis(0.0f);
  bool twoSided = false;
  for (std::size_t i = first; i < emitters.size(); ++i) {
    const auto& e = emitters[i];
    for (const glm::vec3 v : {glm::vec3(e.v0), glm::vec3(e.v1), glm::vec3(e.v2)}) {
      lo = glm::min(lo, v);
      hi = glm::max(hi, v);
    }
    axis += glm::cross(glm::vec3(e.v1) - glm::vec3(e.v0), glm::vec3(e.v2) - glm::vec3(e.v0)); // 2 x area x normal
    twoSided = twoSided || e.v2.w != 0.0f;
  }
  if (first == emitters.size()) return;
  glm::vec3 centre = 0.5f * (lo + hi);
  float radius = 0.0f;
  for (std::size_t i = first; i < emitters.size(); ++i)
    for (const glm::vec3 v : {glm::vec3(emitters[i].v0), glm::vec3(emitters[i].v1), glm::vec3(emitters[i].v2)})
      radius = std::max(radius, glm::length(v - centre));
  light.position = glm::vec4(centre, radius * 1.001f + 1e-6f); // a hair larger: rounding stays inside
  float length = glm::length(axis);
  float cosCone = -1.0f;
  if (!twoSided && length > 0.0f) {
    axis /= length;
    cosCone = 1.0f;
    for (std::size_t i = first; i < emitters.size(); ++i) {
      const auto& e = emitters[i];
      glm::vec3 n = glm::cross(glm::vec3(e.v1) - glm::vec3(e.v0), glm::vec3(e.v2) - glm::vec3(e.v0));
      float l = glm::length(n);
      if (l > 0.0f) cosCone = std::min(cosCone, glm::dot(axis, n / l));
    }
    // A little slack for rounding; a cone past 90 degrees bounds nothing useful.
    cosCone = cosCone > 0.0f ? std::max(0.0f, cosCone - 1e-4f) : -1.0f;
  }
  light.direction = glm::vec4(length > 0.0f ? axis : glm::vec3(0.0f, 0.0f, 1.0f), cosCone);
}

} // namespace

std::vector<glm::vec4> emissionRows(const std::vector<glm::vec3>& emissions) {
  std::vector<glm::vec4> out;
  for (const auto& e : emissions) out.emplace_back(e, 0.0f);
  return out;
}

float luminanceWeight(const glm::vec3& rgb) { return (rgb.x + rgb.y + rgb.z) / 3.0f; }

std::size_t backgroundLight(const LightSet& set) {
  for (std::size_t i = 0; i < set.size(); ++i)
    if (set.lights[i].info.x == gpu::kLightBackground) return i;
  return set.size();
}

bool LightSet::anySampled() const {
  return std::any_of(power.begin(), power.end(), [](double p) { return p > 0.0; });
}

LightSet buildLightSet(const scene::Scene& scene) {
  LightSet set;
  // Area lights: one per light group.
  for (const auto& group : scene.lightGroups) {
    gpu::GpuLight light{};
    light.info = glm::uvec4(gpu::kLightArea, static_cast<std::uint32_t>(set.emitters.size()),
                            static_cast<std::uint32_t>(group.triangles.size()), 0u);
    const glm::vec3 scale = group.emission;
    float area = 0.0f;
    glm::vec3 flux(0.0f);
    std::size_t first = set.emitters.size();
    for (std::uint32_t t : group.triangles) {
      const glm::uvec3 tri = scene.triangles[t];
      const scene::Material& m = scene.materials[scene.triangleMaterial[t]];
      glm::vec3 a = scene.positions[tri.x], b = scene.positions[tri.y], c = scene.positions[tri.z];
      float triArea = triangleArea(a, b, c);
      float sides = m.doubleSided ? 2.0f : 1.0f;
      area += triArea;
      // Flux of a Lambertian emitter: pi * L * area per emitting side.
      flux += kPi * sides * triArea * unitRadiance(m.emission, scale);
      set.emitters.push_back({.v0 = glm::vec4(a, area), .v1 = glm::vec4(b, triArea),
                              .v2 = glm::vec4(c, m.doubleSided ? 1.0f : 0.0f),
                              .radiance = glm::vec4(unitRadiance(m.emission, scale), 0.0f)});
    }
    for (std::size_t i = first; i < set.emitters.size(); ++i) // normalise the area CDF
      set.emitters[i].v0.w = area > 0.0f ? set.emitters[i].v0.w / area : 0.0f;
    if (!set.emitters.empty() && set.emitters.size() > first) set.emitters.back().v0.w = 1.0f;
    light.info.w = std::bit_cast<std::uint32_t>(area); // the group's area, for the sample pdf
    setAreaLightBounds(light, set.emitters, first);
    set.lights.push_back(light);
    set.names.push_back(group.name);
    set.emission.push_back(scale);
    set.unitFlux.push_back(flux);
    set.power.push_back(static_cast<double>(luminanceWeight(flux * scale)));
  }
  // Punctual lights (KHR_lights_punctual): E_s = colour x intensity, unit transport per light.
  for (const auto& p : scene.punctualLights) appendPunctual(set, p, scene.bounds);
  if (luminanceWeight(scene.background) > 0.0f) {
    // The sky: unit radiance from every direction, E_s = the background colour. Its "flux" for
    // selection and the paper's I_a is what a sphere around the scene receives from it,
    // pi L x 4 pi R^2 (OURS; the reached I_a measures what lands, reached_surfaces.h).
    gpu::GpuLight light{};
    light.info = glm::uvec4(gpu::kLightBackground, 0u, 0u, 0u);
    const float radius = 0.5f * glm::length(scene.bounds.extent());
    const float unit = kPi * 4.0f * kPi * radius * radius;
    set.lights.push_back(light);
    set.names.push_back("background");
    set.emission.push_back(scene.background);
    set.unitFlux.push_back(glm::vec3(unit));
    set.power.push_back(static_cast<double>(unit * luminanceWeight(scene.background)));
  }
  updateSelection(set);
  return set;
}

void appendPunctual(LightSet& set, const scene::PunctualLight& p, const scene::Bounds& bounds) {
  gpu::GpuLight light{};
  std::uint32_t type = p.type == scene::PunctualType::Point ? gpu::kLightPoint
                       : p.type == scene::PunctualType::Spot ? gpu::kLightSpot
                                                             : gpu::kLightDirectional;
  light.info = glm::uvec4(type, 0u, 0u, 0u);
  light.position = glm::vec4(p.position, p.range);
  light.direction = glm::vec4(glm::normalize(p.direction), 0.0f);
  light.params = glm::vec4(0.0f, 0.0f, std::cos(p.innerConeAngle), std::cos(p.outerConeAngle));
  glm::vec3 scale = p.color * p.intensity;
  // Unit flux: 4 pi sr for point and spot (glTF's spot intensity is that of a point light
  // masked by the cone; we count the full sphere, OURS); irradiance x cross-section for the sun.
  float unit = type == gpu::kLightDirectional ? projectedBoxArea(bounds, p.direction) : 4.0f * kPi;
  set.lights.push_back(light);
  set.names.push_back(p.name.empty() ? "punctual" : p.name);
  set.emission.push_back(scale);
  set.unitFlux.push_back(glm::vec3(unit));
  set.power.push_back(static_cast<double>(unit * luminanceWeight(scale)));
}

void removePunctual(LightSet& set, std::size_t index) {
  if (set.lights.at(index).info.x == gpu::kLightArea)
    throw std::logic_error("removePunctual: light " + set.names[index] + " is an area light");
  set.lights.erase(set.lights.begin() + static_cast<std::ptrdiff_t>(index));
  set.names.erase(set.names.begin() + static_cast<std::ptrdiff_t>(index));
  set.emission.erase(set.emission.begin() + static_cast<std::ptrdiff_t>(index));
  set.unitFlux.erase(set.unitFlux.begin() + static_cast<std::ptrdiff_t>(index));
  set.power.erase(set.power.begin() + static_cast<std::ptrdiff_t>(index));
  updateSelection(set);
}

void updateSelection(LightSet& set) {
  // Selection CDF by power.
  double total = 0.0;
  for (double p : set.power) total += std::max(0.0, p);
  // The last light with positive power closes the CDF at exactly 1 (no rounding gap); lights
  // after it, and every zero-power light, get an empty interval and are never chosen.
  std::size_t lastPositive = set.lights.size();
  for (std::size_t i = 0; i < set.lights.size(); ++i)
    if (set.power[i] > 0.0) lastPositive = i;
  double running = 0.0;
  for (std::size_t i = 0; i < set.lights.size(); ++i) {
    double p = total > 0.0 ? std::max(0.0, set.power[i]) / total : 0.0;
    running += p;
    bool closed = lastPositive < set.lights.size() && i >= lastPositive;
    set.lights[i].params.x = static_cast<float>(closed ? 1.0 : running);
    set.lights[i].params.y = static_cast<float>(p);
  }
}

} // namespace obscura::render
