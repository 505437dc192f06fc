// commands.h — the `obscura` subcommands; each lives in its own file.
#pragma once
#include <memory>

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

// The Vulkan context a command renders on: a new one, unless this process keeps them
// (keepCommandContexts): then one per device choice (the options and the environment that shapes
// a context: OBSCURA_VALIDATE, the Vulkan ICD variables, LP_NUM_THREADS) is made on first use and
// serves every later command, its compiled pipelines with it (an LLVM compile per kernel on
// lavapipe). A process that runs many commands keeps them: the CLI tests, the Python module.
// Not thread-safe: commands run one at a time.
std::shared_ptr<gpu::Context> commandContext(const DeviceOptions& options);
void keepCommandContexts(bool keep);

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
