#include "render/denoise/denoise_frame.h"

#include <fmt/format.h>

#include "core/error.h"
#include "shared/host_device.h"

namespace obscura::render {
namespace {
using Usage = vk::BufferUsageFlagBits;
const auto kStorage = Usage::eStorageBuffer | Usage::eTransferSrc | Usage::eTransferDst;
constexpr std::uint64_t kTexel = 16; // RGBA32UI
constexpr std::uint64_t kIllum = gpu::kDenoiseIllumTexels * kTexel;
} // namespace

DenoiseFrame::DenoiseFrame(const gpu::Context& context, std::uint32_t w, std::uint32_t h) : width(w), height(h) {
  const std::uint64_t px = pixels();
  const auto& info = context.info();
  if (px * kIllum > info.maxStorageBufferRange || px * gpu::kDenoiseIllumTexels > info.maxTexelBufferElements)
    throw InputError(fmt::format("the denoiser keeps whole-frame buffers of {} bytes per pixel: {}x{} needs {:.0f} MiB "
                                 "each, more than the device '{}' allows in one buffer ({:.0f} MiB, {} texels); "
                                 "denoise a smaller image",
                                 kIllum, w, h, static_cast<double>(px * kIllum) / 1048576.0, info.name,
                                 static_cast<double>(info.maxStorageBufferRange) / 1048576.0,
                                 info.maxTexelBufferElements));
  auto texels = [&](std::uint64_t bytesPerPixel, const char* name) {
    return gpu::TexelBuffer(context, px * bytesPerPixel, vk::Format::eR32G32B32A32Uint, kStorage, name);
  };
  params = gpu::Buffer(context, sizeof(gpu::DenoiseParams), kStorage, "denoise.params");
  for (int i = 0; i < 2; ++i) {
    guide[i] = texels(kTexel, i == 0 ? "denoise.guide[0]" : "denoise.guide[1]");
    integrated[i] = texels(kIllum, i == 0 ? "denoise.integrated[0]" : "denoise.integrated[1]");
    filtered[i] = texels(kIllum, i == 0 ? "denoise.filtered[0]" : "denoise.filtered[1]");
  }
  noisy = texels(kIllum, "denoise.noisy");
  carry = gpu::Buffer(context, px * kIllum, kStorage, "denoise.carry");
  emission = gpu::Buffer(context, px * 16, kStorage, "denoise.emission");
  remodulated = gpu::Buffer(context, px * 16, kStorage, "denoise.remodulated");
  combined = gpu::Buffer(context, px * 16, kStorage, "denoise.combined");
  display = gpu::Buffer(context, px * 4, kStorage, "denoise.display");
}

} // namespace obscura::render
