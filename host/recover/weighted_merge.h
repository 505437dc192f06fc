// weighted_merge.h — the per-photo reflectance estimates merged by their expected error, with
// the pixels no lamp lights recovered from their indirect light (OURS, extending IVR eq. 3's
// confidence-weighted mean, which leaves pixels in every lamp's shadow to fills):
//
//   R = sum_i w_i R_i / sum_i w_i,    w_i = K_i / v_i,    R_i = C_i / (D_i + B_i)   (IVR eq. 2)
//
// v_i is R_i's relative variance by first-order error propagation:
//
//   v_i = (sigma_i / C_i)^2 + (e_B m_i B_i / (D_i + B_i))^2
//
//   sigma_i  the photograph's noise at the pixel, estimated from the photographs themselves
//            (shotNoise: the spread of the pixel about its neighbours on the same surface, in
//            the photograph over the other shots' sum, where a texture cancels);
//   e_B      the relative uncertainty of the modelled indirect light B (options below). The
//            direct light D is traced exactly (a point lamp, exact visibility), so a directly lit
//            estimate is as good as its photograph; one lit only indirectly is as good as B.
//   m_i      the share of B_i that rests on the gather's longer reach (PhotoGather::gather's
//            `modelled`: what its hidden hits pass on beyond their own direct light); 1 where
//            the caller has none (the constant and obscurance models). A shot whose light
//            reaches the pixel through the photographs or one hidden bounce outweighs one
//            whose light comes the long way round.
//
// K_i is the paper's filtered confidence where lamp i lights the pixel (confidence_filters.h).
// Where the pixel and its whole (2 r + 1)^2 window lie in lamp i's shadow (V_i = 0 there, the
// same window the min filter distrusts at shadow edges), R_i = C_i / B_i is an indirect-only
// estimate and gets K_i = 1: its v_i >= e_B^2 keeps its weight far below a lit one's, so it
// decides only pixels that no lamp lights. An estimate above 1 (beyond 3 sigma of its photo's
// noise) is left out: no diffuse surface reflects more than it receives, so the lighting model
// is what is wrong there (a pixel that mixes surfaces, a hotspot the point lamp misses). A sliver of a surface (less than two thirds of its
// 3x3 window on it: a face seen edge-on) gets none: its mean point and normal mix two faces.
//
// The merged R is then smoothed along surfaces by its noise (smoothByNoise, its tolerance with
// e_B on all of B, m_i = 1): each pixel averages the pixels of its window that see the same
// object with the same normal and whose R agrees with its own within `agreement` standard
// deviations (a sigma filter, Lee 1983), weighted by their inverse variances. A flat wall's noise
// averages out; a texture edge, larger than the noise, stays sharp.
//
// That tolerance holds B's whole error, which neighbours share, so on a surface lit mostly by
// indirect light it is wide (e_B = 0.25: neighbours within ~50 % pool) and pools a texture's
// levels: the staircase's wallpapers kept 60-83 % of their contrast. On an object whose
// neighbouring pixels differ by more than their independent noise allows (surfaceTextures) the
// tolerance is that noise alone: the photographs' noise, which differs from pixel to pixel.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "recover/confidence_filters.h"
#include "recover/photo_gather.h"

namespace obscura::recover {

// What surfaceTextures (below) judges an object: of one colour, textured, or not at all.
enum class SurfaceTexture : std::uint8_t { Unjudged, Plain, Textured };

struct WeightedMergeOptions {
  float indirectUncertainty = 0.25f; // e_B: relative error of the modelled indirect light
  int shadowRadius = 2;              // the window an indirect-only estimate must be in shadow over
  int smoothingRadius = 3;           // smoothByNoise's window radius (0: no smoothing; the recovery's is
                                     // RecoveryOptions' and wider)
  float agreement = 2.5f;            // smoothByNoise: standard deviations within which pixels pool
};

// sigma^2 per pixel of a photograph (luminance), from the squared differences between each pixel
// and the mean of its same-surface 3x3 neighbours, averaged over its same-surface 5x5 window.
// A texture's own variation counts as noise here (shotNoise below takes it out).
std::vector<float> photoNoise(const std::vector<glm::vec3>& photo, const PixelGeometry& pixels);

// sigma^2 per pixel of photograph `shot` of `photos` (luminance), with the reflectance's texture
// taken out: photoNoise of the ratio C_i / S, S = the sum of the other shots' photographs, where
// the texture (a factor of every shot alike) cancels and what varies between neighbours is the
// lighting's ratio, smooth on a surface, and the noise, scaled back to C_i's units (S's own
// noise adds to it: an overestimate where the other shots are dim). The smaller of that and
// photoNoise(C_i): at a shadow edge the ratio steps and the photograph alone is the better
// measure. On a flat wall the two agree; on the staircase's wallpaper photoNoise counted the
// pattern as noise, and the smoothing by noise then blurred it (BENCHMARKS).
std::vector<float> shotNoise(const std::vector<std::vector<glm::vec3>>& photos, std::size_t shot,
                             const PixelGeometry& pixels);

struct WeightedMerge {
  std::vector<glm::vec3> reflectance;       // merged (smoothed when asked); 0 where nothing informs
  std::vector<float> relativeVariance;      // of the merged R with e_B on all of B (1 / sum w_i at m_i = 1);
                                            // 0 where nothing informs
  // Of the merged R, from the photographs' noise alone (sum_i w_i^2 sigma_i^2 / C_i^2 / (sum_i w_i)^2):
  // what differs from pixel to pixel, where B's error is shared by neighbours. 0 where nothing informs.
  std::vector<float> independentVariance;
  // Per object, surfaceTextures' verdict: a textured object is smoothed within independentVariance,
  // a plain one's pixels the filters emptied take its mean (reflectance_recovery.cpp).
  std::vector<SurfaceTexture> objectTextures;
  // The verdict on a pixel's object; Unjudged where none was made (the paper's merge) or the pixel
  // sees nothing (object -1).
  SurfaceTexture textureOf(std::int32_t object) const {
    return object >= 0 && std::size_t(object) < objectTextures.size() ? objectTextures[std::size_t(object)]
                                                                       : SurfaceTexture::Unjudged;
  }
  std::vector<glm::vec3> unsmoothed;        // the merged R before the smoothing (and before its clamp at 1)
  std::vector<float> directConfidence;      // sum of the paper's K_i over the lit estimates
  std::vector<float> indirectShots;         // how many indirect-only estimates the pixel has
  std::vector<std::vector<float>> weights;  // [shot][pixel] w_i (direct or indirect-only)
};

// `photos[i]` the photographs, `direct[i]` / `indirect[i]` D_i and B_i per unit reflectance,
// `estimates[i]` R_i, `confidences[i]` the paper's filtered K_i, `visibility[i]` the raw V_i,
// `modelled[i]` m_i (none: 1).
WeightedMerge weightedMerge(const std::vector<std::vector<glm::vec3>>& photos,
                            const std::vector<std::vector<glm::vec3>>& direct,
                            const std::vector<std::vector<glm::vec3>>& indirect,
                            const std::vector<std::vector<glm::vec3>>& estimates,
                            const std::vector<ConfidenceImage>& confidences,
                            const std::vector<ConfidenceImage>& visibility, const PixelGeometry& pixels,
                            const WeightedMergeOptions& options,
                            const std::vector<std::vector<float>>* modelled = nullptr);

// A pixel the merge left without an estimate (relativeVariance 0) that some lamp still lights:
// the inverse-variance mean of the merged pixels within kSurfaceFillRadius that see its surface
// (its object, normals within dot 0.95), when there are at least kSurfaceFillSupport of them.
// The paper's filters leave such a pixel without confidence by a shadow edge or on a sliver of
// its surface, where its own estimates are the lighting model's worst (a partly visible lamp, a
// mean point and normal that mix two faces: the classroom's filled from visibility had RMSE 0.22
// against 0.066 overall); its surface's merged pixels beside it are the better guess, and they
// follow a texture, as its object's mean would not (BENCHMARKS).
inline constexpr int kSurfaceFillRadius = 3;
inline constexpr int kSurfaceFillSupport = 3;
// With `whole`, only the merged pixels whose footprint lies wholly on their surface fill (an edge
// pixel's own estimate divides a mix by one surface's light: the modern hall's black door panel,
// filled from its edge pixels, came out 0.16 RMSE over 425 px, its raw estimates 0.01).
std::optional<glm::vec3> surfaceFill(const WeightedMerge& merged, const PixelGeometry& pixels, std::size_t p,
                                     const std::vector<bool>* whole = nullptr);

// Per object (indexed by object id): whether its merged reflectance has a texture the noise does
// not explain (Textured), has none (Plain), or cannot be judged (Unjudged). Over the pairs of horizontally and vertically neighbouring pixels inside one
// surface (both pixels' 3x3 windows wholly on it: no edge, no pixel that mixes surfaces), the
// median squared difference of their luminances against the median of what their independent
// noise gives it (independentVariance): pure noise puts that ratio near 0.455 (the median of a
// chi-square of one degree), less where the variance is overestimated (0.2-0.5 on the three test
// rooms' plain surfaces, measured against their answer keys). Above kTextureRatio, 4.4 times
// that, the object is textured (the staircase's wallpapers and wood: 3.8-9). Objects with fewer
// than kTexturePairs pairs are not judged (a sliver, or an object whose merged pixels are all
// at its edges).
inline constexpr double kTextureRatio = 2.0;
inline constexpr std::size_t kTexturePairs = 20;
std::vector<SurfaceTexture> surfaceTextures(const std::vector<glm::vec3>& reflectance,
                                            const std::vector<float>& independentVariance, const PixelGeometry& pixels);

// Texture coarser than a pixel, which neighbouring pairs do not see (the hall's marble floor: its
// neighbours agree within the noise, its tiles differ): pairs of an object's pixels
// kCoarseTextureStep apart on one surface, each lit in at least two shots (K_i >= kLitConfidence),
// whose difference in luminance d_i repeats from shot to shot. A texture of the reflectance gives
// every shot the same d; a lamp-dependent error of the modelled light does not. Over the pairs,
// sum of mean_i(d_i)^2 against sum of var_i(d_i) / k (k shots): 1 where the shots only scatter.
// Pixels at an edge are left out (their mix of two surfaces repeats in every shot). Measured at the
// last merge: 1.1-1.4 on the Cornell box's walls, floor and tall box, 2.0 on its short box (87
// pairs), 1.3 on the hall's walls; 7.4 on its floor in photographs of 512 samples (less at 128:
// there the noise hides the tiles, and it stays plain), 2.2-660 on the staircase's wallpapers
// and wood, most of which the neighbours' test already judges textured. The first merge, on the paper's constant ambient, puts up to 5 on plain walls, whose
// verdicts the later merges make again. Above kCoarseTextureRatio, twice kTextureRatio, an
// object is textured.
inline constexpr int kCoarseTextureStep = 4;
inline constexpr double kCoarseTextureRatio = 2.0 * kTextureRatio;
inline constexpr float kLitConfidence = 0.9f;
std::vector<bool> coarselyTextured(const std::vector<std::vector<glm::vec3>>& estimates,
                                   const std::vector<ConfidenceImage>& confidences, const PixelGeometry& pixels);

// A merge's `unsmoothed` R smoothed (smoothByNoise over `radius`, 0: none) with the tolerance the
// header describes, relativeVariance or, on a textured object, independentVariance, then clamped
// at 1: weightedMerge's own smoothing, and the recovery's wide pass over the kept merge.
std::vector<glm::vec3> smoothMerge(const WeightedMerge& merged, const PixelGeometry& pixels, int radius,
                                   float agreement, bool acrossNormals = false);

// The sigma filter above on `reflectance` with relative variances `variance` (the weights, and
// the tolerance unless `tolerance` gives the tolerance's own). With `acrossNormals` the window's
// pixels of the centre's object pool whatever their normal (a reflectance belongs to the object,
// and its faces' indirect light errs apart: the recovery's wide pass; the tolerance still keeps
// apart what differs by more than the noise). Rows in parallel.
std::vector<glm::vec3> smoothByNoise(const std::vector<glm::vec3>& reflectance, const std::vector<float>& variance,
                                     const PixelGeometry& pixels, int radius, float agreement,
                                     const std::vector<float>* tolerance = nullptr, bool acrossNormals = false);

} // namespace obscura::recover
