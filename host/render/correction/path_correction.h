// path_correction.h — obscurances that converge to path tracing: the obscurance frame C plus the
// difference to a path-traced frame P of the same view, filtered along surfaces,
//   C' = C + a F[(P - C) / a],
// a the albedo and F an edge-stopping a-trous filter guided by geometry alone
// (shaders/correction_filter.comp). The obscurance frame is the control variate of the paths
// (Rousselle, Jarosz and Novak, "Image-space Control Variates for Rendering", SIGGRAPH Asia 2016,
// §4: the difference to a cheap, correlated estimate is smoother than the image and is filtered
// instead of it): what the ambient model gets wrong (I_a is one intensity for the whole scene, so
// a ceiling over a lit floor gets too little and a face over a contact shadow too much) varies
// slowly over a surface, while the direct light, the contact shadows and the textures stay the
// obscurance frame's. F narrows as the paths grow (iterationsFor), and with enough of them it is
// no filter at all: C' is then P, so the frame is consistent where the obscurances alone keep
// their bias.
//
//   residual  per band: guide, C, and (P - C) / a into whole-frame buffers (correction_residual.comp)
//   filter    a-trous steps 1, 2, 4, ...; the last writes C' (correction_filter.comp)
//
// C' is a still image of fixed lights: relighting composes C's per-light transport, which the
// paths do not have.
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "gpu/context.h"
#include "io/image_io.h"

namespace obscura::render {

class ObscuranceRenderer;
class PathTracer;

class PathCorrection {
public:
  // The renderer must keep its primary and composed AOVs (the guide, the seen emission) and the
  // path tracer must cover the same frame (in bands of its own); std::invalid_argument otherwise,
  // and InputError when a whole-frame buffer exceeds the device's limit.
  PathCorrection(const gpu::Context& context, const ObscuranceRenderer& renderer, const PathTracer& paths);
  ~PathCorrection();
  PathCorrection(const PathCorrection&) = delete;
  PathCorrection& operator=(const PathCorrection&) = delete;

  // C' from the renderer's frame as its last compose() left it and the paths so far.
  void correct(const ObscuranceRenderer& renderer, const PathTracer& paths);

  // C', linear: channels combined.R/G/B.
  io::Image image() const;
  // GPU milliseconds of the last correct().
  double lastGpuMs() const;
  std::map<std::string, double> lastPassMs() const;
  std::uint32_t lastIterations() const { return lastIterations_; }

  // The filter's a-trous iterations for `paths` paths per pixel: 4 for one path (a B3 cascade of
  // standard deviation ~9 pixels), one fewer each time the paths quadruple (its width halves as
  // their noise does), none from 256 on. Measured on the Cornell box at 128^2 against a
  // 4,096-path reference (docs/BENCHMARKS.md, "Obscurances corrected by paths").
  static std::uint32_t iterationsFor(std::uint32_t paths);

  // The paths a still frame of `spp` obscurance samples is corrected by at the defaults (`render
  // --pt-correction auto`, converge's `obscurance`): none up to the paper's budget of 8 samples,
  // which is what the obscurances are for (at equal noise they are 14x faster than path tracing
  // there); past it, a path for each further sample, and at least kMinDefaultPaths: with fewer the
  // paths' own noise outweighs the bias they remove on a scene of small bright lamps (modern-hall
  // 128x72: 8 spp alone RMSE 0.122; corrected by 1 / 2 / 4 paths 0.168 / 0.123 / 0.111).
  static constexpr std::uint32_t kMinDefaultPaths = 4;
  static std::uint32_t defaultPaths(std::uint32_t spp);

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::uint32_t lastIterations_ = 0;
};

} // namespace obscura::render
