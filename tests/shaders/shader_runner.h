// shader_runner.h — runs a one-dimensional test kernel over a buffer of cases and reads the
// results back: the harness of every tests/shaders/*_test.comp.
#pragma once
#include <span>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/kernel.h"
#include "shared/host_device.h"

namespace obscura::test {

// Kernel layout: binding 0 = cases (read), binding 1 = results (written), push constant
// uvec4(case count, 0, 0, 0), local size kWorkgroupSize1D.
template <typename Case, typename Result>
std::vector<Result> runCases(const gpu::Context& context, std::span<const std::uint32_t> spirv,
                             const std::vector<Case>& cases) {
  using Usage = vk::BufferUsageFlagBits;
  gpu::Kernel kernel(context, {.name = "test",
                               .spirv = spirv,
                               .bindings = {gpu::BindingKind::StorageBuffer, gpu::BindingKind::StorageBuffer},
                               .pushConstantBytes = 16});
  gpu::Buffer in(context, cases.size() * sizeof(Case), Usage::eStorageBuffer, "test.cases");
  in.upload(context, cases);
  gpu::Buffer out(context, cases.size() * sizeof(Result), Usage::eStorageBuffer, "test.results");
  kernel.bind(0, in);
  kernel.bind(1, out);
  glm::uvec4 push(static_cast<std::uint32_t>(cases.size()), 0, 0, 0);
  context.submitAndWait([&](const vk::raii::CommandBuffer& cmd) {
    kernel.dispatch(cmd, gpu::groupsFor(cases.size(), gpu::kWorkgroupSize1D), 1, 1, push);
  });
  return out.download<Result>(context);
}

} // namespace obscura::test
