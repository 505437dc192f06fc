#include "render/obscurance_renderer.h"

#include <algorithm>
#include <atomic>
#include <future>
#include <thread>
#include <chrono>

#include <fmt/format.h>

#include "core/error.h"
#include "render/scene_data/light_tree.h"
#include "render/scene_data/secondary_reflectors.h"
#include "shading/bsdf.h"

namespace obscura::render {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}


const std::vector<std::string> kComposeAovs = {"combined", "direct", "indirect", "specular", "obscurance"};

} // namespace

const std::vector<std::string>& obscuranceAovNames() {
  static const std::vector<std::string> names = {"combined", "direct", "indirect", "specular", "obscurance",
                                                 "albedo", "emission", "normal", "depth", "position",
                                                 "coverage", "primitive", "material", "preview"};
  return names;
}

namespace {

// Shadow rays per primary hit a frame keeps: N_s, where it can keep them.
std::uint32_t keptShadowRays(const ObscuranceSettings& settings) {
  return settings.shadowRays <= gpu::kMaxKeptShadowRays ? settings.shadowRays : 0u;
}

// The samples whose rays a frame keeps: as many as asked, within kKeptRayBytes and a third of
// the device's memory (the frame lowers it to what one band's buffer holds); none where it could
// not keep every shadow ray, nor with per-light shadow sampling.
std::uint32_t keptRaySamples(const gpu::Context& context, const ObscuranceSettings& settings, bool specular) {
  if (settings.keptRaySamples == 0 || keptShadowRays(settings) != settings.shadowRays ||
      settings.shadowSampling != ShadowSampling::Selection)
    return 0;
  const std::uint64_t perSample = std::uint64_t(settings.width) * settings.height *
                                  ObscuranceFrame::keptRayBytesPerSample(keptShadowRays(settings), specular);
  const std::uint64_t budget = std::min(kKeptRayBytes, context.info().deviceLocalBytes / 3);
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(settings.keptRaySamples, budget / std::max<std::uint64_t>(perSample, 1)));
}

// Runs an edit's GPU work while a reach measurement runs on threads of its own; on an exception,
// waits for the measurement before passing it on (it reads the renderer).
template <class T, class Work>
void besideMeasurement(std::future<T>& measurement, Work&& gpuWork) {
  try {
    gpuWork();
  } catch (...) {
    if (measurement.valid()) measurement.wait();
    throw;
  }
}

} // namespace

bool sceneHasGlossy(const scene::Scene& scene) {
  std::vector<bool> glossy;
  for (const auto& m : scene.materials) glossy.push_back(isGlossy(m.metallic, m.roughness));
  for (std::uint32_t m : scene.triangleMaterial)
    if (glossy[m]) return true;
  return false;
}

ObscuranceRenderer::ObscuranceRenderer(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                                       const ObscuranceSettings& settings)
    : context_(&context), scene_(&scene), settings_(settings),
      runSpecular_(sceneHasGlossy(scene) && settings.maxDepth > 1),
      sceneBuffers_(context, scene, bvh), lights_(buildLightSet(scene)),
      frame_(context, settings.width, settings.height, static_cast<std::uint32_t>(lights_.size()),
             FrameContents{.specular = runSpecular_, .primaryAovs = settings.primaryAovs,
                           .composedSlots = settings.composedAovs ? gpu::kComposeSlots : 1u,
                           .spareLightSlots = settings.spareLightSlots,
                           .keptRaySamples = keptRaySamples(context, settings, runSpecular_),
                           .keptShadowRays = keptShadowRays(settings)},
             settings.maxBufferBytes, settings.maxTexelElements, settings.rows),
      sceneKernels_(sceneBuffers_.specialisation()),
      primary_(context, frame_.layout().bandCount(), sceneKernels_, settings.editableGeometry),
      shadow_(context, shadingKernels()),
      obscurance_(context, shadingKernels()), specularPass_(context, shadingKernels()),
      compose_(context, frame_.layout().bandCount()), tonemap_(context, frame_.layout().bandCount()),
      resolve_(context, frame_.layout().bandCount()), lightMix_(context, frame_.layout().bandCount()),
      dirty_(context, frame_.layout().bandCount()), sceneScale_(sceneScale(scene.bounds)),
      stream_(context), timestamps_(context) {
  bvhOrder_ = bvh.order;
  bvhNodes_ = bvh.nodes.size();
  for (const auto& m : scene.materials) meanAlbedo_.push_back(materialMeanAlbedo(m));
  ambient_ = computeAmbient(scene, lights_, meanAlbedo_, settings.colourBleeding);
  if (settings.ambient != AmbientModel::Global) ambient_.model = settings.ambient;
  defaultDMax_ = defaultDMax(scene, bvh, settings.camera); // first: the Seen fit needs dmax
  if (settings.ambient != AmbientModel::Global || settings.secondaryReflectors > 0.0f) measureReach(scene, bvh);
  emissions_ = lights_.emission;
  configure(settings);
  if (reflectorsOn()) markReflectors();
  uploadLights();
}

gpu::GpuCamera ObscuranceRenderer::primaryCamera() const {
  const std::size_t sky = backgroundLight(lights_);
  return gpuCamera(settings_.camera, settings_.width, settings_.height,
                   sky < lights_.size() ? static_cast<std::uint32_t>(sky) : gpu::kInvalidIndex);
}

void ObscuranceRenderer::measureReach(const scene::Scene& scene, const bvh::Bvh& bvh,
                                      const std::vector<scene::Bounds>* changed) {
  applyReach(measureReachOf(scene, bvh, changed));
}

ObscuranceRenderer::ReachMeasurement ObscuranceRenderer::measureReachOf(const scene::Scene& scene, const bvh::Bvh& bvh,
                                                                        const std::vector<scene::Bounds>* changed) const {
  const auto start = Clock::now();
  ReachMeasurement m;
  // Every triangle's mean reflectance: a move or a removal keeps them (averaging modern-hall's
  // textures takes ~0.25 s); an insert brings its own.
  if (!changed || reachReflectance_.size() != scene.triangles.size()) {
    std::vector<glm::vec3> meanAlbedo;
    for (const auto& material : scene.materials) meanAlbedo.push_back(materialMeanAlbedo(material));
    m.reflectance = triangleReflectances(scene, meanAlbedo);
  } else {
    m.reflectance = reachReflectance_;
  }
  m.reached = std::make_unique<ReachedSurfaces>(scene, bvh, m.reflectance);
  if (ambient_.model == AmbientModel::Seen) m.reached->setSeenView(seenView());
  std::vector<scene::Bounds> padded;
  if (changed && reached_) {
    const float pad = changedBoxPadding();
    for (scene::Bounds b : *changed) padded.push_back({b.lo - pad, b.hi + pad});
  }
  m.reach = reachOfEveryLight(*m.reached, changed ? reached_.get() : nullptr, padded);
  for (const LightReach& r : m.reach) m.update.rays += r.rays.traced;
  m.update.ms = 1e3 * secondsSince(start); // the reflectances and surface samples included
  return m;
}

void ObscuranceRenderer::applyReach(ReachMeasurement m) {
  reachReflectance_ = std::move(m.reflectance);
  reached_ = std::move(m.reached);
  ambient_.reach = std::move(m.reach);
  ambient_.depth = settings_.maxDepth;
  updateAmbientWeights(ambient_, lights_, settings_.colourBleeding);
  lastReach_ = m.update;
}

void ObscuranceRenderer::finishReach() {
  if (pendingReach_.valid()) applyReach(pendingReach_.get());
}

SeenView ObscuranceRenderer::seenView() const {
  const scene::Camera& c = settings_.camera;
  return {.position = c.position, .forward = c.forward, .up = c.up, .yfov = c.yfov,
          .aspect = static_cast<float>(settings_.width) / static_cast<float>(std::max(settings_.height, 1u)),
          .dMax = settings_.dMax > 0.0f ? settings_.dMax : defaultDMax_, .rho = static_cast<std::uint32_t>(settings_.rho),
          .tau = settings_.tau, .colourBleeding = settings_.colourBleeding,
          .averageReflectance = ambient_.averageReflectance};
}

std::vector<LightReach> ObscuranceRenderer::reachOfEveryLight(const ReachedSurfaces& reached,
                                                             const ReachedSurfaces* before,
                                                             const std::vector<scene::Bounds>& changed) const {
  const bool incremental = before && ambient_.reach.size() == lights_.size();
  const std::vector<LightReach>& previous = ambient_.reach;
  // Lights spread over the cores (measure is const and draws its own numbers): the CPU rays of
  // modern-hall's 13 lights take ~0.3 s on one core when measured whole.
  std::vector<LightReach> reach(lights_.size());
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t s = next++; s < lights_.size(); s = next++)
      reach[s] = incremental ? reached.remeasure(*before, previous[s], lights_, s, changed) : reached.measure(lights_, s);
  };
  std::vector<std::future<void>> workers;
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  for (unsigned w = 1; w < std::min<std::size_t>(cores, lights_.size()); ++w) workers.push_back(std::async(std::launch::async, worker));
  worker();
  for (auto& w : workers) w.get();
  return reach;
}

void ObscuranceRenderer::measureAllReach() {
  const auto start = Clock::now();
  ambient_.reach = reachOfEveryLight(*reached_, nullptr, {});
  updateAmbientWeights(ambient_, lights_, settings_.colourBleeding);
  lastReach_ = {0, 1e3 * secondsSince(start)};
  for (const LightReach& r : ambient_.reach) lastReach_.rays += r.rays.traced;
}

float ObscuranceRenderer::changedBoxPadding() const {
  const scene::Bounds& bounds = scene_->bounds;
  return 1e-3f * (glm::length(bounds.extent()) + glm::length(glm::max(glm::abs(bounds.lo), glm::abs(bounds.hi))));
}

void ObscuranceRenderer::markReflectors() {
  SecondaryReflectorMarks marks;
  if (reflectorsOn())
    marks = markSecondaryReflectors(*scene_, ambient_.reach, settings_.secondaryReflectors, reached_->totalArea(),
                                    ambient_.model != AmbientModel::Global);
  reflectorsMarked_ = marks.count;
  unmarkedFirstBounce_ = marks.unmarkedFirstBounce;
  sceneBuffers_.setSecondaryReflectors(*scene_, std::move(marks.marked));
}

void ObscuranceRenderer::retraceAll() {
  const std::uint32_t samples = samples_;
  const double wall = wallSeconds_;
  reset();
  wallSeconds_ = wall;
  iterate(samples);
}

void ObscuranceRenderer::configure(const ObscuranceSettings& settings) {
  if (settings.emissionSamples == 0 || settings.emissionSamples > gpu::kMaxEmissionSamples)
    throw InputError(fmt::format("--emission-samples {}: camera rays per sample for the seen emission must be in 1..{}",
                                 settings.emissionSamples, gpu::kMaxEmissionSamples));
  if ((settings.firstSample > 0 || !settings.rows.whole()) && (settings.editableGeometry || settings.keptRaySamples > 0))
    throw std::logic_error("ObscuranceRenderer: a part of a frame (firstSample, rows) is rendered, not edited");
  if (settings.width != frame_.layout().width || settings.height != frame_.layout().imageHeight ||
      settings.rows.first != frame_.layout().firstRow ||
      (settings.rows.whole() ? settings.height : settings.rows.count) != frame_.layout().height ||
      settings.primaryAovs != frame_.contents().primaryAovs ||
      (settings.composedAovs ? gpu::kComposeSlots : 1u) != frame_.contents().composedSlots)
    throw std::logic_error("ObscuranceRenderer::configure: resolution and AOVs are the frame's; make a new renderer");
  if (settings.ambient != settings_.ambient)
    throw std::logic_error("ObscuranceRenderer::configure: the ambient model is the scene's; make a new renderer");
  if (settings.editableGeometry != settings_.editableGeometry)
    throw std::logic_error("ObscuranceRenderer::configure: whether the scene may be edited is fixed when the renderer "
                           "is made (its primary pass's kernels); make a new renderer");
  if (settings.secondaryReflectors > 0.0f && settings.shadowSampling == ShadowSampling::PerLight)
    throw InputError("secondary reflectors choose among all lights by importance, which per-light shadow sampling "
                     "(each light's transport independent of the others' power) does not allow");
  const bool bleedChanged = settings.colourBleeding != settings_.colourBleeding;
  if (settings.secondaryReflectors > 0.0f && !reached_)
    throw std::logic_error("ObscuranceRenderer::configure: secondary reflectors need the lights' reach; make the "
                           "renderer with them or with the Reached ambient model");
  const bool remark = settings.secondaryReflectors != settings_.secondaryReflectors;
  const SeenView fittedTo = seenView();
  settings_ = settings;
  if (remark) markReflectors();
  dMax_ = settings.dMax > 0.0f ? settings.dMax : defaultDMax_;
  const bool depthChanged = ambient_.depth != (reached_ ? settings.maxDepth : 0u);
  ambient_.depth = reached_ ? settings.maxDepth : 0u;
  // The Seen fit depends on the camera and the obscurance settings: fitted again when they change.
  if (ambient_.model == AmbientModel::Seen && reached_ && !(fittedTo == seenView())) {
    reached_->setSeenView(seenView());
    measureAllReach();
  } else if (bleedChanged || depthChanged) {
    updateAmbientWeights(ambient_, lights_, settings.colourBleeding);
  }
  reset();
}

void ObscuranceRenderer::markResolveStale(std::uint32_t fromLight, bool ambient) {
  resolveFrom_ = std::min(resolveFrom_, fromLight);
  resolveAmbient_ = resolveAmbient_ || ambient;
}

void ObscuranceRenderer::reset() {
  markResolveStale(0, true);
  keptRaysValid_ = true; // the samples to come write them anew
  samples_ = 0;
  gbufferSample_ = kNoSample;
  primaryRays_ = 0;
  wallSeconds_ = 0.0;
  frame_.resetStatus();
  timestamps_ = gpu::Timestamps(*context_);
  // Sample 0 of the primary pass starts the AOV and M_s accumulators; the shading passes add to
  // theirs, so those start at zero.
  stream_.submit([&](const vk::raii::CommandBuffer& cmd) {
    for (std::uint32_t b = 0; b < frame_.layout().bandCount(); ++b) {
      const auto& band = frame_.band(b);
      for (const gpu::Buffer* buffer : {&band.basis.buffer(), &band.ambient.buffer(), &band.specularBasis.buffer(), &band.specularAmbient.buffer(),
                                        &band.emissionBasis.buffer(), &band.aovs, &band.sampleCounts})
        cmd.fillBuffer(buffer->handle(), 0, VK_WHOLE_SIZE, 0u);
    }
  });
}

void ObscuranceRenderer::makeTracingPasses(const SceneSpecialisation& scene) {
  sceneKernels_ = scene;
  primary_ = PrimaryPass(*context_, frame_.layout().bandCount(), sceneKernels_, settings_.editableGeometry);
  shadow_ = ShadowPass(*context_, shadingKernels());
  obscurance_ = ObscurancePass(*context_, shadingKernels());
  specularPass_ = SpecularPass(*context_, shadingKernels());
}

void ObscuranceRenderer::uploadLights() {
  lightBuffers_.lights = tableTexels(*context_, lights_.lights, "lights", "lights.lights");
  lightBuffers_.emitters = tableTexels(*context_, lights_.emitters, "emissive triangles", "lights.emitters");
  lightBuffers_.tree = gpu::uploadArray(*context_, buildLightTree(lights_.lights), "lights.tree");
  lightBuffers_.scales = gpu::uploadArray(*context_, emissionRows(lights_.emission), "lights.render_scales");
  emissionBuffer_ = gpu::uploadArray(*context_, emissionRows(emissions_), "compose.emissions");
  lightBounds_ = gpu::uploadArray(*context_, lightBounds(lights_), "dirty.light_bounds");
  bindAll();
}

void ObscuranceRenderer::bindAll() {
  const ShadingInputs inputs{.scene = sceneBuffers_, .lights = lightBuffers_, .frame = frame_};
  for (std::uint32_t b = 0; b < frame_.layout().bandCount(); ++b) {
    primary_.bind(b, sceneBuffers_, frame_, lightBuffers_.scales);
    shadow_.bind(b, inputs);
    obscurance_.bind(b, inputs);
    specularPass_.bind(b, inputs);
    compose_.bind(b, frame_, emissionBuffer_);
    tonemap_.bind(b, frame_);
    resolve_.bind(b, frame_);
    lightMix_.bind(b, frame_, emissionBuffer_);
    dirty_.bind(b, frame_, lightBounds_);
  }
}

void ObscuranceRenderer::prepareForEdits() const {
  shadow_.compileEditKernels(frame_.contents().keptRaySamples > 0);
  obscurance_.compileEditKernels(false);
  specularPass_.compileEditKernels(frame_.contents().keptRaySamples > 0);
}

std::uint32_t ObscuranceRenderer::keptRaysFlag(std::uint32_t sample, bool replaying) const {
  // Per-light shadow sampling takes 4 to 64 rays per light: those are not kept.
  const bool kept = sample < frame_.contents().keptRaySamples && settings_.maxDepth <= gpu::kPathHitsPerSample + 1 &&
                    settings_.shadowRays <= frame_.contents().keptShadowRays &&
                    settings_.shadowSampling == ShadowSampling::Selection;
  return kept && (!replaying || keptRaysValid_) ? gpu::kShadeFlagKeptRays : 0u;
}

gpu::ShadePush ObscuranceRenderer::forLight(gpu::ShadePush push, std::uint32_t light) {
  push.band.z |= gpu::kShadeFlagPerLight;
  push.band.w = light;
  return push;
}

gpu::ShadePush ObscuranceRenderer::shadePush(std::uint32_t sample) const {
  // Glossy MIS needs the specular pass's lobe sample and light samples drawn over all lights.
  const bool glossyMis = settings_.lightSampling == LightSampling::Spatial &&
                         settings_.shadowSampling == ShadowSampling::Selection && runSpecular_;
  const std::uint32_t flags = (settings_.systematic ? gpu::kFlagSystematic : 0u) |
                              (settings_.colourBleeding ? gpu::kFlagBleed : 0u) |
                              (settings_.lightSampling == LightSampling::Area ? gpu::kFlagAreaLightSampling : 0u) |
                              (glossyMis ? gpu::kFlagGlossyMis : 0u) |
                              (reflectorsOn() ? gpu::kFlagSecondaryReflectors : 0u) |
                              (settings_.vertexRaysByThroughput ? gpu::kFlagVertexRaysByThroughput : 0u);
  return {.frame = glm::uvec4(settings_.width, settings_.height, settings_.firstSample + sample, settings_.seed),
          .counts = glm::uvec4(static_cast<std::uint32_t>(lights_.size()), settings_.shadowRays,
                               settings_.obscuranceRays, flags),
          .params = glm::vec4(dMax_, settings_.tau, static_cast<float>(settings_.rho),
                              static_cast<float>(settings_.maxDepth)),
          .rAve = glm::vec4(ambient_.averageReflectance, 0.0f),
          .eye = glm::vec4(settings_.camera.position, sceneScale_),
          .band = glm::uvec4(0u),
          .reflectors = glm::vec4(ambientShareBeyondFirstBounce(ambient_.averageReflectance,
                                                                ambient_.model != AmbientModel::Global ? ambient_.depth : 0u),
                                  unmarkedFirstBounce_)};
}

void ObscuranceRenderer::iterate(std::uint32_t samples, const ProgressFn& progress) {
  const auto start = Clock::now();
  const double wallBefore = wallSeconds_;
  const FrameLayout& layout = frame_.layout();
  const std::uint32_t end = samples_ + samples;
  markResolveStale(0, true);
  while (samples_ < end) {
    const std::uint32_t last = std::min(end, samples_ + kSamplesPerSubmission);
    stream_.submit([&](const vk::raii::CommandBuffer& cmd) {
      timestamps_.reset(cmd);
      for (std::uint32_t s = samples_; s < last; ++s) {
        if (s > samples_) gpu::computeBarrier(cmd);
        recordSample(cmd, s, settings_.primaryAovs ? 0u : gpu::kPrimaryFlagNoAovs, 0u);
      }
    });
    timestamps_.collect();
    primaryRays_ += layout.pixels() * (last - samples_) * cameraRaysPerSample();
    samples_ = last;
    gbufferSample_ = last - 1;
    wallSeconds_ = wallBefore + secondsSince(start);
    if (progress) progress(samples_ - (end - samples), samples, secondsSince(start));
  }
}

std::uint64_t ObscuranceRenderer::cameraRaysPerSample() const {
  return settings_.emissionSamples > 1 ? 1u + settings_.emissionSamples : 1u;
}

void ObscuranceRenderer::recordSample(const vk::raii::CommandBuffer& cmd, std::uint32_t s, std::uint32_t primaryFlags,
                                      std::uint32_t shadeFlags, bool tracePrimary) {
  const FrameLayout& layout = frame_.layout();
  const std::uint32_t bands = layout.bandCount();
  const auto lightCount = static_cast<std::uint32_t>(lights_.size());
  const gpu::GpuCamera camera = primaryCamera();
  gpu::ShadePush push = shadePush(s);
  push.band.z = shadeFlags;
  // A probe follows the kept lobe hits; every other pass writes them (a per-light shadow sampling's
  // per-light dispatches follow the hits the plain dispatch just wrote for the same pixels).
  const bool probe = (shadeFlags & gpu::kShadeFlagProbe) != 0;
  push.band.z |= keptRaysFlag(s, probe);
  // A retrace runs over the dirty pixels' list (dirty.comp), dispatched indirectly.
  const bool dirtyOnly = (shadeFlags & gpu::kShadeFlagDirtyOnly) != 0;
  if (dirtyOnly != ((primaryFlags & gpu::kPrimaryFlagDirtyOnly) != 0))
    throw std::logic_error("recordSample: the primary and shading passes retrace different pixels");
  const ObscuranceFrame* dirtyOf = dirtyOnly ? &frame_ : nullptr;
  // A probe's passes are timed as probe.<pass>.
  const auto label = [probe](const char* pass) { return probe ? "probe." + std::string(pass) : std::string(pass); };
  // The emission rays go with every primary pass that sums (its flags ask for them).
  if ((primaryFlags & gpu::kPrimaryFlagGBufferOnly) == 0 && settings_.emissionSamples > 1)
    primaryFlags |= settings_.emissionSamples << gpu::kPrimaryEmissionSamplesShift;
  if (tracePrimary) {
    recordBands(cmd, label("primary"), [&](std::uint32_t b) {
      primary_.record(cmd, b, layout, camera, {.index = settings_.firstSample + s, .first = settings_.firstSample},
                      settings_.seed, lightCount, primaryFlags, dirtyOf);
    });
    gpu::computeBarrier(cmd);
  }
  if (settings_.shadowSampling == ShadowSampling::PerLight) {
    timestamps_.time(cmd, label("shadow"), [&] {
      for (std::uint32_t light = 0; light < lightCount; ++light) recordShadowForLight(cmd, push, light);
    });
  } else if (lights_.anySampled() && settings_.shadowRays > 0) {
    recordBands(cmd, label("shadow"), [&](std::uint32_t b) { shadow_.record(cmd, b, layout, push, dirtyOf); });
  }
  if (settings_.obscuranceRays > 0) {
    recordBands(cmd, label("obscurance"), [&](std::uint32_t b) { obscurance_.record(cmd, b, layout, push, dirtyOf); });
  }
  if (runSpecular_) {
    if (probe) gpu::computeBarrier(cmd); // the costly specular probe skips what the others found
    timestamps_.time(cmd, label("specular"), [&] {
      const auto specularBands = [&](const gpu::ShadePush& p) {
        for (std::uint32_t b = 0; b < bands; ++b) specularPass_.record(cmd, b, layout, frame_, p);
      };
      if (settings_.shadowSampling == ShadowSampling::PerLight) {
        // The ambient along the paths once, then every light alone along the same paths: each
        // light's S_s is as independent of the others' powers as its D_s.
        gpu::ShadePush ambientOnly = push;
        ambientOnly.band.z |= gpu::kShadeFlagNoDirect;
        specularBands(ambientOnly);
        for (std::uint32_t light = 0; light < lightCount; ++light) {
          gpu::computeBarrier(cmd);
          specularBands(forLight(push, light));
        }
      } else {
        specularBands(push);
      }
    });
  }
}

void ObscuranceRenderer::recordShadowForLight(const vk::raii::CommandBuffer& cmd, gpu::ShadePush push,
                                              std::uint32_t light) const {
  const bool dirtyOnly = (push.band.z & gpu::kShadeFlagDirtyOnly) != 0;
  for (std::uint32_t b = 0; b < frame_.layout().bandCount(); ++b)
    shadow_.record(cmd, b, frame_.layout(), forLight(push, light), dirtyOnly ? &frame_ : nullptr);
}

std::uint64_t ObscuranceRenderer::updateGeometry(const scene::Scene& edited, const bvh::Bvh& bvh,
                                                 const std::vector<scene::Bounds>& changed) {
  const auto start = Clock::now();
  const double wallBefore = wallSeconds_;
  const bool emittersMoved = replaceScene(edited, bvh, &changed);
  std::uint64_t retraced = 0;
  besideMeasurement(pendingReach_, [&] { retraced = retraceDirty(changed, emittersMoved); });
  finishReach();
  wallSeconds_ = wallBefore + secondsSince(start);
  return retraced;
}

bool ObscuranceRenderer::replaceScene(const scene::Scene& edited, const bvh::Bvh& bvh,
                                      const std::vector<scene::Bounds>* changed) {
  if (!settings_.editableGeometry)
    throw std::logic_error("ObscuranceRenderer: a geometry edit of a renderer made with editableGeometry = false "
                           "(its frame keeps no hit bounds to find the pixels to retrace)");
  // Same lights: only an emitter that moved changes them, and then every pixel may change.
  LightSet moved = buildLightSet(edited);
  bool emittersMoved = moved.emitters.size() != lights_.emitters.size();
  for (std::size_t i = 0; !emittersMoved && i < moved.emitters.size(); ++i)
    emittersMoved = std::memcmp(&moved.emitters[i], &lights_.emitters[i], sizeof(gpu::GpuEmitter)) != 0;
  if (emittersMoved) {
    // The area lights (first in both sets, one per light group) take their new emitters, areas,
    // fluxes and powers (a removed emitter has none and is never sampled); added punctual lights stay.
    lights_.emitters = moved.emitters;
    for (std::size_t i = 0; i < edited.lightGroups.size(); ++i) {
      lights_.lights[i] = moved.lights[i];
      lights_.power[i] = moved.power[i];
      lights_.unitFlux[i] = moved.unitFlux[i];
    }
    updateSelection(lights_);
    updateAmbientWeights(ambient_, lights_, settings_.colourBleeding);
  }
  // Same materials and textures (a move or a removal): only the BVH and the triangles' shading
  // data are uploaded again; an insert brings surfaces of its own and uploads the scene anew.
  const bool sameSurfaces = edited.materials.size() == scene_->materials.size() &&
                            edited.textures.size() == scene_->textures.size();
  scene_ = &edited;
  // A rebuilt BVH lays the triangles out anew: the kept lobe hits name other triangles now.
  if (bvh.nodes.size() != bvhNodes_ || bvh.order != bvhOrder_) {
    keptRaysValid_ = false;
    bvhOrder_ = bvh.order;
    bvhNodes_ = bvh.nodes.size();
  }
  // Moved occluders change what every light reaches: where the emitters and surfaces stayed, only
  // the rays that meet the changed boxes are traced again.
  if (reached_) {
    const std::vector<scene::Bounds>* boxes = emittersMoved || !sameSurfaces ? nullptr : changed;
    if (reflectorsOn()) {
      measureReach(edited, bvh, boxes); // markReflectors below needs it
    } else {
      // Compose needs it, the passes do not: measured on threads of their own beside the GPU work
      // of the edit, and applied when that is done (finishReach). The edit's callers keep `edited`,
      // `bvh` and `changed` alive until then.
      pendingReach_ = std::async(std::launch::async, [this, &edited, &bvh, boxes] { return measureReachOf(edited, bvh, boxes); });
    }
  }
  bool rebind = true;
  if (sameSurfaces) rebind = sceneBuffers_.updateGeometry(edited, bvh);
  else sceneBuffers_ = SceneBuffers(*context_, edited, bvh);
  // Compact-stack kernels could overflow their stack on a deeper BVH (and would miss hits
  // unnoticed), and kernels without a kind of texture lookup would not see new textures: the
  // passes are made again for what the edited scene needs.
  if (!sceneKernels_.holds(sceneBuffers_.specialisation())) {
    makeTracingPasses(sceneBuffers_.specialisation());
    rebind = true;
  }
  if (reflectorsOn()) markReflectors();
  if (rebind || emittersMoved) uploadLights();
  return emittersMoved;
}

std::uint64_t ObscuranceRenderer::retraceDirty(const std::vector<scene::Bounds>& changed, bool everyPixel,
                                               std::uint32_t tracedLight) {
  const FrameLayout& layout = frame_.layout();
  const gpu::GpuCamera camera = primaryCamera();
  const auto lightCount = static_cast<std::uint32_t>(lights_.size());
  // Ray origins leave their surfaces by a few hundred ulps of their coordinates (lib/ray.glsl):
  // a changed box grown by 1e-3 of the scene's size and reach covers them.
  const float dirtyPad = changedBoxPadding();
  // The sky lights every pixel from every direction: any edit may change any pixel.
  // So do secondary reflectors: what the edit lights or shades anew is marked anew.
  const bool all = everyPixel || backgroundLight(lights_) < lights_.size() || reflectorsOn();
  // Probing replays the rays the frame traced, so not after addEmitter: its new light changed how
  // lights are chosen, and the replayed rays would not be those traced.
  // Auto probes where the frame has specular paths (a path that left the scene bounds nothing) or
  // keeps every sample's rays (a probe then draws no light sample: cheaper than the retrace it saves).
  const bool keptAll = samples_ <= frame_.contents().keptRaySamples && keptRaysFlag(0, true) != 0;
  const bool probing = settings_.dirtyTest == DirtyTest::Probe || (settings_.dirtyTest == DirtyTest::Auto && (runSpecular_ || keptAll));
  const bool probe = probing && !all && tracedLight == gpu::kInvalidIndex && samples_ > 0;
  for (std::uint32_t b = 0; b < layout.bandCount(); ++b)
    dirty_.prepare(b, layout, camera, changed, dirtyPad, dMax_, lightCount, all, tracedLight, probe);
  const std::uint32_t dirtyBefore = frame_.statusWords()[gpu::kStatusDirtyPixels];
  const auto clear = [&](const vk::raii::CommandBuffer& cmd) {
    gpu::computeBarrier(cmd);
    for (std::uint32_t b = 0; b < layout.bandCount(); ++b) dirty_.recordClear(cmd, b, layout, lightCount, runSpecular_);
  };
  stream_.submit([&](const vk::raii::CommandBuffer& cmd) {
    timestamps_.reset(cmd);
    timestamps_.time(cmd, "dirty", [&] {
      for (std::uint32_t b = 0; b < layout.bandCount(); ++b) dirty_.record(cmd, b, layout);
      if (!probe) clear(cmd);
    });
  });
  timestamps_.collect();
  if (probe) {
    probeCandidates();
    stream_.submit([&](const vk::raii::CommandBuffer& cmd) {
      timestamps_.reset(cmd);
      timestamps_.time(cmd, "dirty", [&] {
        for (std::uint32_t b = 0; b < layout.bandCount(); ++b) dirty_.recordList(cmd, b, layout);
        clear(cmd);
      });
    });
    timestamps_.collect();
  }
  const std::uint64_t retraced = frame_.statusWords()[gpu::kStatusDirtyPixels] - dirtyBefore;
  const std::uint32_t primaryFlags = gpu::kPrimaryFlagDirtyOnly | (settings_.primaryAovs ? 0u : gpu::kPrimaryFlagNoAovs);
  for (std::uint32_t first = 0; retraced > 0 && first < samples_; first += kSamplesPerSubmission) {
    const std::uint32_t last = std::min(samples_, first + kSamplesPerSubmission);
    stream_.submit([&](const vk::raii::CommandBuffer& cmd) {
      timestamps_.reset(cmd);
      for (std::uint32_t s = first; s < last; ++s) {
        gpu::computeBarrier(cmd);
        recordSample(cmd, s, primaryFlags, gpu::kShadeFlagDirtyOnly);
      }
    });
    timestamps_.collect();
    primaryRays_ += retraced * (last - first) * cameraRaysPerSample();
  }
  // The retraced pixels' G-buffer now holds the last sample; the others' still hold theirs.
  if (retraced > 0 && gbufferSample_ + 1 != samples_) gbufferSample_ = kNoSample;
  // Only the listed pixels changed: where the rest is resolved, the next light mix resolves them
  // alone (the lists stay until the next edit, so a second edit before it resolves everything).
  if (resolveFrom_ >= lightCount && !resolveAmbient_ && !resolveDirty_) resolveDirty_ = retraced > 0;
  else markResolveStale(0, true);
  return retraced;
}

void ObscuranceRenderer::probeCandidates() {
  // Every sample in order over the candidates: the G-buffer holds sample 0 already only where the
  // frame has one sample; else each sample's primary hits are traced again (G-buffer only: the
  // candidates' camera rays miss the changed boxes, so they find what the frame's did).
  const std::uint32_t primaryFlags = gpu::kPrimaryFlagDirtyOnly | gpu::kPrimaryFlagGBufferOnly;
  const std::uint32_t shadeFlags = gpu::kShadeFlagDirtyOnly | gpu::kShadeFlagProbe;
  for (std::uint32_t first = 0; first < samples_; first += kSamplesPerSubmission) {
    const std::uint32_t last = std::min(samples_, first + kSamplesPerSubmission);
    stream_.submit([&](const vk::raii::CommandBuffer& cmd) {
      timestamps_.reset(cmd);
      for (std::uint32_t s = first; s < last; ++s) {
        gpu::computeBarrier(cmd);
        recordSample(cmd, s, primaryFlags, shadeFlags, !(s == 0 && gbufferSample_ == 0));
      }
    });
    timestamps_.collect();
  }
  // The candidates' G-buffer now holds the last sample; the others' still hold theirs.
  if (gbufferSample_ + 1 != samples_) gbufferSample_ = kNoSample;
}

void ObscuranceRenderer::render(const ProgressFn& progress) {
  reset();
  iterate(settings_.spp, progress);
  compose();
}

void ObscuranceRenderer::setEmissions(const std::vector<glm::vec3>& emissions) {
  if (emissions.size() != lights_.size())
    throw std::logic_error(fmt::format("setEmissions: {} emissions for {} lights", emissions.size(), lights_.size()));
  emissions_ = emissions;
  emissionBuffer_.upload(*context_, emissionRows(emissions_));
}

void ObscuranceRenderer::setAmbientModel(AmbientModel model) {
  if (model != AmbientModel::Global && !reached_)
    throw std::logic_error("setAmbientModel: this renderer did not measure what the lights reach");
  ambient_.model = model;
  if (model == AmbientModel::Seen && reached_->seenPoints() == 0) { // fitted on first use
    reached_->setSeenView(seenView());
    measureAllReach();
  }
  updateAmbientWeights(ambient_, lights_, settings_.colourBleeding); // the resolved A_t stays: I_a is a push
}

void ObscuranceRenderer::compose(float exposureStops) {
  const auto start = Clock::now();
  const FrameLayout& layout = frame_.layout();
  const glm::vec3 ia = ambientIntensity();
  const auto lightCount = static_cast<std::uint32_t>(lights_.size());
  stream_.submit([&](const vk::raii::CommandBuffer& cmd) {
    timestamps_.reset(cmd);
    recordBands(cmd, "compose", [&](std::uint32_t b) {
      compose_.record(cmd, b, layout, lightCount, ia, runSpecular_, frame_.contents().composedSlots);
    });
    gpu::computeBarrier(cmd);
    recordBands(cmd, "tonemap", [&](std::uint32_t b) {
      tonemap_.record(cmd, b, layout, gpu::kComposeCombined, 3, exposureStops, frame_.contents().composedSlots);
    });
  });
  timestamps_.collect();
  wallSeconds_ += secondsSince(start);
}

void ObscuranceRenderer::composeDisplay(float exposureStops) {
  const auto start = Clock::now();
  const FrameLayout& layout = frame_.layout();
  const glm::vec3 ia = ambientIntensity();
  const auto lightCount = static_cast<std::uint32_t>(lights_.size());
  const bool resolve = resolveFrom_ < lightCount || resolveAmbient_;
  const bool resolveDirty = !resolve && resolveDirty_;
  const std::uint32_t slots = frame_.lightCapacity();
  stream_.submit([&](const vk::raii::CommandBuffer& cmd) {
    timestamps_.reset(cmd);
    if (resolve || resolveDirty) {
      recordBands(cmd, "resolve", [&](std::uint32_t b) {
        resolve_.record(cmd, b, layout, lightCount, slots, runSpecular_, resolveDirty ? 0u : resolveFrom_,
                        resolveDirty || resolveAmbient_, resolveDirty);
      });
      gpu::computeBarrier(cmd);
    }
    recordBands(cmd, "lightmix",
                [&](std::uint32_t b) { lightMix_.record(cmd, b, layout, lightCount, slots, ia, exposureStops); });
  });
  timestamps_.collect();
  resolveFrom_ = lightCount;
  resolveAmbient_ = false;
  resolveDirty_ = false;
  wallSeconds_ += secondsSince(start);
}

std::vector<glm::vec4> ObscuranceRenderer::downloadBand(const gpu::Buffer& buffer) const {
  return buffer.download<glm::vec4>(*context_);
}

io::Image ObscuranceRenderer::image() const {
  const FrameLayout& layout = frame_.layout();
  const std::uint32_t slots = frame_.contents().composedSlots;
  const bool primaryAovs = frame_.contents().primaryAovs;
  io::Image image;
  image.width = static_cast<int>(layout.width);
  image.height = static_cast<int>(layout.height);
  // Composed slots in order (emission after obscurance), then the primary pass's AOVs, whose
  // emission is replaced by the composed one (it follows the current E_s).
  std::vector<std::uint32_t> shown;
  for (std::uint32_t slot = 0; slot < slots; ++slot)
    if (slot != gpu::kComposeEmission || !primaryAovs) shown.push_back(slot);
  const char* slotNames[gpu::kComposeSlots] = {"combined", "direct", "indirect", "specular", "obscurance", "emission"};
  for (std::uint32_t slot : shown)
    for (const auto& c : aovChannels(slotNames[slot])) image.channels.push_back(c);
  if (primaryAovs)
    for (const auto& name : aovNames())
      for (const auto& c : aovChannels(name)) image.channels.push_back(c);
  const std::size_t nc = image.channels.size();
  image.pixels.resize(layout.pixels() * nc);
  const int emissionChannel = image.channelIndex("emission.R");
  for (std::uint32_t b = 0; b < layout.bandCount(); ++b) {
    const auto composed = downloadBand(frame_.band(b).composed);
    io::Image primary;
    if (primaryAovs)
      primary = resolvePrimaryAovs(downloadBand(frame_.band(b).aovs), layout.width, layout.bands[b].rows,
                                   frame_.band(b).sampleCounts.download<std::uint32_t>(*context_));
    const std::size_t pc = primary.channels.size();
    const std::uint64_t first = layout.bandFirstPixel(b);
    for (std::uint64_t p = 0; p < layout.bandPixels(b); ++p) {
      float* out = &image.pixels[(first + p) * nc];
      std::size_t k = 0;
      for (std::uint32_t slot : shown) {
        const glm::vec4 v = composed[p * slots + slot];
        const std::size_t n = slot == gpu::kComposeObscurance ? 1 : 3;
        for (std::size_t c = 0; c < n; ++c) out[k++] = v[static_cast<int>(c)];
      }
      if (!primaryAovs) continue;
      std::copy_n(&primary.pixels[p * pc], pc, out + k);
      const glm::vec4 seen = composed[p * slots + gpu::kComposeEmission];
      for (int c = 0; c < 3; ++c) out[emissionChannel + c] = seen[c];
    }
  }
  return image;
}

Transport ObscuranceRenderer::transport() const {
  Sums s = sums(false);
  return resolveSums(std::move(s.transport), s.counts);
}

ObscuranceRenderer::Sums ObscuranceRenderer::sums(bool withPrimaryAovs) const {
  const FrameLayout& layout = frame_.layout();
  Sums out;
  Transport& t = out.transport;
  t.width = static_cast<int>(layout.width);
  t.height = static_cast<int>(layout.height);
  t.lights = lights_.names;
  t.specular = runSpecular_;
  const std::size_t lights = lights_.size();
  t.direct.assign(lights, std::vector<glm::vec3>(layout.pixels()));
  t.seen.assign(lights, std::vector<glm::vec3>(layout.pixels()));
  if (runSpecular_) {
    t.specularDirect.assign(lights, std::vector<glm::vec3>(layout.pixels()));
    t.specularAmbient.resize(layout.pixels());
  }
  t.ambient.resize(layout.pixels());
  out.counts.resize(layout.pixels());
  const bool primaryAovs = withPrimaryAovs && frame_.contents().primaryAovs;
  if (primaryAovs) out.primaryAovs.resize(layout.pixels() * gpu::kAovSlots);
  // Accumulators are Kahan pairs: the sum of entry i is element i * kAccumulatorVec4s.
  auto sum = [](const std::vector<glm::vec4>& v, std::uint64_t i) { return v[i * gpu::kAccumulatorVec4s]; };
  for (std::uint32_t b = 0; b < layout.bandCount(); ++b) {
    const auto& band = frame_.band(b);
    const auto basis = downloadBand(band.basis.buffer()), seen = downloadBand(band.emissionBasis.buffer());
    const auto ambient = downloadBand(band.ambient.buffer());
    const std::vector<glm::vec4> specularBasis = runSpecular_ ? downloadBand(band.specularBasis.buffer()) : std::vector<glm::vec4>();
    const std::vector<glm::vec4> specularAmbient = runSpecular_ ? downloadBand(band.specularAmbient.buffer()) : std::vector<glm::vec4>();
    const std::vector<glm::vec4> aovs = primaryAovs ? downloadBand(band.aovs) : std::vector<glm::vec4>();
    const auto counts = band.sampleCounts.download<std::uint32_t>(*context_);
    const std::uint64_t px = layout.bandPixels(b);
    const std::uint64_t first = layout.bandFirstPixel(b);
    for (std::uint64_t p = 0; p < px; ++p) {
      out.counts[first + p] = counts[p];
      t.ambient[first + p] = sum(ambient, p);
      if (runSpecular_) t.specularAmbient[first + p] = glm::vec3(sum(specularAmbient, p));
      for (std::size_t l = 0; l < lights; ++l) {
        t.direct[l][first + p] = glm::vec3(sum(basis, l * px + p));
        t.seen[l][first + p] = glm::vec3(sum(seen, l * px + p));
        if (runSpecular_) t.specularDirect[l][first + p] = glm::vec3(sum(specularBasis, l * px + p));
      }
      if (primaryAovs)
        for (std::uint32_t slot = 0; slot < gpu::kAovSlots; ++slot)
          out.primaryAovs[(first + p) * gpu::kAovSlots + slot] = sum(aovs, p * gpu::kAovSlots + slot);
    }
  }
  return out;
}

std::vector<std::uint32_t> ObscuranceRenderer::sampleCounts() const {
  std::vector<std::uint32_t> out;
  for (std::uint32_t b = 0; b < frame_.layout().bandCount(); ++b) {
    auto band = frame_.band(b).sampleCounts.download<std::uint32_t>(*context_);
    out.insert(out.end(), band.begin(), band.begin() + static_cast<std::ptrdiff_t>(frame_.layout().bandPixels(b)));
  }
  return out;
}

std::vector<std::uint32_t> ObscuranceRenderer::display() const {
  std::vector<std::uint32_t> out;
  out.reserve(frame_.layout().pixels());
  for (std::uint32_t b = 0; b < frame_.layout().bandCount(); ++b) {
    auto band = frame_.band(b).display.download<std::uint32_t>(*context_);
    out.insert(out.end(), band.begin(), band.begin() + static_cast<std::ptrdiff_t>(frame_.layout().bandPixels(b)));
  }
  return out;
}

std::size_t ObscuranceRenderer::lightIndex(const std::string& name) const {
  auto it = std::find(lights_.names.begin(), lights_.names.end(), name);
  if (it == lights_.names.end())
    throw InputError(fmt::format("light '{}': no such light (lights: {})", name, fmt::join(lights_.names, ", ")));
  return static_cast<std::size_t>(it - lights_.names.begin());
}

std::size_t ObscuranceRenderer::addLight(const scene::PunctualLight& light) {
  if (std::find(lights_.names.begin(), lights_.names.end(), light.name) != lights_.names.end())
    throw InputError(fmt::format("add light '{}': a light of that name exists", light.name));
  const std::size_t index = lights_.size();
  frame_.addLightSlot(stream_, static_cast<std::uint32_t>(index));
  markResolveStale(static_cast<std::uint32_t>(index), false);
  appendPunctual(lights_, light, scene_->bounds);
  updateSelection(lights_);
  emissions_.push_back(lights_.emission.back());
  uploadLights();
  // What the new light reaches (CPU rays, for I_a) is measured on a thread of its own while its
  // rays are traced: compose needs it, the passes do not (lights_ stays as it is meanwhile).
  std::future<LightReach> reach;
  if (reached_) {
    reach = std::async(std::launch::async, [this, index] {
      const auto start = Clock::now();
      LightReach r = reached_->measure(lights_, index);
      lastReach_ = {r.rays.traced, 1e3 * secondsSince(start)};
      return r;
    });
  }
  const auto reachIn = [&] {
    if (reach.valid()) ambient_.reach.push_back(reach.get());
    updateAmbientWeights(ambient_, lights_, settings_.colourBleeding);
  };
  if (reflectorsOn()) {
    // What the new light marks reflects every light's light: all of it again.
    reachIn();
    markReflectors();
    retraceAll();
    return index;
  }
  besideMeasurement(reach, [&] { traceAddedLight(static_cast<std::uint32_t>(index)); });
  reachIn();
  return index;
}

void ObscuranceRenderer::traceAddedLight(std::uint32_t light) {
  // The new light's rays from the frame's own primary hits and specular paths: the G-buffer of
  // every sample so far is made again (same seed, same sub-pixel position, no accumulation), the
  // shadow pass samples the new light alone, and the specular pass follows the same paths again
  // (their lobe samples have a generator of their own) gathering that light alone.
  const auto start = Clock::now();
  const double wallBefore = wallSeconds_;
  const FrameLayout& layout = frame_.layout();
  const gpu::GpuCamera camera = primaryCamera();
  const auto lightCount = static_cast<std::uint32_t>(lights_.size());
  // The sample whose G-buffer the frame holds goes first and needs no primary pass (at one sample
  // per pixel, none at all); the others follow in order.
  std::vector<std::uint32_t> order;
  if (gbufferSample_ < samples_) order.push_back(gbufferSample_);
  for (std::uint32_t s = 0; s < samples_; ++s)
    if (s != gbufferSample_) order.push_back(s);
  std::uint64_t primaryPixels = 0;
  for (std::size_t first = 0; first < order.size(); first += kSamplesPerSubmission) {
    const std::size_t last = std::min(order.size(), first + kSamplesPerSubmission);
    stream_.submit([&](const vk::raii::CommandBuffer& cmd) {
      timestamps_.reset(cmd);
      for (std::size_t k = first; k < last; ++k) {
        const std::uint32_t s = order[k];
        if (k > first) gpu::computeBarrier(cmd);
        if (s != gbufferSample_) {
          recordBands(cmd, "primary", [&](std::uint32_t b) {
            primary_.record(cmd, b, layout, camera, {.index = settings_.firstSample + s, .first = settings_.firstSample},
                            settings_.seed, lightCount, gpu::kPrimaryFlagGBufferOnly);
          });
          gpu::computeBarrier(cmd);
          primaryPixels += layout.pixels();
        }
        gpu::ShadePush push = forLight(shadePush(s), light);
        push.band.z |= keptRaysFlag(s, true); // the specular paths by their kept hits
        recordBands(cmd, "shadow", [&](std::uint32_t b) { shadow_.record(cmd, b, layout, push); });
        if (runSpecular_)
          recordBands(cmd, "specular", [&](std::uint32_t b) { specularPass_.record(cmd, b, layout, frame_, push); });
      }
    });
    timestamps_.collect();
  }
  primaryRays_ += primaryPixels;
  if (!order.empty()) gbufferSample_ = order.back();
  wallSeconds_ = wallBefore + secondsSince(start);
}

std::uint64_t ObscuranceRenderer::addEmitter(const scene::Scene& edited, const bvh::Bvh& bvh,
                                            const std::vector<scene::Bounds>& changed) {
  // Area lights come first, one per light group, so the new group's light goes between them and
  // the punctual lights (its triangles name it by that index).
  const auto areaLights = static_cast<std::size_t>(std::count_if(
      lights_.lights.begin(), lights_.lights.end(), [](const gpu::GpuLight& l) { return l.info.x == gpu::kLightArea; }));
  if (edited.lightGroups.size() != areaLights + 1)
    throw std::logic_error("addEmitter: the edited scene must have exactly one light group more than the renderer");
  const std::size_t index = areaLights;
  if (std::find(lights_.names.begin(), lights_.names.end(), edited.lightGroups[index].name) != lights_.names.end())
    throw InputError(fmt::format("add light '{}': a light of that name exists", edited.lightGroups[index].name));
  const auto start = Clock::now();
  const double wallBefore = wallSeconds_;
  frame_.addLightSlot(stream_, static_cast<std::uint32_t>(index));
  markResolveStale(static_cast<std::uint32_t>(index), true);
  const LightSet fresh = buildLightSet(edited);
  lights_.emitters = fresh.emitters; // the new group's triangles come last: the others keep their places
  auto insertAt = [&](auto& v, const auto& value) { v.insert(v.begin() + static_cast<std::ptrdiff_t>(index), value); };
  insertAt(lights_.lights, fresh.lights[index]);
  insertAt(lights_.names, fresh.names[index]);
  insertAt(lights_.emission, fresh.emission[index]);
  insertAt(lights_.unitFlux, fresh.unitFlux[index]);
  insertAt(lights_.power, fresh.power[index]);
  updateSelection(lights_);
  insertAt(emissions_, fresh.emission[index]);
  if (reached_) ambient_.reach.insert(ambient_.reach.begin() + static_cast<std::ptrdiff_t>(index), LightReach{});
  updateAmbientWeights(ambient_, lights_, settings_.colourBleeding);
  // The quad is geometry too: replaceScene uploads it, measures what every light reaches anew,
  // and the pixels it can change are retraced for every light (the new one included).
  const bool everyPixel = replaceScene(edited, bvh, nullptr);
  std::uint64_t retraced = 0;
  if (reflectorsOn()) {
    retraceAll();
    retraced = frame_.layout().pixels();
  } else {
    besideMeasurement(pendingReach_, [&] {
      traceAddedLight(static_cast<std::uint32_t>(index));
      retraced = retraceDirty(changed, everyPixel, static_cast<std::uint32_t>(index));
    });
    finishReach();
  }
  wallSeconds_ = wallBefore + secondsSince(start);
  return retraced;
}

void ObscuranceRenderer::removeLight(std::size_t index) {
  if (index >= lights_.size()) throw std::logic_error("removeLight: no such light");
  if (lights_.lights[index].info.x == gpu::kLightArea) {
    // Area lights stay: their triangles name them by index. Off is a scale of 0, which is what
    // a scene without that emission renders (D_s, M_s and I_a's share all vanish).
    emissions_[index] = glm::vec3(0.0f);
    emissionBuffer_.upload(*context_, emissionRows(emissions_));
    return;
  }
  frame_.removeLightSlot(stream_, static_cast<std::uint32_t>(index));
  markResolveStale(static_cast<std::uint32_t>(index), false);
  removePunctual(lights_, index);
  if (reached_) ambient_.reach.erase(ambient_.reach.begin() + static_cast<std::ptrdiff_t>(index));
  emissions_.erase(emissions_.begin() + static_cast<std::ptrdiff_t>(index));
  updateAmbientWeights(ambient_, lights_, settings_.colourBleeding);
  uploadLights();
  if (reflectorsOn()) {
    markReflectors();
    retraceAll();
  }
}

RenderStats ObscuranceRenderer::stats() const {
  RenderStats st;
  st.notes = sceneBuffers_.notes();
  const auto status = frame_.statusWords();
  st.truncatedTraversals = status[gpu::kStatusTruncated];
  auto pass = [&](const char* name, std::uint64_t rays) {
    if (!timestamps_.totalsMs().contains(name)) return;
    st.passes[name] = {.gpuMs = timestamps_.totalsMs().at(name), .rays = rays};
  };
  pass("primary", primaryRays_);
  pass("shadow", status[gpu::kStatusShadowRays]);
  pass("obscurance", status[gpu::kStatusObscuranceRays]);
  pass("specular", status[gpu::kStatusSpecularRays]);
  pass("compose", 0);
  pass("tonemap", 0);
  pass("resolve", 0);
  pass("lightmix", 0);
  pass("dirty", 0);
  for (const char* probed : {"probe.primary", "probe.shadow", "probe.obscurance", "probe.specular"}) pass(probed, 0);
  st.deviceBytes = deviceBytes();
  st.wallSeconds = wallSeconds_;
  return st;
}

std::uint64_t ObscuranceRenderer::deviceBytes() const {
  return sceneBuffers_.bytes() + frame_.bytes() + lightBuffers_.lights.buffer().size() +
         lightBuffers_.emitters.buffer().size() + lightBuffers_.tree.size() + lightBuffers_.scales.size() + emissionBuffer_.size();
}

} // namespace obscura::render
