#include "gpu/context.h"
#include "gpu/pipeline_cache.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <mutex>

#include <fmt/core.h>

#include "core/error.h"

namespace obscura::gpu {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

std::atomic<std::uint64_t> gValidationMessages{0};
std::mutex gValidationMutex;
std::vector<std::string> gValidationLog;

VKAPI_ATTR VkBool32 VKAPI_CALL onValidationMessage(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
    const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
  if (severity < VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) return VK_FALSE;
  gValidationMessages.fetch_add(1);
  std::string message = data && data->pMessage ? data->pMessage : "(no message)";
  fmt::print(stderr, "obscura: validation: {}\n", message);
  std::lock_guard lock(gValidationMutex);
  if (gValidationLog.size() < 64) gValidationLog.push_back(std::move(message));
  return VK_FALSE;
}

bool environmentFlag(const char* name) {
  const char* value = std::getenv(name);
  return value && *value && std::strcmp(value, "0") != 0;
}

std::string deviceTypeName(vk::PhysicalDeviceType type) {
  switch (type) {
  case vk::PhysicalDeviceType::eDiscreteGpu: return "discrete";
  case vk::PhysicalDeviceType::eIntegratedGpu: return "integrated";
  case vk::PhysicalDeviceType::eVirtualGpu: return "virtual";
  case vk::PhysicalDeviceType::eCpu: return "cpu";
  default: return "other";
  }
}

// Automatic choice: real GPUs first (discrete, integrated, virtual), then CPU implementations
// such as lavapipe; more device-local memory breaks ties.
int deviceRank(vk::PhysicalDeviceType type) {
  switch (type) {
  case vk::PhysicalDeviceType::eDiscreteGpu: return 4;
  case vk::PhysicalDeviceType::eIntegratedGpu: return 3;
  case vk::PhysicalDeviceType::eVirtualGpu: return 2;
  case vk::PhysicalDeviceType::eCpu: return 1;
  default: return 0;
  }
}

std::optional<std::uint32_t> computeQueueFamily(
    const vk::raii::PhysicalDevice& device,
    const std::function<bool(const vk::raii::PhysicalDevice&, std::uint32_t)>& canPresent) {
  auto families = device.getQueueFamilyProperties();
  for (std::uint32_t i = 0; i < families.size(); ++i) {
    if (!(families[i].queueFlags & vk::QueueFlagBits::eCompute)) continue;
    if (canPresent && !canPresent(device, i)) continue;
    return i;
  }
  return std::nullopt;
}

DeviceInfo describe(const vk::raii::PhysicalDevice& device, std::uint32_t index) {
  DeviceInfo info;
  info.index = index;
  auto chain = device.getProperties2<vk::PhysicalDeviceProperties2,
                                     vk::PhysicalDeviceSubgroupProperties,
                                     vk::PhysicalDeviceDriverProperties>();
  const auto& props = chain.get<vk::PhysicalDeviceProperties2>().properties;
  const auto& driver = chain.get<vk::PhysicalDeviceDriverProperties>();
  info.name = props.deviceName.data();
  info.type = deviceTypeName(props.deviceType);
  info.driver = fmt::format("{} ({})", driver.driverName.data(), driver.driverInfo.data());
  info.apiVersion = fmt::format("{}.{}.{}", VK_API_VERSION_MAJOR(props.apiVersion),
                                VK_API_VERSION_MINOR(props.apiVersion),
                                VK_API_VERSION_PATCH(props.apiVersion));
  info.maxStorageBufferRange = props.limits.maxStorageBufferRange;
  info.maxTexelBufferElements = props.limits.maxTexelBufferElements;
  info.maxComputeWorkGroupInvocations = props.limits.maxComputeWorkGroupInvocations;
  for (int i = 0; i < 3; ++i) info.maxComputeWorkGroupCount[i] = props.limits.maxComputeWorkGroupCount[i];
  info.maxPushConstantsSize = props.limits.maxPushConstantsSize;
  info.subgroupSize = chain.get<vk::PhysicalDeviceSubgroupProperties>().subgroupSize;
  info.timestampPeriodNs = props.limits.timestampPeriod;
  info.isLavapipe = driver.driverID == vk::DriverId::eMesaLlvmpipe;
  auto memory = device.getMemoryProperties();
  for (std::uint32_t h = 0; h < memory.memoryHeapCount; ++h)
    if (memory.memoryHeaps[h].flags & vk::MemoryHeapFlagBits::eDeviceLocal)
      info.deviceLocalBytes += memory.memoryHeaps[h].size;
  auto families = device.getQueueFamilyProperties();
  for (const auto& family : families) {
    if (!(family.queueFlags & vk::QueueFlagBits::eCompute)) continue;
    info.hasComputeQueue = true;
    info.timestamps = family.timestampValidBits > 0;
    break;
  }
  return info;
}

bool layerAvailable(const vk::raii::Context& context, const char* name) {
  for (const auto& layer : context.enumerateInstanceLayerProperties())
    if (std::strcmp(layer.layerName.data(), name) == 0) return true;
  return false;
}

bool instanceExtensionAvailable(const vk::raii::Context& context, const char* name) {
  for (const auto& ext : context.enumerateInstanceExtensionProperties())
    if (std::strcmp(ext.extensionName.data(), name) == 0) return true;
  return false;
}

vk::raii::Instance createInstance(const vk::raii::Context& context, bool validate, bool debugUtils,
                                  std::vector<const char*> extensions) {
  vk::ApplicationInfo app{.pApplicationName = "obscura",
                          .applicationVersion = 1,
                          .pEngineName = "obscura",
                          .engineVersion = 1,
                          .apiVersion = VK_API_VERSION_1_2};
  std::vector<const char*> layers;
  if (validate) layers.push_back(kValidationLayer);
  if (debugUtils) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  vk::InstanceCreateInfo info{.pApplicationInfo = &app,
                              .enabledLayerCount = static_cast<std::uint32_t>(layers.size()),
                              .ppEnabledLayerNames = layers.data(),
                              .enabledExtensionCount = static_cast<std::uint32_t>(extensions.size()),
                              .ppEnabledExtensionNames = extensions.data()};
  try {
    return vk::raii::Instance(context, info);
  } catch (const vk::SystemError& e) {
    throw DeviceError(fmt::format("cannot create a Vulkan instance: {} (is a Vulkan driver "
                                  "installed? on Debian: apt-get install mesa-vulkan-drivers)",
                                  e.what()));
  }
}

} // namespace

std::uint64_t Context::validationMessageCount() { return gValidationMessages.load(); }

std::vector<std::string> Context::validationMessages() {
  std::lock_guard lock(gValidationMutex);
  return gValidationLog;
}

std::vector<DeviceInfo> Context::listDevices(std::uint32_t* automaticChoice) {
  vk::raii::Context context;
  auto instance = createInstance(context, false, false, {});
  std::vector<DeviceInfo> result;
  int bestRank = -1;
  std::uint64_t bestMemory = 0;
  vk::raii::PhysicalDevices devices(instance);
  for (std::uint32_t i = 0; i < devices.size(); ++i) {
    result.push_back(describe(devices[i], i));
    int rank = deviceRank(devices[i].getProperties().deviceType);
    if (result.back().hasComputeQueue &&
        (rank > bestRank || (rank == bestRank && result.back().deviceLocalBytes > bestMemory))) {
      bestRank = rank;
      bestMemory = result.back().deviceLocalBytes;
      if (automaticChoice) *automaticChoice = i;
    }
  }
  return result;
}

Context::Context(const ContextOptions& options) : traversal_(options.traversal) {
  validation_ = options.validate || environmentFlag("OBSCURA_VALIDATE");
  if (validation_ && !layerAvailable(context_, kValidationLayer))
    throw DeviceError("validation was requested but the Khronos validation layer is not "
                      "installed (on Debian: apt-get install vulkan-validationlayers)");
  debugUtils_ = instanceExtensionAvailable(context_, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  instance_ = createInstance(context_, validation_, debugUtils_, options.instanceExtensions);
  if (validation_ && debugUtils_) {
    using Severity = vk::DebugUtilsMessageSeverityFlagBitsEXT;
    using Type = vk::DebugUtilsMessageTypeFlagBitsEXT;
    messenger_ = instance_.createDebugUtilsMessengerEXT(
        {.messageSeverity = Severity::eWarning | Severity::eError,
         .messageType = Type::eGeneral | Type::eValidation | Type::ePerformance,
         .pfnUserCallback = &onValidationMessage});
  }

  vk::raii::PhysicalDevices devices(instance_);
  if (devices.empty())
    throw DeviceError("no Vulkan device found (on Debian, apt-get install mesa-vulkan-drivers "
                      "provides lavapipe, a CPU implementation)");
  std::optional<std::uint32_t> chosen;
  if (!options.device.empty()) {
    char* end = nullptr;
    unsigned long index = std::strtoul(options.device.c_str(), &end, 10);
    if (end && *end == '\0') {
      if (index >= devices.size())
        throw InputError(fmt::format("--device {}: there are only {} Vulkan devices (see "
                                     "'obscura info')", options.device, devices.size()));
      chosen = static_cast<std::uint32_t>(index);
    } else {
      for (std::uint32_t i = 0; i < devices.size() && !chosen; ++i) {
        std::string name = devices[i].getProperties().deviceName.data();
        std::string lowerName = name, lowerWanted = options.device;
        std::transform(lowerName.begin(), lowerName.end(), lowerName.begin(), ::tolower);
        std::transform(lowerWanted.begin(), lowerWanted.end(), lowerWanted.begin(), ::tolower);
        if (lowerName.find(lowerWanted) != std::string::npos) chosen = i;
      }
      if (!chosen)
        throw InputError(fmt::format("--device '{}': no Vulkan device has that name (see "
                                     "'obscura info')", options.device));
    }
  } else {
    int bestRank = -1;
    std::uint64_t bestMemory = 0;
    for (std::uint32_t i = 0; i < devices.size(); ++i) {
      if (!computeQueueFamily(devices[i], options.canPresent)) continue;
      DeviceInfo candidate = describe(devices[i], i);
      int rank = deviceRank(devices[i].getProperties().deviceType);
      if (rank > bestRank || (rank == bestRank && candidate.deviceLocalBytes > bestMemory)) {
        bestRank = rank;
        bestMemory = candidate.deviceLocalBytes;
        chosen = i;
      }
    }
    if (!chosen) throw DeviceError("no Vulkan device has a compute queue");
  }

  physicalDevice_ = std::move(devices[*chosen]);
  info_ = describe(physicalDevice_, *chosen);
  memoryProperties_ = physicalDevice_.getMemoryProperties();
  auto family = computeQueueFamily(physicalDevice_, options.canPresent);
  if (!family)
    throw DeviceError(fmt::format("device '{}' has no suitable compute queue", info_.name));
  queueFamily_ = *family;

  float priority = 1.0f;
  vk::DeviceQueueCreateInfo queueInfo{
      .queueFamilyIndex = queueFamily_, .queueCount = 1, .pQueuePriorities = &priority};
  std::vector<const char*> extensions;
  if (options.canPresent) extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  vk::PhysicalDeviceFeatures features{};
  vk::DeviceCreateInfo deviceInfo{.queueCreateInfoCount = 1,
                                  .pQueueCreateInfos = &queueInfo,
                                  .enabledExtensionCount = static_cast<std::uint32_t>(extensions.size()),
                                  .ppEnabledExtensionNames = extensions.data(),
                                  .pEnabledFeatures = &features};
  try {
    device_ = vk::raii::Device(physicalDevice_, deviceInfo);
  } catch (const vk::SystemError& e) {
    throw DeviceError(fmt::format("cannot create the Vulkan device on '{}': {}", info_.name, e.what()));
  }
  queue_ = device_.getQueue(queueFamily_, 0);
  commandPool_ = device_.createCommandPool(
      {.flags = vk::CommandPoolCreateFlagBits::eResetCommandBuffer, .queueFamilyIndex = queueFamily_});
  fence_ = device_.createFence({});
  pipelines_ = std::make_unique<PipelineCache>(device_);
}

Context::~Context() = default;

void Context::setObjectName(vk::ObjectType type, std::uint64_t handle, const std::string& name) const {
  if (!debugUtils_) return;
  device_.setDebugUtilsObjectNameEXT(
      {.objectType = type, .objectHandle = handle, .pObjectName = name.c_str()});
}

void Context::submitAndWait(const std::function<void(const vk::raii::CommandBuffer&)>& record) const {
  try {
    vk::raii::CommandBuffers buffers(device_, {.commandPool = *commandPool_,
                                               .level = vk::CommandBufferLevel::ePrimary,
                                               .commandBufferCount = 1});
    const vk::raii::CommandBuffer& cmd = buffers.front();
    cmd.begin({.flags = vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
    record(cmd);
    cmd.end();
    vk::CommandBuffer raw = *cmd;
    queue_.submit(vk::SubmitInfo{.commandBufferCount = 1, .pCommandBuffers = &raw}, *fence_);
    // A lost device makes the wait throw vk::DeviceLostError, caught below.
    while (device_.waitForFences(*fence_, VK_TRUE, UINT64_MAX) == vk::Result::eTimeout) {
    }
    device_.resetFences(*fence_);
  } catch (const vk::DeviceLostError& e) {
    throw DeviceError(fmt::format("the Vulkan device '{}' was lost: {}", info_.name, e.what()));
  } catch (const vk::OutOfDeviceMemoryError& e) {
    throw DeviceError(fmt::format("out of device memory on '{}': {}", info_.name, e.what()));
  } catch (const vk::OutOfHostMemoryError& e) {
    throw DeviceError(fmt::format("out of host memory in the Vulkan driver: {}", e.what()));
  }
}

std::uint32_t Context::findMemoryType(std::uint32_t typeBits, vk::MemoryPropertyFlags required,
                                      vk::MemoryPropertyFlags preferred) const {
  std::optional<std::uint32_t> fallback;
  for (std::uint32_t i = 0; i < memoryProperties_.memoryTypeCount; ++i) {
    if (!(typeBits & (1u << i))) continue;
    auto flags = memoryProperties_.memoryTypes[i].propertyFlags;
    if ((flags & required) != required) continue;
    if ((flags & preferred) == preferred) return i;
    if (!fallback) fallback = i;
  }
  if (!fallback) throw DeviceError("no Vulkan memory type has the required properties");
  return *fallback;
}

vk::MemoryPropertyFlags Context::memoryTypeFlags(std::uint32_t type) const {
  return memoryProperties_.memoryTypes[type].propertyFlags;
}

} // namespace obscura::gpu
