#include "gpu/kernel.h"

#include <algorithm>
#include <stdexcept>

#include <fmt/core.h>

#include "gpu/pipeline_cache.h"

namespace obscura::gpu {
vk::DescriptorType descriptorType(BindingKind kind) {
  switch (kind) {
  case BindingKind::StorageBuffer: return vk::DescriptorType::eStorageBuffer;
  case BindingKind::UniformTexelBuffer: return vk::DescriptorType::eUniformTexelBuffer;
  case BindingKind::StorageTexelBuffer: return vk::DescriptorType::eStorageTexelBuffer;
  }
  return vk::DescriptorType::eStorageBuffer;
}

KernelDesc storageKernelDesc(std::string name, std::span<const std::uint32_t> spirv, std::uint32_t bindingCount,
                             std::uint32_t pushConstantBytes, std::uint32_t setCount) {
  return {.name = std::move(name), .spirv = spirv,
          .bindings = std::vector<BindingKind>(bindingCount, BindingKind::StorageBuffer),
          .pushConstantBytes = pushConstantBytes, .setCount = setCount};
}

KernelDesc storageKernelDesc(std::string name, std::span<const std::uint32_t> spirv, std::uint32_t bindingCount,
                             std::uint32_t pushConstantBytes, std::initializer_list<std::uint32_t> uniformTexelBindings,
                             std::uint32_t setCount) {
  KernelDesc desc = storageKernelDesc(std::move(name), spirv, bindingCount, pushConstantBytes, setCount);
  for (std::uint32_t b : uniformTexelBindings) desc.bindings.at(b) = BindingKind::UniformTexelBuffer;
  return desc;
}

Kernel::Kernel(const Context& context, const KernelDesc& desc)
    : context_(&context), name_(desc.name), bindings_(desc.bindings), pushBytes_(desc.pushConstantBytes),
      spirv_(desc.spirv), specConstants_(desc.specConstants) {
  const auto& device = context.device();
  // The layouts and pipeline are the device's, shared with every kernel of the same shape.
  shared_ = context.pipelines().find(spirv_, bindings_, pushBytes_, specConstants_);
  vk::DescriptorSetLayout rawLayout = *shared_->setLayout;

  const std::uint32_t setCount = std::max(desc.setCount, 1u);
  std::vector<vk::DescriptorPoolSize> sizes;
  for (auto kind : {BindingKind::StorageBuffer, BindingKind::UniformTexelBuffer, BindingKind::StorageTexelBuffer}) {
    auto count = static_cast<std::uint32_t>(std::count(bindings_.begin(), bindings_.end(), kind));
    if (count) sizes.push_back({.type = descriptorType(kind), .descriptorCount = count * setCount});
  }
  pool_ = device.createDescriptorPool({.flags = vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet,
                                       .maxSets = setCount,
                                       .poolSizeCount = static_cast<std::uint32_t>(sizes.size()),
                                       .pPoolSizes = sizes.data()});
  std::vector<vk::DescriptorSetLayout> layouts(setCount, rawLayout);
  vk::raii::DescriptorSets sets(device, {.descriptorPool = *pool_, .descriptorSetCount = setCount,
                                         .pSetLayouts = layouts.data()});
  for (auto& set : sets) sets_.push_back(std::move(set));
}

Kernel& Kernel::operator=(Kernel&& other) noexcept {
  if (this == &other) return *this;
  sets_.clear();
  pool_ = nullptr;
  context_ = other.context_;
  name_ = std::move(other.name_);
  bindings_ = std::move(other.bindings_);
  pushBytes_ = other.pushBytes_;
  shared_ = std::move(other.shared_);
  spirv_ = other.spirv_;
  specConstants_ = std::move(other.specConstants_);
  pool_ = std::move(other.pool_);
  sets_ = std::move(other.sets_);
  return *this;
}

std::uint32_t Kernel::specConstant(std::uint32_t id) const {
  for (const SpecConstant& c : specConstants_)
    if (c.id == id) return c.value;
  return 0;
}

void Kernel::compile() const {
  if (compiled()) return;
  context_->pipelines().compile(*shared_, spirv_, specConstants_);
  context_->setName(shared_->pipeline, name_);
}

const vk::raii::DescriptorSet& Kernel::descriptorSet(std::uint32_t set) const {
  if (set >= sets_.size())
    throw std::logic_error(fmt::format("{}: descriptor set {} of {}", name_, set, sets_.size()));
  return sets_[set];
}

void Kernel::bind(std::uint32_t binding, const Buffer& buffer, std::uint32_t set) {
  if (binding >= bindings_.size() || bindings_[binding] != BindingKind::StorageBuffer)
    throw std::logic_error(fmt::format("{}: binding {} is not a storage buffer", name_, binding));
  vk::DescriptorBufferInfo info{.buffer = buffer.handle(), .offset = 0, .range = VK_WHOLE_SIZE};
  context_->device().updateDescriptorSets(
      vk::WriteDescriptorSet{.dstSet = *descriptorSet(set),
                             .dstBinding = binding,
                             .descriptorCount = 1,
                             .descriptorType = vk::DescriptorType::eStorageBuffer,
                             .pBufferInfo = &info},
      nullptr);
}

void Kernel::bind(std::uint32_t binding, const TexelBuffer& buffer, std::uint32_t set) {
  if (binding >= bindings_.size() || bindings_[binding] == BindingKind::StorageBuffer)
    throw std::logic_error(fmt::format("{}: binding {} is not a texel buffer", name_, binding));
  vk::BufferView view = buffer.view();
  context_->device().updateDescriptorSets(
      vk::WriteDescriptorSet{.dstSet = *descriptorSet(set),
                             .dstBinding = binding,
                             .descriptorCount = 1,
                             .descriptorType = descriptorType(bindings_[binding]),
                             .pTexelBufferView = &view},
      nullptr);
}

void Kernel::bindCommon(const vk::raii::CommandBuffer& cmd, const void* push, std::uint32_t bytes,
                        std::uint32_t set) const {
  if (bytes != pushBytes_)
    throw std::logic_error(fmt::format("{}: push constants of {} bytes for a kernel that declares {}", name_, bytes,
                                       pushBytes_));
  compile();
  cmd.bindPipeline(vk::PipelineBindPoint::eCompute, *shared_->pipeline);
  cmd.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *shared_->layout, 0, {*descriptorSet(set)}, {});
  if (pushBytes_)
    cmd.pushConstants<std::uint8_t>(*shared_->layout, vk::ShaderStageFlagBits::eCompute, 0,
                                    vk::ArrayProxy<const std::uint8_t>(pushBytes_, static_cast<const std::uint8_t*>(push)));
}

void Kernel::recordIndirect(const vk::raii::CommandBuffer& cmd, const Buffer& args, vk::DeviceSize offset) const {
  cmd.dispatchIndirect(args.handle(), offset);
}

void computeBarrier(const vk::raii::CommandBuffer& cmd) {
  vk::MemoryBarrier barrier{.srcAccessMask = vk::AccessFlagBits::eShaderWrite | vk::AccessFlagBits::eTransferWrite,
                            .dstAccessMask = vk::AccessFlagBits::eShaderRead | vk::AccessFlagBits::eShaderWrite |
                                             vk::AccessFlagBits::eTransferRead | vk::AccessFlagBits::eIndirectCommandRead};
  cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader | vk::PipelineStageFlagBits::eTransfer,
                      vk::PipelineStageFlagBits::eComputeShader | vk::PipelineStageFlagBits::eTransfer |
                          vk::PipelineStageFlagBits::eDrawIndirect,
                      {}, barrier, nullptr, nullptr);
}

} // namespace obscura::gpu
