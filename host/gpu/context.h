// context.h — the Vulkan instance, the chosen device, its compute queue and command pool.
//
// Members are vk::raii values declared in dependency order, so destruction runs in reverse with
// no cleanup code. Device choice: a real GPU when there is one, else lavapipe; `--device`
// overrides. Validation (the Khronos layer) is on with `--validate` and in every test
// (OBSCURA_VALIDATE=1); each message it prints is counted, and tests fail on any.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

namespace obscura::gpu {

struct DeviceInfo {
  std::uint32_t index = 0;
  std::string name;
  std::string type;            // "discrete", "integrated", "virtual", "cpu", "other"
  std::string driver;          // driver name and info string
  std::string apiVersion;
  std::uint64_t deviceLocalBytes = 0;
  std::uint32_t maxStorageBufferRange = 0;
  std::uint32_t maxTexelBufferElements = 0;
  std::uint32_t maxComputeWorkGroupInvocations = 0;
  std::uint32_t maxComputeWorkGroupCount[3] = {0, 0, 0};
  std::uint32_t maxPushConstantsSize = 0;
  std::uint32_t subgroupSize = 0;
  float timestampPeriodNs = 0.0f;
  bool timestamps = false;
  bool hasComputeQueue = false;
  bool isLavapipe = false;
};

struct ContextOptions {
  bool validate = false;       // also forced on by OBSCURA_VALIDATE=1 in the environment
  std::string device;          // "" = automatic; else an index or a substring of the name
  // For the window mode: when set, only queue families for which this returns true (presentation
  // to the window's surface) are eligible. Headless rendering leaves it empty.
  std::function<bool(const vk::raii::PhysicalDevice&, std::uint32_t family)> canPresent;
  std::vector<const char*> instanceExtensions; // e.g. the window system's surface extensions
  // The BVH layout and traversal loop the kernels use on this device: "" or "auto" for the
  // device's own (render/scene_data/bvh_layout.h, which also reads and checks the name), else one it
  // names. Kept by the context because it is a property of how this device is driven.
  std::string traversal;
};

class PipelineCache;

class Context {
public:
  explicit Context(const ContextOptions& options = {});
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  ~Context();

  // Every device the loader reports, with the one automatic selection would choose marked.
  static std::vector<DeviceInfo> listDevices(std::uint32_t* automaticChoice = nullptr);

  const DeviceInfo& info() const { return info_; }
  // ContextOptions::traversal, as given.
  const std::string& traversalRequest() const { return traversal_; }
  const vk::raii::Device& device() const { return device_; }
  const vk::raii::PhysicalDevice& physicalDevice() const { return physicalDevice_; }
  const vk::raii::Queue& queue() const { return queue_; }
  std::uint32_t queueFamily() const { return queueFamily_; }
  const vk::raii::Instance& instance() const { return instance_; }

  // Records commands into a one-time command buffer, submits and waits. Device loss and
  // out-of-memory become obscura::DeviceError.
  void submitAndWait(const std::function<void(const vk::raii::CommandBuffer&)>& record) const;

  // Finds a memory type with `required` properties (and `preferred` ones when possible).
  std::uint32_t findMemoryType(std::uint32_t typeBits, vk::MemoryPropertyFlags required,
                               vk::MemoryPropertyFlags preferred = {}) const;
  vk::MemoryPropertyFlags memoryTypeFlags(std::uint32_t type) const;

  // The compute pipelines made on this device, shared by kernels of the same shape
  // (gpu/pipeline_cache.h).
  PipelineCache& pipelines() const { return *pipelines_; }
  // Validation warnings and errors seen so far (by this process, all contexts together).
  static std::uint64_t validationMessageCount();
  static std::vector<std::string> validationMessages();

  // Gives the name to a Vulkan object (shows in validation messages and debuggers).
  template <typename Handle>
  void setName(const Handle& handle, const std::string& name) const {
    setObjectName(Handle::objectType, reinterpret_cast<std::uint64_t>(
                                          static_cast<typename Handle::CType>(*handle)), name);
  }

private:
  void setObjectName(vk::ObjectType type, std::uint64_t handle, const std::string& name) const;

  bool validation_ = false;
  bool debugUtils_ = false;
  std::string traversal_;
  vk::raii::Context context_;
  vk::raii::Instance instance_ = nullptr;
  vk::raii::DebugUtilsMessengerEXT messenger_ = nullptr;
  vk::raii::PhysicalDevice physicalDevice_ = nullptr;
  std::uint32_t queueFamily_ = 0;
  vk::raii::Device device_ = nullptr;
  std::unique_ptr<PipelineCache> pipelines_; // after device_: destroyed before it
  vk::raii::Queue queue_ = nullptr;
  vk::raii::CommandPool commandPool_ = nullptr;
  vk::raii::Fence fence_ = nullptr;
  DeviceInfo info_;
  vk::PhysicalDeviceMemoryProperties memoryProperties_;
};

} // namespace obscura::gpu
