#include "bench/pass_bench.h"

#include <algorithm>
#include <chrono>
#include <limits>

#include <fmt/format.h>

#include "bench/cpu_time.h"
#include "core/error.h"
#include "render/obscurance_renderer.h"

namespace obscura::bench {

ObscuraFrameResult runObscuraFrame(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                                   const scene::Camera& camera, const ObscuranceFrameWork& work, int repeats) {
  render::ObscuranceSettings settings;
  settings.width = work.width;
  settings.height = work.height;
  settings.spp = work.spp;
  settings.seed = work.seed;
  settings.camera = camera;
  settings.shadowRays = 0;
  settings.obscuranceRays = work.obscuranceRays;
  settings.dMax = work.dMax;
  settings.rho = render::RhoKind::Sqrt;
  settings.systematic = true;
  settings.colourBleeding = false;
  settings.escapes = render::EscapeModel::Ambient; // Embree's frame traces to dMax only
  settings.maxDepth = 1; // the primary hit only: no specular pass
  settings.emissionSamples = 1; // the camera rays Embree's frame traces too, no emitter-edge rays
  settings.primaryAovs = false;
  settings.editableGeometry = false;
  settings.ambient = render::AmbientModel::Global; // no light rays for the reach (not timed, not needed)
  render::ObscuranceRenderer renderer(context, scene, bvh, settings);
  renderer.iterate(1); // warm-up: the first dispatches fault the buffers in

  ObscuraFrameResult result;
  result.bestCpuMs = std::numeric_limits<double>::infinity();
  std::vector<double> times;
  for (int k = 0; k < std::max(1, repeats); ++k) {
    renderer.reset();
    const double c0 = processCpuMs();
    renderer.iterate(work.spp);
    result.bestCpuMs = std::min(result.bestCpuMs, processCpuMs() - c0);
    const render::RenderStats stats = renderer.stats();
    if (stats.truncatedTraversals > 0)
      throw DeviceError(fmt::format("{} traversals ran out of steps", stats.truncatedTraversals));
    const auto ms = [&](const char* pass) { return stats.passes.contains(pass) ? stats.passes.at(pass).gpuMs : 0.0; };
    const auto rays = [&](const char* pass) { return stats.passes.contains(pass) ? stats.passes.at(pass).rays : 0u; };
    const double frameMs = ms("primary") + ms("obscurance");
    if (times.empty() || frameMs < *std::min_element(times.begin(), times.end())) {
      result.bestPrimaryMs = ms("primary");
      result.bestObscuranceMs = ms("obscurance");
    }
    times.push_back(frameMs);
    result.primaryRays = rays("primary");
    result.obscuranceRays = rays("obscurance");
  }
  std::sort(times.begin(), times.end());
  result.bestMs = times.front();
  result.medianMs = times[times.size() / 2];
  renderer.compose();
  const io::Image image = renderer.image();
  const int w = image.channelIndex(render::aovChannels("obscurance").front());
  if (w < 0) throw std::logic_error("runObscuraFrame: the frame has no obscurance AOV");
  result.obscurance.resize(std::size_t(work.width) * work.height);
  for (std::uint32_t y = 0; y < work.height; ++y)
    for (std::uint32_t x = 0; x < work.width; ++x)
      result.obscurance[std::size_t(y) * work.width + x] = image.at(static_cast<int>(x), static_cast<int>(y), w);
  return result;
}

render::RenderStats renderPaperBudget(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                                      const scene::Camera& camera, std::uint32_t width, std::uint32_t height, int repeats) {
  render::ObscuranceSettings settings;
  settings.spp = render::kPaperSpp;
  settings.shadowRays = render::kPaperShadowRays;
  settings.obscuranceRays = render::kPaperObscuranceRays;
  settings.width = width;
  settings.height = height;
  settings.camera = camera;
  // The image as `render -o out.png` makes it: no AOV besides the combined one, no edits.
  settings.editableGeometry = false;
  settings.primaryAovs = false;
  settings.composedAovs = false;
  render::ObscuranceRenderer renderer(context, scene, bvh, settings);
  // Warm-up: pipelines, caches, and a GPU's clocks, which are down after a pause (bench-rays checks
  // its rays on the CPU before) and take a few hundred ms of work to come up.
  const auto start = std::chrono::steady_clock::now();
  do renderer.iterate(1);
  while (context.info().type != "cpu" && std::chrono::steady_clock::now() - start < std::chrono::milliseconds(400));
  render::RenderStats best;
  for (int k = 0; k < std::max(1, repeats); ++k) {
    renderer.reset();
    renderer.iterate(settings.spp);
    renderer.compose(); // and the frame from its sums, tonemapped, as the render's last step
    render::RenderStats stats = renderer.stats();
    if (stats.truncatedTraversals > 0)
      throw DeviceError(fmt::format("{} traversals ran out of steps", stats.truncatedTraversals));
    if (k == 0 || stats.totalGpuMs() < best.totalGpuMs()) best = std::move(stats);
  }
  return best;
}

} // namespace obscura::bench
