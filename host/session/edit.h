// edit.h — one change to a scene being edited: the one vocabulary of `relight --edits` (its JSON
// file, relight/light_edits.h), the window's panel and scripts (window/viewer_action.h) and
// `remodel`. An EditSession (session/edit_session.h) applies it to a rendered frame; `remodel`
// applies the scene and light part of it to a photographed room (session/scene_history.h,
// session/light_controls.h). Lights and objects are addressed by name, never by index.
#pragma once
#include <cstddef>
#include <memory>
#include <string>

#include <glm/glm.hpp>

#include "scene/scene.h"
#include "scene/scene_edit.h"

namespace obscura::session {

struct Edit {
  enum class Kind {
    Scale,       // light `name`: intensity multiplier `scale` (absolute, starts at 1)
    Color,       // light `name`: RGB multipliers `color` (absolute, start at 1, 1, 1)
    AddLight,    // punctual `light` (point or spot): only its rays are traced
    AddQuad,     // emissive `quad`: a light and an object of that name
    RemoveLight, // light `name`: a punctual light goes, an area light is switched off
    MoveLight,   // punctual light `name`, added by an edit, to `position` (a drag): its rays again
    Move,        // object `name` by `translate` and `rotateDegrees`: the pixels it can change
    Remove,      // object `name`
    Insert,      // `inserted` (another glTF's triangles) as object `name`, by `translate`
  };
  Kind kind = Kind::Scale;
  std::size_t entry = 0;       // index in the file or script, for messages
  std::string name;            // the light or object it names
  float scale = 1.0f;
  glm::vec3 color{1.0f};
  scene::PunctualLight light;  // AddLight
  scene::EmissiveQuad quad;    // AddQuad
  glm::vec3 position{0.0f};    // MoveLight
  glm::vec3 translate{0.0f};   // Move, Insert
  glm::vec3 rotateDegrees{0.0f};
  std::string path;            // Insert: the other glTF, loaded (and so checked) when read
  std::shared_ptr<const scene::Scene> inserted;

  // The name edits.jsonl and the panel give the kind: "scale", "color", "add_light", ...
  std::string kindName() const;
  // Whether it changes the scene's triangles (and so the BVH).
  bool changesGeometry() const;
};

} // namespace obscura::session
