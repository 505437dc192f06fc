// light_reach_model.h — what each light reaches, measured with rays for I_a's Reached and Seen
// models (render/scene_data/reached_surfaces.h, OURS after [RTO §6]) and for marking secondary
// reflectors: measured when a renderer is made, re-measured after an edit (only the rays a move
// can change), a new light measured alone.
//
// One of ObscuranceRenderer's jobs, kept apart: it owns the measured surfaces and the measurement;
// the renderer owns the lights and the AmbientTerm it fills (compose reads I_a from it).
//
// Where the rays run (useRays): on the device, through the renderer's traversal (GpuRayBatch),
// a stage of a light's rays per submission, on the renderer's thread, so start() measures at
// once; without one, on the CPU's BVH, on threads of its own beside an edit's GPU work (finish()
// waits for them).
#pragma once
#include <cstdint>
#include <future>
#include <memory>
#include <optional>
#include <vector>

#include "bvh/bvh.h"
#include "render/scene_data/ambient.h"
#include "render/scene_data/light_set.h"
#include "render/scene_data/ray_batch.h"
#include "render/scene_data/reached_surfaces.h"
#include "scene/scene.h"

namespace obscura::render {

class LightReachModel {
public:
  // The last measurement: rays traced and wall ms; after a move, only the rays it could change.
  struct Update {
    std::uint64_t rays = 0;
    double ms = 0.0;
  };
  // What the measurement reads besides the scene: the lights, the Seen model's view (none for
  // Reached), and how I_a sums the bounces (AmbientTerm::depth, colour bleeding).
  struct Inputs {
    const LightSet& lights;
    std::optional<SeenView> seen;
    std::uint32_t depth = 0;
    bool colourBleeding = true;
  };

  LightReachModel() = default;
  LightReachModel(LightReachModel&&) = default;
  LightReachModel& operator=(LightReachModel&&) = default;
  // Waits for a measurement still running: it reads the renderer's lights.
  ~LightReachModel() { wait(); }

  // The rays through `rays` from now on (the renderer's GpuRayBatch, which must outlive this or be
  // replaced first); nullptr: the CPU's BVH.
  void useRays(RayBatch* rays) {
    wait();
    rays_ = rays;
  }

  // Whether anything was measured (the renderer was made with Reached or Seen, or reflectors).
  bool measured() const { return reached_ != nullptr; }
  const ReachedSurfaces& surfaces() const { return *reached_; }
  Update lastUpdate() const { return last_; }

  // Every light in `scene`, now, into `ambient` (its reach, depth and weights). After a geometry
  // edit that kept the lights, emitters and surfaces, `changed` (the edited objects' old and new
  // boxes) lets each light re-trace only the rays the edit can change (ReachedSurfaces::remeasure:
  // the same numbers).
  void measure(const scene::Scene& scene, const bvh::Bvh& bvh, const Inputs& inputs, AmbientTerm& ambient,
               const std::vector<scene::Bounds>* changed = nullptr);
  // The same measurement on threads of its own, so that it runs beside an edit's GPU work;
  // finish() applies it. `scene`, `bvh`, `changed`, `inputs.lights` and `ambient` must stay as
  // they are until then.
  void start(const scene::Scene& scene, const bvh::Bvh& bvh, const Inputs& inputs, const AmbientTerm& ambient,
             const std::vector<scene::Bounds>* changed);
  // The light `light` (just added to `lights`) alone, on a thread of its own; finish() appends it.
  void startLight(const LightSet& lights, std::size_t light);
  // Applies what start() or startLight() measured, with I_a's weights; nothing if none was started.
  void finish(const Inputs& inputs, AmbientTerm& ambient);
  // Runs `gpuWork` while a started measurement runs; on an exception, waits for the measurement
  // before passing it on (it reads what the caller may then free).
  template <class Work>
  void beside(Work&& gpuWork) {
    try {
      gpuWork();
    } catch (...) {
      wait();
      throw;
    }
  }
  // Every light again with the surfaces as they are (the Seen fit after a new view).
  void measureAll(const Inputs& inputs, AmbientTerm& ambient);
  // The view the Seen fit measures from (fitted by the next measurement).
  void setSeenView(const SeenView& view);

private:
  struct Measurement {
    std::vector<glm::vec3> reflectance; // per triangle
    std::unique_ptr<ReachedSurfaces> reached;
    std::vector<LightReach> reach;      // per light
    Update update;
  };
  Measurement measurementOf(const scene::Scene& scene, const bvh::Bvh& bvh, const LightSet& lights,
                            const std::optional<SeenView>& seen, const std::vector<LightReach>& previous,
                            const std::vector<scene::Bounds>* changed);
  void apply(Measurement measurement, const Inputs& inputs, AmbientTerm& ambient);
  // Every light's reach with `reached`; with `before` (the reach of the scene before an edit, and
  // `previous` its per-light results), re-tracing only the rays `changed` (padded) can change.
  std::vector<LightReach> reachOfEveryLight(const ReachedSurfaces& reached, const LightSet& lights,
                                            const ReachedSurfaces* before, const std::vector<LightReach>& previous,
                                            const std::vector<scene::Bounds>& changed) const;
  void wait();

  RayBatch* rays_ = nullptr;                // the device's rays, or none: the CPU's
  std::vector<glm::vec3> reflectance_;      // mean reflectance per triangle of the measured scene
  std::vector<glm::vec3> textureMeans_;     // mean colour per texture (an edit only appends textures)
  std::unique_ptr<ReachedSurfaces> reached_;
  Update last_;
  // A measurement started: on threads (CPU rays), or done already (the device's).
  std::future<Measurement> pending_;
  std::future<LightReach> pendingLight_;
  std::optional<Measurement> ready_;
  std::optional<LightReach> readyLight_;
};

// How far beyond a changed box the rays' offset origins may start: 1e-3 of the scene's size and
// reach (lib/ray.glsl offsets by a few hundred ulps of the coordinates).
float changedBoxPadding(const scene::Bounds& sceneBounds);

} // namespace obscura::render
