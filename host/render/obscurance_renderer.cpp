#include "render/obscurance_renderer.h"

#include <algorithm>
#include <array>
#include <chrono>

#include "compose.spv.h"
#include "gpu/kernel.h"
#include "gpu/timestamps.h"
#include "obscurance.spv.h"
#include "render/passes/primary_pass.h"
#include "render/scene/scene_buffers.h"
#include "shading/bsdf.h"
#include "shadow.spv.h"
#include "specular.spv.h"
#include "specular_queue.spv.h"

namespace obscura::render {
namespace {

using Usage = vk::BufferUsageFlagBits;

gpu::KernelDesc shadingKernelDesc(const char* name, std::span<const std::uint32_t> spirv) {
  auto bindings = sceneBindingKinds();
  bindings.insert(bindings.end(), gpu::kShadingBindingCount - gpu::kSceneBindingCount, gpu::BindingKind::StorageBuffer);
  return {.name = name, .spirv = spirv, .bindings = bindings, .pushConstantBytes = sizeof(gpu::ShadePush)};
}

gpu::KernelDesc composeKernelDesc() {
  return {.name = "compose", .spirv = kSpirv_compose,
          .bindings = std::vector<gpu::BindingKind>(7, gpu::BindingKind::StorageBuffer),
          .pushConstantBytes = sizeof(gpu::ComposePush)};
}

// Whether any triangle has a glossy material: only then does the specular pass run.
bool hasGlossy(const scene::Scene& scene) {
  std::vector<bool> glossy;
  for (const auto& m : scene.materials) glossy.push_back(isGlossy(m.metallic, m.roughness));
  for (std::uint32_t m : scene.triangleMaterial)
    if (glossy[m]) return true;
  return false;
}

const std::vector<std::string> kComposeAovs = {"combined", "direct", "indirect", "specular", "obscurance"};

} // namespace

float defaultDMax(const scene::Bounds& bounds) {
  glm::vec3 e = bounds.extent();
  float largest = std::max({e.x, e.y, e.z});
  return largest > 0.0f ? 0.25f * largest : 1.0f;
}

const std::vector<std::string>& obscuranceAovNames() {
  static const std::vector<std::string> names = {"combined", "direct", "indirect", "specular", "obscurance",
                                                 "albedo", "emission", "normal", "depth", "position",
                                                 "coverage", "primitive", "material", "preview"};
  return names;
}

std::uint64_t obscuranceLargestBuffer(std::uint32_t width, std::uint32_t height, std::size_t lights) {
  const std::uint64_t pixels = std::uint64_t(width) * height, vec4 = 16;
  const std::uint64_t aovs = pixels * gpu::kAovSlots * gpu::kAccumulatorVec4s * vec4;
  const std::uint64_t basis = pixels * std::max<std::uint64_t>(lights, 1) * gpu::kAccumulatorVec4s * vec4;
  const std::uint64_t composed = pixels * gpu::kComposeSlots * vec4;
  return std::max({aovs, basis, composed, pixels * sizeof(gpu::GBufferTexel)});
}

std::uint64_t obscuranceBytesNeeded(std::uint32_t width, std::uint32_t height, std::size_t lights) {
  std::uint64_t pixels = std::uint64_t(width) * height;
  return PrimaryPass::bytesNeeded(width, height) +
         pixels * 16 * (gpu::kAccumulatorVec4s * (lights + 1) + gpu::kComposeSlots);
}

ObscuranceResult renderObscurances(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                                   const ObscuranceSettings& settings, const ProgressFn& progress) {
  auto start = std::chrono::steady_clock::now();
  ObscuranceResult result;
  result.dMax = settings.dMax > 0.0f ? settings.dMax : defaultDMax(scene.bounds);
  result.lights = buildLightSet(scene);
  const LightSet& lights = result.lights;
  std::vector<glm::vec3> meanAlbedo;
  for (const auto& m : scene.materials) meanAlbedo.push_back(materialMeanAlbedo(m));
  result.ambient = computeAmbient(scene, lights, meanAlbedo, settings.colourBleeding);
  result.ambientIntensity = result.ambient.intensity(lights.emission);

  SceneBuffers buffers(context, scene, bvh);
  result.stats.notes = buffers.notes();
  PrimaryPass primary(context, buffers, settings.width, settings.height);
  const std::uint64_t pixels = std::uint64_t(settings.width) * settings.height;
  const auto lightCount = static_cast<std::uint32_t>(lights.size());

  gpu::Buffer lightBuffer = gpu::uploadArray(context, lights.lights, "shadow.lights");
  gpu::Buffer emitterBuffer = gpu::uploadArray(context, lights.emitters, "shadow.emitters");
  constexpr std::uint64_t kAccumulator = gpu::kAccumulatorVec4s * sizeof(glm::vec4);
  gpu::Buffer basis(context, std::max<std::uint64_t>(lightCount, 1) * pixels * kAccumulator, Usage::eStorageBuffer,
                    "shadow.basis");
  gpu::Buffer ambient(context, pixels * kAccumulator, Usage::eStorageBuffer, "obscurance.ambient");
  std::vector<glm::vec4> scales;
  for (const auto& e : lights.emission) scales.emplace_back(e, 0.0f);
  gpu::Buffer scaleBuffer = gpu::uploadArray(context, scales, "compose.emission");
  gpu::Buffer composed(context, pixels * gpu::kComposeSlots * 16, Usage::eStorageBuffer, "compose.output");
  // The specular buffers exist in full only when a glossy material does (a pass the scene does
  // not need is not dispatched, and needs no memory).
  const bool runSpecular = hasGlossy(scene) && settings.maxDepth > 1;
  const std::uint64_t specularPixels = runSpecular ? pixels : 1;
  gpu::Buffer specularBasis(context, std::max<std::uint64_t>(lightCount, 1) * specularPixels * kAccumulator,
                            Usage::eStorageBuffer, "specular.basis");
  gpu::Buffer specularAmbient(context, specularPixels * kAccumulator, Usage::eStorageBuffer, "specular.ambient");
  gpu::Buffer queue(context, (gpu::kQueueHeader + specularPixels) * 4,
                    Usage::eStorageBuffer | Usage::eIndirectBuffer, "specular.queue");

  gpu::Kernel shadow(context, shadingKernelDesc("shadow", kSpirv_shadow));
  gpu::Kernel obscurance(context, shadingKernelDesc("obscurance", kSpirv_obscurance));
  gpu::Kernel specularQueue(context, shadingKernelDesc("specular.queue", kSpirv_specular_queue));
  gpu::Kernel specular(context, shadingKernelDesc("specular", kSpirv_specular));
  for (gpu::Kernel* k : {&shadow, &obscurance, &specularQueue, &specular}) {
    buffers.bindTo(*k);
    k->bind(gpu::kBindingGBuffer, primary.gbuffer());
    k->bind(gpu::kBindingLights, lightBuffer);
    k->bind(gpu::kBindingEmitters, emitterBuffer);
    k->bind(gpu::kBindingBasis, basis);
    k->bind(gpu::kBindingAmbient, ambient);
    k->bind(gpu::kBindingSpecularBasis, specularBasis);
    k->bind(gpu::kBindingSpecularAmbient, specularAmbient);
    k->bind(gpu::kBindingSpecularQueue, queue);
    k->bind(gpu::kBindingLightScales, scaleBuffer);
  }
  gpu::Kernel compose(context, composeKernelDesc());
  compose.bind(0, basis);
  compose.bind(1, ambient);
  compose.bind(2, primary.aovs());
  compose.bind(3, scaleBuffer);
  compose.bind(4, composed);
  compose.bind(5, specularBasis);
  compose.bind(6, specularAmbient);

  const bool runShadow = lights.anySampled() && settings.shadowRays > 0;
  const bool runObscurance = settings.obscuranceRays > 0;
  const gpu::GpuCamera camera = gpuCamera(settings.camera, settings.width, settings.height);
  std::uint32_t flags = (settings.systematic ? gpu::kFlagSystematic : 0u) | (settings.colourBleeding ? gpu::kFlagBleed : 0u);
  gpu::ShadePush push{.frame = glm::uvec4(settings.width, settings.height, 0u, settings.seed),
                      .counts = glm::uvec4(lightCount, settings.shadowRays, settings.obscuranceRays, flags),
                      .params = glm::vec4(result.dMax, settings.tau, static_cast<float>(settings.rho),
                                          static_cast<float>(settings.maxDepth)),
                      .rAve = glm::vec4(result.ambient.averageReflectance, 0.0f),
                      .eye = glm::vec4(settings.camera.position, sceneScale(scene.bounds))};
  const std::uint32_t groupsX = gpu::groupsFor(settings.width, gpu::kWorkgroupSizeX);
  const std::uint32_t groupsY = gpu::groupsFor(settings.height, gpu::kWorkgroupSizeY);

  gpu::Timestamps timestamps(context);
  context.submitAndWait([&](const vk::raii::CommandBuffer& cmd) {
    cmd.fillBuffer(basis.handle(), 0, VK_WHOLE_SIZE, 0u);
    cmd.fillBuffer(ambient.handle(), 0, VK_WHOLE_SIZE, 0u);
    cmd.fillBuffer(specularBasis.handle(), 0, VK_WHOLE_SIZE, 0u);
    cmd.fillBuffer(specularAmbient.handle(), 0, VK_WHOLE_SIZE, 0u);
  });
  const std::array<std::uint32_t, gpu::kQueueHeader> emptyQueue = {0u, 1u, 1u, 0u};
  for (std::uint32_t s = 0; s < settings.spp; ++s) {
    push.frame.z = s;
    context.submitAndWait([&](const vk::raii::CommandBuffer& cmd) {
      timestamps.reset(cmd);
      timestamps.begin(cmd, "primary");
      primary.record(cmd, camera, s, settings.seed);
      timestamps.end(cmd, "primary");
      gpu::computeBarrier(cmd);
      if (runShadow) {
        timestamps.begin(cmd, "shadow");
        shadow.dispatch(cmd, groupsX, groupsY, 1, &push);
        timestamps.end(cmd, "shadow");
      }
      if (runObscurance) {
        timestamps.begin(cmd, "obscurance");
        obscurance.dispatch(cmd, groupsX, groupsY, 1, &push);
        timestamps.end(cmd, "obscurance");
      }
      if (runSpecular) {
        timestamps.begin(cmd, "specular");
        cmd.updateBuffer<std::uint32_t>(queue.handle(), 0, emptyQueue);
        gpu::computeBarrier(cmd);
        specularQueue.dispatch(cmd, groupsX, groupsY, 1, &push);
        gpu::computeBarrier(cmd);
        specular.dispatchIndirect(cmd, queue, 0, &push);
        timestamps.end(cmd, "specular");
      }
    });
    timestamps.collect();
    if (progress)
      progress(s + 1, settings.spp, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  gpu::ComposePush composePush{.frame = glm::uvec4(settings.width, settings.height, settings.spp, lightCount),
                               .ambient = glm::vec4(result.ambientIntensity, runSpecular ? 1.0f : 0.0f)};
  context.submitAndWait([&](const vk::raii::CommandBuffer& cmd) {
    timestamps.reset(cmd);
    timestamps.begin(cmd, "compose");
    compose.dispatch(cmd, gpu::groupsFor(pixels, gpu::kWorkgroupSize1D), 1, 1, &composePush);
    timestamps.end(cmd, "compose");
  });
  timestamps.collect();

  auto status = buffers.statusWords();
  auto& st = result.stats;
  st.truncatedTraversals = status[gpu::kStatusTruncated];
  auto pass = [&](const char* name, std::uint64_t rays) {
    if (!timestamps.totalsMs().contains(name)) return;
    st.passes[name] = {.gpuMs = timestamps.totalsMs().at(name), .rays = rays};
  };
  pass("primary", pixels * settings.spp);
  pass("shadow", status[gpu::kStatusShadowRays]);
  pass("obscurance", status[gpu::kStatusObscuranceRays]);
  pass("specular", status[gpu::kStatusSpecularRays]);
  pass("compose", 0);
  st.deviceBytes = buffers.bytes() + obscuranceBytesNeeded(settings.width, settings.height, lights.size());

  // Image: the composed AOVs, then the primary pass's.
  auto composedData = composed.download<glm::vec4>(context);
  io::Image primaryImage = resolvePrimaryAovs(primary.aovs().download<glm::vec4>(context), settings.width,
                                              settings.height, settings.spp);
  io::Image& image = result.image;
  image.width = static_cast<int>(settings.width);
  image.height = static_cast<int>(settings.height);
  for (const auto& name : kComposeAovs)
    for (const auto& c : aovChannels(name)) image.channels.push_back(c);
  for (const auto& c : primaryImage.channels) image.channels.push_back(c);
  const std::size_t nc = image.channels.size(), pc = primaryImage.channels.size();
  image.pixels.resize(pixels * nc);
  for (std::size_t p = 0; p < pixels; ++p) {
    float* out = &image.pixels[p * nc];
    std::size_t k = 0;
    for (std::uint32_t slot = 0; slot < gpu::kComposeSlots; ++slot) {
      glm::vec4 v = composedData[p * gpu::kComposeSlots + slot];
      std::size_t n = slot == gpu::kComposeObscurance ? 1 : 3;
      for (std::size_t c = 0; c < n; ++c) out[k++] = v[static_cast<int>(c)];
    }
    std::copy_n(&primaryImage.pixels[p * pc], pc, out + k);
  }
  st.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

} // namespace obscura::render
