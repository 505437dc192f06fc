#include "session/edit_session.h"

#include <chrono>

#include <fmt/format.h>

#include "core/error.h"
#include "core/host_cpu_time.h"
#include "render/scene_data/light_set.h"

namespace obscura::session {
namespace {
using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

} // namespace

render::ObscuranceSettings editSettings(render::ObscuranceSettings settings, std::uint32_t spareLights) {
  settings.spareLightSlots = spareLights;
  // An added light's gather and a geometry edit's probes follow the frame's kept rays (shadow
  // rays, lobe hits) instead of tracing them again.
  settings.keptRaySamples = settings.spp;
  return settings;
}

EditSession::EditSession(const gpu::Context& context, scene::Scene scene, bvh::Bvh bvh,
                         const render::ObscuranceSettings& settings, bvh::BuildOptions rebuildOptions,
                         EditKernels editKernels)
    : history_(std::move(scene), std::move(bvh), rebuildOptions) {
  renderer_ = std::make_unique<render::ObscuranceRenderer>(context, history_.scene(), history_.bvh(), settings);
  if (editKernels == EditKernels::UpFront) renderer_->prepareForEdits(); // the first edit's time is its own
  const render::LightSet& set = renderer_->lights();
  for (std::size_t i = 0; i < set.names.size(); ++i) {
    lights_.insert(i, {.name = set.names[i], .base = renderer_->emissions()[i],
                       .area = set.type(i) == render::LightType::Area});
  }
}

void EditSession::updateEmissions() { renderer_->setEmissions(lights_.emissions()); }

void EditSession::addLight(const scene::PunctualLight& light, bool added) {
  const std::size_t at = renderer_->addLight(light);
  lights_.insert(at, {.name = light.name, .base = renderer_->emissions()[at], .added = added, .light = light});
}

EditReport EditSession::apply(const Edit& e, const std::string& where) {
  using Kind = Edit::Kind;
  const auto start = Clock::now();
  const HostCpuClock cpu;
  const render::RenderStats before = renderer_->stats();
  EditReport report;
  report.kind = e.kindName();
  report.name = e.name;
  const std::uint64_t everyPixel = renderer_->layout().pixels();
  auto geometry = [&] {
    const GeometryChange change = history_.apply(e, where);
    report.bvh = change.bvh;
    return change;
  };
  switch (e.kind) {
    case Kind::Scale: lights_.at(e.name).scale = e.scale; break;
    case Kind::Color: lights_.at(e.name).color = e.color; break;
    case Kind::AddLight:
      if (lights_.contains(e.light.name)) throw InputError(fmt::format("{}: a light named '{}' exists", where, e.light.name));
      updateEmissions(); // compose's emissions first: addLight appends the new light's own
      addLight(e.light, true);
      report.pixelsRetraced = everyPixel;
      break;
    case Kind::MoveLight: {
      const std::size_t i = lights_.index(e.name);
      if (!lights_[i].added)
        throw InputError(fmt::format("{}: '{}' is not a light added by an edit (only those move)", where, e.name));
      LightControl moved = lights_[i];
      moved.light.position = e.position;
      renderer_->removeLight(i);
      lights_.erase(i);
      const std::size_t at = renderer_->addLight(moved.light);
      moved.base = renderer_->emissions()[at];
      lights_.insert(at, std::move(moved));
      report.pixelsRetraced = everyPixel;
      break;
    }
    case Kind::RemoveLight: {
      const std::size_t i = lights_.index(e.name);
      updateEmissions();
      renderer_->removeLight(i);
      lights_.remove(e.name);
      break;
    }
    case Kind::AddQuad: {
      if (lights_.contains(e.quad.name)) throw InputError(fmt::format("{}: a light named '{}' exists", where, e.quad.name));
      updateEmissions();
      const GeometryChange change = geometry();
      report.pixelsRetraced = renderer_->addEmitter(history_.scene(), history_.bvh(), change.changed);
      // An area light: it goes before the punctual lights, at its light group's index.
      const std::size_t at = renderer_->lightIndex(e.quad.name);
      lights_.insert(at, {.name = e.quad.name, .base = renderer_->emissions()[at], .area = true, .added = true});
      history_.dropPrevious();
      break;
    }
    case Kind::Move:
    case Kind::Remove:
    case Kind::Insert: {
      const GeometryChange change = geometry();
      report.pixelsRetraced = renderer_->updateGeometry(history_.scene(), history_.bvh(), change.changed);
      history_.dropPrevious(); // the renderer points at the new version now
      break;
    }
  }
  updateEmissions();
  if (report.bvh || e.kind == Kind::AddLight || e.kind == Kind::MoveLight) report.reach = renderer_->lastReachUpdate();
  report.addPasses(before, renderer_->stats());
  report.totalMs = msSince(start);
  report.cpuMs = cpu.ms();
  return report;
}

void EditSession::composeDisplay(EditReport& report, float exposureStops) {
  const auto start = Clock::now();
  const HostCpuClock cpu;
  const render::RenderStats before = renderer_->stats();
  renderer_->composeDisplay(exposureStops);
  report.addPasses(before, renderer_->stats());
  report.totalMs += msSince(start);
  report.cpuMs += cpu.ms();
}

} // namespace obscura::session
