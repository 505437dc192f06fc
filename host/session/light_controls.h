// light_controls.h — the lights of a scene being edited, addressed by name: each light's own
// emission and the intensity and colour multipliers edits set on it. The order is the renderer's
// (area lights first, then punctual ones, as render/scene_data/light_set.h builds them), which an
// EditSession keeps in step with the renderer's; nothing outside the session sees an index.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace obscura::session {

struct LightControl {
  std::string name;
  glm::vec3 base{1.0f};       // the light's own emission E_s (scale 1, colour 1)
  float scale = 1.0f;         // intensity multiplier (0: switched off)
  glm::vec3 color{1.0f};      // RGB multipliers
  bool area = false;          // an emissive mesh: removing it switches it off, its slot stays
  bool added = false;         // added by an edit: a punctual light that may be moved
  scene::PunctualLight light; // a punctual light's definition (position, intensity, colour)

  // E_s as edited: base x scale x colour, as if the glTF's emissive strength and factor (or the
  // punctual light's intensity and colour) were edited.
  glm::vec3 emission() const { return base * scale * color; }
};

class LightControls {
public:
  std::size_t size() const { return lights_.size(); }
  const LightControl& operator[](std::size_t i) const { return lights_[i]; }
  auto begin() const { return lights_.begin(); }
  auto end() const { return lights_.end(); }

  bool contains(const std::string& name) const;
  // The position of the light named `name`; InputError listing the lights when there is none.
  std::size_t index(const std::string& name) const;
  LightControl& at(const std::string& name) { return lights_[index(name)]; }
  const LightControl& at(const std::string& name) const { return lights_[index(name)]; }

  void insert(std::size_t at, LightControl light);
  void erase(std::size_t at);
  // Removes the light named `name` as the renderer does: a punctual light goes, an area light
  // stays switched off (its triangles name it by index).
  void remove(const std::string& name);

  std::vector<std::string> names() const;
  // E_s of every light, in order (LightControl::emission).
  std::vector<glm::vec3> emissions() const;

private:
  std::vector<LightControl> lights_;
};

} // namespace obscura::session
