// camera_controller.cpp — see camera_controller.h.
#include "window/camera_controller.h"

#include <cmath>
#include <fstream>

#include <fmt/format.h>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "core/error.h"
#include "io/json_file.h"

namespace obscura::window {
namespace {

constexpr float kOrbitDegreesPerPixel = 0.25f;

// Keeps forward and up orthonormal, with up as close to `worldUp` as forward allows.
void orthonormalise(scene::Camera& camera, glm::vec3 worldUp) {
  camera.forward = glm::normalize(camera.forward);
  glm::vec3 right = glm::cross(camera.forward, worldUp);
  if (glm::dot(right, right) < 1e-8f) right = glm::cross(camera.forward, camera.up);
  right = glm::normalize(right);
  camera.up = glm::normalize(glm::cross(right, camera.forward));
}

glm::vec3 rightOf(const scene::Camera& c) { return glm::normalize(glm::cross(c.forward, c.up)); }

} // namespace

CameraController::CameraController(const scene::Camera& camera, const scene::Bounds& bounds)
    : sceneSize_(std::max(glm::length(bounds.hi - bounds.lo), 1e-3f)), sceneCentre_(0.5f * (bounds.lo + bounds.hi)) {
  setCamera(camera);
}

void CameraController::setCamera(const scene::Camera& camera) {
  camera_ = camera;
  worldUp_ = glm::normalize(camera.up);
  orthonormalise(camera_, worldUp_);
  // Orbiting turns about the point of the view axis nearest the scene's centre (an inside view
  // turns about a point a little ahead).
  pivotDistance_ = std::max(glm::dot(sceneCentre_ - camera_.position, camera_.forward), 0.05f * sceneSize_);
}

void CameraController::orbit(float yawDegrees, float pitchDegrees) {
  const glm::vec3 pivot = camera_.position + camera_.forward * pivotDistance_;
  glm::vec3 offset = camera_.position - pivot;
  const glm::quat yaw = glm::angleAxis(glm::radians(-yawDegrees), worldUp_);
  offset = yaw * offset;
  camera_.forward = yaw * camera_.forward;
  camera_.up = yaw * camera_.up;
  // Pitch about the camera's right axis, stopping short of the poles (no flip over the top).
  const float current = glm::degrees(std::asin(glm::clamp(glm::dot(camera_.forward, worldUp_), -1.0f, 1.0f)));
  const float pitch = glm::clamp(current - pitchDegrees, -85.0f, 85.0f) - current;
  const glm::quat tilt = glm::angleAxis(glm::radians(pitch), rightOf(camera_));
  offset = tilt * offset;
  camera_.forward = tilt * camera_.forward;
  camera_.position = pivot + offset;
  orthonormalise(camera_, worldUp_);
}

void CameraController::pan(float right, float up) {
  camera_.position += rightOf(camera_) * right + camera_.up * up;
}

void CameraController::dolly(float forward) {
  const float step = std::min(forward, pivotDistance_ - 1e-3f * sceneSize_);
  camera_.position += camera_.forward * step;
  pivotDistance_ -= step;
}

bool CameraController::update(const InputState& in, double seconds) {
  const scene::Camera before = camera_;
  if (!in.uiWantsMouse) {
    if (in.buttonDown[0] && (in.mouseDx != 0.0 || in.mouseDy != 0.0))
      orbit(static_cast<float>(in.mouseDx) * kOrbitDegreesPerPixel, static_cast<float>(in.mouseDy) * kOrbitDegreesPerPixel);
    const float perPixel = 0.002f * pivotDistance_;
    if (in.buttonDown[1]) pan(-static_cast<float>(in.mouseDx) * perPixel, static_cast<float>(in.mouseDy) * perPixel);
    if (in.buttonDown[2]) dolly(-static_cast<float>(in.mouseDy) * perPixel * 2.0f);
    if (in.scroll != 0.0) dolly(static_cast<float>(in.scroll) * 0.1f * pivotDistance_);
  }
  if (!in.uiWantsKeyboard) {
    const float speed = 0.25f * sceneSize_ * static_cast<float>(seconds) * (in.shift ? 4.0f : 1.0f);
    glm::vec3 move{0.0f};
    if (in.keyDown[GLFW_KEY_W]) move += camera_.forward;
    if (in.keyDown[GLFW_KEY_S]) move -= camera_.forward;
    if (in.keyDown[GLFW_KEY_D]) move += rightOf(camera_);
    if (in.keyDown[GLFW_KEY_A]) move -= rightOf(camera_);
    if (in.keyDown[GLFW_KEY_E]) move += worldUp_;
    if (in.keyDown[GLFW_KEY_Q]) move -= worldUp_;
    camera_.position += move * speed;
  }
  return camera_.position != before.position || camera_.forward != before.forward || camera_.up != before.up;
}

void saveView(const std::string& path, const scene::Camera& camera) {
  const glm::vec3 right = glm::normalize(glm::cross(camera.forward, camera.up));
  const glm::quat rotation = glm::quat_cast(glm::mat3(right, camera.up, -camera.forward));
  nlohmann::json json = {{"name", camera.name.empty() ? "view" : camera.name},
                         {"type", "perspective"},
                         {"perspective", {{"yfov", camera.yfov}, {"aspectRatio", camera.aspectRatio}}},
                         {"translation", {camera.position.x, camera.position.y, camera.position.z}},
                         {"rotation", {rotation.x, rotation.y, rotation.z, rotation.w}}};
  std::ofstream out(path);
  out << json.dump(2) << "\n";
  if (!out) throw InputError(fmt::format("{}: cannot write the view", path));
}

scene::Camera loadView(const std::string& path) {
  const nlohmann::json json = io::readJsonFile(path, "view");
  auto vec = [&](const char* key, std::size_t n) {
    if (!json.contains(key) || !json[key].is_array() || json[key].size() != n)
      throw InputError(fmt::format("{}: \"{}\" must be a list of {} numbers", path, key, n));
    std::vector<float> v;
    for (const auto& x : json[key]) {
      if (!x.is_number() || !std::isfinite(x.get<double>()))
        throw InputError(fmt::format("{}: \"{}\" must hold finite numbers", path, key));
      v.push_back(x.get<float>());
    }
    return v;
  };
  const auto t = vec("translation", 3);
  const auto r = vec("rotation", 4);
  glm::quat rotation(r[3], r[0], r[1], r[2]);
  if (glm::length(rotation) < 1e-6f) throw InputError(fmt::format("{}: \"rotation\" is not a rotation", path));
  rotation = glm::normalize(rotation);
  scene::Camera camera;
  camera.name = json.value("name", std::string("view"));
  camera.position = {t[0], t[1], t[2]};
  camera.forward = rotation * glm::vec3(0.0f, 0.0f, -1.0f);
  camera.up = rotation * glm::vec3(0.0f, 1.0f, 0.0f);
  if (json.contains("perspective")) {
    const auto& p = json["perspective"];
    if (!p.is_object() || !p.contains("yfov") || !p["yfov"].is_number())
      throw InputError(fmt::format("{}: \"perspective\" needs a number \"yfov\"", path));
    camera.yfov = p["yfov"].get<float>();
    if (!(camera.yfov > 0.0f && camera.yfov < 3.1f))
      throw InputError(fmt::format("{}: \"yfov\" must be in (0, 3.1) radians", path));
    camera.aspectRatio = p.value("aspectRatio", 0.0f);
  }
  return camera;
}

} // namespace obscura::window
