// reflectance_recovery.h — per-pixel diffuse reflectance from photographs of one view, each lit
// by one lamp [IVR §4.2-4.3, SPEC §2]:
//
//   R_i = C_i / (F V E_i + B_i)     per photo i and pixel (IVR eq. 2, camera response linear)
//   K_i = V_i, filtered (confidence_filters.h);  R = sum K_i R_i / sum K_i  (IVR eq. 3)
//
// F V E_i, the direct light per unit reflectance, comes from the obscurance renderer's shadow
// rays to the lamp (a point light, ShadowSampling::PerLight). B_i, the indirect light per unit
// reflectance, is one of
//   Constant    the paper's ambient: B_i = k * (mean of photo i over the pixels that see a
//               surface), k a user's average reflectance;
//   Obscurance  the obscurance term I_a W_c [RTO eqs. 6, 12] computed with the current estimate:
//               each object's material is given its mean recovered reflectance, which sets both
//               R(Q) in W_c and R_ave in I_a; rendered again each iteration;
//   Gather      OURS (photo_gather.h): gathered from the photographs' own radiance where the
//               camera sees the surface, from the current estimate where it does not.
// The iterated ones start from the Constant estimate, then: estimate R, per-object means,
// B_i again, re-estimate.
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "bvh/bvh.h"
#include "core/names.h"
#include "gpu/context.h"
#include "recover/confidence_filters.h"
#include "recover/photo_gather.h"
#include "recover/photo_set.h"
#include "recover/weighted_merge.h"
#include "render/scene_data/ambient.h"
#include "scene/scene.h"

namespace obscura::recover {

enum class IndirectModel { Constant, Obscurance, Gather };
inline constexpr NameTable<IndirectModel, 3> kIndirectModelNames{
    {{"gather", IndirectModel::Gather}, {"obscurance", IndirectModel::Obscurance}, {"constant", IndirectModel::Constant}}};

// How the per-photo estimates become one: the paper's confidence-weighted mean of the lit
// estimates (IVR eq. 3), or weighted by their expected error with the unlit pixels recovered from
// their indirect light (weighted_merge.h).
enum class MergeModel { Weighted, Paper };
inline constexpr NameTable<MergeModel, 2> kMergeModelNames{
    {{"weighted", MergeModel::Weighted}, {"paper", MergeModel::Paper}}};

// The I_a models recovery offers (--ambient): not Seen, whose first bounce is fitted to a
// render's camera view rather than to the photographs.
inline constexpr NameTable<render::AmbientModel, 2> kRecoveryAmbientNames{
    {{nameOf(render::kAmbientModelNames, render::AmbientModel::Reached), render::AmbientModel::Reached},
     {nameOf(render::kAmbientModelNames, render::AmbientModel::Global), render::AmbientModel::Global}}};

struct RecoveryOptions {
  std::uint32_t spp = 8;             // primary samples per pixel (and shadow/obscurance rays with them)
  std::uint32_t obscuranceRays = 8;  // per sample
  std::uint32_t seed = 1;
  float dMax = 0.0f;                 // 0 = the renderer's default
  IndirectModel indirect = IndirectModel::Gather;
  std::uint32_t iterations = 6;      // estimates after the Constant start (paths through hidden
                                     // surfaces carry the object means further: slower to settle)
  std::uint32_t gatherRays = 16;     // Gather: rays per pixel (each hidden hit goes on as a path;
                                     // the smoothing pools a 7x7 window's)
  int gatherSmoothing = 3;           // Gather: window radius of the surface-aware smoothing of B
  std::uint32_t hiddenBounces = kDefaultHiddenBounces; // Gather: path vertices through surfaces the camera does not see
  float unseenReflectance = 0.0f;    // objects no photograph shows, of no seen object's material: this grey
                                     // (0: the seen pixels' mean luminance)
  float constantReflectance = 0.5f;  // Constant: k
  render::AmbientModel ambient = render::AmbientModel::Reached; // of kRecoveryAmbientNames
  FilterOptions filters;
  MergeModel merge = MergeModel::Weighted;
  // The weighted merge's; the kept merge smoothed over a 65 x 65 window (the iterations' over 7 x 7).
  WeightedMergeOptions weighted{.smoothingRadius = 32};
};

// One render's lighting per photo, per unit reflectance, and what the pixels see.
struct Lighting {
  std::vector<std::vector<glm::vec3>> direct;   // [shot][pixel] F V E_i
  // [shot][pixel] D_s / albedo: the direct light per unit reflectance and unit lamp emission, which
  // the relighting state scales by R (F V E_i without E_i, kept whole where a lamp has a black channel).
  std::vector<std::vector<glm::vec3>> directPerEmission;
  std::vector<glm::vec3> emission;              // [shot] E_i, the renderer's emission of the shot's lamp
  std::vector<std::vector<glm::vec3>> indirect; // [shot][pixel] B_i (the obscurance term)
  std::vector<ConfidenceImage> visibility;      // [shot] V_i in [0, 1]
  PixelGeometry geometry;                       // what each pixel sees
  double seconds = 0.0;
};

struct IterationReport {
  std::uint32_t iteration = 0;      // 0 = the Constant estimate
  double seconds = 0.0;             // render + estimate
  double rmsChange = 0.0;           // RMS over confident pixels of R - previous R (0 for the first)
  std::vector<glm::vec3> objectReflectance; // the per-object means the next render uses
};

struct Recovery {
  int width = 0, height = 0;
  std::vector<glm::vec3> reflectance;            // merged and filled, mixed where a footprint covers several surfaces
  // The same before the footprints' mix: the reflectance of the surface each
  // pixel's centre sees. What remodel re-lights: an edit changes what a footprint covers (a removed
  // object's neighbours would keep its share of their mix).
  std::vector<glm::vec3> surfaceReflectance;
  std::vector<float> confidence;                 // sum of the filtered K_i of the lit estimates
  std::vector<float> indirectShots;              // how many indirect-only estimates the pixel has (weighted merge)
  std::vector<float> relativeVariance;           // of the merged R (weighted merge; 1 / sum K_i for the paper's)
  std::vector<std::uint8_t> filled;              // 0 merged, 1 filled from visibility, 2 from the object's mean,
                                                 // 3 from the merged pixels of its surface nearby
                                                 // (of surfaceReflectance: the footprints' mix comes after)
  std::vector<std::vector<glm::vec3>> estimates; // [shot] R_i
  std::vector<ConfidenceImage> visibility;       // [shot] V_i
  std::vector<std::vector<glm::vec3>> direct;    // [shot] F V E_i of the last render
  std::vector<std::vector<glm::vec3>> directPerEmission; // [shot] the same per unit emission (Lighting's)
  std::vector<glm::vec3> emission;               // [shot] E_i (Lighting's)
  std::vector<std::vector<glm::vec3>> indirect;  // [shot] B_i the last estimate used
  std::vector<ConfidenceImage> confidences;      // [shot] filtered K_i
  std::vector<std::int32_t> object;
  std::vector<std::string> objectNames;
  double gatherSeen = 0.0, gatherHidden = 0.0; // Gather: fractions of its rays (photo_gather.h)
  std::vector<IterationReport> iterations;
  std::size_t filledFromSurface = 0, filledFromVisibility = 0, filledFromObject = 0;
  std::size_t mixedFromFootprint = 0; // pixels whose footprint covers several surfaces (pixel_footprint.h)
  std::size_t texturedPixels = 0;     // pixels of textured objects, smoothed within the photographs' noise (weighted_merge.h)
  std::size_t litPixels = 0, indirectOnlyPixels = 0; // merged from a lit estimate / from indirect-only ones alone
  double seconds = 0.0;
};

using RecoveryLog = std::function<void(const std::string&)>;

// The whole recovery. `room` and `bvh` are the glTF as loaded (its own emitters are switched off
// here), `camera` the glTF camera the photos were taken with.
Recovery recoverReflectance(const gpu::Context& context, const scene::Scene& room, const bvh::Bvh& bvh,
                            const scene::Camera& camera, const PhotoSet& photos, const RecoveryOptions& options,
                            const RecoveryLog& log = nullptr);

// One render of the recovery scene with `objectReflectance` per object.
Lighting traceLighting(const gpu::Context& context, const scene::Scene& room, const bvh::Bvh& bvh,
                       const scene::Camera& camera, const PhotoSet& photos,
                       const std::vector<glm::vec3>& objectReflectance, const RecoveryOptions& options);

// Writes `dir` as a relighting state (relight/relight_state.h) of the photographed room whose
// albedo is `recovery`'s reflectance R, with no ray: per shot's lamp, D_s is the lighting render's
// direct light per unit reflectance and emission (recovery.directPerEmission) times R, and its own
// indirect light I_s the B_i the recovery ended with, per unit emission, times R; no lamp has an
// obscurance share (w_s = 0). Relit with one lamp, the state is the recovery's model of that
// photograph, R (F V E_i + B_i). Its lights are the shots' lamps, "shot<i>", so
// `obscura relight DIR --light shot2=0.5` relights the photographed room.
void saveRecoveredState(const std::string& dir, const std::string& scenePath, const PhotoSet& photos,
                        const Recovery& recovery, const RecoveryOptions& options);

// IVR eq. 2 per pixel: C / (direct + indirect), 0 where nothing lights the pixel.
std::vector<glm::vec3> estimateReflectance(const std::vector<glm::vec3>& photo, const std::vector<glm::vec3>& direct,
                                           const std::vector<glm::vec3>& indirect);

// The paper's ambient B_i: k times the photo's mean over the pixels that see a surface.
std::vector<glm::vec3> constantAmbient(const std::vector<glm::vec3>& photo, const std::vector<std::int32_t>& object,
                                       float k);

// The confidence-weighted mean reflectance of each object's pixels; objects with no confident
// pixel get their `photographed` ratio where it has one (the camera sees them, but no estimate
// of theirs merged: slivers and penumbrae), else the mean over the confident pixels of the
// objects of their material (`objectMaterial`), or, with none, a grey of the luminance of the
// mean over all confident pixels (an unknown colour: not the room's dominant one). An object
// the model gives one colour (`oneColour`, see oneColourObjects) takes, before all that, the mean
// over the confident pixels of every such object of its material, where they have any. With
// `modelColour` (modelColours), an object of a material no photograph shows takes the colour the
// model gives it, where it gives one, instead of the grey; a grey the user gives (`unseenGrey`)
// comes before both.
std::vector<glm::vec3> objectMeans(const std::vector<glm::vec3>& reflectance, const std::vector<float>& confidence,
                                   const std::vector<std::int32_t>& object, std::size_t objects,
                                   const std::vector<std::uint32_t>* objectMaterial = nullptr,
                                   const std::vector<std::optional<glm::vec3>>* photographed = nullptr,
                                   std::optional<float> unseenGrey = std::nullopt,
                                   const std::vector<bool>* oneColour = nullptr,
                                   const std::vector<std::optional<glm::vec3>>* modelColour = nullptr);

// Per object, sum_i sum_p C_i(p) / sum_i sum_p (D_i + B_i)(p) per channel over its pixels p and
// the shots i (at most 1): the ratio estimate of its reflectance, the light weighting each
// estimate. What the photographs say of an object none of whose pixels merged; the classroom's
// ceiling bar (16 px, 2 rows, in a penumbra in every shot; true 0.02) took the unknown grey, 0.62.
// None where nothing lights the object's pixels.
std::vector<std::optional<glm::vec3>> photographedRatios(const std::vector<std::vector<glm::vec3>>& photos,
                                                         const std::vector<std::vector<glm::vec3>>& direct,
                                                         const std::vector<std::vector<glm::vec3>>& indirect,
                                                         const std::vector<std::int32_t>& object, std::size_t objects);

} // namespace obscura::recover
