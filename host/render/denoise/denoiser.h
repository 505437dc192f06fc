// denoiser.h — a denoiser for low-sample obscurance frames, in the spirit of SVGF (Schied et al.,
// "Spatiotemporal Variance-Guided Filtering: Real-Time Reconstruction for Path-Traced Global
// Illumination", HPG 2017), on the GPU.
//
// It works on the renderer's composed terms after compose(): the direct term sum_s E_s D_s and
// the ambient term I_a A are divided by the albedo (demodulated, so that textures stay sharp) and
// filtered apart from each other and from the specular paths' light (not demodulated):
//   gather    the frame's terms, guides (normal, depth, albedo, material) and sample counts into
//             whole-frame buffers (one dispatch per band; the whole frame must fit one buffer)
//   reproject after a camera move, the previous frame's terms (its history) seen from the new
//             camera, rejected where normal, depth or material disagree (disocclusions)
//   temporal  the current n-sample mean blended with the reprojected history by sample counts
//             (the renderer's own accumulation is the temporal sum while the camera stays), and
//             each term's luminance variance
//   a-trous   edge-aware wavelet iterations (steps 1, 2, 4, ...) guided by normal, depth (plane
//             distance) and albedo, the luminance weight steered by the variance
//   remodulate x albedo, + specular, + the seen emission (never filtered)
//   edges     the pixels an edge crosses (another surface, in a 1-spp frame, or another emission
//             in the 3x3 around them), resolved from camera rays of their own: each ray takes the
//             filtered light of the neighbour on its surface and its own emission, so silhouettes
//             and emitter borders are covered by K more points; then the tonemap pass
//             (display bytes as ObscuranceRenderer::display(): RGBA8, R in the low byte).
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "gpu/context.h"
#include "io/image_io.h"
#include "shared/host_device.h"

namespace obscura::render {

class ObscuranceRenderer;

struct DenoiserSettings {
  std::uint32_t iterations = 4;         // a-trous iterations (steps 1, 2, 4, 8); 0: no spatial filter
  bool temporal = true;                 // reproject the history across camera moves
  std::uint32_t maxHistorySamples = 16; // the most samples a reprojected history counts for
  float luminanceSigma = 2.0f;          // sigma_l: how many standard deviations of noise a luminance
                                        // step may be and still be filtered over (Schied et al. use 4
                                        // with temporal variances; 2 measured lower error with these
                                        // spatial ones at 4 spp: tests/render/denoise_test.cpp)
  // Camera rays per pixel an edge crosses (denoise_edges.comp): where a geometric edge does (in a
  // 1-spp frame), and the most where an emitter's border does (8 per unit of its emission step
  // over I_a's luminance, at least the geometric count). 0 geometry rays: no edge pass.
  std::uint32_t geometryEdgeRays = 8;
  std::uint32_t emitterEdgeRays = gpu::kMaxEdgeRays;
};

class Denoiser {
public:
  // The renderer must keep its primary and composed AOVs (ObscuranceSettings::primaryAovs and
  // composedAovs, the defaults); std::invalid_argument otherwise. Its resolution is the
  // denoiser's: make a new one for another size.
  Denoiser(const gpu::Context& context, const ObscuranceRenderer& renderer, const DenoiserSettings& settings = {});
  ~Denoiser();
  Denoiser(const Denoiser&) = delete;
  Denoiser& operator=(const Denoiser&) = delete;

  // Forgets the history: the next denoise() uses the current frame alone. Call it after anything
  // but a camera move changed the image (a light or geometry edit, other render settings).
  void reset();
  // Denoises the renderer's frame as its last compose() left it (composeDisplay() does not write
  // the composed terms it reads), seen with the renderer's current camera (settings().camera),
  // which it remembers for the next reprojection; tonemaps with `exposureStops` for display().
  // After a camera move the history is reprojected once and blended with the new frame by sample
  // counts; while the camera stays, the renderer's own accumulation does the temporal work.
  void denoise(const ObscuranceRenderer& renderer, float exposureStops = 0.0f);

  // The tonemapped denoised combined image, RGBA8 per pixel (R in the low byte), row by row.
  std::vector<std::uint32_t> display() const;
  // The denoised combined image, linear: channels combined.R/G/B.
  io::Image image() const;
  // GPU milliseconds of the last denoise(), in all and per pass (gather, reproject, temporal,
  // atrous, remodulate, edges, tonemap).
  double lastGpuMs() const;
  std::map<std::string, double> lastPassMs() const;

  // What the last denoise() took from the history, for tests: channels direct.R/G/B and
  // indirect.R/G/B (demodulated), specular.R/G/B, reprojected to the current camera, and
  // history.N (the samples it counts for; 0 where rejected or where there was no history).
  io::Image reprojectedHistory() const;

  const DenoiserSettings& settings() const { return settings_; }

private:
  struct Impl;
  DenoiserSettings settings_;
  std::unique_ptr<Impl> impl_;
};

} // namespace obscura::render
