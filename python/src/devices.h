// devices.h — the Vulkan contexts the module's renders and sessions share: one per device choice
// (--device, --validate, --traversal), made on first use and kept, so that the compiled pipelines
// (gpu/pipeline_cache.h, seconds of LLVM per kernel on lavapipe) serve every later render. A
// context serves one operation at a time (its queue and command pool are not thread-safe):
// callers hold `busy` while they use it, with the GIL released.
#pragma once
#include <memory>
#include <mutex>

#include "app/commands.h"
#include "gpu/context.h"

namespace obscura::python {

struct Device {
  explicit Device(const gpu::ContextOptions& options) : context(options) {}
  gpu::Context context;
  std::mutex busy;
};

// The device `options` choose, made on first use (InputError/DeviceError when there is none).
std::shared_ptr<Device> sharedDevice(const app::DeviceOptions& options);

} // namespace obscura::python
