#include "render/frame/obscurance_frame.h"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "core/error.h"
#include "gpu/kernel.h"
#include "shared/host_device.h"

namespace obscura::render {
namespace {

using Usage = vk::BufferUsageFlagBits;
constexpr std::uint64_t kVec4 = 16;
constexpr std::uint64_t kAccumulator = gpu::kAccumulatorVec4s * kVec4; // a Kahan pair
const auto kStorage = Usage::eStorageBuffer | Usage::eTransferSrc | Usage::eTransferDst;

// Vulkan has no empty buffers: a kind a frame does not use still gets 16 bytes to bind.
std::uint64_t atLeastOne(std::uint64_t bytes) { return std::max<std::uint64_t>(bytes, kVec4); }
static_assert(sizeof(gpu::GBufferTexel) == gpu::kTexelsPerGBuffer * sizeof(gpu::vec4)); // gbufferAt's view

} // namespace

std::vector<FrameBufferKind> ObscuranceFrame::bufferKinds(const FrameContents& contents) {
  std::vector<FrameBufferKind> kinds = {
      {"gbuffer", sizeof(gpu::GBufferTexel), false},
      {"basis", kAccumulator, true},
      {"emission_basis", kAccumulator, true},
      {"ambient", kAccumulator, false},
      {"composed", contents.composedSlots * kVec4, false},
      {"display", 4, false},
      {"resolved", 4, true},
      {"resolved_ambient", 4, false},
      {"hit_bounds", 2 * kVec4, false},
      {"dirty", 8, false}, // mask and list (and the changed boxes: a few words a band)
      {"sample_counts", 4, false},
  };
  if (contents.primaryAovs) kinds.push_back({"aovs", gpu::kAovSlots * kAccumulator, false});
  if (contents.specular) {
    kinds.push_back({"queue", 2 * 4, false}); // two queues: one path depth reads one, fills the other
    kinds.push_back({"specular_paths", gpu::kSpecularPathTexels * kVec4, false});
    kinds.push_back({"specular_basis", kAccumulator, true});
    kinds.push_back({"specular_ambient", kAccumulator, false});
    if (contents.keptRaySamples > 0)
      kinds.push_back({"path_hits", contents.keptRaySamples * kPathHitBytesPerSample, false, false});
  }
  if (contents.keptRaySamples > 0)
    kinds.push_back({"kept_shadow_rays", contents.keptRaySamples * keptShadowRayBytesPerSample(contents.keptShadowRays),
                     false, false});
  return kinds;
}

std::uint64_t ObscuranceFrame::bytesNeeded(std::uint32_t width, std::uint32_t height, std::uint32_t lights,
                                           const FrameContents& contents) {
  std::uint64_t perPixel = 0;
  for (const auto& k : bufferKinds(contents)) perPixel += k.bytesPerPixel * (k.perLight ? lights : 1u);
  return perPixel * width * height;
}

ObscuranceFrame::ObscuranceFrame(const gpu::Context& context, std::uint32_t width, std::uint32_t height,
                                 std::uint32_t lights, const FrameContents& contents, std::uint64_t maxBufferBytes,
                                 std::uint64_t maxTexelElements, RowRange rows)
    : context_(&context), lights_(lights), maxLights_(lights + contents.spareLightSlots), contents_(contents) {
  const bool specular = contents.specular;
  const std::uint64_t limit = maxBufferBytes > 0 ? maxBufferBytes : context.info().maxStorageBufferRange;
  std::uint64_t largest = 0;
  for (const auto& k : bufferKinds(contents))
    if (k.splitsBands) largest = std::max(largest, k.bytesPerPixel * (k.perLight ? maxLights_ : 1u));
  // A band's texel views hold at most maxTexelBufferElements texels each: the G-buffer
  // (kTexelsPerGBuffer a pixel, read by the shading passes) and the per-light Kahan sums (a vec4
  // pair per light and pixel: the shading passes, compose and resolve). That bounds a band's pixels
  // too, as a byte limit of the largest buffer. The resolved transport (a word per light and pixel
  // and one for the ambient, rows padded to kResolvedPixelAlign) then fits with room to spare:
  // (L + 1) ceil(px / 4) texels against the sums' 2 L px.
  const std::uint64_t maxTexels = maxTexelElements > 0 ? std::min<std::uint64_t>(maxTexelElements, context.info().maxTexelBufferElements)
                                                       : context.info().maxTexelBufferElements;
  const std::uint64_t byGBuffer = maxTexels / gpu::kTexelsPerGBuffer;
  const std::uint64_t bySums = maxTexels / (gpu::kAccumulatorVec4s * std::max<std::uint64_t>(maxLights_, 1));
  const std::uint64_t pixelBound = std::max<std::uint64_t>(std::min(byGBuffer, bySums), 1);
  layout_ = FrameLayout::split(width, height, largest, std::min(limit, pixelBound * largest), "the per-light basis buffers",
                               rows);
  // The kept rays: as many samples as fit in one buffer of the largest band.
  std::uint64_t bandPixels = 1;
  for (std::size_t i = 0; i < layout_.bands.size(); ++i) bandPixels = std::max<std::uint64_t>(bandPixels, layout_.bandPixels(i));
  const std::uint64_t keptPerSample = std::max(kPathHitBytesPerSample, keptShadowRayBytesPerSample(contents.keptShadowRays));
  contents_.keptRaySamples = static_cast<std::uint32_t>(
      std::min<std::uint64_t>(contents.keptRaySamples, limit / (bandPixels * keptPerSample)));

  const std::uint64_t need = bytesNeeded(width, layout_.height, maxLights_, contents_);
  if (need > context.info().deviceLocalBytes)
    throw InputError(fmt::format("{}x{} with {} light groups: the frame buffers need {:.1f} MiB, more than the device "
                                 "'{}' offers ({:.0f} MiB); merge light groups (--light-groups material) or render "
                                 "fewer pixels",
                                 width, height, lights, static_cast<double>(need) / 1048576.0, context.info().name,
                                 static_cast<double>(context.info().deviceLocalBytes) / 1048576.0));

  const auto sums = [&](std::uint64_t bytes, const std::string& name) {
    return gpu::TexelBuffer(context, bytes, vk::Format::eR32G32B32A32Sfloat, kStorage | Usage::eStorageTexelBuffer, name);
  };
  for (std::size_t i = 0; i < layout_.bands.size(); ++i) {
    Band b;
    b.rows = layout_.bands[i];
    const std::uint64_t px = layout_.bandPixels(i);
    const std::string tag = layout_.bands.size() > 1 ? fmt::format("[band {}]", i) : "";
    b.gbuffer = gpu::TexelBuffer(context, atLeastOne(px * sizeof(gpu::GBufferTexel)), vk::Format::eR32G32B32A32Sfloat,
                                 kStorage, "frame.gbuffer" + tag);
    b.aovs = gpu::Buffer(context, contents.primaryAovs ? px * gpu::kAovSlots * kAccumulator : kVec4, kStorage,
                         "frame.aovs" + tag);
    b.ambient = sums(px * kAccumulator, "frame.ambient" + tag);
    b.specularAmbient = sums(specular ? px * kAccumulator : kVec4, "frame.specular_ambient" + tag);
    b.queue = gpu::Buffer(context, 2 * (gpu::kQueueHeader + (specular ? px : 1)) * 4,
                          kStorage | Usage::eIndirectBuffer, "frame.specular_queue" + tag);
    b.specularPaths = gpu::Buffer(context, specular ? px * gpu::kSpecularPathTexels * kVec4 : kVec4, kStorage,
                                  "frame.specular_paths" + tag);
    b.composed = gpu::Buffer(context, px * contents.composedSlots * kVec4, kStorage, "frame.composed" + tag);
    b.display = gpu::Buffer(context, atLeastOne(px * 4), kStorage, "frame.display" + tag);
    const std::uint64_t slots = maxLights_;
    b.basis = sums(px * slots * kAccumulator, "frame.basis" + tag);
    b.emissionBasis = sums(px * slots * kAccumulator, "frame.emission_basis" + tag);
    b.specularBasis = sums(specular ? px * slots * kAccumulator : kVec4, "frame.specular_basis" + tag);
    // One word per light and pixel, each light's row padded to whole RGBA32UI texels.
    const std::uint64_t resolvedWords = std::uint64_t(gpu::resolvedStride(static_cast<std::uint32_t>(px))) * (slots + 1);
    b.resolved = gpu::TexelBuffer(context, resolvedWords * 4, vk::Format::eR32G32B32A32Uint, kStorage,
                                  "frame.resolved" + tag);
    b.hitBounds = gpu::Buffer(context, px * 2 * kVec4, kStorage, "frame.hit_bounds" + tag);
    b.dirty = gpu::Buffer(context, (2 * px + gpu::kQueueHeader + gpu::kDirtyBoxWords + 8 * slots) * 4, kStorage | Usage::eIndirectBuffer,
                          "frame.dirty" + tag);
    b.sampleCounts = gpu::Buffer(context, atLeastOne(px * 4), kStorage, "frame.sample_counts" + tag);
    b.emitterEdges = gpu::Buffer(context, atLeastOne(px * 4), kStorage, "frame.emitter_edges" + tag);
    b.pathHits = gpu::Buffer(context, specular ? atLeastOne(px * contents_.keptRaySamples * kPathHitBytesPerSample) : kVec4,
                             kStorage, "frame.path_hits" + tag);
    b.shadowRays = gpu::Buffer(context, atLeastOne(px * contents_.keptRaySamples * keptShadowRayBytesPerSample(contents.keptShadowRays)),
                               kStorage, "frame.kept_shadow_rays" + tag);
    bands_.push_back(std::move(b));
  }
  status_ = StatusCounters(context, "frame.status");
}

std::uint64_t ObscuranceFrame::bytes() const {
  std::uint64_t total = status_.buffer().size();
  for (const auto& b : bands_)
    for (const gpu::Buffer* buffer : {&b.gbuffer.buffer(), &b.aovs, &b.basis.buffer(), &b.emissionBasis.buffer(), &b.ambient.buffer(),
                                      &b.specularBasis.buffer(),
                                      &b.specularAmbient.buffer(), &b.queue, &b.specularPaths, &b.composed, &b.display, &b.resolved.buffer(), &b.hitBounds, &b.dirty,
                                      &b.sampleCounts, &b.emitterEdges, &b.pathHits, &b.shadowRays})
      total += buffer->size();
  return total;
}

void ObscuranceFrame::addLightSlot(gpu::CommandStream& stream, std::uint32_t index) {
  if (lights_ >= maxLights_)
    throw InputError(fmt::format("{} lights: this frame was made with room for {} (spare light slots: {})",
                                 lights_ + 1, maxLights_, contents_.spareLightSlots));
  if (index > lights_) throw std::logic_error("addLightSlot: index past the last light");
  stream.submit([&](const vk::raii::CommandBuffer& cmd) {
    for (std::size_t i = 0; i < bands_.size(); ++i) {
      const std::uint64_t slot = layout_.bandPixels(i) * kAccumulator;
      Band& b = bands_[i];
      std::vector<const gpu::Buffer*> perLight = {&b.basis.buffer(), &b.emissionBasis.buffer()};
      if (contents_.specular) perLight.push_back(&b.specularBasis.buffer());
      // Slot by slot from the top, each copy after the last (copies within one buffer must not overlap).
      for (std::uint32_t l = lights_; l > index; --l) {
        const vk::BufferCopy region{.srcOffset = (l - 1) * slot, .dstOffset = l * slot, .size = slot};
        for (const gpu::Buffer* buffer : perLight) cmd.copyBuffer(buffer->handle(), buffer->handle(), region);
        gpu::computeBarrier(cmd);
      }
      for (const gpu::Buffer* buffer : perLight) cmd.fillBuffer(buffer->handle(), index * slot, slot, 0u);
    }
  });
  ++lights_;
}

void ObscuranceFrame::removeLightSlot(gpu::CommandStream& stream, std::uint32_t index) {
  if (index >= lights_) throw std::logic_error("removeLightSlot: no such light");
  stream.submit([&](const vk::raii::CommandBuffer& cmd) {
    for (std::size_t i = 0; i < bands_.size(); ++i) {
      const std::uint64_t slot = layout_.bandPixels(i) * kAccumulator;
      Band& b = bands_[i];
      // Slot by slot, each copy after the last (copies within one buffer must not overlap).
      for (std::uint32_t l = index + 1; l < lights_; ++l) {
        const vk::BufferCopy region{.srcOffset = l * slot, .dstOffset = (l - 1) * slot, .size = slot};
        cmd.copyBuffer(b.basis.buffer().handle(), b.basis.buffer().handle(), region);
        cmd.copyBuffer(b.emissionBasis.buffer().handle(), b.emissionBasis.buffer().handle(), region);
        if (contents_.specular) cmd.copyBuffer(b.specularBasis.buffer().handle(), b.specularBasis.buffer().handle(), region);
        gpu::computeBarrier(cmd);
      }
    }
  });
  --lights_;
}

} // namespace obscura::render
