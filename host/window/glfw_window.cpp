// glfw_window.cpp — see glfw_window.h.
#include "window/glfw_window.h"

#include <cstdlib>

#include <fmt/format.h>
#include <vulkan/vulkan.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "core/error.h"

namespace obscura::window {
namespace {

std::string glfwError() {
  const char* description = nullptr;
  int code = glfwGetError(&description);
  if (code == GLFW_NO_ERROR) return "no reason given";
  return description ? description : fmt::format("GLFW error {:#x}", code);
}

GlfwWindow* owner(GLFWwindow* window) { return static_cast<GlfwWindow*>(glfwGetWindowUserPointer(window)); }

} // namespace

void InputState::beginFrame() {
  keysPressed.clear();
  clicks.clear();
  mouseDx = mouseDy = 0.0;
  scroll = 0.0;
  uiWantsMouse = uiWantsKeyboard = false; // the panel says so again when it is drawn
}

GlfwWindow::GlfwWindow(int width, int height, const std::string& title) {
  const char* x11 = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((!x11 || !*x11) && (!wayland || !*wayland))
    throw DeviceError("view: no window system (neither DISPLAY nor WAYLAND_DISPLAY is set); "
                      "run under X11, Wayland or Xvfb (e.g. xvfb-run), or render headless with 'obscura render'");
  if (!glfwInit()) throw DeviceError(fmt::format("view: cannot reach the window system: {}", glfwError()));
  if (!glfwVulkanSupported()) {
    glfwTerminate();
    throw DeviceError("view: GLFW finds no Vulkan loader able to present to this window system");
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window_) {
    std::string reason = glfwError();
    glfwTerminate();
    throw DeviceError(fmt::format("view: cannot open a {}x{} window: {}", width, height, reason));
  }
  glfwSetWindowUserPointer(window_, this);
  glfwSetKeyCallback(window_, onKey);
  glfwSetMouseButtonCallback(window_, onButton);
  glfwSetCursorPosCallback(window_, onCursor);
  glfwSetScrollCallback(window_, onScroll);
}

GlfwWindow::~GlfwWindow() {
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
}

std::vector<const char*> GlfwWindow::requiredInstanceExtensions() {
  std::uint32_t count = 0;
  const char** names = glfwGetRequiredInstanceExtensions(&count);
  if (!names) throw DeviceError(fmt::format("view: no Vulkan surface for this window system: {}", glfwError()));
  return {names, names + count};
}

vk::raii::SurfaceKHR GlfwWindow::createSurface(const vk::raii::Instance& instance) const {
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  VkResult result = glfwCreateWindowSurface(static_cast<VkInstance>(*instance), window_, nullptr, &surface);
  if (result != VK_SUCCESS)
    throw DeviceError(fmt::format("view: cannot make a Vulkan surface on the window ({}): {}",
                                  vk::to_string(static_cast<vk::Result>(result)), glfwError()));
  return vk::raii::SurfaceKHR(instance, surface);
}

void GlfwWindow::pollEvents(double waitSeconds) {
  if (waitSeconds > 0.0)
    glfwWaitEventsTimeout(waitSeconds);
  else
    glfwPollEvents();
}

bool GlfwWindow::shouldClose() const { return glfwWindowShouldClose(window_); }
void GlfwWindow::requestClose() { glfwSetWindowShouldClose(window_, GLFW_TRUE); }

std::array<int, 2> GlfwWindow::framebufferSize() const {
  std::array<int, 2> size{0, 0};
  glfwGetFramebufferSize(window_, &size[0], &size[1]);
  if (glfwGetWindowAttrib(window_, GLFW_ICONIFIED)) size = {0, 0};
  return size;
}

void GlfwWindow::resize(int width, int height) { glfwSetWindowSize(window_, width, height); }
void GlfwWindow::iconify() { glfwIconifyWindow(window_); }
void GlfwWindow::restore() { glfwRestoreWindow(window_); }

void GlfwWindow::onKey(GLFWwindow* window, int key, int, int action, int mods) {
  InputState& in = owner(window)->input_;
  in.shift = (mods & GLFW_MOD_SHIFT) != 0;
  if (key < 0 || key >= static_cast<int>(in.keyDown.size())) return;
  if (action == GLFW_PRESS) {
    in.keyDown[key] = true;
    in.keysPressed.push_back(key);
  } else if (action == GLFW_RELEASE) {
    in.keyDown[key] = false;
  }
}

void GlfwWindow::onButton(GLFWwindow* window, int button, int action, int) {
  GlfwWindow* self = owner(window);
  InputState& in = self->input_;
  if (button < 0 || button > 2) return;
  in.buttonDown[button] = action == GLFW_PRESS;
  if (button != GLFW_MOUSE_BUTTON_LEFT) return;
  if (action == GLFW_PRESS) {
    self->pressX_ = in.mouseX;
    self->pressY_ = in.mouseY;
  } else if (action == GLFW_RELEASE && std::abs(in.mouseX - self->pressX_) < 3.0 &&
             std::abs(in.mouseY - self->pressY_) < 3.0) {
    in.clicks.push_back({in.mouseX, in.mouseY});
  }
}

void GlfwWindow::onCursor(GLFWwindow* window, double x, double y) {
  GlfwWindow* self = owner(window);
  InputState& in = self->input_;
  if (self->cursorKnown_) {
    in.mouseDx += x - in.mouseX;
    in.mouseDy += y - in.mouseY;
  }
  self->cursorKnown_ = true;
  in.mouseX = x;
  in.mouseY = y;
}

void GlfwWindow::onScroll(GLFWwindow* window, double, double dy) { owner(window)->input_.scroll += dy; }

} // namespace obscura::window
