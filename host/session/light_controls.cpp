#include "session/light_controls.h"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/error.h"

namespace obscura::session {

bool LightControls::contains(const std::string& name) const {
  return std::any_of(lights_.begin(), lights_.end(), [&](const LightControl& l) { return l.name == name; });
}

std::size_t LightControls::index(const std::string& name) const {
  for (std::size_t i = 0; i < lights_.size(); ++i)
    if (lights_[i].name == name) return i;
  throw InputError(fmt::format("no light named '{}' (lights: {})", name, fmt::join(names(), ", ")));
}

void LightControls::insert(std::size_t at, LightControl light) {
  if (contains(light.name)) throw InputError(fmt::format("a light named '{}' exists", light.name));
  lights_.insert(lights_.begin() + static_cast<std::ptrdiff_t>(std::min(at, lights_.size())), std::move(light));
}

void LightControls::erase(std::size_t at) { lights_.erase(lights_.begin() + static_cast<std::ptrdiff_t>(at)); }

void LightControls::remove(const std::string& name) {
  const std::size_t i = index(name);
  if (lights_[i].area) lights_[i].scale = 0.0f;
  else erase(i);
}

std::vector<std::string> LightControls::names() const {
  std::vector<std::string> out;
  for (const auto& l : lights_) out.push_back(l.name);
  return out;
}

std::vector<glm::vec3> LightControls::emissions() const {
  std::vector<glm::vec3> out;
  for (const auto& l : lights_) out.push_back(l.emission());
  return out;
}

} // namespace obscura::session
