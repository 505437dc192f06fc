#include "gpu/pipeline_cache.h"

#include <functional>
#include <string_view>

#include <fmt/format.h>

#include "gpu/kernel.h"

namespace obscura::gpu {
namespace {

// The shader by its words' hash and length (embedded arrays; a 64-bit hash, so two shaders of the
// same length that collide are out of reach), then everything else that shapes the pipeline.
std::string keyOf(std::span<const std::uint32_t> spirv, const std::vector<BindingKind>& bindings,
                  std::uint32_t pushConstantBytes, const std::vector<SpecConstant>& specConstants) {
  const std::string_view words(reinterpret_cast<const char*>(spirv.data()), spirv.size_bytes());
  std::string key = fmt::format("{:x}:{}:{}:", std::hash<std::string_view>{}(words), spirv.size(), pushConstantBytes);
  for (BindingKind b : bindings) key.push_back(static_cast<char>('a' + static_cast<int>(b)));
  for (const SpecConstant& c : specConstants) key += fmt::format(":{}={}", c.id, c.value);
  return key;
}

} // namespace

std::shared_ptr<SharedPipeline> PipelineCache::find(std::span<const std::uint32_t> spirv,
                                                    const std::vector<BindingKind>& bindings,
                                                    std::uint32_t pushConstantBytes,
                                                    const std::vector<SpecConstant>& specConstants) {
  std::shared_ptr<SharedPipeline>& entry = entries_[keyOf(spirv, bindings, pushConstantBytes, specConstants)];
  if (entry) return entry;
  entry = std::make_shared<SharedPipeline>();
  std::vector<vk::DescriptorSetLayoutBinding> layoutBindings;
  for (std::uint32_t i = 0; i < bindings.size(); ++i)
    layoutBindings.push_back({.binding = i,
                              .descriptorType = descriptorType(bindings[i]),
                              .descriptorCount = 1,
                              .stageFlags = vk::ShaderStageFlagBits::eCompute});
  entry->setLayout = device_->createDescriptorSetLayout(
      {.bindingCount = static_cast<std::uint32_t>(layoutBindings.size()), .pBindings = layoutBindings.data()});
  vk::PushConstantRange range{.stageFlags = vk::ShaderStageFlagBits::eCompute, .offset = 0, .size = pushConstantBytes};
  vk::DescriptorSetLayout rawLayout = *entry->setLayout;
  entry->layout = device_->createPipelineLayout({.setLayoutCount = 1,
                                                 .pSetLayouts = &rawLayout,
                                                 .pushConstantRangeCount = pushConstantBytes ? 1u : 0u,
                                                 .pPushConstantRanges = pushConstantBytes ? &range : nullptr});
  return entry;
}

void PipelineCache::compile(SharedPipeline& shared, std::span<const std::uint32_t> spirv,
                            const std::vector<SpecConstant>& specConstants) const {
  if (*shared.pipeline) return;
  vk::raii::ShaderModule module = device_->createShaderModule({.codeSize = spirv.size_bytes(), .pCode = spirv.data()});
  std::vector<vk::SpecializationMapEntry> entries;
  std::vector<std::uint32_t> values;
  for (std::size_t i = 0; i < specConstants.size(); ++i) {
    entries.push_back({.constantID = specConstants[i].id, .offset = static_cast<std::uint32_t>(i * 4), .size = 4});
    values.push_back(specConstants[i].value);
  }
  vk::SpecializationInfo specialization{.mapEntryCount = static_cast<std::uint32_t>(entries.size()),
                                        .pMapEntries = entries.data(),
                                        .dataSize = values.size() * 4,
                                        .pData = values.data()};
  vk::ComputePipelineCreateInfo pipelineInfo{
      .stage = {.stage = vk::ShaderStageFlagBits::eCompute,
                .module = *module,
                .pName = "main",
                .pSpecializationInfo = entries.empty() ? nullptr : &specialization},
      .layout = *shared.layout};
  shared.pipeline = vk::raii::Pipeline(*device_, nullptr, pipelineInfo);
}

} // namespace obscura::gpu
