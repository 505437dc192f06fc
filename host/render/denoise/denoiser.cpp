#include "render/denoise/denoiser.h"

#include <algorithm>
#include <bit>
#include <stdexcept>

#include <fmt/format.h>
#include <glm/gtc/packing.hpp>

#include "core/luminance.h"
#include "gpu/command_stream.h"
#include "gpu/timestamps.h"
#include "render/denoise/atrous_pass.h"
#include "render/denoise/denoise_frame.h"
#include "render/denoise/edge_pass.h"
#include "render/denoise/gather_pass.h"
#include "render/denoise/remodulate_pass.h"
#include "render/denoise/reproject_pass.h"
#include "render/denoise/temporal_pass.h"
#include "render/obscurance_renderer.h"
#include "render/passes/primary_pass.h"
#include "render/passes/tonemap_pass.h"

namespace obscura::render {
namespace {

// The filter's edge-stopping parameters (denoise_atrous.comp; sigma_l is in the settings, sigma_n
// = 128, Schied et al.'s (2017, §5), in the shader): sigma_z is in pixel widths off the plane per
// pixel of distance; sigma_a stops the filter at strong albedo changes only (textures are
// demodulated, so need no stop).
constexpr float kSigmaPlane = 1.0f;
constexpr float kSigmaAlbedo = 0.25f;

bool sameCamera(const scene::Camera& a, const scene::Camera& b) {
  return a.position == b.position && a.forward == b.forward && a.up == b.up && a.yfov == b.yfov;
}

} // namespace

struct Denoiser::Impl {
  Impl(const gpu::Context& c, const ObscuranceRenderer& renderer)
      : context(&c), source(&renderer.frame()), frame(c, renderer.layout().width, renderer.layout().height),
        gather(c, renderer.layout().bandCount()), reproject(c), temporal(c), atrous(c), remodulate(c),
        edges(c, renderer.sceneKernels()), tonemap(c, 1),
        stream(c), timestamps(c) {
    for (std::uint32_t copy = 0; copy < 2; ++copy) {
      for (std::uint32_t b = 0; b < renderer.layout().bandCount(); ++b) gather.bind(b, copy, *source, frame);
      reproject.bind(copy, frame);
      temporal.bind(copy, frame);
      atrous.bind(copy, frame);
      remodulate.bind(copy, frame);
    }
    tonemap.bind(0, frame.combined, frame.display);
  }

  const gpu::Context* context;
  const ObscuranceFrame* source; // the renderer's frame the gather pass is bound to
  DenoiseFrame frame;
  GatherPass gather;
  ReprojectPass reproject;
  TemporalPass temporal;
  AtrousPass atrous;
  RemodulatePass remodulate;
  EdgePass edges;
  TonemapPass tonemap;
  gpu::CommandStream stream;
  gpu::Timestamps timestamps;

  std::uint32_t parity = 0;     // which copy of the guide and integrated terms this frame writes
  bool haveHistory = false;     // the other copy holds a frame made with previousCamera
  bool carryStale = true;       // the carry holds nothing worth blending (after reset)
  scene::Camera previousCamera;
  std::map<std::string, double> lastMs;
};

Denoiser::Denoiser(const gpu::Context& context, const ObscuranceRenderer& renderer, const DenoiserSettings& settings)
    : settings_(settings) {
  const FrameContents& contents = renderer.frame().contents();
  if (!contents.primaryAovs || contents.composedSlots != gpu::kComposeSlots)
    throw std::invalid_argument("Denoiser: the renderer must keep its primary and composed AOVs (the normal, depth "
                                "and albedo guides, the direct and ambient terms)");
  if (settings.iterations > 16) throw std::invalid_argument("Denoiser: at most 16 a-trous iterations");
  if (settings.geometryEdgeRays > gpu::kMaxEdgeRays || settings.emitterEdgeRays > gpu::kMaxEdgeRays)
    throw std::invalid_argument(fmt::format("Denoiser: at most {} edge rays a pixel", gpu::kMaxEdgeRays));
  impl_ = std::make_unique<Impl>(context, renderer);
}

Denoiser::~Denoiser() = default;

void Denoiser::reset() {
  impl_->haveHistory = false;
  impl_->carryStale = true;
}

void Denoiser::denoise(const ObscuranceRenderer& renderer, float exposureStops) {
  Impl& d = *impl_;
  if (&renderer.frame() != d.source)
    throw std::invalid_argument("Denoiser::denoise: made for another renderer's frame");
  const FrameLayout& layout = renderer.layout();
  const scene::Camera& camera = renderer.settings().camera;
  const bool moved = d.haveHistory && !sameCamera(camera, d.previousCamera);
  const bool useHistory = settings_.temporal && moved;
  const bool clearCarry = !settings_.temporal || d.carryStale;

  const gpu::DenoiseParams params{
      .camera = renderer.primaryCamera(), // the sky's slot in up.w for the edge rays
      .previous = gpuCamera(d.haveHistory ? d.previousCamera : camera, layout.width, layout.height),
      .frame = glm::uvec4(layout.width, layout.height, settings_.maxHistorySamples, renderer.specular() ? 1u : 0u),
      .weights = glm::vec4(kSigmaPlane, kSigmaAlbedo, settings_.luminanceSigma, 0.0f)};
  d.frame.params.upload(*d.context, &params, sizeof(params));

  const std::map<std::string, double> before = d.timestamps.totalsMs();
  const std::uint32_t parity = d.parity;
  d.edges.bind(renderer, d.frame, parity);
  // The renderer's emission rays per sample at an emitter's border (--emission-samples): how many
  // points its own estimate of the seen emission there has.
  const ObscuranceSettings& rs = renderer.settings();
  const EdgePass::Dispatch edgeDispatch{.geometryRays = settings_.geometryEdgeRays,
                                        .emitterRays = settings_.emitterEdgeRays,
                                        .lights = static_cast<std::uint32_t>(renderer.lights().size()),
                                        .ownEmissionRays = std::max(rs.emissionSamples, 1u),
                                        .ambientLuminance = luminance(renderer.ambientIntensity())};
  d.stream.submit([&](const vk::raii::CommandBuffer& cmd) {
    d.timestamps.reset(cmd);
    d.timestamps.begin(cmd, "denoise.gather");
    for (std::uint32_t b = 0; b < layout.bandCount(); ++b) d.gather.record(cmd, b, parity, *d.source);
    d.timestamps.end(cmd, "denoise.gather");
    if (clearCarry) cmd.fillBuffer(d.frame.carry.handle(), 0, VK_WHOLE_SIZE, 0u);
    gpu::computeBarrier(cmd);
    if (useHistory) {
      d.timestamps.begin(cmd, "denoise.reproject");
      d.reproject.record(cmd, parity, d.frame);
      d.timestamps.end(cmd, "denoise.reproject");
      gpu::computeBarrier(cmd);
    }
    d.timestamps.begin(cmd, "denoise.temporal");
    d.temporal.record(cmd, parity, d.frame);
    d.timestamps.end(cmd, "denoise.temporal");
    gpu::computeBarrier(cmd);
    d.timestamps.begin(cmd, "denoise.atrous");
    for (std::uint32_t i = 0; i < settings_.iterations; ++i) {
      d.atrous.record(cmd, parity, i, d.frame);
      gpu::computeBarrier(cmd);
    }
    d.timestamps.end(cmd, "denoise.atrous");
    d.timestamps.begin(cmd, "denoise.remodulate");
    d.remodulate.record(cmd, parity, filterSourceAfter(settings_.iterations), d.frame);
    d.timestamps.end(cmd, "denoise.remodulate");
    gpu::computeBarrier(cmd);
    d.timestamps.begin(cmd, "denoise.edges");
    d.edges.record(cmd, d.frame, edgeDispatch);
    d.timestamps.end(cmd, "denoise.edges");
    gpu::computeBarrier(cmd);
    const FrameLayout whole{.width = layout.width, .height = layout.height, .bands = {{0, layout.height}}};
    d.timestamps.begin(cmd, "denoise.tonemap");
    d.tonemap.record(cmd, 0, whole, 0, 3, exposureStops, 1);
    d.timestamps.end(cmd, "denoise.tonemap");
  });
  d.timestamps.collect();
  d.lastMs = d.timestamps.msSince(before, "denoise.");
  // The carry stays while the camera does: the renderer's accumulation goes on with the same view.
  if (clearCarry && settings_.temporal) d.carryStale = false;
  d.previousCamera = camera;
  d.haveHistory = true;
  d.parity = 1 - parity;
}

std::vector<std::uint32_t> Denoiser::display() const {
  auto bytes = impl_->frame.display.download<std::uint32_t>(*impl_->context);
  bytes.resize(impl_->frame.pixels());
  return bytes;
}

io::Image Denoiser::image() const {
  const DenoiseFrame& f = impl_->frame;
  const auto combined = f.combined.download<glm::vec4>(*impl_->context);
  io::Image image{.width = static_cast<int>(f.width), .height = static_cast<int>(f.height),
                  .channels = {"combined.R", "combined.G", "combined.B"}, .pixels = {}};
  image.pixels.reserve(f.pixels() * 3);
  for (std::uint64_t p = 0; p < f.pixels(); ++p)
    for (int c = 0; c < 3; ++c) image.pixels.push_back(combined[p][c]);
  return image;
}

io::Image Denoiser::reprojectedHistory() const {
  const DenoiseFrame& f = impl_->frame;
  const auto carry = f.carry.download<glm::uvec4>(*impl_->context);
  io::Image image{.width = static_cast<int>(f.width), .height = static_cast<int>(f.height),
                  .channels = {"direct.R", "direct.G", "direct.B", "indirect.R", "indirect.G", "indirect.B",
                               "specular.R", "specular.G", "specular.B", "history.N"},
                  .pixels = {}};
  image.pixels.reserve(f.pixels() * image.channels.size());
  for (std::uint64_t p = 0; p < f.pixels(); ++p) {
    // The halves of shared/host_device.h's illum layout: direct rgb, ambient rgb, variances; then
    // specular rgb, its variance, unused, the sample count.
    const glm::uvec4 t0 = carry[gpu::kDenoiseIllumTexels * p], t1 = carry[gpu::kDenoiseIllumTexels * p + 1];
    const glm::vec2 a = glm::unpackHalf2x16(t0.x), b = glm::unpackHalf2x16(t0.y), c = glm::unpackHalf2x16(t0.z);
    const glm::vec2 s = glm::unpackHalf2x16(t1.x), sb = glm::unpackHalf2x16(t1.y);
    for (float v : {a.x, a.y, b.x, b.y, c.x, c.y, s.x, s.y, sb.x, std::bit_cast<float>(t1.w)}) image.pixels.push_back(v);
  }
  return image;
}

double Denoiser::lastGpuMs() const { return gpu::sumMs(impl_->lastMs); }

std::map<std::string, double> Denoiser::lastPassMs() const { return impl_->lastMs; }

} // namespace obscura::render
