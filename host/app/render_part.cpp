#include "app/render_part.h"

#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "core/error.h"
#include "core/sha256.h"
#include "farm/part.h"
#include "io/image_io.h"
#include "relight/relight_state.h"
#include "render/obscurance_renderer.h"
#include "render/path_tracer.h"
#include "shared/host_device.h"

namespace obscura::app {
namespace {
namespace fs = std::filesystem;

void checkPartOptions(const RenderOptions& o) {
  if (io::extensionOf(o.output) != "exr")
    throw InputError(fmt::format("{}: a part (--samples, --tile) is written as .exr, the sums that 'obscura merge' "
                                 "adds up; merge the parts to get a PNG", o.output));
  if (o.denoise)
    throw InputError("--denoise with --samples or --tile: a denoised part would not merge exactly; denoise the merged "
                     "frame instead");
  if (!o.aovs.empty())
    throw InputError("--aov with --samples or --tile: a part keeps every AOV's sums; choose AOVs when merging");
  if (!o.saveState.empty())
    throw InputError("--save-state with --samples or --tile: every part keeps its per-light transport; give "
                     "--save-state DIR to 'obscura merge' to write the merged relighting state");
}

// Appends a channel per value of `values` (pixels x components) named `names`.
void appendSums(io::Image& image, const std::vector<std::string>& names, const std::vector<float>& values) {
  io::Image more;
  more.width = image.width;
  more.height = image.height;
  more.channels = names;
  more.pixels = values;
  io::appendChannels(image, more);
}

io::Image countChannel(std::uint32_t width, std::uint32_t rows, const std::vector<std::uint32_t>& counts) {
  io::Image image;
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(rows);
  image.channels = {"count"};
  image.pixels.assign(counts.begin(), counts.end());
  return image;
}

} // namespace

bool isPartRender(const RenderOptions& o) { return !o.partSamples.empty() || !o.partTile.empty(); }

nlohmann::json jobIdentity(const RenderOptions& o) {
  nlohmann::json job = {
      {"method", nameString(render::kMethodNames, o.method)}, {"width", o.width}, {"height", o.height}, {"spp", o.spp}, {"seed", o.seed},
      {"camera", o.camera}, {"scene", farm::sceneHash(o.scenePath)},
      {"light_groups", fs::is_regular_file(o.lightGroups) ? "file:" + sha256OfFile(o.lightGroups) : o.lightGroups},
      {"background", o.background}, {"emission_samples", o.obscurance.emissionSamples},
      {"emission_at_edges", o.obscurance.emissionAtEdges},
      {"max_depth", o.obscurance.maxDepth}, {"light_sampling", nameString(render::kLightSamplingNames, o.obscurance.lightSampling)}};
  if (o.method == render::Method::Obscurance) {
    job["shadow_rays"] = o.obscurance.shadowRays;
    job["obscurance_rays"] = o.obscurance.obscuranceRays;
    job["rho"] = nameString(render::kRhoKindNames, o.obscurance.rho);
    job["tau"] = o.obscurance.tau;
    job["dmax"] = o.dMax;
    job["sampling"] = nameString(render::kObscuranceSamplingNames, o.obscurance.systematic);
    job["colour_bleeding"] = !o.noBleed;
    job["escapes"] = nameString(render::kEscapeModelNames, o.obscurance.escapes);
    job["vertex_rays"] = nameString(render::kVertexRaysNames, o.obscurance.vertexRaysByThroughput);
    job["shadow_sampling"] = nameString(render::kShadowSamplingNames, o.obscurance.shadowSampling);
    job["ambient"] = nameString(render::kAmbientModelNames, o.obscurance.ambient);
    job["secondary_reflectors"] = o.obscurance.secondaryReflectors;
  }
  return job;
}

void renderPart(RenderOptions& o) {
  checkPartOptions(o);
  checkRenderOptions(o);
  // What can be checked without the scene is, before it is loaded.
  farm::Part part;
  part.samples = o.partSamples.empty() ? farm::SampleRange{0, o.spp} : farm::parseSampleRange(o.partSamples);
  if (part.samples.end > o.spp)
    throw InputError(fmt::format("--samples {}:{} goes past --spp {} (the job's samples are 0:{})", part.samples.begin,
                                 part.samples.end, o.spp, o.spp));
  if (o.spp > (1u << 24)) throw InputError("--spp above 2^24: a part's sample counts are kept as floats");
  part.tile = o.partTile.empty() ? farm::Tile{} : farm::parseTile(o.partTile);
  LoadedScene loaded = loadScene(o.scenePath, o.lightGroups, std::nullopt);
  applyBackground(o, loaded);
  const scene::Camera camera = chooseCamera(loaded.scene, o.camera);
  chooseSize(o, camera); // the tile's rows need the image's height
  part.rows = farm::tileRows(part.tile, o.height);
  part.job = jobIdentity(o);
  warnIfUnlit(loaded);

  const std::shared_ptr<gpu::Context> contextHandle = commandContext(o.device);
  const gpu::Context& context = *contextHandle;
  fmt::print(stderr, "device: {} ({})\n", context.info().name, context.info().driver);
  buildTreeFor(loaded, context);
  fmt::print(stderr, "{}\n", sceneSummary(loaded));
  render::ObscuranceSettings settings = obscuranceSettings(o, camera);
  settings.editableGeometry = false;
  settings.firstSample = part.samples.begin;
  settings.rows = part.rows;
  render::RenderStats stats;
  if (o.method == render::Method::PathTrace) {
    const render::PathTraceSettings pt = pathTraceSettings(settings); // the part's rows and samples
    render::PathTracer tracer(context, loaded.scene, loaded.bvh, pt);
    tracer.reset();
    tracer.iterate(part.samples.count());
    stats = tracer.stats();
    part.sums = countChannel(o.width, part.rows.count,
                             std::vector<std::uint32_t>(std::size_t(o.width) * part.rows.count, part.samples.count()));
    io::appendChannels(part.sums, tracer.sums());
    part.frame = {{"lights", render::buildLightSet(loaded.scene).names}};
  } else {
    // Every AOV's sums are kept; nothing is composed here (merge composes the merged sums).
    settings.primaryAovs = true;
    settings.composedAovs = false;
    render::ObscuranceRenderer renderer(context, loaded.scene, loaded.bvh, settings);
    renderer.reset();
    renderer.iterate(part.samples.count());
    stats = renderer.stats();
    const render::ObscuranceRenderer::Sums sums = renderer.sums();
    part.sums = countChannel(o.width, part.rows.count, sums.counts);
    io::appendChannels(part.sums, sums.transport.toImage());
    std::vector<std::string> names;
    for (std::uint32_t slot = 0; slot < gpu::kAovSlots; ++slot)
      for (const char* c : {"X", "Y", "Z", "W"}) names.push_back(fmt::format("P{}.{}", slot, c));
    std::vector<float> values(sums.primaryAovs.size() * 4);
    for (std::size_t i = 0; i < sums.primaryAovs.size(); ++i)
      for (int k = 0; k < 4; ++k) values[i * 4 + k] = sums.primaryAovs[i][k];
    appendSums(part.sums, names, values);
    nlohmann::json state = relight::stateJson(renderer, o.scenePath);
    state.erase("samples"); // the merged frame's, not the part's
    state.erase("scene");   // where it lies is the part's info, not the frame's
    part.frame = {{"state", state}, {"primary_aovs", true}};
  }
  for (const auto& note : stats.notes) fmt::print(stderr, "note: {}\n", note);
  if (stats.truncatedTraversals > 0)
    throw DeviceError(fmt::format("{} traversals ran out of steps (kMaxTraversalSteps); the part would be wrong",
                                  stats.truncatedTraversals));
  const double gpuMs = stats.totalGpuMs();
  part.info = {{"scene_path", o.scenePath}, {"device", context.info().name}, {"gpu_ms", gpuMs},
               {"wall_s", stats.wallSeconds}};
  farm::writePart(o.output, part);
  fmt::print(stderr, "render: part tile {}/{} (rows {}..{}) samples {}:{} of {}x{}, {} spp, {:.1f} ms GPU, {:.2f} s wall -> {}\n",
             part.tile.index, part.tile.count, part.rows.first, part.rows.first + part.rows.count, part.samples.begin,
             part.samples.end, o.width, o.height, o.spp, gpuMs, stats.wallSeconds, o.output);
  if (!o.metrics.empty()) {
    std::ofstream out(o.metrics);
    out << nlohmann::json({{"part", part.info}, {"job", part.job}}).dump(2) << "\n";
    if (!out) throw InputError(fmt::format("{}: cannot write metrics", o.metrics));
  }
}

} // namespace obscura::app
