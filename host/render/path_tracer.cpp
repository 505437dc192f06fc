#include "render/path_tracer.h"

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/error.h"
#include "pathtrace.spv.h"
#include "render/passes/primary_pass.h"

namespace obscura::render {
namespace {

using Usage = vk::BufferUsageFlagBits;
using Clock = std::chrono::steady_clock;
constexpr std::uint64_t kAccumulator = gpu::kAccumulatorVec4s * sizeof(glm::vec4);

gpu::KernelDesc pathKernelDesc(std::uint32_t bands, const SceneSpecialisation& scene) {
  auto bindings = sceneBindingKinds();
  bindings.insert(bindings.end(), gpu::kPathBindingCount - gpu::kSceneBindingCount, gpu::BindingKind::StorageBuffer);
  bindings[gpu::kBindingPathLights] = bindings[gpu::kBindingPathEmitters] = gpu::BindingKind::UniformTexelBuffer;
  gpu::KernelDesc desc{.name = "pathtrace", .spirv = kSpirv_pathtrace, .bindings = bindings,
                       .pushConstantBytes = sizeof(gpu::PathPush), .setCount = bands};
  scene.addTo(desc);
  return desc;
}

const PathTraceSettings& checked(const PathTraceSettings& settings) {
  if (settings.width == 0 || settings.height == 0) throw InputError("path tracing: the image has no pixels");
  if (settings.spp == 0) throw InputError("path tracing: --spp must be at least 1");
  if (settings.emissionSamples == 0 || settings.emissionSamples > gpu::kMaxEmissionSamples)
    throw InputError(fmt::format("path tracing: --emission-samples {} is not in 1..{}", settings.emissionSamples,
                                 gpu::kMaxEmissionSamples));
  if (settings.maxDepth > kMaxPathDepth)
    throw InputError(fmt::format("path tracing: depth {} is above the limit of {}", settings.maxDepth, kMaxPathDepth));
  return settings;
}

} // namespace

std::uint64_t pathTraceBytesNeeded(std::uint32_t width, std::uint32_t height) {
  return std::uint64_t(width) * height * kAccumulator;
}

PathTracer::PathTracer(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                       const PathTraceSettings& settings, std::uint64_t maxBufferBytes)
    : context_(&context), scene_(&scene), settings_(checked(settings)), sceneBuffers_(context, scene, bvh),
      lights_(buildLightSet(scene)),
      layout_(FrameLayout::split(settings.width, settings.height, kAccumulator,
                                 maxBufferBytes ? maxBufferBytes : context.info().maxStorageBufferRange,
                                 "the radiance accumulator", settings.rows)),
      kernel_(context, pathKernelDesc(layout_.bandCount(), sceneBuffers_.specialisation())), stream_(context),
      timestamps_(context) {
  if (pathTraceBytesNeeded(settings.width, layout_.height) > context.info().deviceLocalBytes)
    throw InputError(fmt::format("{}x{}: path tracing needs {:.1f} MiB, more than the device offers", settings.width,
                                 layout_.height,
                                 static_cast<double>(pathTraceBytesNeeded(settings.width, layout_.height)) / 1048576.0));
  lightBuffer_ = tableTexels(context, lights_.lights, "lights", "pathtrace.lights");
  emitterBuffer_ = tableTexels(context, lights_.emitters, "emissive triangles", "pathtrace.emitters");
  treeBuffer_ = gpu::uploadArray(context, buildLightTree(lights_.lights), "pathtrace.light_tree");
  scaleBuffer_ = gpu::uploadArray(context, emissionRows(lights_.emission), "pathtrace.emission");
  status_ = StatusCounters(context, "pathtrace.status");
  for (std::uint32_t b = 0; b < layout_.bandCount(); ++b) {
    radiance_.emplace_back(context, layout_.bandPixels(b) * kAccumulator,
                           Usage::eStorageBuffer | Usage::eTransferDst, fmt::format("pathtrace.radiance[{}]", b));
    edges_.emplace_back(context, std::max<std::uint64_t>(4, layout_.bandPixels(b) * 4), Usage::eStorageBuffer,
                        fmt::format("pathtrace.emitter_edges[{}]", b));
    sceneBuffers_.bindTo(kernel_, b, &status_.buffer());
    kernel_.bind(gpu::kBindingPathRadiance, radiance_.back(), b);
    kernel_.bind(gpu::kBindingPathLights, lightBuffer_, b);
    kernel_.bind(gpu::kBindingPathEmitters, emitterBuffer_, b);
    kernel_.bind(gpu::kBindingPathLightTree, treeBuffer_, b);
    kernel_.bind(gpu::kBindingPathScales, scaleBuffer_, b);
    kernel_.bind(gpu::kBindingPathEmitterEdges, edges_.back(), b);
  }
  reset();
}

void PathTracer::configure(const PathTraceSettings& settings) {
  checked(settings);
  if (settings.width != settings_.width || settings.height != settings_.height ||
      settings.rows.first != settings_.rows.first || settings.rows.count != settings_.rows.count)
    throw std::logic_error("PathTracer::configure: the resolution is the frame's; make a new path tracer");
  settings_ = settings;
  reset();
}

void PathTracer::reset() {
  samples_ = 0;
  wallSeconds_ = 0.0;
  timestamps_ = gpu::Timestamps(*context_);
  status_.reset();
  stream_.submit([&](const vk::raii::CommandBuffer& cmd) {
    for (const auto& r : radiance_) cmd.fillBuffer(r.handle(), 0, VK_WHOLE_SIZE, 0u);
  });
}

void PathTracer::iterate(std::uint32_t samples, const ProgressFn& progress) {
  const auto start = Clock::now();
  const double wallBefore = wallSeconds_;
  // No light with power: no light sampling at all (sampleLight needs a light it can pick), so the
  // shader traces no shadow ray; emitters of zero power still show where a ray sees them.
  const auto lightCount = lights_.anySampled() ? static_cast<std::uint32_t>(lights_.size()) : 0u;
  const std::size_t sky = backgroundLight(lights_);
  gpu::PathPush push{.camera = gpuCamera(settings_.camera, settings_.width, settings_.height,
                                         sky < lights_.size() && lightCount > 0 ? static_cast<std::uint32_t>(sky)
                                                                                : gpu::kInvalidIndex),
                     .width = settings_.width, .height = settings_.height, .sampleIndex = 0u, .seed = settings_.seed,
                     .lightCount = lightCount, .maxDepth = settings_.maxDepth, .rrDepth = settings_.rrDepth,
                     .strategy = static_cast<std::uint32_t>(settings_.strategy), .firstRow = 0u, .rows = 0u,
                     .lightSampling = static_cast<std::uint32_t>(settings_.lightSampling),
                     .emissionSamples = settings_.emissionSamples,
                     .emissionAtEdges = settings_.emissionAtEdges ? 1u : 0u, .firstSample = settings_.firstSample,
                     .unused0 = 0u, .unused1 = 0u};
  push.camera.right.w = sceneScale(scene_->bounds); // the ray-origin offset's scale (ray.glsl)
  const std::uint32_t end = samples_ + samples;
  while (samples_ < end) {
    const std::uint32_t last = std::min(end, samples_ + kSamplesPerSubmission);
    stream_.submit([&](const vk::raii::CommandBuffer& cmd) {
      timestamps_.reset(cmd);
      timestamps_.begin(cmd, "pathtrace");
      for (std::uint32_t s = samples_; s < last; ++s) {
        if (s > samples_) gpu::computeBarrier(cmd);
        push.sampleIndex = settings_.firstSample + s;
        for (std::uint32_t b = 0; b < layout_.bandCount(); ++b) {
          push.firstRow = layout_.bands[b].firstRow;
          push.rows = layout_.bands[b].rows;
          kernel_.dispatch(cmd, gpu::groupsFor(settings_.width, gpu::kWorkgroupSizeX),
                           gpu::groupsFor(layout_.bands[b].rows, gpu::kWorkgroupSizeY), 1, push, b);
        }
      }
      timestamps_.end(cmd, "pathtrace");
    });
    timestamps_.collect();
    samples_ = last;
    wallSeconds_ = wallBefore + std::chrono::duration<double>(Clock::now() - start).count();
    if (progress)
      progress(samples_ - (end - samples), samples, std::chrono::duration<double>(Clock::now() - start).count());
  }
}

void PathTracer::render(const ProgressFn& progress) {
  reset();
  iterate(settings_.spp, progress);
}

io::Image PathTracer::image() const {
  io::Image image = sums();
  const float inv = 1.0f / static_cast<float>(std::max(samples_, 1u));
  for (float& v : image.pixels) v *= inv;
  return image;
}

io::Image PathTracer::sums() const {
  io::Image image;
  image.width = static_cast<int>(layout_.width);
  image.height = static_cast<int>(layout_.height);
  image.channels = aovChannels("combined");
  image.pixels.resize(layout_.pixels() * 3);
  for (std::uint32_t b = 0; b < layout_.bandCount(); ++b) {
    // The shader never adds a non-finite sample (it counts it in .w instead).
    const auto sums = radiance_[b].download<glm::vec4>(*context_);
    const std::uint64_t first = layout_.bandFirstPixel(b);
    for (std::uint64_t p = 0; p < layout_.bandPixels(b); ++p)
      for (int c = 0; c < 3; ++c) image.pixels[(first + p) * 3 + c] = sums[p * gpu::kAccumulatorVec4s][c];
  }
  return image;
}

std::uint64_t PathTracer::nonFiniteSamples() const {
  std::uint64_t n = 0;
  for (const auto& r : radiance_) {
    const auto sums = r.download<glm::vec4>(*context_);
    for (std::size_t p = 0; p < sums.size(); p += gpu::kAccumulatorVec4s) n += static_cast<std::uint64_t>(sums[p].w);
  }
  return n;
}

RenderStats PathTracer::stats() const {
  RenderStats st;
  st.notes = sceneBuffers_.notes();
  const std::vector<std::uint32_t> status = status_.words();
  st.truncatedTraversals = status[gpu::kStatusTruncated];
  st.passes["pathtrace"] = {.gpuMs = timestamps_.totalsMs().contains("pathtrace") ? timestamps_.totalsMs().at("pathtrace")
                                                                                   : 0.0,
                            .rays = status[gpu::kStatusPathRays]};
  std::uint64_t bytes = sceneBuffers_.bytes() + lightBuffer_.buffer().size() + emitterBuffer_.buffer().size() +
                        scaleBuffer_.size() + status_.buffer().size();
  for (const auto& r : radiance_) bytes += r.size();
  for (const auto& e : edges_) bytes += e.size();
  st.deviceBytes = bytes;
  if (const auto n = nonFiniteSamples(); n > 0)
    st.notes.push_back(fmt::format("path tracing dropped {} non-finite samples (NaN or inf radiance)", n));
  st.wallSeconds = wallSeconds_;
  return st;
}

} // namespace obscura::render
