// glfw_window.h — the operating system's window for `obscura view`: GLFW (X11, Wayland) with no
// client API, the Vulkan surface made on it, and the input of each frame gathered into InputState.
//
// A scripted run (`view --script`) feeds the same InputState, so the camera, the panel and the
// picking see a script exactly as they see a person.
#pragma once
#include <array>
#include <string>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

struct GLFWwindow;

namespace obscura::window {

// What the person (or the script) did since the last frame.
struct InputState {
  std::array<bool, 512> keyDown{};     // GLFW key codes (GLFW_KEY_*), held
  std::vector<int> keysPressed;        // pressed this frame (once per press)
  double mouseX = 0.0, mouseY = 0.0;   // window coordinates
  double mouseDx = 0.0, mouseDy = 0.0; // motion this frame
  std::array<bool, 3> buttonDown{};    // left, right, middle
  std::vector<std::array<double, 2>> clicks; // left clicks (press and release in place)
  double scroll = 0.0;                 // wheel steps this frame
  bool shift = false;
  bool uiWantsMouse = false, uiWantsKeyboard = false; // the panel took it (set by the overlay)

  // Forgets the per-frame parts (presses, clicks, motion, scroll, the panel's claims); held keys and
  // buttons stay.
  void beginFrame();
};

class GlfwWindow {
public:
  // Opens a window of `width` x `height` named `title`. DeviceError when there is no window system
  // (no DISPLAY / WAYLAND_DISPLAY, or GLFW cannot reach it) or it has no Vulkan.
  GlfwWindow(int width, int height, const std::string& title);
  ~GlfwWindow();
  GlfwWindow(const GlfwWindow&) = delete;
  GlfwWindow& operator=(const GlfwWindow&) = delete;

  // The instance extensions the surface needs (VK_KHR_surface and the platform's).
  static std::vector<const char*> requiredInstanceExtensions();
  vk::raii::SurfaceKHR createSurface(const vk::raii::Instance& instance) const;

  // Polls the window system (waits up to `waitSeconds` when > 0, e.g. while minimised) into input().
  void pollEvents(double waitSeconds = 0.0);
  bool shouldClose() const;
  void requestClose();
  // The drawable size in pixels (0 x 0 while minimised).
  std::array<int, 2> framebufferSize() const;
  void resize(int width, int height);
  void iconify();
  void restore();

  InputState& input() { return input_; }
  GLFWwindow* handle() const { return window_; }

private:
  static void onKey(GLFWwindow*, int key, int scancode, int action, int mods);
  static void onButton(GLFWwindow*, int button, int action, int mods);
  static void onCursor(GLFWwindow*, double x, double y);
  static void onScroll(GLFWwindow*, double dx, double dy);

  GLFWwindow* window_ = nullptr;
  InputState input_;
  double pressX_ = 0.0, pressY_ = 0.0; // where the left button went down (a click releases there)
  bool cursorKnown_ = false;
};

} // namespace obscura::window
