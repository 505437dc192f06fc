// pipeline_cache.h — the compute pipelines a device has made, shared by every Kernel with the
// same shader, bindings, push constant size and specialisation. A renderer made again for the
// same scene kind (a test's next case, the window's path tracer after an edit, a farm part)
// then makes no pipeline: on lavapipe each one costs ~0.1-1 s of CPU (SPIR-V to NIR, LLVM, and
// the validation layer's checks), which dominated the small renders of the test suite. A Kernel
// keeps its own descriptor pool and sets. Entries live as long as the Context (their number is
// bounded by the distinct kernel variants a program uses); single-threaded, as kernels are made.
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

namespace obscura::gpu {

enum class BindingKind;
struct SpecConstant;

struct SharedPipeline {
  vk::raii::DescriptorSetLayout setLayout = nullptr;
  vk::raii::PipelineLayout layout = nullptr;
  vk::raii::Pipeline pipeline = nullptr; // made on the first compile()
};

class PipelineCache {
public:
  explicit PipelineCache(const vk::raii::Device& device) : device_(&device) {}

  // The layouts (and, once compiled, the pipeline) of a kernel of this shape; made on first use.
  std::shared_ptr<SharedPipeline> find(std::span<const std::uint32_t> spirv, const std::vector<BindingKind>& bindings,
                                       std::uint32_t pushConstantBytes, const std::vector<SpecConstant>& specConstants);
  // Makes `shared`'s pipeline unless it is made.
  void compile(SharedPipeline& shared, std::span<const std::uint32_t> spirv,
               const std::vector<SpecConstant>& specConstants) const;

  std::size_t size() const { return entries_.size(); }

private:
  const vk::raii::Device* device_;
  std::map<std::string, std::shared_ptr<SharedPipeline>> entries_;
};

} // namespace obscura::gpu
