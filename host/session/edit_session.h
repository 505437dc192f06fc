// edit_session.h — one scene being rendered and edited [IVR §3]: the one place that `relight
// --edits`, the window and (through Python or a farm) anything else drives. It owns
//   - the renderer (render/obscurance_renderer.h), made for edits (kept rays, the edit kernels
//     compiled up front unless the caller says otherwise);
//   - the scene's versions and their BVHs, and the refit-or-rebuild choice (session/scene_history.h);
//   - the lights by name with their edited intensity and colour (session/light_controls.h), kept
//     in step with the renderer's light order, which shifts as lights come and go.
// apply(edit) does one edit (session/edit.h) and says what it cost (session/edit_report.h):
//   a light's scale or colour   new emissions, no ray (the next compose shows it)
//   add a punctual light        its rays alone, at every pixel and along the specular paths
//   move an added light         removed and added again at its new place
//   remove a light              a punctual light's transport goes; an area light is switched off
//   move / remove / insert      the pixels the object's old and new boxes can change, retraced
//   add an emissive quad        its light everywhere, and the pixels its surface can change
// After apply the renderer's emissions are the edited ones; composing and showing the frame is
// the caller's (composeDisplay() for the fast path with the compose's cost in the report).
#pragma once
#include <memory>
#include <string>

#include "bvh/bvh.h"
#include "gpu/context.h"
#include "render/obscurance_renderer.h"
#include "scene/scene.h"
#include "session/edit.h"
#include "session/edit_report.h"
#include "session/light_controls.h"
#include "session/scene_history.h"

namespace obscura::session {

// When the kernels only edits use are compiled: before anything else, so that the first edit's
// time is its own (what `relight --edits` reports), or when an edit first needs them (a window on
// lavapipe, where they cost ~1.8 s of CPU that a session which never edits would pay at start).
enum class EditKernels { UpFront, OnFirstUse };

class EditSession {
public:
  // `settings` as the renderer takes them (editSettings gives what edits want); `rebuildOptions`:
  // the BVH build of edits that add triangles (the device's tree, render::treeOptionsFor).
  EditSession(const gpu::Context& context, scene::Scene scene, bvh::Bvh bvh, const render::ObscuranceSettings& settings,
              bvh::BuildOptions rebuildOptions = {}, EditKernels editKernels = EditKernels::UpFront);

  // Applies `edit`; `where` names it in errors (the file and entry, the script's event). An
  // InputError (no such light or object, a name taken, moving a light no edit added) leaves the
  // session as it was.
  EditReport apply(const Edit& edit, const std::string& where = "edit");
  // composeDisplay on the renderer, its GPU ms and wall time added to `report`.
  void composeDisplay(EditReport& report, float exposureStops);

  render::ObscuranceRenderer& renderer() { return *renderer_; }
  const render::ObscuranceRenderer& renderer() const { return *renderer_; }
  const scene::Scene& scene() const { return history_.scene(); }
  const bvh::Bvh& bvh() const { return history_.bvh(); }
  const LightControls& lights() const { return lights_; }

private:
  void addLight(const scene::PunctualLight& light, bool added);
  void updateEmissions();

  SceneHistory history_;
  std::unique_ptr<render::ObscuranceRenderer> renderer_; // points at history_'s current scene
  LightControls lights_;
};

// The renderer settings of a session: those given with as many kept ray samples as the frame
// has (added lights and probes follow them) and `spareLights` basis buffers reserved.
render::ObscuranceSettings editSettings(render::ObscuranceSettings settings, std::uint32_t spareLights);

} // namespace obscura::session
