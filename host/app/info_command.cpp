// obscura info [SCENE] — the Vulkan devices, their limits and the one a render would choose; with
// a scene, what edits can name: its lights (groups and punctual, with type and power), objects, cameras,
// triangles, bounds and the default dmax.
#include <fmt/core.h>

#include "app/commands.h"
#include "app/scene_setup.h"
#include "render/obscurance_renderer.h"
#include "render/scene_data/light_set.h"
#include "relight/relight_state.h"
#include "scene/scene_edit.h"

namespace obscura::app {
namespace {

struct InfoOptions {
  std::string scenePath;
  std::string lightGroups = "node";
};

void printDevices() {
  std::uint32_t chosen = 0;
  auto devices = gpu::Context::listDevices(&chosen);
  if (devices.empty()) {
    fmt::print("no Vulkan device found\n");
    return;
  }
  for (const auto& d : devices) {
    fmt::print("[{}] {}{}\n", d.index, d.name, d.index == chosen ? "   <- chosen (automatic)" : "");
    fmt::print("    type {}, Vulkan {}, driver {}\n", d.type, d.apiVersion, d.driver);
    fmt::print("    device-local memory {:.0f} MiB, max storage buffer {} MiB, max texel buffer {} texels\n",
               static_cast<double>(d.deviceLocalBytes) / 1048576.0, d.maxStorageBufferRange >> 20,
               d.maxTexelBufferElements);
    fmt::print("    workgroup invocations <= {}, groups <= {}x{}x{}, push constants {} B, subgroup {}\n",
               d.maxComputeWorkGroupInvocations, d.maxComputeWorkGroupCount[0], d.maxComputeWorkGroupCount[1],
               d.maxComputeWorkGroupCount[2], d.maxPushConstantsSize, d.subgroupSize);
    fmt::print("    timestamps {} (period {} ns), compute queue {}\n", d.timestamps ? "yes" : "no",
               d.timestampPeriodNs, d.hasComputeQueue ? "yes" : "no");
  }
}

void printScene(const InfoOptions& o) {
  const LoadedScene loaded = loadScene(o.scenePath, o.lightGroups);
  const auto& s = loaded.scene;
  fmt::print("{}\n", sceneSummary(loaded));
  const scene::Camera camera = s.cameras.empty() ? scene::defaultCamera(s.bounds) : s.cameras.front();
  const render::FreePath freePath = render::measureFreePath(s, loaded.bvh, camera);
  fmt::print("bounds: ({:.4g}, {:.4g}, {:.4g}) .. ({:.4g}, {:.4g}, {:.4g}); default dmax {:.4g} (half the median free "
             "path {:.4g} seen from the first camera, {:.1f}% of those rays leave the scene; the paper's 1/4 of the "
             "box: {:.4g}); --escapes auto: {}\n",
             s.bounds.lo.x, s.bounds.lo.y, s.bounds.lo.z, s.bounds.hi.x, s.bounds.hi.y, s.bounds.hi.z,
             render::defaultDMax(s, freePath), freePath.median, 100.0 * freePath.escaped,
             render::boundsDMax(s.bounds), freePath.open() ? "dark (rays leave the scene)" : "ambient (closed)");
  const render::LightSet lights = render::buildLightSet(s);
  fmt::print("lights ({}; names for --light and edits):\n", lights.size());
  for (std::size_t i = 0; i < lights.size(); ++i) {
    const auto& e = lights.emission[i];
    const std::size_t triangles = i < s.lightGroups.size() ? s.lightGroups[i].triangles.size() : 0;
    fmt::print("  {:<28} {:<11} E ({:.4g}, {:.4g}, {:.4g})  power {:.4g}{}\n", lights.names[i],
               nameOf(render::kLightTypeNames, lights.type(i)), e.x, e.y, e.z, lights.power[i],
               triangles ? fmt::format("  ({} triangles)", triangles) : std::string());
  }
  fmt::print("objects ({}; names for move, remove):\n", s.objects.size());
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    const scene::Bounds b = scene::objectBounds(s, i);
    fmt::print("  {:<28} {:>7} triangles  ({:.3g}, {:.3g}, {:.3g}) .. ({:.3g}, {:.3g}, {:.3g})\n", s.objects[i].name,
               s.objects[i].triangleCount, b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
  }
  fmt::print("cameras ({}; --camera N):\n", s.cameras.size());
  for (std::size_t i = 0; i < s.cameras.size(); ++i) {
    const auto& c = s.cameras[i];
    fmt::print("  [{}] {:<24} at ({:.4g}, {:.4g}, {:.4g}), yfov {:.1f} deg\n", i, c.name, c.position.x, c.position.y,
               c.position.z, c.yfov * 57.29578f);
  }
}

} // namespace

void addInfoCommand(CLI::App& app) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand(
      "info", "List the Vulkan devices and the chosen one; with a scene, its lights, cameras and size");
  cmd->add_option("scene", options->scenePath, "a glTF scene to describe (optional)");
  cmd->add_option("--light-groups", options->lightGroups, "node (default), material, or a JSON file of groups");
  cmd->callback([options] {
    if (options->scenePath.empty()) printDevices();
    else printScene(*options);
  });
}

} // namespace obscura::app
