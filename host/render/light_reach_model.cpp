#include "render/light_reach_model.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

#include "core/host_cpu_time.h"
#include "render/scene_data/ray_rounds.h"
#include "render/scene_data/scene_buffers.h"

namespace obscura::render {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return 1e3 * std::chrono::duration<double>(Clock::now() - start).count();
}

} // namespace

float changedBoxPadding(const scene::Bounds& bounds) {
  return 1e-3f * (glm::length(bounds.extent()) + glm::length(glm::max(glm::abs(bounds.lo), glm::abs(bounds.hi))));
}

void LightReachModel::measure(const scene::Scene& scene, const bvh::Bvh& bvh, const Inputs& inputs,
                              AmbientTerm& ambient, const std::vector<scene::Bounds>* changed) {
  apply(measurementOf(scene, bvh, inputs.lights, inputs.seen, ambient.reach, changed), inputs, ambient);
}

void LightReachModel::start(const scene::Scene& scene, const bvh::Bvh& bvh, const Inputs& inputs,
                            const AmbientTerm& ambient, const std::vector<scene::Bounds>* changed) {
  wait();
  if (rays_) { // the device's rays: now, between the renderer's submissions
    ready_ = measurementOf(scene, bvh, inputs.lights, inputs.seen, ambient.reach, changed);
    return;
  }
  pending_ = std::async(std::launch::async, [this, &scene, &bvh, &lights = inputs.lights, seen = inputs.seen,
                                             &previous = ambient.reach, changed] {
    const HelperThreadCpu counted; // the edit's host work (core/host_cpu_time.h)
    return measurementOf(scene, bvh, lights, seen, previous, changed);
  });
}

void LightReachModel::startLight(const LightSet& lights, std::size_t light) {
  wait();
  if (rays_) {
    const auto start = Clock::now();
    readyLight_ = reached_->measure(*rays_, lights, light);
    last_ = {readyLight_->rays.traced, msSince(start)};
    return;
  }
  pendingLight_ = std::async(std::launch::async, [this, &lights, light] {
    const HelperThreadCpu counted;
    const auto start = Clock::now();
    LightReach reach = reached_->measure(lights, light);
    last_ = {reach.rays.traced, msSince(start)};
    return reach;
  });
}

void LightReachModel::finish(const Inputs& inputs, AmbientTerm& ambient) {
  if (pending_.valid()) ready_ = pending_.get();
  if (pendingLight_.valid()) readyLight_ = pendingLight_.get();
  if (ready_) {
    apply(std::move(*ready_), inputs, ambient);
    ready_.reset();
  }
  if (readyLight_) {
    ambient.reach.push_back(std::move(*readyLight_));
    readyLight_.reset();
    updateAmbientWeights(ambient, inputs.lights, inputs.colourBleeding);
  }
}

void LightReachModel::setSeenView(const SeenView& view) {
  if (rays_) reached_->setSeenView(*rays_, view);
  else reached_->setSeenView(view);
}

void LightReachModel::wait() {
  if (pending_.valid()) pending_.wait();
  if (pendingLight_.valid()) pendingLight_.wait();
}

LightReachModel::Measurement LightReachModel::measurementOf(const scene::Scene& scene, const bvh::Bvh& bvh,
                                                            const LightSet& lights, const std::optional<SeenView>& seen,
                                                            const std::vector<LightReach>& previous,
                                                            const std::vector<scene::Bounds>* changed) {
  const auto start = Clock::now();
  Measurement m;
  // Every triangle's mean reflectance: a move or a removal keeps them; an insert or a quad brings
  // its own (with the textures' means kept: averaging modern-hall's takes ~0.25 s).
  bool replayable = changed && reached_;
  if (!changed || reflectance_.size() != scene.triangles.size()) {
    std::vector<glm::vec3> meanAlbedo;
    for (const auto& material : scene.materials) meanAlbedo.push_back(materialMeanAlbedo(material));
    textureMeans_ = textureMeanColours(scene, std::move(textureMeans_));
    m.reflectance = triangleReflectances(scene, meanAlbedo, textureMeans_);
    // Triangles appended (a quad, an inserted object) and the others as they were: the rays before
    // still say what they found (surface samples are drawn triangle by triangle).
    replayable = replayable && m.reflectance.size() >= reflectance_.size() &&
                 std::equal(reflectance_.begin(), reflectance_.end(), m.reflectance.begin());
  } else {
    m.reflectance = reflectance_;
  }
  m.reached = std::make_unique<ReachedSurfaces>(scene, bvh, m.reflectance, /*copyBvh=*/rays_ == nullptr);
  if (seen) {
    if (rays_) m.reached->setSeenView(*rays_, *seen);
    else m.reached->setSeenView(*seen);
  }
  std::vector<scene::Bounds> padded;
  if (replayable) {
    const float pad = changedBoxPadding(scene.bounds);
    for (scene::Bounds b : *changed) padded.push_back({b.lo - pad, b.hi + pad});
  }
  m.reach = reachOfEveryLight(*m.reached, lights, replayable ? reached_.get() : nullptr, previous, padded);
  for (const LightReach& r : m.reach) m.update.rays += r.rays.traced;
  m.update.ms = msSince(start); // the reflectances and surface samples included
  return m;
}

void LightReachModel::apply(Measurement m, const Inputs& inputs, AmbientTerm& ambient) {
  reflectance_ = std::move(m.reflectance);
  reached_ = std::move(m.reached);
  ambient.reach = std::move(m.reach);
  ambient.depth = inputs.depth;
  updateAmbientWeights(ambient, inputs.lights, inputs.colourBleeding);
  last_ = m.update;
}

void LightReachModel::measureAll(const Inputs& inputs, AmbientTerm& ambient) {
  const auto start = Clock::now();
  ambient.reach = reachOfEveryLight(*reached_, inputs.lights, nullptr, {}, {});
  updateAmbientWeights(ambient, inputs.lights, inputs.colourBleeding);
  last_ = {0, msSince(start)};
  for (const LightReach& r : ambient.reach) last_.rays += r.rays.traced;
}

std::vector<LightReach> LightReachModel::reachOfEveryLight(const ReachedSurfaces& reached, const LightSet& lights,
                                                           const ReachedSurfaces* before,
                                                           const std::vector<LightReach>& previous,
                                                           const std::vector<scene::Bounds>& changed) const {
  const bool incremental = before && previous.size() == lights.size();
  std::vector<LightReach> reach(lights.size());
  if (rays_) {
    // The device's: every light on a thread of its own, their stages traced together (RayRounds),
    // a few submissions in all.
    RayRounds rounds(*rays_, lights.size());
    std::vector<std::future<void>> measured;
    for (std::size_t s = 0; s < lights.size(); ++s)
      measured.push_back(std::async(std::launch::async, [&, s] {
        const HelperThreadCpu counted; // the edit's host work
        RayRounds::Member member(rounds);
        reach[s] = incremental ? reached.remeasure(member, *before, previous[s], lights, s, changed)
                               : reached.measure(member, lights, s);
      }));
    for (auto& m : measured) m.wait(); // all of them before any error leaves `rounds`
    for (auto& m : measured) m.get();
    return reach;
  }
  // Lights spread over the cores (measure is const and draws its own numbers): the CPU rays of
  // modern-hall's 13 lights take ~0.3 s on one core when measured whole.
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t s = next++; s < lights.size(); s = next++)
      reach[s] = incremental ? reached.remeasure(*before, previous[s], lights, s, changed) : reached.measure(lights, s);
  };
  std::vector<std::future<void>> workers;
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  for (unsigned w = 1; w < std::min<std::size_t>(cores, lights.size()); ++w)
    workers.push_back(std::async(std::launch::async, [&worker] {
      const HelperThreadCpu counted; // the caller's thread counts its own
      worker();
    }));
  worker();
  for (auto& w : workers) w.get();
  return reach;
}

} // namespace obscura::render
