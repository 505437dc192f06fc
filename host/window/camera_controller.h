// camera_controller.h — orbit and fly navigation for `obscura view`, and the view saved as a small
// glTF-style camera JSON.
//
//   left drag     orbit around the pivot (in front of the camera, at the pivot distance)
//   right drag    pan;  middle drag or wheel: dolly towards the pivot
//   W A S D       fly forward, left, back, right;  Q E: down, up;  Shift: 4x faster
// Speeds scale with the scene's size, so a 1 m box and a 200 m classroom feel the same.
#pragma once
#include <string>

#include <glm/glm.hpp>

#include "scene/scene.h"
#include "window/glfw_window.h"

namespace obscura::window {

class CameraController {
public:
  // `bounds`: the scene's; speeds follow its diagonal, and the pivot starts where the camera's
  // axis passes its centre.
  CameraController(const scene::Camera& camera, const scene::Bounds& bounds);

  // Starts again from `camera` (a glTF camera chosen, a view loaded).
  void setCamera(const scene::Camera& camera);
  // Moves the camera by this frame's input over `seconds`; returns whether it moved.
  bool update(const InputState& input, double seconds);
  const scene::Camera& camera() const { return camera_; }

  // Explicit moves (the script's and the panel's): yaw and pitch in degrees about the pivot;
  // a pan and a dolly in metres along the camera's right/up and forward.
  void orbit(float yawDegrees, float pitchDegrees);
  void pan(float right, float up);
  void dolly(float forward);

private:
  scene::Camera camera_;
  glm::vec3 worldUp_;
  float sceneSize_;
  glm::vec3 sceneCentre_;
  float pivotDistance_;
};

// The view as a glTF-style camera node: {"name", "type": "perspective", "perspective": {"yfov",
// "aspectRatio"}, "translation": [x, y, z], "rotation": [x, y, z, w]} (the node looks down its -Z
// with +Y up, as glTF cameras do).
void saveView(const std::string& path, const scene::Camera& camera);
// Reads such a file; InputError naming the file and the field when it is not one.
scene::Camera loadView(const std::string& path);

} // namespace obscura::window
