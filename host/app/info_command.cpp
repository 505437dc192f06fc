// obscura info — the Vulkan devices, their limits, and the one a render would choose.
#include <fmt/core.h>

#include "app/commands.h"

namespace obscura::app {

void addInfoCommand(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("info", "List the Vulkan devices, their limits and the chosen one");
  cmd->callback([] {
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
  });
}

} // namespace obscura::app
