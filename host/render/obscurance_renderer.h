// obscurance_renderer.h — ray-traced obscurances [RTO] as a renderer that lives across frames.
//
// Made once per scene and view; it holds resources by lifetime:
//   scene  SceneBuffers (geometry, BVH, materials, textures), the light set and its GPU buffers,
//          the ambient term (what each light reaches, for I_a)
//   frame  ObscuranceFrame (G-buffer, basis sums D_s, M_s, S_s per light, ambient sums A, the
//          specular paths and queue, kept rays, composed AOVs, resolved transport, display bytes,
//          ray counters), split into bands
//   pass   one small class per pass owning its kernel (render/passes/): primary, shadow,
//          obscurance, specular, dirty (geometry edits), compose, tonemap, resolve, light mix
// and offers what a frame loop needs: reset(), iterate(n), compose() / composeDisplay(), image(),
// plus the edits an EditSession (session/edit_session.h) drives: lights added and removed,
// emissions, geometry replaced with only the pixels it can change retraced.
//
//   iterate: primary.comp -> G-buffer -> shadow.comp     -> D_s (per light, unit E_s)
//                                     -> obscurance.comp -> A, W
//                                     -> specular passes -> S_s, A^spec along specular paths
//   compose: C = sum_s E_s (D_s + M_s + S_s) + I_a(E) (A + A^spec)  [SPEC §3] — a light edit
//            reruns this alone (composeDisplay: resolve once, then the light mix).
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bvh/bvh.h"
#include "gpu/command_stream.h"
#include "gpu/context.h"
#include "gpu/timestamps.h"
#include "io/image_io.h"
#include "render/aovs.h"
#include "render/frame/obscurance_frame.h"
#include "render/geometry_retrace.h"
#include "render/gpu_ray_batch.h"
#include "render/light_reach_model.h"
#include "render/passes/compose_pass.h"
#include "render/passes/light_mix_pass.h"
#include "render/passes/resolve_pass.h"
#include "render/passes/obscurance_pass.h"
#include "render/passes/primary_pass.h"
#include "render/passes/shading_inputs.h"
#include "render/passes/shadow_pass.h"
#include "render/passes/specular_pass.h"
#include "render/passes/tonemap_pass.h"
#include "render/scene_data/ambient.h"
#include "render/scene_data/free_path.h"
#include "render/scene_data/light_set.h"
#include "render/scene_data/scene_buffers.h"
#include "render/transport.h"
#include "core/names.h"
#include "scene/scene.h"

namespace obscura::render {

enum class RhoKind : std::uint32_t { Sqrt = 0, Exp = 1, Ao = 2 };
// --rho, the window's panel and scripts, job descriptions.
inline constexpr NameTable<RhoKind, 3> kRhoKindNames{
    {{"sqrt", RhoKind::Sqrt}, {"exp", RhoKind::Exp}, {"ao", RhoKind::Ao}}};

// How the shadow pass spends its rays [SPEC §1.3, IVR §3.1].
enum class ShadowSampling {
  Selection, // shadowRays per hit, each to a light chosen by power (the obscurance paper's)
  PerLight,  // every light alone, 4 rays per hit, up to 64 in penumbrae, one to a point light (exact)
             // (the relighting paper's):
             // each D_s is independent of the other lights' powers, and a light of zero power
             // still gets transport, so switching it on later is a clean relight
};

inline constexpr NameTable<ShadowSampling, 2> kShadowSamplingNames{
    {{"selection", ShadowSampling::Selection}, {"per-light", ShadowSampling::PerLight}}};

// What an obscurance ray that meets nothing within dMax brings (kFlagDarkEscapes). The paper's
// Ambient: I_a from R_ave, whatever lies beyond. Dark (OURS): the ray is traced on, and if it
// leaves the scene it brings nothing, for what lies outside is the background, a light whose
// direct light is sampled, and no surface sends ambient light from there. It lowered the bias
// against path tracing by 23 % on the Cornell box (its open front) and 8 % on modern-hall
// (docs/BENCHMARKS.md, "Rays that leave the scene"). Auto: Dark where some of the free-path rays
// from the renderer's first camera leave the scene (free_path.h), Ambient in a closed scene,
// where the extra rays would always find a surface.
enum class EscapeModel { Auto, Dark, Ambient };
inline constexpr NameTable<EscapeModel, 3> kEscapeModelNames{
    {{"auto", EscapeModel::Auto}, {"dark", EscapeModel::Dark}, {"ambient", EscapeModel::Ambient}}};

// The obscurance rays' directions (ObscuranceSettings::systematic) and the rays at a specular
// path's vertices (ObscuranceSettings::vertexRaysByThroughput): two-valued options with names.
inline constexpr NameTable<bool, 2> kObscuranceSamplingNames{{{"systematic", true}, {"random", false}}};
inline constexpr NameTable<bool, 2> kVertexRaysNames{{{"throughput", true}, {"per-hit", false}}};

// The paper's budget [RTO §4.1]: 8 primary samples with 5 shadow and 5 obscurance rays per hit
// (the benchmarks' frame, converge's obscurance-5+5).
inline constexpr std::uint32_t kPaperSpp = 8, kPaperShadowRays = 5, kPaperObscuranceRays = 5;

struct ObscuranceSettings {
  std::uint32_t width = 512, height = 512;
  std::uint32_t spp = 8;             // primary samples (iterations) per pixel
  // A part of a frame (a render farm's task, host/farm/): the accumulation starts at sample
  // `firstSample` of the frame's sequence (the same seeds and sub-pixel positions a single process
  // gives those samples), and the frame holds only the rows `rows` of the width x height image
  // (every pixel as the whole frame would render it). Only for a renderer that does not edit
  // (editableGeometry false, no kept rays).
  std::uint32_t firstSample = 0;
  RowRange rows;
  // Camera rays per primary sample for the emission the camera sees (M_s), 1..64: above 1, that
  // many cheap rays of their own (a closest hit, no shading) estimate it instead of the primary
  // ray, which sharpens the edges of bright emitters seen directly (lib/emission_samples.glsl);
  // with `emissionAtEdges` (the default, --emission-samples auto) only in the pixels an emitter's
  // edge crosses, found by probing each pixel's corners at its first sample.
  std::uint32_t emissionSamples = gpu::kEdgeEmissionSamples;
  bool emissionAtEdges = true;
  std::uint32_t seed = 1;
  scene::Camera camera;
  // N_s and N_obs per hit. The paper's ten rays per hit are spent as 8 + 2 where its budget
  // splits them 5 + 5 (kPaperShadowRays): on modern-hall the direct light holds 2/3 of the noise
  // and the obscurance 2 %, and at 8 spp the split measured 15.6x path tracing's speed where 5 + 5
  // gives 10.1x, on the Cornell box 24.2x against 26.0x (docs/BENCHMARKS.md, converge at the
  // defaults).
  std::uint32_t shadowRays = 8;
  std::uint32_t obscuranceRays = 2;
  RhoKind rho = RhoKind::Sqrt;
  float tau = 3.0f;                  // for RhoKind::Exp
  float dMax = 0.0f;                 // 0 = half the median free path seen from the camera the
                                     // renderer was made with (render/scene_data/free_path.h)
  bool systematic = true;            // [RTO §4.2]
  bool colourBleeding = true;        // W_c [RTO eq. 6]; false: grey W [RTO eq. 2]
  EscapeModel escapes = EscapeModel::Auto; // obscurance rays that leave the scene (above)
  std::uint32_t maxDepth = 6;        // specular paths: scattering vertices, the primary hit is 1
  // A specular path's vertices gather with N_s and N_obs scaled by the path's throughput there
  // (at least one ray of each kind; the mean is the same, the rays go where they count:
  // specular.comp, raysAtVertex); false: N_s and N_obs at every vertex, as at a primary hit.
  bool vertexRaysByThroughput = true;
  std::uint64_t maxBufferBytes = 0;  // per-buffer limit for frame bands; 0 = the device's
  std::uint64_t maxTexelElements = 0; // per texel view (maxTexelBufferElements); 0 = the device's
  // What the frame keeps (only what is asked for is allocated): the primary pass's AOVs (albedo,
  // normal, depth, ...), and all composed AOVs or `combined` alone.
  bool primaryAovs = true;
  bool composedAovs = true;
  // Lights addLight may add (their basis buffers are reserved up front; 4 bytes x 16 per pixel
  // each). `relight --edits` reserves one per add_light edit.
  std::uint32_t spareLightSlots = 0;
  // Samples (the first ones) whose rays the frame keeps, within kKeptRayBytes and one buffer of a
  // band: the specular paths' lobe hits (80 bytes per pixel, glossy scenes) and the shadow rays at
  // the primary hits and the paths' vertices (16 bytes each; N_s up to gpu::kMaxKeptShadowRays,
  // light selection only). An added light's gather and a geometry
  // edit's probes then follow those samples' rays without tracing or drawing them again
  // (shaders/lib/kept_rays.glsl). Programs that edit (relight --edits, the window) ask for them;
  // a plain render keeps none.
  std::uint32_t keptRaySamples = 0;
  ShadowSampling shadowSampling = ShadowSampling::Selection;
  LightSampling lightSampling = LightSampling::Spatial;
  AmbientModel ambient = AmbientModel::Reached; // which surfaces share a light's flux in I_a
  // Important secondary reflectors [RTO §2.2, §6] (render/scene_data/secondary_reflectors.h): 0 = off;
  // > 0 = the marking threshold (a triangle lit at least this many times its light's mean direct
  // irradiance is marked). Needs ShadowSampling::Selection. With them on, adding or removing a
  // light and a geometry edit mark anew and retrace every pixel.
  float secondaryReflectors = 0.0f;
  // How a geometry edit finds the pixels to retrace (dirty.comp): Bounds retraces every pixel
  // whose rays' bounds (hit box, shafts to the lights, dMax, specular paths' boxes) may meet a
  // changed box; Probe replays those pixels' rays first and retraces only those one of whose rays
  // does (lib/probe.glsl). Both retrace every pixel that can change. Auto probes where the frame
  // has specular paths (a path that left the scene bounds nothing, so the bounds keep most glossy
  // pixels) or keeps every sample's rays (keptRaySamples: the probes then draw no light sample).
  // Otherwise the pixels a probe clears are those with the cheapest rays, and on lavapipe the
  // replay (light selection above all) costs what their retrace would (docs/BENCHMARKS.md,
  // "Geometry edits: probing").
  DirtyTest dirtyTest = DirtyTest::Auto;
  // Whether the scene may be edited (updateGeometry, addEmitter): only then does the primary pass
  // keep each pixel's box of hits that the edits' dirty test reads. A render that is written out
  // and done (`render`, the benchmarks) sets it false; fixed when the renderer is made.
  bool editableGeometry = true;
};

// The most device memory the kept rays may take (ObscuranceSettings::keptRaySamples), and at
// most a third of the device's: with 5 shadow rays per hit (560 bytes per pixel and sample), 9
// samples at 400x300. One band's buffer holding them is the tighter bound on lavapipe (128 MiB:
// 2 samples at 400x300).
inline constexpr std::uint64_t kKeptRayBytes = 640ull << 20;

// dMax used when the settings leave it 0: a quarter of the scene's largest extent.
float defaultDMax(const scene::Bounds& bounds);

// The AOVs of an obscurance render, in EXR layer order [RTO fig. 5].
const std::vector<std::string>& obscuranceAovNames();

// Whether any triangle has a glossy material: only then does the specular pass run.
bool sceneHasGlossy(const scene::Scene& scene);

// Its jobs beside the sample loop, compose and read-back live in units of their own:
// GeometryRetrace (render/geometry_retrace.h) finds and retraces what a geometry edit changes,
// LightReachModel (render/light_reach_model.h) measures what each light reaches for I_a.
class ObscuranceRenderer : private SampleRecorder {
public:
  ObscuranceRenderer(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                     const ObscuranceSettings& settings);

  // New per-sample parameters (rays, rho, dmax, sampling, seed, camera, spp); what the renderer
  // was made for must stay (resolution, AOVs, ambient model, editableGeometry: a logic_error).
  // Restarts the accumulation.
  void configure(const ObscuranceSettings& settings);
  // Forgets every sample (the next iterate starts at sample 0) and the ray counters.
  void reset();
  // Adds `samples` progressive samples: one primary sample per pixel with its shadow, obscurance
  // and specular rays each. Several samples share one submission.
  void iterate(std::uint32_t samples, const ProgressFn& progress = nullptr);
  // reset() + iterate(settings.spp) + compose(): one finished frame.
  void render(const ProgressFn& progress = nullptr);

  // The emission scales E_s compose uses (default: the scene's own). I_a follows them [SPEC §3].
  void setEmissions(const std::vector<glm::vec3>& emissions);
  // Which I_a compose uses (no ray: I_a only weighs the ambient sums). Reached needs a renderer
  // made with AmbientModel::Reached or Seen (its reach was measured; Seen is fitted on first use);
  // Global is always there.
  void setAmbientModel(AmbientModel model);
  const std::vector<glm::vec3>& emissions() const { return emissions_; }
  // Composes the AOVs on the GPU with the current emissions, then tonemaps `combined` to the
  // display bytes with `exposureStops`.
  void compose(float exposureStops = 0.0f);

  // The AOVs the frame keeps (all of obscuranceAovNames() by default) as image channels, from the
  // last compose().
  io::Image image() const;
  // The per-light transport so far, resolved on the host (what relighting keeps).
  Transport transport() const;
  // One RGB layer per light with the current E_s (render/transport.h lightLayers).
  io::Image lightLayers() const { return render::lightLayers(transport(), emissions_, ambient_.weight); }
  // The display bytes alone, the fast way a light edit takes: the sums are resolved once to
  // shared-exponent transport per light (again only after new samples or lights), then one pass
  // composes and tonemaps combined. Agrees with compose() to 2 display levels (LightMix.*).
  void composeDisplay(float exposureStops = 0.0f);
  // The tonemapped combined image of the last compose() or composeDisplay(), RGBA8 per pixel
  // (R in the low byte).
  std::vector<std::uint32_t> display() const;

  // Light edits that trace rays. addLight traces only the new light's shadow rays, from the same
  // primary hits as the frame's samples (the G-buffer is made again per sample), sampled alone
  // (4 rays per hit, up to 64 in penumbrae; one to a point light), into a new basis buffer, and
  // along the frame's specular paths (specular.comp followed again); removeLight drops one. Both
  // update I_a. Indices shift like a vector's.
  std::size_t addLight(const scene::PunctualLight& light);
  void removeLight(std::size_t index);
  // Compiles the kernels that only edits use (the probes of a geometry edit, the passes for one
  // light alone), which are otherwise compiled on an edit's first dispatch: a program that will
  // edit (relight --edits, the window) calls this first, so that the first edit's time is its own.
  void prepareForEdits() const;
  // A geometry edit [IVR §3.3]: `edited` (with its BVH) replaces the scene — the same lights,
  // materials and camera — and `changed` holds the world boxes of what changed (an object's old
  // and new places). Only the pixels those can change (dirty.comp) are retraced, for every sample
  // so far with the same seeds, so every pixel ends as a full render of `edited` would make it;
  // the others keep their sums bit for bit. `edited` must outlive the renderer. Returns the
  // pixels retraced. Moving an emitter retraces every pixel.
  std::uint64_t updateGeometry(const scene::Scene& edited, const bvh::Bvh& bvh,
                               const std::vector<scene::Bounds>& changed);
  // Adds an area light that is also geometry (an emissive quad, scene::insertEmissiveQuad):
  // `edited` is the scene with one light group more, the last, and `changed` the new object's box.
  // The new light's rays are traced at every pixel and along the frame's specular paths, as
  // addLight does, and the pixels the new surface can change (it is seen, casts shadows and
  // occludes) are retraced for every light, as updateGeometry does. Its light index is that of
  // its group (area lights come first). Returns the pixels retraced.
  std::uint64_t addEmitter(const scene::Scene& edited, const bvh::Bvh& bvh, const std::vector<scene::Bounds>& changed);

  // The index of the light named `name`; InputError listing the names when there is none.
  std::size_t lightIndex(const std::string& name) const;

  const LightSet& lights() const { return lights_; }
  const AmbientTerm& ambient() const { return ambient_; }
  glm::vec3 ambientIntensity() const { return ambient_.intensity(emissions_); }
  float dMax() const { return dMax_; }
  // Whether obscurance rays that leave the scene bring nothing (EscapeModel, resolved).
  bool darkEscapes() const {
    return settings_.escapes == EscapeModel::Dark || (settings_.escapes == EscapeModel::Auto && openScene_);
  }
  std::uint32_t samples() const { return frame_.progress().samples; }
  // The samples each pixel's sums hold, row by row (compose divides by them): samples() everywhere
  // once a frame or an edit's retrace is done.
  std::vector<std::uint32_t> sampleCounts() const;
  // The frame's sums as they are, not divided by the sample counts (what a farm's part keeps so
  // that parts merge exactly, host/farm/): the per-light transport's sums, the primary pass's AOV
  // accumulators (gpu::kAovSlots vec4 sums a pixel, kAovIds as written; when the frame keeps them
  // and `withPrimaryAovs`) and the counts.
  struct Sums {
    Transport transport;                   // sums, not means
    std::vector<glm::vec4> primaryAovs;    // [pixel * kAovSlots + slot]; empty without primary AOVs
    std::vector<std::uint32_t> counts;     // [pixel]
  };
  Sums sums(bool withPrimaryAovs = true) const;
  const ObscuranceSettings& settings() const { return settings_; }
  const FrameLayout& layout() const { return frame_.layout(); }
  // The frame's buffers, for passes outside the renderer that read them (the denoiser).
  const ObscuranceFrame& frame() const { return frame_; }
  // What a pass outside the renderer that traces its scene binds (the denoiser's edge rays): the
  // scene's buffers and what its kernels are specialised for (both change with geometry edits),
  // the lights' render-time emission scales (which make M_s unit) and the E_s compose uses.
  const SceneBuffers& sceneBuffers() const { return sceneBuffers_; }
  const SceneSpecialisation& sceneKernels() const { return sceneKernels_; }
  const gpu::Buffer& lightScales() const { return lightBuffers_.scales; }
  const gpu::Buffer& composeEmissions() const { return emissionBuffer_; }
  // The camera the primary pass sees the scene with: gpuCamera with the background light's slot.
  gpu::GpuCamera primaryCamera() const;
  bool specular() const { return runSpecular_; }
  // Per-pass GPU ms and rays since the last reset, wall time, memory, truncations, notes.
  RenderStats stats() const;
  // The last measurement of what the lights reach (the Reached ambient model, on the device): rays
  // traced and wall ms; after a move, only the rays it could change.
  using ReachUpdate = LightReachModel::Update;
  ReachUpdate lastReachUpdate() const { return reach_.lastUpdate(); }
  // Triangles marked as important secondary reflectors (0 when they are off).
  std::uint32_t secondaryReflectors() const { return reflectorsMarked_; }
  // Bytes of device memory held: scene, lights and frame (the real allocations).
  std::uint64_t deviceBytes() const;
  // The compact traversal stack the tracing passes' kernels keep (0: the general stack).
  std::uint32_t compactStackVectors() const { return sceneKernels_.compactStackVectors; }

private:
  // What the shading passes' kernels are specialised for: the frame's bands, the flat light
  // selection where this render can take no other, and the scene (settings_, frame_ and
  // sceneKernels_ are made first).
  ShadingSpecialisation shadingKernels() const {
    return shadingSpecialisation(frame_.layout().bandCount(), settings_.lightSampling == LightSampling::Spatial,
                                 frame_.lightCapacity(), sceneKernels_);
  }
  // Makes the tracing passes again for what a scene needs (SceneBuffers::specialisation); bind
  // them after.
  void makeTracingPasses(const SceneSpecialisation& scene);
  // The light tables to the device (refilled in place where they fit); `bind`: bind every kernel
  // again even where no table was made anew (the scene's buffers were).
  void uploadLights(bool bind = false);
  // Records `record(band)` for every band of the frame, timed as one pass named `label`.
  template <class Record>
  void recordBands(const vk::raii::CommandBuffer& cmd, const std::string& label, Record&& record) {
    timestamps_.time(cmd, label, [&] {
      for (std::uint32_t b = 0; b < frame_.layout().bandCount(); ++b) record(b);
    });
  }
  // What the reach model reads of the renderer: the lights, the Seen view (with that model), I_a's depth.
  LightReachModel::Inputs reachInputs() const;
  SeenView seenView() const; // the camera and obscurance settings the Seen fit uses
  // Marks the secondary reflectors from the measured reach (settings_.secondaryReflectors > 0).
  void markReflectors();
  bool reflectorsOn() const { return settings_.secondaryReflectors > 0.0f; }
  // Every sample so far again, every pixel (an edit that changed what the reflectors are).
  void retraceAll();
  void bindAll();
  // The new light `light`'s rays at every pixel and along the specular paths of every sample so
  // far, the light sampled alone (addLight, addEmitter).
  void traceAddedLight(std::uint32_t light);
  // The geometry half of an edit: `edited` replaces the scene (buffers, reach, lights whose
  // emitters moved). Returns whether emitters moved (then every pixel may change).
  // `changed`: the boxes of a move or removal (null: anything may have changed, e.g. an insert).
  bool replaceScene(const scene::Scene& edited, const bvh::Bvh& bvh, const std::vector<scene::Bounds>* changed);
  // Clears and retraces, for every sample so far, the pixels `changed` can change (all of them
  // with `everyPixel`). `tracedLight`, a new light traced at every pixel, is left out of the
  // shadow-segment test. Returns how many.
  std::uint64_t retraceDirty(const std::vector<scene::Bounds>& changed, bool everyPixel,
                             std::uint32_t tracedLight = gpu::kInvalidIndex);
  // The reach of an edited scene was measured beside the edit's GPU work: applied now.
  void finishReach() { reach_.finish(reachInputs(), ambient_); }
  // What every shading dispatch of sample `sample` shares (the settings, I_a's constants).
  ShadeSample shadeSample(std::uint32_t sample) const;
  // Sample `sample`'s primary dispatch over every pixel, summing.
  PrimaryPass::Dispatch primaryDispatch(std::uint32_t sample) const;
  // Whether the frame keeps sample `sample`'s rays: for a pass that writes them, or (`replaying`)
  // for one that follows them, only while they are the current scene's.
  bool keptRays(std::uint32_t sample, bool replaying) const;
  std::vector<glm::vec4> downloadBand(const gpu::Buffer& buffer) const;

  const gpu::Context* context_;
  const scene::Scene* scene_;
  ObscuranceSettings settings_;
  float dMax_ = 0.0f;
  float defaultDMax_ = 0.0f; // measured once, at construction (stable across camera and geometry edits)
  bool openScene_ = false;   // some of the same measurement's rays left the scene (EscapeModel::Auto)
  bool runSpecular_ = false;
  std::vector<glm::vec3> meanAlbedo_;

  // Scene lifetime.
  SceneBuffers sceneBuffers_;
  LightSet lights_;
  AmbientTerm ambient_;
  std::uint32_t reflectorsMarked_ = 0;       // triangles marked as secondary reflectors
  float unmarkedFirstBounce_ = 1.0f;         // r of secondary_reflectors.h
  LightBuffers lightBuffers_;
  std::vector<glm::vec3> emissions_; // what compose uses
  gpu::Buffer emissionBuffer_;

  // Frame lifetime.
  ObscuranceFrame frame_; // its buffers and progress (samples, the G-buffer's sample, what is resolved)
  FrameProgress& progress() { return frame_.progress(); }
  const FrameProgress& progress() const { return frame_.progress(); }

  // Passes. Those that trace (primary to specular) are specialised for the scene
  // (sceneKernels_: the compact traversal stack its BVH needs, the texture kinds its materials
  // use); an edit whose scene needs more makes them again (makeTracingPasses).
  SceneSpecialisation sceneKernels_;
  PrimaryPass primary_;
  ShadowPass shadow_;
  ObscurancePass obscurance_;
  SpecularPass specularPass_;
  ComposePass compose_;
  TonemapPass tonemap_;
  ResolvePass resolve_;
  LightMixPass lightMix_;
  GeometryRetrace geometry_; // the dirty test and retrace of geometry edits, the kept rays' validity
  float sceneScale_ = 1.0f; // the ray-origin offset's scale, kept across geometry edits
  // Sample `sample`'s passes over every pixel, or the dirty list's (a retrace), or probing its
  // candidates (lib/probe.glsl, timed as "probe.<pass>"); `tracePrimary` false: the G-buffer holds
  // the sample already.
  void recordSample(const vk::raii::CommandBuffer& cmd, std::uint32_t sample, SampleMode mode,
                    bool tracePrimary = true) override;

  gpu::CommandStream stream_;
  gpu::Timestamps timestamps_;
  double wallSeconds_ = 0.0;
  // What each light reaches (for I_a and the reflectors), its rays traced on the device through
  // reachRays_ (the scene's buffers and traversal). Last: its destructor waits for a measurement
  // still running beside an edit (CPU rays), which reads the members above.
  std::unique_ptr<GpuRayBatch> reachRays_;
  void useReachRays(); // made (again) for the scene's buffers and kernels
  LightReachModel reach_;
};

} // namespace obscura::render
