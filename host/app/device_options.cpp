// The options every GPU command takes (app/commands.h DeviceOptions), registered here in the
// library beside the commands that call it, and the contexts commands run on.
#include <cstdlib>
#include <map>
#include <tuple>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "app/commands.h"
#include "render/scene_data/bvh_layout.h"

namespace obscura::app {

void addDeviceOptions(CLI::App& command, DeviceOptions& options) {
  command.add_option("--device", options.device, "Vulkan device: index or part of its name (see 'obscura info')");
  command.add_flag("--validate", options.validate, "enable the Khronos validation layer");
  const std::vector<std::string> names = render::traversalRequestNames();
  command.add_option("--traversal", options.traversal,
                     fmt::format("BVH layout and traversal loop: {} (default auto: wide on a CPU device such as "
                                 "lavapipe, binary-while-while on a GPU)",
                                 fmt::join(names, ", ")))
      ->check(CLI::IsMember(names));
}

namespace {

bool keepContexts = false;

// What makes two contexts differ: the options, and the environment a context reads when made.
using ContextKey = std::tuple<std::string, bool, std::string, std::string>;
ContextKey contextKey(const DeviceOptions& options) {
  std::string environment;
  for (const char* name : {"OBSCURA_VALIDATE", "VK_ICD_FILENAMES", "VK_DRIVER_FILES", "LP_NUM_THREADS"}) {
    const char* value = std::getenv(name);
    environment += fmt::format("{}={};", name, value ? value : "<unset>");
  }
  return {options.device, options.validate, options.traversal, environment};
}

// Kept until the process ends and never destroyed: a static's destructor would run after the
// Vulkan loader and lavapipe may have begun to tear down.
std::map<ContextKey, std::shared_ptr<gpu::Context>>& keptContexts() {
  static auto* kept = new std::map<ContextKey, std::shared_ptr<gpu::Context>>();
  return *kept;
}

} // namespace

std::shared_ptr<gpu::Context> commandContext(const DeviceOptions& options) {
  if (!keepContexts) return std::make_shared<gpu::Context>(options.contextOptions());
  auto& kept = keptContexts();
  const ContextKey key = contextKey(options);
  if (auto found = kept.find(key); found != kept.end()) return found->second;
  auto context = std::make_shared<gpu::Context>(options.contextOptions());
  kept.emplace(key, context);
  return context;
}

void keepCommandContexts(bool keep) {
  keepContexts = keep;
  if (!keep) keptContexts().clear();
}

} // namespace obscura::app
