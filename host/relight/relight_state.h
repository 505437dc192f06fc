// relight_state.h — what `obscura render --save-state DIR` keeps so that `obscura relight DIR`
// can relight a finished render with no scene and no ray (as Cycles light groups or LightMix do):
//   DIR/state.json     version, scene, size, samples, settings, and per light its name, type,
//                      render-time emission E_s and I_a weight w_s [RTO eq. 12]
//   DIR/transport.exr  the resolved per-light transport (render/transport.h channels)
// `obscura recover` writes one too: the photographed room's, whose lights carry their own
// indirect light as the photographs measured it (render/transport.h I_s).
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "render/obscurance_renderer.h"
#include "render/transport.h"

namespace obscura::relight {

// 2: a light may carry its own indirect light (I.<light> channels). Version 1 states read as before.
inline constexpr int kStateVersion = 2;
inline constexpr int kOldestStateVersion = 1;

struct LightRecord {
  std::string name;
  std::string type;             // "area", "point", "spot", "directional"
  glm::vec3 emission{0.0f};     // E_s at render time
  glm::vec3 ambientWeight{0.0f};// w_s: I_a per unit E_s
};

struct RelightState {
  nlohmann::json document; // state.json as written or read (what saveState(dir, state) writes back)
  std::string scene;
  std::uint32_t samples = 0;
  nlohmann::json settings;
  std::vector<LightRecord> lights;
  render::Transport transport;

  std::vector<glm::vec3> emissions() const;
  std::vector<glm::vec3> ambientWeights() const;
  // The index of the light named `name`; InputError naming the state and listing the lights.
  std::size_t lightIndex(const std::string& name, const std::string& where) const;
};


// Writes DIR (created when missing). The files are written under temporary names and renamed,
// so an interrupted write leaves no half state.
void saveState(const std::string& dir, const render::ObscuranceRenderer& renderer, const std::string& scenePath);
// The same with `transport` in place of the renderer's own (same lights and size): a transport
// whose albedo was replaced (`recover`'s recovered reflectance).
void saveState(const std::string& dir, const render::ObscuranceRenderer& renderer, const render::Transport& transport,
               const std::string& scenePath);

// What state.json says of a renderer's frame (its samples so far among it).
nlohmann::json stateJson(const render::ObscuranceRenderer& renderer, const std::string& scenePath);
// The same of a transport no renderer traced whole (recover's): `settings` says how it was made;
// its size and specular flag are the transport's.
nlohmann::json stateJson(const std::string& scenePath, std::uint32_t samples, const nlohmann::json& settings,
                         const glm::vec3& averageReflectance, const std::vector<LightRecord>& lights,
                         const render::Transport& transport);
// Writes DIR from state.json's contents and the resolved transport (a farm's merged parts).
void saveState(const std::string& dir, const nlohmann::json& state, const render::Transport& transport);

// The state of `renderer`'s frame now (its transport resolved on the host): what saveState writes,
// without the files (the Python API's results).
RelightState currentState(const render::ObscuranceRenderer& renderer, const std::string& scenePath);
// Writes DIR from a state (as loaded or made by currentState).
void saveState(const std::string& dir, const RelightState& state);

// Reads DIR; InputError naming the file for a missing, truncated, foreign-version or inconsistent
// state.
RelightState loadState(const std::string& dir);

} // namespace obscura::relight
