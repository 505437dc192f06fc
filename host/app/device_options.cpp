// The options every GPU command takes (app/commands.h DeviceOptions), registered here in the
// library beside the commands that call it.
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

} // namespace obscura::app
