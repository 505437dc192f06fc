#include "render/correction/path_correction.h"

#include <algorithm>
#include <bit>
#include <stdexcept>

#include <fmt/format.h>

#include "core/error.h"
#include "gpu/buffer.h"
#include "gpu/command_stream.h"
#include "gpu/kernel.h"
#include "gpu/timestamps.h"
#include "render/obscurance_renderer.h"
#include "render/path_tracer.h"
#include "shared/host_device.h"

#include "correction_filter.spv.h"
#include "correction_residual.spv.h"

namespace obscura::render {
namespace {
using Usage = vk::BufferUsageFlagBits;
const auto kStorage = Usage::eStorageBuffer | Usage::eTransferSrc | Usage::eTransferDst;
// The plane stop in pixel widths off the plane per pixel of distance: the denoiser's sigma_z.
constexpr float kSigmaPlane = 1.0f;
// A pixel's radiance sum in the path tracer's buffers: a vec4 accumulator pair.
constexpr std::uint64_t kPathBytes = gpu::kAccumulatorVec4s * 16;
// The filter's widest cascade (steps 1..8) and the paths from which it is left out.
constexpr std::uint32_t kMaxIterations = 4;
} // namespace

std::uint32_t PathCorrection::iterationsFor(std::uint32_t paths) {
  std::uint32_t quadruplings = 0;
  for (std::uint32_t n = paths; n >= 4; n /= 4) ++quadruplings;
  return quadruplings >= kMaxIterations ? 0u : kMaxIterations - quadruplings;
}

std::uint32_t PathCorrection::defaultPaths(std::uint32_t spp) {
  return spp > kPaperSpp ? std::max(kMinDefaultPaths, spp - kPaperSpp) : 0u;
}

struct PathCorrection::Impl {
  Impl(const gpu::Context& c, const ObscuranceRenderer& renderer, const PathTracer& paths)
      : context(&c), source(&renderer.frame()), pathSource(&paths), width(renderer.layout().width),
        height(renderer.layout().height),
        residualKernel(c, gpu::storageKernelDesc("correction.residual", kSpirv_correction_residual,
                                                 gpu::kResidualBindingCount, sizeof(gpu::CorrectionPush),
                                                 renderer.layout().bandCount())),
        filterKernel(c, gpu::storageKernelDesc("correction.filter", kSpirv_correction_filter,
                                               gpu::kCorrectionBindingCount, sizeof(gpu::CorrectionPush), 2)),
        stream(c), timestamps(c) {
    const std::uint64_t px = std::uint64_t(width) * height;
    if (px * kPathBytes > c.info().maxStorageBufferRange)
      throw InputError(fmt::format("the path-traced correction keeps whole-frame buffers of up to {} bytes per "
                                   "pixel: {}x{} is more than the device '{}' allows in one buffer",
                                   kPathBytes, width, height, c.info().name));
    pathSums = gpu::Buffer(c, px * kPathBytes, kStorage, "correction.paths");
    params = gpu::Buffer(c, sizeof(gpu::DenoiseParams), kStorage, "correction.params");
    guide = gpu::Buffer(c, px * 16, kStorage, "correction.guide");
    base = gpu::Buffer(c, px * 16, kStorage, "correction.base");
    residual[0] = gpu::Buffer(c, px * 16, kStorage, "correction.residual[0]");
    residual[1] = gpu::Buffer(c, px * 16, kStorage, "correction.residual[1]");
    corrected = gpu::Buffer(c, px * 16, kStorage, "correction.corrected");
    const FrameLayout& layout = renderer.layout();
    for (std::uint32_t b = 0; b < layout.bandCount(); ++b) {
      const auto& band = source->band(b);
      residualKernel.bind(gpu::kBindingCorrectionParams, params, b);
      residualKernel.bind(gpu::kBindingResidualComposed, band.composed, b);
      residualKernel.bind(gpu::kBindingResidualAovs, band.aovs, b);
      residualKernel.bind(gpu::kBindingResidualSampleCounts, band.sampleCounts, b);
      residualKernel.bind(gpu::kBindingResidualPaths, pathSums, b);
      residualKernel.bind(gpu::kBindingResidualGuide, guide, b);
      residualKernel.bind(gpu::kBindingResidualBase, base, b);
      residualKernel.bind(gpu::kBindingResidualOut, residual[0], b);
    }
    // Set s reads residual[s] and writes the other: the steps ping-pong.
    for (std::uint32_t s = 0; s < 2; ++s) {
      filterKernel.bind(gpu::kBindingCorrectionParams, params, s);
      filterKernel.bind(gpu::kBindingCorrectionGuide, guide, s);
      filterKernel.bind(gpu::kBindingCorrectionBase, base, s);
      filterKernel.bind(gpu::kBindingCorrectionIn, residual[s], s);
      filterKernel.bind(gpu::kBindingCorrectionOut, residual[1 - s], s);
      filterKernel.bind(gpu::kBindingCorrectionImage, corrected, s);
    }
  }

  const gpu::Context* context;
  const ObscuranceFrame* source;
  const PathTracer* pathSource;
  std::uint32_t width, height;
  gpu::Kernel residualKernel, filterKernel;
  gpu::Buffer params, guide, base, residual[2], corrected;
  gpu::Buffer pathSums; // the path tracer's bands in one buffer: its bands need not be the renderer's
  gpu::CommandStream stream;
  gpu::Timestamps timestamps;
  std::map<std::string, double> lastMs;
};

PathCorrection::PathCorrection(const gpu::Context& context, const ObscuranceRenderer& renderer,
                               const PathTracer& paths) {
  const FrameContents& contents = renderer.frame().contents();
  if (!contents.primaryAovs || contents.composedSlots != gpu::kComposeSlots)
    throw std::invalid_argument("PathCorrection: the renderer must keep its primary and composed AOVs (the guide, "
                                "the seen emission)");
  const FrameLayout &a = renderer.layout(), &b = paths.layout();
  if (a.width != b.width || a.height != b.height)
    throw std::invalid_argument(fmt::format("PathCorrection: the path tracer's frame ({}x{}) is not the renderer's "
                                            "({}x{})",
                                            b.width, b.height, a.width, a.height));
  impl_ = std::make_unique<Impl>(context, renderer, paths);
}

PathCorrection::~PathCorrection() = default;

void PathCorrection::correct(const ObscuranceRenderer& renderer, const PathTracer& paths) {
  Impl& d = *impl_;
  if (&renderer.frame() != d.source || &paths != d.pathSource)
    throw std::invalid_argument("PathCorrection::correct: made for another renderer or path tracer");
  if (paths.samples() == 0) throw std::invalid_argument("PathCorrection::correct: the path tracer has no paths yet");
  const FrameLayout& layout = renderer.layout();
  const gpu::DenoiseParams params{.camera = renderer.primaryCamera(),
                                  .previous = renderer.primaryCamera(),
                                  .frame = glm::uvec4(layout.width, layout.height, 0u, 0u),
                                  .weights = glm::vec4(kSigmaPlane, 0.0f, 0.0f, 0.0f)};
  d.params.upload(*d.context, &params, sizeof(params));
  const std::uint32_t iterations = iterationsFor(paths.samples());
  const std::map<std::string, double> before = d.timestamps.totalsMs();
  const FrameLayout& pathLayout = paths.layout();
  d.stream.submit([&](const vk::raii::CommandBuffer& cmd) {
    d.timestamps.reset(cmd);
    d.timestamps.begin(cmd, "correction.residual");
    for (std::uint32_t b = 0; b < pathLayout.bandCount(); ++b)
      cmd.copyBuffer(paths.radiance(b).handle(), d.pathSums.handle(),
                     vk::BufferCopy(0, pathLayout.bandFirstPixel(b) * kPathBytes, pathLayout.bandPixels(b) * kPathBytes));
    gpu::computeBarrier(cmd);
    for (std::uint32_t b = 0; b < layout.bandCount(); ++b) {
      const gpu::CorrectionPush push{.firstRow = layout.bands[b].firstRow, .rows = layout.bands[b].rows,
                                     .composedSlots = gpu::kComposeSlots, .pathSamples = paths.samples(),
                                     .step = 0u, .lastStep = 0u, .unused0 = 0u, .unused1 = 0u};
      d.residualKernel.dispatch(cmd, gpu::groupsFor(layout.bandPixels(b), gpu::kWorkgroupSize1D), 1, 1, push, b);
    }
    d.timestamps.end(cmd, "correction.residual");
    gpu::computeBarrier(cmd);
    d.timestamps.begin(cmd, "correction.filter");
    // At least one step: the last one writes the image (step 0: the residual unfiltered).
    const std::uint32_t steps = std::max(iterations, 1u);
    for (std::uint32_t i = 0; i < steps; ++i) {
      const gpu::CorrectionPush push{.firstRow = 0u, .rows = 0u, .composedSlots = 0u, .pathSamples = 0u,
                                     .step = iterations == 0 ? 0u : 1u << i, .lastStep = i + 1 == steps ? 1u : 0u,
                                     .unused0 = 0u, .unused1 = 0u};
      d.filterKernel.dispatch(cmd, gpu::groupsFor(layout.width, gpu::kWorkgroupSizeX),
                              gpu::groupsFor(layout.height, gpu::kWorkgroupSizeY), 1, push, i % 2);
      gpu::computeBarrier(cmd);
    }
    d.timestamps.end(cmd, "correction.filter");
  });
  d.timestamps.collect();
  d.lastMs = d.timestamps.msSince(before, "correction.");
  lastIterations_ = iterations;
}

io::Image PathCorrection::image() const {
  const Impl& d = *impl_;
  const auto pixels = d.corrected.download<glm::vec4>(*d.context);
  io::Image image{.width = static_cast<int>(d.width), .height = static_cast<int>(d.height),
                  .channels = {"combined.R", "combined.G", "combined.B"}, .pixels = {}};
  image.pixels.reserve(std::uint64_t(d.width) * d.height * 3);
  for (std::uint64_t p = 0; p < std::uint64_t(d.width) * d.height; ++p)
    for (int c = 0; c < 3; ++c) image.pixels.push_back(pixels[p][c]);
  return image;
}

double PathCorrection::lastGpuMs() const { return gpu::sumMs(impl_->lastMs); }

std::map<std::string, double> PathCorrection::lastPassMs() const { return impl_->lastMs; }

} // namespace obscura::render
