// commands.h — the `obscura` subcommands; each lives in its own file.
#pragma once
#include <CLI/CLI.hpp>

#include "gpu/context.h"

namespace obscura::app {

// Options every GPU command takes (--device, --validate).
struct DeviceOptions {
  std::string device;
  bool validate = false;
  std::string traversal; // render/scene_data/bvh_layout.h: "" or "auto" = the device's
  gpu::ContextOptions contextOptions() const { return {.validate = validate, .device = device, .traversal = traversal}; }
};
void addDeviceOptions(CLI::App& command, DeviceOptions& options);

void addRenderCommand(CLI::App& app);
void addInfoCommand(CLI::App& app);
void addBenchRaysCommand(CLI::App& app);
void addConvergeCommand(CLI::App& app);
void addRelightCommand(CLI::App& app);
void addCompareCommand(CLI::App& app);
void addViewCommand(CLI::App& app);
void addRecoverCommand(CLI::App& app);
void addRemodelCommand(CLI::App& app);
void addMergeCommand(CLI::App& app);

} // namespace obscura::app
