// ambient.h — the ambient intensity I_a of ray-traced obscurances [RTO eqs. 3-5, 12; SPEC §1.2].
//
//   R_ave = sum_i A_i R_i / A_t                       (per channel, R_i the mean albedo a-bar)
//   grey:            I_a = R_ave / (1 - R_ave) * sum_i A_i E_i / A_t    (with W)
//   colour bleeding: I_a =     1 / (1 - R_ave) * sum_i A_i E_i / A_t    (with W_c)
//
// I_a is kept in RADIANCE units (the paper's radiosity / pi), so the indirect term R(P) I_a W
// adds directly to the image. sum_i A_i E_i is the emitted flux. It is linear in the lights' scales E_s, so I_a is kept as
// one weight per light: I_a(E) = sum_s E_s * weight_s (relighting recomputes it for free).
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "render/scene_data/light_set.h"
#include "render/scene_data/reached_surfaces.h"
#include "core/names.h"
#include "scene/scene.h"

namespace obscura::render {

// Which surfaces share a light's flux in I_a: Reached (default, OURS after the paper's §6: those
// the light reaches, reached_surfaces.h), Seen (Reached with the first bounce fitted to what the
// light's landing points send to the surfaces the camera sees, reached_surfaces.h) or Global (the
// paper's: the whole scene).
enum class AmbientModel { Reached, Global, Seen };
inline constexpr NameTable<AmbientModel, 3> kAmbientModelNames{
    {{"reached", AmbientModel::Reached}, {"seen", AmbientModel::Seen}, {"global", AmbientModel::Global}}};

struct AmbientTerm {
  AmbientModel model = AmbientModel::Global;
  glm::vec3 averageReflectance{0.0f}; // R_ave of the whole scene [RTO eq. 3]: R(Q) of a miss within
                                      // dmax in W_c (a render-time constant, so edits stay exact)
  glm::vec3 reachedReflectance{0.0f}; // the lights' R_s weighted by power (Reached; reported)
  bool reflectanceClamped = false;    // R_ave reached 1 in a channel: I_a would be infinite
  double totalArea = 0.0;             // A_t
  std::vector<LightReach> reach;      // per light (Reached); an entry of zero area falls back to A_t
  // Reached: the bounces I_a sums, as the render's path depth d (paths of at most d scattering
  // vertices, like the path tracer): sum_{j=1}^{d-1} q^(j-1) instead of 1 / (1 - q), q = R_s (1 - e_1).
  // 0: all of them (the paper's series).
  std::uint32_t depth = 0;
  std::vector<glm::vec3> weight;      // per light: I_a per unit E_s
  std::vector<glm::vec3> globalWeight; // the same by the paper's formula (whole scene), for reports
  glm::vec3 intensity(const std::vector<glm::vec3>& emission) const;       // I_a(E)
  glm::vec3 globalIntensity(const std::vector<glm::vec3>& emission) const; // the paper's I_a(E)
};

// Mean reflectance of every triangle: a-bar of its material times its texture's mean colour.
std::vector<glm::vec3> triangleReflectances(const scene::Scene& scene, const std::vector<glm::vec3>& meanAlbedo);
// The same with the textures' mean colours given (textureMeans), which averaging every texel of
// modern-hall's textures again would cost ~0.25 s on every edit that adds triangles.
std::vector<glm::vec3> triangleReflectances(const scene::Scene& scene, const std::vector<glm::vec3>& meanAlbedo,
                                            const std::vector<glm::vec3>& textureMeans);
// `known`, the mean colours of the scene's first textures, followed by those of the rest (an edit
// appends textures and never changes one).
std::vector<glm::vec3> textureMeanColours(const scene::Scene& scene, std::vector<glm::vec3> known = {});

// `meanAlbedo[m]` is a-bar of material m with its base colour factor; textured materials are
// scaled by their texture's mean (linear) colour. OURS: a texture modulates a-bar linearly.
AmbientTerm computeAmbient(const scene::Scene& scene, const LightSet& lights,
                           const std::vector<glm::vec3>& meanAlbedo, bool colourBleeding);

// The weights w_s of `term` (whose R_ave and A_t stay) for another set of lights: what adding or
// removing a light changes, without summing the scene's areas and textures again. With the
// Reached model, term.reach must hold one entry per light (the renderer measures them).
void updateAmbientWeights(AmbientTerm& term, const LightSet& lights, bool colourBleeding);

// Mean linear colour of a texture (sRGB decoded when the texture is sRGB).
glm::vec3 meanTextureColour(const scene::Texture& texture);

} // namespace obscura::render
