// kernel.h — one compute pipeline with its descriptor set, push constants and specialisation
// constants. Each pass owns its Kernel(s); nothing is rebuilt per dispatch.
//
// The pipeline is compiled on the kernel's first dispatch (or by `compile()`), never in the
// constructor: a pass owns variants a frame may never dispatch (edits' probes, one light alone,
// specular paths in a scene without glossy surfaces, grey obscurances), and on lavapipe each
// pipeline is an LLVM compile of the whole shader, ~0.1 s of CPU apiece (a 20x14 Cornell box
// render took 2.3 s with every kernel compiled up front, 1.3 s compiling what it dispatches).
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/buffer.h"
#include "gpu/context.h"
#include "gpu/pipeline_cache.h"

namespace obscura::gpu {

enum class BindingKind { StorageBuffer, UniformTexelBuffer, StorageTexelBuffer };
vk::DescriptorType descriptorType(BindingKind kind);

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
  // Descriptor sets: one per frame band (render/frame/frame_layout.h), each bound to that band's
  // buffers once; a dispatch names the set it uses.
  std::uint32_t setCount = 1;
};

// A kernel whose bindings are all storage buffers (the frame passes: compose, tonemap, ...).
KernelDesc storageKernelDesc(std::string name, std::span<const std::uint32_t> spirv, std::uint32_t bindingCount,
                             std::uint32_t pushConstantBytes, std::uint32_t setCount = 1);
// The same but for `uniformTexelBindings`, read through uniform texel buffers (where lavapipe
// gathers a texel per lane as one vector: compose, resolve, the light mix, the denoiser).
KernelDesc storageKernelDesc(std::string name, std::span<const std::uint32_t> spirv, std::uint32_t bindingCount,
                             std::uint32_t pushConstantBytes, std::initializer_list<std::uint32_t> uniformTexelBindings,
                             std::uint32_t setCount = 1);

// The push constants of a kernel that declares none.
struct NoPush {};
inline constexpr NoPush kNoPush{};

class Kernel {
public:
  Kernel(const Context& context, const KernelDesc& desc);
  Kernel(Kernel&&) noexcept = default;
  // Member-wise assignment would destroy the old descriptor pool before the old sets that are
  // freed into it; this frees the old objects in reverse order of creation first.
  Kernel& operator=(Kernel&& other) noexcept;

  void bind(std::uint32_t binding, const Buffer& buffer, std::uint32_t set = 0);
  void bind(std::uint32_t binding, const TexelBuffer& buffer, std::uint32_t set = 0);

  // Records `push` (the kernel's push-constant struct from shaders/shared/host_device.h, or
  // kNoPush) and a dispatch of groups over descriptor set `set`. A struct of another size than the
  // kernel declared (KernelDesc::pushConstantBytes) is a logic_error naming the kernel.
  template <class Push>
  void dispatch(const vk::raii::CommandBuffer& cmd, std::uint32_t groupsX, std::uint32_t groupsY,
                std::uint32_t groupsZ, const Push& push, std::uint32_t set = 0) const {
    bindCommon(cmd, pushBytes(push), pushSize(push), set);
    cmd.dispatch(groupsX, groupsY, groupsZ);
  }
  void dispatch(const vk::raii::CommandBuffer& cmd, std::uint32_t groupsX, std::uint32_t groupsY,
                std::uint32_t groupsZ) const {
    dispatch(cmd, groupsX, groupsY, groupsZ, kNoPush);
  }
  // The same, its group counts read from `args` at `offset` (an indirect dispatch).
  template <class Push>
  void dispatchIndirect(const vk::raii::CommandBuffer& cmd, const Buffer& args, vk::DeviceSize offset,
                        const Push& push, std::uint32_t set = 0) const {
    bindCommon(cmd, pushBytes(push), pushSize(push), set);
    recordIndirect(cmd, args, offset);
  }

  // Creates the pipeline now (before a timed dispatch), if no dispatch has yet.
  void compile() const;
  bool compiled() const { return static_cast<bool>(*shared_->pipeline); }
  // The value of specialisation constant `id` (0 where the kernel does not set it: the default
  // of every boolean specialisation constant here).
  std::uint32_t specConstant(std::uint32_t id) const;

  const std::string& name() const { return name_; }
  std::uint32_t setCount() const { return static_cast<std::uint32_t>(sets_.size()); }

private:
  template <class Push>
  static const void* pushBytes(const Push& push) {
    static_assert(std::is_trivially_copyable_v<Push> && !std::is_pointer_v<Push>,
                  "push constants are a struct of host_device.h, passed by reference");
    return std::is_same_v<Push, NoPush> ? nullptr : &push;
  }
  template <class Push>
  static std::uint32_t pushSize(const Push&) {
    return std::is_same_v<Push, NoPush> ? 0u : static_cast<std::uint32_t>(sizeof(Push));
  }
  void bindCommon(const vk::raii::CommandBuffer& cmd, const void* push, std::uint32_t bytes, std::uint32_t set) const;
  void recordIndirect(const vk::raii::CommandBuffer& cmd, const Buffer& args, vk::DeviceSize offset) const;
  const vk::raii::DescriptorSet& descriptorSet(std::uint32_t set) const;

  const Context* context_;
  std::string name_;
  std::vector<BindingKind> bindings_;
  std::uint32_t pushBytes_ = 0;
  // Layouts and pipeline, the device's (gpu/pipeline_cache.h).
  std::shared_ptr<SharedPipeline> shared_;
  // What a deferred compile needs: the shader (static, embedded) and its specialisation.
  std::span<const std::uint32_t> spirv_;
  std::vector<SpecConstant> specConstants_;
  vk::raii::DescriptorPool pool_ = nullptr;
  std::vector<vk::raii::DescriptorSet> sets_;
};

// A compute-to-compute (and compute-to-transfer) memory barrier between dispatches.
void computeBarrier(const vk::raii::CommandBuffer& cmd);

// Group count for n items in groups of `groupSize`.
inline std::uint32_t groupsFor(std::uint64_t n, std::uint32_t groupSize) {
  return static_cast<std::uint32_t>((n + groupSize - 1) / groupSize);
}

} // namespace obscura::gpu
