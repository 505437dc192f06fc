// devices.h — the Vulkan contexts the module's renders, sessions and commands share: the ones
// app::commandContext keeps for a process that runs many commands (one per device choice, made on
// first use with its compiled pipelines: an LLVM compile per kernel on lavapipe), so that
// run_command's commands and render() compile each kernel once between them. A context's queue
// and command pool are not thread-safe: every call's device work holds deviceWork(), with the GIL
// released.
#pragma once
#include <memory>
#include <mutex>

#include "app/commands.h"
#include "gpu/context.h"

namespace obscura::python {

// Held by every call while it uses a device (and while it gets its context).
std::mutex& deviceWork();

// The context `options` choose (InputError/DeviceError when there is none); deviceWork() held.
std::shared_ptr<gpu::Context> sharedContext(const app::DeviceOptions& options);

} // namespace obscura::python
