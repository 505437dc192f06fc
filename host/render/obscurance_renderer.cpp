#include "render/obscurance_renderer.h"

#include <algorithm>
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

} // namespace

bool sceneHasGlossy(const scene::Scene& scene) {
  std::vector<bool> glossy;
  for (const auto& m : scene.materials) glossy.push_back(shading::isGlossy(m.metallic, m.roughness));
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
      geometry_(context, frame_.layout(), bvh), sceneScale_(sceneScale(scene.bounds)),
      stream_(context), timestamps_(context) {
  for (const auto& m : scene.materials) meanAlbedo_.push_back(materialMeanAlbedo(m));
  ambient_ = computeAmbient(scene, lights_, meanAlbedo_, settings.colourBleeding);
  if (settings.ambient != AmbientModel::Global) ambient_.model = settings.ambient;
  { // first: the Seen fit needs dmax and the escape model
    const FreePath freePath = measureFreePath(scene, bvh, settings.camera);
    defaultDMax_ = defaultDMax(scene, freePath);
    openScene_ = freePath.open();
  }
  if (settings.ambient != AmbientModel::Global || settings.secondaryReflectors > 0.0f) {
    useReachRays();
    reach_.measure(scene, bvh, reachInputs(), ambient_);
  }
  emissions_ = lights_.emission;
  configure(settings);
  if (reflectorsOn()) markReflectors();
  uploadLights(true);
}

void ObscuranceRenderer::useReachRays() {
  reach_.useRays(nullptr);
  reachRays_ = std::make_unique<GpuRayBatch>(*context_, sceneBuffers_);
  reach_.useRays(reachRays_.get());
}

gpu::GpuCamera ObscuranceRenderer::primaryCamera() const {
  const std::size_t sky = backgroundLight(lights_);
  return gpuCamera(settings_.camera, settings_.width, settings_.height,
                   sky < lights_.size() ? static_cast<std::uint32_t>(sky) : gpu::kInvalidIndex);
}

LightReachModel::Inputs ObscuranceRenderer::reachInputs() const {
  return {.lights = lights_,
          .seen = ambient_.model == AmbientModel::Seen ? std::optional<SeenView>(seenView()) : std::nullopt,
          .depth = settings_.maxDepth, .colourBleeding = settings_.colourBleeding};
}

SeenView ObscuranceRenderer::seenView() const {
  const scene::Camera& c = settings_.camera;
  return {.position = c.position, .forward = c.forward, .up = c.up, .yfov = c.yfov,
          .aspect = static_cast<float>(settings_.width) / static_cast<float>(std::max(settings_.height, 1u)),
          .dMax = settings_.dMax > 0.0f ? settings_.dMax : defaultDMax_, .rho = static_cast<std::uint32_t>(settings_.rho),
          .tau = settings_.tau, .colourBleeding = settings_.colourBleeding,
          .averageReflectance = ambient_.averageReflectance, .darkEscapes = darkEscapes()};
}

void ObscuranceRenderer::markReflectors() {
  SecondaryReflectorMarks marks;
  if (reflectorsOn())
    marks = markSecondaryReflectors(*scene_, ambient_.reach, settings_.secondaryReflectors, reach_.surfaces().totalArea(),
                                    ambient_.model != AmbientModel::Global);
  reflectorsMarked_ = marks.count;
  unmarkedFirstBounce_ = marks.unmarkedFirstBounce;
  sceneBuffers_.setSecondaryReflectors(*scene_, std::move(marks.marked));
}

void ObscuranceRenderer::retraceAll() {
  const std::uint32_t samples = progress().samples;
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
  if (settings.secondaryReflectors > 0.0f && !reach_.measured())
    throw std::logic_error("ObscuranceRenderer::configure: secondary reflectors need the lights' reach; make the "
                           "renderer with them or with the Reached ambient model");
  const bool remark = settings.secondaryReflectors != settings_.secondaryReflectors;
  const SeenView fittedTo = seenView();
  settings_ = settings;
  if (remark) markReflectors();
  dMax_ = settings.dMax > 0.0f ? settings.dMax : defaultDMax_;
  const bool depthChanged = ambient_.depth != (reach_.measured() ? settings.maxDepth : 0u);
  ambient_.depth = reach_.measured() ? settings.maxDepth : 0u;
  // The Seen fit depends on the camera and the obscurance settings: fitted again when they change.
  if (ambient_.model == AmbientModel::Seen && reach_.measured() && !(fittedTo == seenView())) {
    reach_.setSeenView(seenView());
    reach_.measureAll(reachInputs(), ambient_);
  } else if (bleedChanged || depthChanged) {
    updateAmbientWeights(ambient_, lights_, settings.colourBleeding);
  }
  reset();
}

void ObscuranceRenderer::reset() {
  progress().restart();
  geometry_.keptRaysRenderedAnew();
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

void ObscuranceRenderer::uploadLights(bool bind) {
  // Refilled in place in one submission, and the kernels bound again only when a table outgrew
  // its buffer: an added or removed light re-made five buffers and rebound every kernel, ~13 ms
  // of host work on an H200's host.
  gpu::UploadBatch uploads(*context_);
  bool made = refillTable(*context_, uploads, lightBuffers_.lights, lights_.lights, "lights", "lights.lights");
  made = refillTable(*context_, uploads, lightBuffers_.emitters, lights_.emitters, "emissive triangles",
                     "lights.emitters") || made;
  made = gpu::refillArray(*context_, uploads, lightBuffers_.tree, buildLightTree(lights_.lights), "lights.tree") || made;
  made = gpu::refillArray(*context_, uploads, lightBuffers_.scales, emissionRows(lights_.emission),
                          "lights.render_scales") || made;
  made = gpu::refillArray(*context_, uploads, emissionBuffer_, emissionRows(emissions_), "compose.emissions") || made;
  made = geometry_.setLights(*context_, lights_, uploads) || made;
  uploads.submit();
  if (made || bind) bindAll();
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
    geometry_.bind(b, frame_);
  }
}

void ObscuranceRenderer::prepareForEdits() const {
  const bool kept = frame_.contents().keptRaySamples > 0;
  shadow_.compileEditKernels(kept);
  obscurance_.compileEditKernels(false);
  specularPass_.compileEditKernels(kept);
  // An edit that rebuilds the BVH (an emissive quad, an insert) leaves the kept rays naming other
  // triangles: its added light and probes take the variants without them. A GPU's driver compiles
  // those now rather than inside the edit (tens of ms of host work each); lavapipe, whose JIT
  // would cost every session of the test suite seconds, compiles them when an edit first needs them.
  if (kept && context_->info().type != "cpu") {
    shadow_.compileEditKernels(false);
    specularPass_.compileEditKernels(false);
  }
}

bool ObscuranceRenderer::keptRays(std::uint32_t sample, bool replaying) const {
  // Per-light shadow sampling takes 4 to 64 rays per light: those are not kept.
  const bool kept = sample < frame_.contents().keptRaySamples && settings_.maxDepth <= gpu::kPathHitsPerSample + 1 &&
                    settings_.shadowRays <= frame_.contents().keptShadowRays &&
                    settings_.shadowSampling == ShadowSampling::Selection;
  return kept && (!replaying || geometry_.keptRaysValid());
}

ShadeSample ObscuranceRenderer::shadeSample(std::uint32_t sample) const {
  return {.width = settings_.width, .height = settings_.height, .sample = settings_.firstSample + sample,
          .seed = settings_.seed, .lights = static_cast<std::uint32_t>(lights_.size()),
          .shadowRays = settings_.shadowRays, .obscuranceRays = settings_.obscuranceRays,
          .dMax = dMax_, .tau = settings_.tau, .rho = static_cast<std::uint32_t>(settings_.rho),
          .maxDepth = settings_.maxDepth, .systematic = settings_.systematic,
          .colourBleeding = settings_.colourBleeding,
          .areaLightSampling = settings_.lightSampling == LightSampling::Area,
          // Glossy MIS needs the specular pass's lobe sample and light samples drawn over all lights.
          .glossyMis = settings_.lightSampling == LightSampling::Spatial &&
                       settings_.shadowSampling == ShadowSampling::Selection && runSpecular_,
          .secondaryReflectors = reflectorsOn(), .vertexRaysByThroughput = settings_.vertexRaysByThroughput,
          .darkEscapes = darkEscapes(),
          .averageReflectance = ambient_.averageReflectance, .eye = settings_.camera.position,
          .sceneSize = sceneScale_,
          .kappa = ambientShareBeyondFirstBounce(ambient_.averageReflectance,
                                                 ambient_.model != AmbientModel::Global ? ambient_.depth : 0u),
          .unmarkedFirstBounce = unmarkedFirstBounce_};
}

PrimaryPass::Dispatch ObscuranceRenderer::primaryDispatch(std::uint32_t sample) const {
  return {.sample = settings_.firstSample + sample, .firstSample = settings_.firstSample, .seed = settings_.seed,
          .lights = static_cast<std::uint32_t>(lights_.size()), .aovs = settings_.primaryAovs,
          .emissionSamples = settings_.emissionSamples, .emissionAtEdges = settings_.emissionAtEdges};
}

void ObscuranceRenderer::iterate(std::uint32_t samples, const ProgressFn& progress) {
  const auto start = Clock::now();
  const double wallBefore = wallSeconds_;
  const FrameLayout& layout = frame_.layout();
  FrameProgress& done = frame_.progress();
  const std::uint32_t end = done.samples + samples;
  done.markResolveStale(0, true);
  while (done.samples < end) {
    const std::uint32_t last = std::min(end, done.samples + kSamplesPerSubmission);
    stream_.submit([&](const vk::raii::CommandBuffer& cmd) {
      timestamps_.reset(cmd);
      for (std::uint32_t s = done.samples; s < last; ++s) {
        if (s > done.samples) gpu::computeBarrier(cmd);
        recordSample(cmd, s, SampleMode::Render);
      }
    });
    timestamps_.collect();
    done.primaryRays += layout.pixels() * (last - done.samples); // the emission rays: kStatusEmissionRays
    done.samples = last;
    done.gbufferSample = last - 1;
    wallSeconds_ = wallBefore + secondsSince(start);
    if (progress) progress(done.samples - (end - samples), samples, secondsSince(start));
  }
}

void ObscuranceRenderer::recordSample(const vk::raii::CommandBuffer& cmd, std::uint32_t s, SampleMode mode,
                                      bool tracePrimary) {
  const std::uint32_t bands = frame_.layout().bandCount();
  const auto lightCount = static_cast<std::uint32_t>(lights_.size());
  const ShadeSample sample = shadeSample(s);
  const bool probe = mode == SampleMode::Probe;
  // A retrace and a probe run over the dirty pixels' list (dirty.comp), dispatched indirectly. A
  // probe follows the kept rays; every other pass writes them (a per-light shadow sampling's
  // per-light dispatches follow the hits the plain dispatch just wrote for the same pixels).
  const ShadeDispatch dispatch{.probe = probe, .dirtyOnly = mode != SampleMode::Render, .keptRays = keptRays(s, probe)};
  const auto forLight = [](ShadeDispatch d, std::uint32_t light) {
    d.light = light;
    return d;
  };
  // A probe's passes are timed as probe.<pass>.
  const auto label = [probe](const char* pass) { return probe ? "probe." + std::string(pass) : std::string(pass); };
  if (tracePrimary) {
    PrimaryPass::Dispatch primary = primaryDispatch(s);
    primary.dirtyOnly = dispatch.dirtyOnly;
    // A probe's candidates' camera rays miss the changed boxes, so they find what the frame's did:
    // their G-buffer is made again, and nothing is summed.
    primary.gbufferOnly = probe;
    const gpu::GpuCamera camera = primaryCamera();
    recordBands(cmd, label("primary"), [&](std::uint32_t b) { primary_.record(cmd, b, frame_, camera, primary); });
    gpu::computeBarrier(cmd);
  }
  if (settings_.shadowSampling == ShadowSampling::PerLight) {
    timestamps_.time(cmd, label("shadow"), [&] {
      for (std::uint32_t light = 0; light < lightCount; ++light)
        for (std::uint32_t b = 0; b < bands; ++b) shadow_.record(cmd, b, frame_, sample, forLight(dispatch, light));
    });
  } else if (lights_.anySampled() && settings_.shadowRays > 0) {
    recordBands(cmd, label("shadow"), [&](std::uint32_t b) { shadow_.record(cmd, b, frame_, sample, dispatch); });
  }
  if (settings_.obscuranceRays > 0) {
    recordBands(cmd, label("obscurance"), [&](std::uint32_t b) { obscurance_.record(cmd, b, frame_, sample, dispatch); });
  }
  if (runSpecular_) {
    if (probe) gpu::computeBarrier(cmd); // the costly specular probe skips what the others found
    timestamps_.time(cmd, label("specular"), [&] {
      const auto specularBands = [&](const ShadeDispatch& d) {
        for (std::uint32_t b = 0; b < bands; ++b) specularPass_.record(cmd, b, frame_, sample, d);
      };
      if (settings_.shadowSampling == ShadowSampling::PerLight) {
        // The ambient along the paths once, then every light alone along the same paths: each
        // light's S_s is as independent of the others' powers as its D_s.
        ShadeDispatch ambientOnly = dispatch;
        ambientOnly.noDirect = true;
        specularBands(ambientOnly);
        for (std::uint32_t light = 0; light < lightCount; ++light) {
          gpu::computeBarrier(cmd);
          specularBands(forLight(dispatch, light));
        }
      } else {
        specularBands(dispatch);
      }
    });
  }
}

std::uint64_t ObscuranceRenderer::updateGeometry(const scene::Scene& edited, const bvh::Bvh& bvh,
                                                 const std::vector<scene::Bounds>& changed) {
  const auto start = Clock::now();
  const double wallBefore = wallSeconds_;
  const bool emittersMoved = replaceScene(edited, bvh, &changed);
  std::uint64_t retraced = 0;
  reach_.beside([&] { retraced = retraceDirty(changed, emittersMoved); });
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
  // data are uploaded again; an edit that added materials (a quad) uploads the material table too;
  // one that brought textures (an insert) uploads the scene anew.
  const bool sameTextures = edited.textures.size() == scene_->textures.size();
  const bool sameSurfaces = edited.materials.size() == scene_->materials.size() && sameTextures;
  scene_ = &edited;
  geometry_.useBvh(bvh); // a rebuilt BVH lays the triangles out anew: the kept lobe hits name other triangles

  // An edit that added materials but no texture keeps the textures on the device too.
  bool rebind = true;
  if (sameSurfaces) {
    rebind = sceneBuffers_.updateGeometry(edited, bvh);
  } else if (sameTextures) {
    rebind = sceneBuffers_.updateGeometry(edited, bvh);
    rebind = sceneBuffers_.updateMaterials(edited) || rebind;
  } else {
    sceneBuffers_ = SceneBuffers(*context_, edited, bvh);
  }
  // Compact-stack kernels could overflow their stack on a deeper BVH (and would miss hits
  // unnoticed), and kernels without a kind of texture lookup would not see new textures: the
  // passes are made again for what the edited scene needs.
  if (!sceneKernels_.holds(sceneBuffers_.specialisation())) {
    makeTracingPasses(sceneBuffers_.specialisation());
    if (reachRays_) useReachRays();
    rebind = true;
  } else if (reachRays_ && rebind) {
    reachRays_->rebind();
  }
  // Moved or added occluders change what every light reaches: where the emitters stayed and the
  // surfaces before the edit are as they were (LightReachModel checks their reflectances), only
  // the rays that meet the changed boxes are traced again (on the device, through the buffers
  // just updated).
  if (reach_.measured()) {
    const std::vector<scene::Bounds>* boxes = emittersMoved ? nullptr : changed;
    if (reflectorsOn()) {
      reach_.measure(edited, bvh, reachInputs(), ambient_, boxes); // markReflectors below needs it
    } else {
      // Compose needs it, the passes do not: applied when the edit's GPU work is done
      // (finishReach); with CPU rays measured on threads of their own beside it, and then the
      // edit's callers keep `edited`, `bvh` and `changed` alive until then.
      reach_.start(edited, bvh, reachInputs(), ambient_, boxes);
    }
  }
  if (reflectorsOn()) markReflectors();
  if (rebind || emittersMoved) uploadLights(rebind);
  return emittersMoved;
}

std::uint64_t ObscuranceRenderer::retraceDirty(const std::vector<scene::Bounds>& changed, bool everyPixel,
                                               std::uint32_t tracedLight) {
  const auto lightCount = static_cast<std::uint32_t>(lights_.size());
  // The sky lights every pixel from every direction: any edit may change any pixel.
  // So do secondary reflectors: what the edit lights or shades anew is marked anew.
  const bool all = everyPixel || backgroundLight(lights_) < lights_.size() || reflectorsOn();
  const bool keptAll = progress().samples <= frame_.contents().keptRaySamples && keptRays(0, true);
  const GeometryRetrace::Result r = geometry_.retrace(
      {.stream = stream_, .timestamps = timestamps_, .recorder = *this, .buffers = frame_, .camera = primaryCamera(),
       .lights = lightCount, .samples = progress().samples, .gbufferSample = progress().gbufferSample, .dMax = dMax_,
       .changedBoxPadding = changedBoxPadding(scene_->bounds), .specular = runSpecular_},
      {.changed = changed, .everyPixel = all, .tracedLight = tracedLight,
       .probe = GeometryRetrace::probing(settings_.dirtyTest, runSpecular_ || darkEscapes(), keptAll)});
  progress().primaryRays += r.pixels * progress().samples;
  // The retraced pixels' (and the probed candidates') G-buffer now holds the last sample; the
  // others' still hold theirs.
  if ((r.probed || r.pixels > 0) && progress().gbufferSample + 1 != progress().samples) progress().gbufferSample = FrameProgress::kNoSample;
  // Only the listed pixels changed: where the rest is resolved, the next light mix resolves them
  // alone (the lists stay until the next edit, so a second edit before it resolves everything).
  FrameProgress& p = progress();
  if (p.resolveFrom >= lightCount && !p.resolveAmbient && !p.resolveDirty) p.resolveDirty = r.pixels > 0;
  else p.markResolveStale(0, true);
  return r.pixels;
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
  // Inline in one small submission (UploadBatch): a light's scale or colour is this upload alone.
  gpu::UploadBatch uploads(*context_);
  uploads.add(emissionBuffer_, emissionRows(emissions_));
  uploads.submit();
}

void ObscuranceRenderer::setAmbientModel(AmbientModel model) {
  if (model != AmbientModel::Global && !reach_.measured())
    throw std::logic_error("setAmbientModel: this renderer did not measure what the lights reach");
  ambient_.model = model;
  if (model == AmbientModel::Seen && reach_.surfaces().seenPoints() == 0) { // fitted on first use
    reach_.setSeenView(seenView());
    reach_.measureAll(reachInputs(), ambient_);
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
  const bool resolve = progress().resolveFrom < lightCount || progress().resolveAmbient;
  const bool resolveDirty = !resolve && progress().resolveDirty;
  const std::uint32_t slots = frame_.lightCapacity();
  stream_.submit([&](const vk::raii::CommandBuffer& cmd) {
    timestamps_.reset(cmd);
    if (resolve || resolveDirty) {
      recordBands(cmd, "resolve", [&](std::uint32_t b) {
        resolve_.record(cmd, b, layout, lightCount, slots, runSpecular_, resolveDirty ? 0u : progress().resolveFrom,
                        resolveDirty || progress().resolveAmbient, resolveDirty);
      });
      gpu::computeBarrier(cmd);
    }
    recordBands(cmd, "lightmix",
                [&](std::uint32_t b) { lightMix_.record(cmd, b, layout, lightCount, slots, ia, exposureStops); });
  });
  timestamps_.collect();
  progress().resolved(lightCount);
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
  progress().markResolveStale(static_cast<std::uint32_t>(index), false);
  appendPunctual(lights_, light, scene_->bounds);
  updateSelection(lights_);
  emissions_.push_back(lights_.emission.back());
  uploadLights();
  // What the new light reaches (for I_a): its own rays on the device, before its light rays; with
  // CPU rays on a thread of its own while they are traced. Compose needs it, the passes do not
  // (lights_ stays as it is meanwhile).
  const auto reachIn = [&] {
    if (reach_.measured()) finishReach();
    else updateAmbientWeights(ambient_, lights_, settings_.colourBleeding);
  };
  if (reach_.measured()) reach_.startLight(lights_, index);
  if (reflectorsOn()) {
    // What the new light marks reflects every light's light: all of it again.
    reachIn();
    markReflectors();
    retraceAll();
    return index;
  }
  reach_.beside([&] { traceAddedLight(static_cast<std::uint32_t>(index)); });
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
  if (progress().gbufferSample < progress().samples) order.push_back(progress().gbufferSample);
  for (std::uint32_t s = 0; s < progress().samples; ++s)
    if (s != progress().gbufferSample) order.push_back(s);
  std::uint64_t primaryPixels = 0;
  for (std::size_t first = 0; first < order.size(); first += kSamplesPerSubmission) {
    const std::size_t last = std::min(order.size(), first + kSamplesPerSubmission);
    stream_.submit([&](const vk::raii::CommandBuffer& cmd) {
      timestamps_.reset(cmd);
      for (std::size_t k = first; k < last; ++k) {
        const std::uint32_t s = order[k];
        if (k > first) gpu::computeBarrier(cmd);
        if (s != progress().gbufferSample) {
          const PrimaryPass::Dispatch gbuffer{.sample = settings_.firstSample + s, .firstSample = settings_.firstSample,
                                              .seed = settings_.seed, .lights = lightCount, .gbufferOnly = true};
          recordBands(cmd, "primary", [&](std::uint32_t b) { primary_.record(cmd, b, frame_, camera, gbuffer); });
          gpu::computeBarrier(cmd);
          primaryPixels += layout.pixels();
        }
        const ShadeSample sample = shadeSample(s);
        // The light alone, the specular paths by their kept hits.
        const ShadeDispatch alone{.light = light, .keptRays = keptRays(s, true)};
        recordBands(cmd, "shadow", [&](std::uint32_t b) { shadow_.record(cmd, b, frame_, sample, alone); });
        if (runSpecular_)
          recordBands(cmd, "specular", [&](std::uint32_t b) { specularPass_.record(cmd, b, frame_, sample, alone); });
      }
    });
    timestamps_.collect();
  }
  progress().primaryRays += primaryPixels;
  if (!order.empty()) progress().gbufferSample = order.back();
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
  progress().markResolveStale(static_cast<std::uint32_t>(index), true);
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
  if (reach_.measured()) ambient_.reach.insert(ambient_.reach.begin() + static_cast<std::ptrdiff_t>(index), LightReach{});
  updateAmbientWeights(ambient_, lights_, settings_.colourBleeding);
  // The quad is geometry too: replaceScene uploads it, measures what every light reaches anew,
  // and the pixels it can change are retraced for every light (the new one included).
  const bool everyPixel = replaceScene(edited, bvh, &changed);
  std::uint64_t retraced = 0;
  if (reflectorsOn()) {
    retraceAll();
    retraced = frame_.layout().pixels();
  } else {
    reach_.beside([&] {
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
    setEmissions(emissions_);
    return;
  }
  frame_.removeLightSlot(stream_, static_cast<std::uint32_t>(index));
  progress().markResolveStale(static_cast<std::uint32_t>(index), false);
  removePunctual(lights_, index);
  if (reach_.measured()) ambient_.reach.erase(ambient_.reach.begin() + static_cast<std::ptrdiff_t>(index));
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
  pass("primary", progress().primaryRays + status[gpu::kStatusEmissionRays]);
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
