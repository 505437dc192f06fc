// kernel.h — one compute pipeline with its descriptor set, push constants and specialisation
// constants. Each pass owns its Kernel(s); nothing is rebuilt per dispatch.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/buffer.h"
#include "gpu/context.h"

namespace obscura::gpu {

enum class BindingKind { StorageBuffer, UniformTexelBuffer };

struct SpecConstant {
  std::uint32_t id;
  std::uint32_t value; // 32-bit: uint, int, bool (0/1) or float bits
};

struct KernelDesc {
  std::string name;                        // "<pass>" — also the timestamp label
  std::span<const std::uint32_t> spirv;    // embedded at build time (spirv/<name>.spv.h)
  std::vector<BindingKind> bindings;       // binding i of set 0
  std::uint32_t pushConstantBytes = 0;
  std::vector<SpecConstant> specConstants;
};

class Kernel {
public:
  Kernel(const Context& context, const KernelDesc& desc);

  void bind(std::uint32_t binding, const Buffer& buffer);
  void bind(std::uint32_t binding, const TexelBuffer& buffer);

  // Records push constants + dispatch of groups. `push` must be pushConstantBytes long.
  void dispatch(const vk::raii::CommandBuffer& cmd, std::uint32_t groupsX, std::uint32_t groupsY,
                std::uint32_t groupsZ, const void* push = nullptr) const;
  // Records an indirect dispatch whose group counts come from `args` at `offset`.
  void dispatchIndirect(const vk::raii::CommandBuffer& cmd, const Buffer& args, vk::DeviceSize offset,
                        const void* push = nullptr) const;

  const std::string& name() const { return name_; }

private:
  void bindCommon(const vk::raii::CommandBuffer& cmd, const void* push) const;

  const Context* context_;
  std::string name_;
  std::vector<BindingKind> bindings_;
  std::uint32_t pushBytes_ = 0;
  vk::raii::DescriptorSetLayout setLayout_ = nullptr;
  vk::raii::PipelineLayout pipelineLayout_ = nullptr;
  vk::raii::Pipeline pipeline_ = nullptr;
  vk::raii::DescriptorPool pool_ = nullptr;
  vk::raii::DescriptorSet set_ = nullptr;
};

// A compute-to-compute (and compute-to-transfer) memory barrier between dispatches.
void computeBarrier(const vk::raii::CommandBuffer& cmd);

// Group count for n items in groups of `groupSize`.
inline std::uint32_t groupsFor(std::uint64_t n, std::uint32_t groupSize) {
  return static_cast<std::uint32_t>((n + groupSize - 1) / groupSize);
}

} // namespace obscura::gpu
