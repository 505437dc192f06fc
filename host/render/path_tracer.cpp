#include "render/path_tracer.h"

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/error.h"
#include "gpu/kernel.h"
#include "gpu/timestamps.h"
#include "pathtrace.spv.h"
#include "render/scene/light_set.h"
#include "render/passes/primary_pass.h"
#include "render/scene/scene_buffers.h"

namespace obscura::render {
namespace {


using Usage = vk::BufferUsageFlagBits;

gpu::KernelDesc pathKernelDesc() {
  auto bindings = sceneBindingKinds();
  bindings.insert(bindings.end(), gpu::kPathBindingCount - gpu::kSceneBindingCount, gpu::BindingKind::StorageBuffer);
  return {.name = "pathtrace", .spirv = kSpirv_pathtrace, .bindings = bindings,
          .pushConstantBytes = sizeof(gpu::PathPush)};
}

} // namespace

std::uint64_t pathTraceBytesNeeded(std::uint32_t width, std::uint32_t height) {
  return std::uint64_t(width) * height * gpu::kAccumulatorVec4s * sizeof(glm::vec4);
}

PathTraceResult renderPathTraced(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                                 const PathTraceSettings& settings, const ProgressFn& progress) {
  if (settings.width == 0 || settings.height == 0) throw InputError("path tracing: the image has no pixels");
  if (settings.spp == 0) throw InputError("path tracing: --spp must be at least 1");
  if (settings.maxDepth > kMaxPathDepth)
    throw InputError(fmt::format("path tracing: depth {} is above the limit of {}", settings.maxDepth, kMaxPathDepth));

  auto start = std::chrono::steady_clock::now();
  PathTraceResult result;
  const LightSet lights = buildLightSet(scene);
  SceneBuffers buffers(context, scene, bvh);
  result.stats.notes = buffers.notes();
  const std::uint64_t pixels = std::uint64_t(settings.width) * settings.height;

  gpu::Buffer radiance(context, pixels * gpu::kAccumulatorVec4s * sizeof(glm::vec4), Usage::eStorageBuffer,
                       "pathtrace.radiance");
  gpu::Buffer lightBuffer = gpu::uploadArray(context, lights.lights, "pathtrace.lights");
  gpu::Buffer emitterBuffer = gpu::uploadArray(context, lights.emitters, "pathtrace.emitters");
  std::vector<glm::vec4> scales;
  for (const auto& e : lights.emission) scales.emplace_back(e, 0.0f);
  gpu::Buffer scaleBuffer = gpu::uploadArray(context, scales, "pathtrace.emission");

  gpu::Kernel kernel(context, pathKernelDesc());
  buffers.bindTo(kernel);
  kernel.bind(gpu::kBindingPathRadiance, radiance);
  kernel.bind(gpu::kBindingPathLights, lightBuffer);
  kernel.bind(gpu::kBindingPathEmitters, emitterBuffer);
  kernel.bind(gpu::kBindingPathScales, scaleBuffer);

  // No light with power: no light sampling at all (sampleLight needs a light it can pick), so the
  // shader traces no shadow ray; emitters of zero power still show where a ray sees them.
  const auto lightCount = lights.anySampled() ? static_cast<std::uint32_t>(lights.size()) : 0u;
  gpu::PathPush push{.camera = gpuCamera(settings.camera, settings.width, settings.height),
                .frame = glm::uvec4(settings.width, settings.height, 0u, settings.seed),
                .params = glm::uvec4(lightCount, settings.maxDepth, settings.rrDepth,
                                     static_cast<std::uint32_t>(settings.strategy))};
  push.camera.right.w = sceneScale(scene.bounds); // the ray-origin offset's scale (ray.glsl)
  const std::uint32_t groupsX = gpu::groupsFor(settings.width, gpu::kWorkgroupSizeX);
  const std::uint32_t groupsY = gpu::groupsFor(settings.height, gpu::kWorkgroupSizeY);

  gpu::Timestamps timestamps(context);
  context.submitAndWait([&](const vk::raii::CommandBuffer& cmd) { cmd.fillBuffer(radiance.handle(), 0, VK_WHOLE_SIZE, 0u); });
  for (std::uint32_t s = 0; s < settings.spp; ++s) {
    push.frame.z = s;
    context.submitAndWait([&](const vk::raii::CommandBuffer& cmd) {
      timestamps.reset(cmd);
      timestamps.begin(cmd, "pathtrace");
      kernel.dispatch(cmd, groupsX, groupsY, 1, &push);
      timestamps.end(cmd, "pathtrace");
    });
    timestamps.collect();
    if (progress)
      progress(s + 1, settings.spp, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }

  auto status = buffers.statusWords();
  auto& st = result.stats;
  st.truncatedTraversals = status[gpu::kStatusTruncated];
  st.passes["pathtrace"] = {.gpuMs = timestamps.totalsMs().contains("pathtrace") ? timestamps.totalsMs().at("pathtrace") : 0.0,
                            .rays = status[gpu::kStatusPathRays]};
  st.deviceBytes = buffers.bytes() + pathTraceBytesNeeded(settings.width, settings.height) +
                   (lightBuffer.size() + emitterBuffer.size() + scaleBuffer.size());

  // The image: sum / spp. The shader never adds a non-finite sample (it counts it in .w instead).
  auto sums = radiance.download<glm::vec4>(context);
  io::Image& image = result.image;
  image.width = static_cast<int>(settings.width);
  image.height = static_cast<int>(settings.height);
  image.channels = aovChannels("combined");
  image.pixels.resize(pixels * 3);
  const float inv = 1.0f / static_cast<float>(settings.spp);
  for (std::uint64_t p = 0; p < pixels; ++p) {
    const glm::vec4 sum = sums[p * gpu::kAccumulatorVec4s]; // (sum, compensation) pairs
    for (int c = 0; c < 3; ++c) image.pixels[p * 3 + c] = sum[c] * inv;
    result.nonFiniteSamples += static_cast<std::uint64_t>(sum.w);
  }
  if (result.nonFiniteSamples > 0)
    st.notes.push_back(fmt::format("path tracing dropped {} non-finite samples (NaN or inf radiance)",
                                   result.nonFiniteSamples));
  st.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

} // namespace obscura::render
