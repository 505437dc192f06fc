// convergence_study.h — the renders of `obscura converge` [SPEC §4]: each method (obscurances with
// several budgets and estimators, denoised or not, and path tracing) rendered at a sample count
// with persistent renderers, and the converged references of each family, cached as EXR with a
// .txt naming the settings that made them (convergence.h draws the figures from the curves).
//
// Every obscurance method estimates the same image (ray counts and light sampling change the
// noise, not the expectation), so one converged obscurance render, made with the best
// estimators, is the noise reference of all of them. The denoised methods (render/denoise/) are
// measured the same way: one frame denoised alone, its GPU time counted.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "analysis/image_error.h"
#include "bvh/bvh.h"
#include "gpu/context.h"
#include "io/image_io.h"
#include "render/correction/path_correction.h"
#include "render/denoise/denoiser.h"
#include "render/obscurance_renderer.h"
#include "render/path_tracer.h"
#include "scene/scene.h"

namespace obscura::analysis {


// What a convergence study measures and how: `obscura converge`'s settings.
struct StudySettings {
  std::string scenePath;
  std::string outputDir;
  std::uint32_t width = 256; // per-pixel noise as a user sees it
  std::uint32_t obscuranceMaxSpp = 32; // past the paper's 8, the defaults' points are corrected by paths
  std::uint32_t pathMaxSpp = 256;
  std::uint32_t referenceFactor = 64;   // a reference has this many times the largest curve's spp
  std::uint32_t pathReferenceSpp = 0;   // 0: referenceFactor x pathMaxSpp
  // A merged farm render (`obscura merge`'s EXR of --method pathtrace parts) to take as the path
  // tracing reference instead of rendering it here: the longest render of a study, spread over a
  // cluster (tools/farm/).
  std::string pathReferenceFile;
  std::uint32_t seed = 1;
  float dMax = 0.0f; // 0: the renderer's default
  render::EscapeModel escapes = render::EscapeModel::Auto; // the obscurance methods' (render --escapes)
  float secondaryReflectors = 0.0f; // > 0: one more method, obscurances with secondary reflectors
  std::vector<float> background;    // R,G,B of a sky (render --background); empty: none
  // Camera rays per sample for the emission the camera sees (render --emission-samples auto|K),
  // for each method family; by default the renderers' (K rays where an emitter's edge crosses the
  // pixel, lib/emission_samples.glsl).
  std::uint32_t emissionSamples = gpu::kEdgeEmissionSamples;
  bool emissionAtEdges = true;
  std::uint32_t pathEmissionSamples = gpu::kEdgeEmissionSamples;
  bool pathEmissionAtEdges = true;
  std::string commandLine; // how the study was asked for: written beside each cached reference
};

// A method the study measures (its curve, its figures at its budget).
struct StudyMethod {
  std::string name;
  bool pathTrace = false;
  render::LightSampling lightSampling = render::LightSampling::Spatial;
  std::uint32_t raysPerHit = 5;   // shadow (and obscurance, see below) rays per hit (obscurance methods)
  std::uint32_t budgetSpp = 8;    // the budget its summary is read at
  std::string what;
  float secondaryReflectors = 0.0f; // their marking threshold, 0 = off
  bool denoise = false;             // the frame denoised (render/denoise/), its GPU time counted
  std::uint32_t obscuranceRays = 0; // obscurance rays per hit; 0: raysPerHit
  std::uint32_t emissionSamples = 0; // camera rays per sample for the seen emission; 0: the study's
  bool vertexRaysByThroughput = true; // specular path vertices: rays scaled by throughput, or N per hit
  // Corrected by paths past the paper's budget as `render` is by default (--pt-correction auto,
  // PathCorrection::defaultPaths): those points converge to path tracing's image.
  bool defaultCorrection = false;
  // The paths a frame of `spp` samples of this method is corrected by (0: none).
  std::uint32_t correctionPaths(std::uint32_t spp) const;
};

using render::kPaperSpp;

// The methods a study runs: every obscurance method with its budget, path tracing last; with
// --secondary-reflectors the best obscurance method with them too, and with --emission-samples
// K > 1 the best one without them.
std::vector<StudyMethod> studyMethods(const StudySettings& settings);

// One render of a method: its image, GPU time and rays per pixel.
struct StudyRender {
  io::Image image;
  double gpuMs = 0.0;
  double rays = 0.0;
};

class ConvergenceStudy {
public:
  // `settings.pathReferenceFile`, if any, is checked at once (a wrong reference fails the study
  // before anything is rendered).
  ConvergenceStudy(const StudySettings& settings, const scene::Scene& scene, const bvh::Bvh& bvh,
                   const gpu::Context& context);

  // Method `m` at `spp` samples with `seed`, with the study's persistent renderers: the scene is
  // uploaded and the pipelines are made once per method family, not once per render. A method's
  // first render is preceded by an untimed 1-spp one: lavapipe compiles a kernel variant on its
  // first dispatch, inside the GPU timestamps (with a cold shader cache the first points of the
  // curves took 0.2-0.9 s instead of 40-60 ms).
  StudyRender render(const StudyMethod& m, std::uint32_t spp, std::uint32_t seed);
  // The converged image of a method, from the cache in the output folder when the same settings
  // made it (the path tracing one from --pt-reference where given).
  io::Image reference(const StudyMethod& m);
  // How converged reference(m) is: its own error, from the difference of the two halves it is
  // the mean of (rendered with different seeds); nullptr where not known (a farm's reference).
  const ImageError* referenceNoise(const std::string& method) const;
  // Obscurance method `name`'s reference composed with the `model` I_a ("global": the paper's,
  // "reached") instead of the Seen one (after reference() of it).
  const io::Image& otherReference(const std::string& model, const std::string& name) const;

  std::uint32_t width() const { return width_; }
  std::uint32_t height() const { return height_; }
  const std::string& stem() const { return stem_; }

private:
  render::PathTraceSettings pathSettings(const StudyMethod& m, std::uint32_t spp, std::uint32_t seed) const;
  // The path tracing reference from a merged farm render, checked to be of this study's image:
  // the same scene (hash), camera, size, depth and sky.
  io::Image farmReference() const;
  static io::Image combinedOnly(const io::Image& image);
  static io::Image meanOf(const io::Image& a, const io::Image& b);
  static ImageError ownNoise(const io::Image& a, const io::Image& b);
  static std::filesystem::path otherPath(std::filesystem::path exr, const std::string& model);

  const StudySettings& o_;
  const scene::Scene& scene_;
  const bvh::Bvh& bvh_;
  const gpu::Context& context_;
  std::unique_ptr<render::ObscuranceRenderer> obscurance_;
  std::unique_ptr<render::Denoiser> denoiser_; // bound to obscurance_'s frame
  std::unique_ptr<render::PathTracer> pathTracer_;
  std::unique_ptr<render::PathCorrection> correction_; // bound to obscurance_'s frame and pathTracer_'s sums
  std::set<std::string> warmedUp_; // methods rendered once, untimed
  scene::Camera camera_;
  std::uint32_t width_ = 0, height_ = 0;
  std::string stem_;
  mutable render::RenderStats statsCopy_;
  std::map<std::string, std::map<std::string, io::Image>> otherReferences_; // model -> method -> image
  io::Image farmReference_; // --pt-reference
  std::map<std::string, ImageError> referenceNoise_; // method -> its reference's own error
};

} // namespace obscura::analysis
