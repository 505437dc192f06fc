#include "render/scene_data/ambient.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace obscura::render {

// Largest R_ave we accept: at 1 a closed scene never loses light and I_a diverges.
constexpr float kMaxAverageReflectance = 0.999f;

glm::vec3 meanTextureColour(const scene::Texture& texture) {
  // A texel holds one of 256 values: decoded once into a table (the same sRGB curve, so the same
  // sums). A pow per texel was ~2 s of a recovery on the staircase's textures, which every render
  // of a room pays twice (the reach's reflectances and the ambient's).
  static const std::array<std::array<double, 256>, 2> decoded = [] {
    std::array<std::array<double, 256>, 2> table{};
    for (int i = 0; i < 256; ++i) {
      const double v = i / 255.0;
      table[0][i] = v;
      table[1][i] = v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
    }
    return table;
  }();
  const std::array<double, 256>& decode = decoded[texture.srgb ? 1 : 0];
  glm::dvec3 sum(0.0);
  const std::size_t n = std::size_t(texture.width) * texture.height;
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) sum[c] += decode[texture.rgba8[i * 4 + c]];
  return n ? glm::vec3(sum / static_cast<double>(n)) : glm::vec3(1.0f);
}

namespace {
glm::vec3 weighted(const std::vector<glm::vec3>& weight, const std::vector<glm::vec3>& emission) {
  glm::vec3 ia(0.0f);
  for (std::size_t s = 0; s < weight.size() && s < emission.size(); ++s) ia += emission[s] * weight[s];
  return ia;
}
} // namespace

glm::vec3 AmbientTerm::intensity(const std::vector<glm::vec3>& emission) const { return weighted(weight, emission); }
glm::vec3 AmbientTerm::globalIntensity(const std::vector<glm::vec3>& emission) const {
  return weighted(globalWeight, emission);
}

std::vector<glm::vec3> textureMeanColours(const scene::Scene& scene, std::vector<glm::vec3> known) {
  known.resize(std::min(known.size(), scene.textures.size()));
  for (std::size_t t = known.size(); t < scene.textures.size(); ++t) known.push_back(meanTextureColour(scene.textures[t]));
  return known;
}

std::vector<glm::vec3> triangleReflectances(const scene::Scene& scene, const std::vector<glm::vec3>& meanAlbedo) {
  return triangleReflectances(scene, meanAlbedo, textureMeanColours(scene));
}

std::vector<glm::vec3> triangleReflectances(const scene::Scene& scene, const std::vector<glm::vec3>& meanAlbedo,
                                            const std::vector<glm::vec3>& textureMean) {
  std::vector<glm::vec3> material(scene.materials.size());
  for (std::size_t m = 0; m < scene.materials.size(); ++m) {
    material[m] = meanAlbedo[m];
    int tex = scene.materials[m].baseColorTexture;
    if (tex >= 0 && tex < static_cast<int>(textureMean.size())) material[m] *= textureMean[tex];
  }
  std::vector<glm::vec3> out(scene.triangles.size());
  for (std::size_t i = 0; i < scene.triangles.size(); ++i) out[i] = material[scene.triangleMaterial[i]];
  return out;
}

namespace {

glm::vec3 clampReflectance(glm::vec3 r, bool& clamped) {
  for (int c = 0; c < 3; ++c)
    if (r[c] > kMaxAverageReflectance) {
      r[c] = kMaxAverageReflectance;
      clamped = true;
    }
  return r;
}

} // namespace

AmbientTerm computeAmbient(const scene::Scene& scene, const LightSet& lights,
                           const std::vector<glm::vec3>& meanAlbedo, bool colourBleeding) {
  AmbientTerm term;
  const std::vector<glm::vec3> reflectance = triangleReflectances(scene, meanAlbedo);
  glm::dvec3 weighted(0.0);
  for (std::size_t i = 0; i < scene.triangles.size(); ++i) {
    const glm::uvec3 t = scene.triangles[i];
    double area = 0.5 * glm::length(glm::cross(glm::dvec3(scene.positions[t.y] - scene.positions[t.x]),
                                               glm::dvec3(scene.positions[t.z] - scene.positions[t.x])));
    term.totalArea += area;
    weighted += area * glm::dvec3(reflectance[i]);
  }
  glm::vec3 rAve = term.totalArea > 0.0 ? glm::vec3(weighted / term.totalArea) : glm::vec3(0.0f);
  term.averageReflectance = term.reachedReflectance = clampReflectance(rAve, term.reflectanceClamped);
  updateAmbientWeights(term, lights, colourBleeding);
  return term;
}

void updateAmbientWeights(AmbientTerm& term, const LightSet& lights, bool colourBleeding) {
  // [RTO eq. 4] (grey) or [RTO eq. 12] (colour bleeding), per unit E_s. The paper's I_a is a
  // radiosity (E_i = pi L_e); our images are radiance, so I_a is divided by pi: for a Lambertian
  // reflector the indirect radiance is R(P) I_a W / pi. OURS [SPEC §5: no hidden scale].
  // Reached: light s's kept flux over the area A_s it reaches, with that area's reflectance R_s and
  // escapes; Seen: the same series after a first bounce fitted at the camera's points.
  const bool reached = term.model != AmbientModel::Global && term.reach.size() == lights.size();
  const bool seen = reached && term.model == AmbientModel::Seen;
  // A series of bounces each keeping q = R (1 - e_1): all of them (1 / (1 - q)), or the d - 1 a path
  // of depth d holds (light -> Q_1 .. Q_j -> P, j < d).
  auto seriesOf = [](glm::vec3 q, std::uint32_t depth) {
    glm::vec3 out(0.0f);
    for (int c = 0; c < 3; ++c) {
      double qc = std::min(static_cast<double>(q[c]), static_cast<double>(kMaxAverageReflectance));
      out[c] = static_cast<float>(depth == 0 ? 1.0 / (1.0 - qc) : (1.0 - std::pow(qc, depth - 1.0)) / (1.0 - qc));
    }
    return out;
  };
  auto series = [&](glm::vec3 r, double escapeBounce, std::uint32_t depth) {
    return seriesOf(r * static_cast<float>(1.0 - escapeBounce), depth);
  };
  // The first bounce: flux kept (1 - e_0) over the area (x R for grey obscurance, whose W has no R(Q)).
  auto firstBounce = [&](std::size_t s, glm::vec3 r, double area, double escapeDirect) {
    if (!(area > 0.0)) return glm::vec3(0.0f);
    glm::vec3 perArea = lights.unitFlux[s] * static_cast<float>((1.0 - escapeDirect) / (area * std::numbers::pi));
    return (colourBleeding ? glm::vec3(1.0f) : r) * perArea;
  };
  term.weight.clear();
  term.globalWeight.clear();
  glm::dvec3 byPower(0.0);
  double power = 0.0;
  for (std::size_t s = 0; s < lights.size(); ++s) {
    glm::vec3 r = term.averageReflectance;
    double area = term.totalArea;
    term.globalWeight.push_back(firstBounce(s, r, area, 0.0) * series(r, 0.0, 0));
    double escapeDirect = 0.0, escapeBounce = 0.0;
    if (reached && term.reach[s].area > 0.0) {
      r = clampReflectance(term.reach[s].reflectance, term.reflectanceClamped);
      area = term.reach[s].area;
      escapeDirect = term.reach[s].escapeDirect;
      escapeBounce = term.reach[s].escapeBounce;
      byPower += lights.power[s] * glm::dvec3(r);
      power += lights.power[s];
    }
    // Seen: the first bounce fitted at the camera's points (it holds R(Q) and the escapes already),
    // the later ones with the q measured around them.
    if (seen && term.reach[s].seenFitted)
      term.weight.push_back(term.reach[s].seenFirstBounce * seriesOf(term.reach[s].seenBounce, term.depth));
    else
      term.weight.push_back(firstBounce(s, r, area, escapeDirect) * series(r, escapeBounce, reached ? term.depth : 0));
  }
  term.reachedReflectance = power > 0.0 ? glm::vec3(byPower / power) : term.averageReflectance;
}

} // namespace obscura::render
