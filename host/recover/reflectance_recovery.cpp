// reflectance_recovery.cpp — see reflectance_recovery.h.
#include "recover/reflectance_recovery.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>

#include <fmt/format.h>
#include <glm/gtc/constants.hpp>

#include "core/error.h"
#include "core/luminance.h"
#include "core/names.h"
#include "recover/pixel_footprint.h"
#include "recover/recovery_scene.h"
#include "relight/relight_state.h"
#include "render/gpu_ray_batch.h"
#include "render/obscurance_renderer.h"
#include "render/scene_data/scene_buffers.h"

namespace obscura::recover {
namespace {
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

int channel(const io::Image& image, const std::string& name) {
  const int c = image.channelIndex(name);
  if (c < 0) throw std::logic_error("recover: the renderer's image lacks " + name);
  return c;
}

glm::vec3 pixel3(const io::Image& image, std::size_t p, int first) {
  const float* v = &image.pixels[p * image.channels.size() + std::size_t(first)];
  return {v[0], v[1], v[2]};
}

// Reflectances the renderer may use: above 0 so that dividing by the albedo AOV recovers the
// lighting, below 1 so that I_a (1 / (1 - R_ave)) stays finite.
glm::vec3 renderable(const glm::vec3& r) { return glm::clamp(r, glm::vec3(0.02f), glm::vec3(0.95f)); }

render::ObscuranceSettings recoverySettings(const PhotoSet& photos, const scene::Camera& camera,
                                            const RecoveryOptions& options) {
  render::ObscuranceSettings settings;
  settings.width = static_cast<std::uint32_t>(photos.width);
  settings.height = static_cast<std::uint32_t>(photos.height);
  settings.spp = options.spp;
  settings.seed = options.seed;
  settings.camera = camera;
  settings.obscuranceRays = options.obscuranceRays;
  // The gather brings its own B: the lighting render's obscurance term would go unused, so it is
  // not traced (the staircase's lighting pass 0.3 s less).
  if (options.indirect == IndirectModel::Gather) settings.obscuranceRays = 0;
  settings.dMax = options.dMax;
  settings.shadowSampling = render::ShadowSampling::PerLight; // each lamp alone, one exact ray to a point
  settings.ambient = options.ambient;
  return settings;
}

// The recovery scene with `objectReflectance` per object, rendered once (the renderer keeps a
// pointer to the scene, so both live here).
struct RoomRender {
  scene::Scene scene;
  std::unique_ptr<render::ObscuranceRenderer> renderer;

  RoomRender(const gpu::Context& context, const scene::Scene& room, const bvh::Bvh& bvh, const scene::Camera& camera,
             const PhotoSet& photos, const std::vector<glm::vec3>& objectReflectance, const RecoveryOptions& options) {
    std::vector<glm::vec3> materials;
    for (const auto& r : objectReflectance) materials.push_back(renderable(r));
    scene = recoveryScene(room, photos.shots, materials);
    renderer = std::make_unique<render::ObscuranceRenderer>(context, scene, bvh, recoverySettings(photos, camera, options));
    renderer->render();
    if (renderer->stats().truncatedTraversals > 0)
      throw DeviceError("traversals ran out of steps (kMaxTraversalSteps); the lighting would be wrong");
  }
};

std::vector<std::vector<glm::vec3>> estimatesWith(const PhotoSet& photos, const Lighting& lighting,
                                                  const std::vector<std::vector<glm::vec3>>& indirect) {
  std::vector<std::vector<glm::vec3>> r;
  for (std::size_t i = 0; i < photos.shots.size(); ++i)
    r.push_back(estimateReflectance(photos.shots[i].radiance, lighting.direct[i], indirect[i]));
  return r;
}

// The iterations' merges smooth over at most this radius (the recovery's own, wider, smooths the
// kept merge after the last): they give the object means the next gather uses, which a wider
// window barely moves, and their change from one to the next is measured alike.
constexpr int kIterationSmoothingRadius = 3;

// The estimates merged as `options.merge` says; the paper's mean in WeightedMerge's terms
// (relative variance 1 / sum K_i, no indirect-only estimate, no smoothing).
WeightedMerge mergeShots(const std::vector<std::vector<glm::vec3>>& radiance, const Lighting& lighting,
                         const std::vector<std::vector<glm::vec3>>& indirect,
                         const std::vector<std::vector<glm::vec3>>& estimates,
                         const std::vector<ConfidenceImage>& confidences, const RecoveryOptions& options,
                         const std::vector<std::vector<float>>* modelled = nullptr) {
  if (options.merge == MergeModel::Weighted) {
    WeightedMergeOptions weighted = options.weighted;
    weighted.smoothingRadius = std::min(weighted.smoothingRadius, kIterationSmoothingRadius);
    return weightedMerge(radiance, lighting.direct, indirect, estimates, confidences, lighting.visibility,
                         lighting.geometry, weighted, modelled);
  }
  const Merged paper = mergeEstimates(estimates, confidences);
  WeightedMerge out;
  out.reflectance = paper.reflectance;
  out.directConfidence = paper.confidence;
  out.indirectShots.assign(paper.confidence.size(), 0.0f);
  out.relativeVariance.assign(paper.confidence.size(), 0.0f);
  for (std::size_t p = 0; p < paper.confidence.size(); ++p)
    if (paper.confidence[p] > 0.0f) out.relativeVariance[p] = 1.0f / paper.confidence[p];
  return out;
}

// The merged estimates' inverse variances: the weights of the object means and the change.
std::vector<float> inverseVariance(const WeightedMerge& m) {
  std::vector<float> w(m.relativeVariance.size(), 0.0f);
  for (std::size_t p = 0; p < w.size(); ++p)
    if (m.relativeVariance[p] > 0.0f) w[p] = 1.0f / m.relativeVariance[p];
  return w;
}

// The object means the next gather uses, from `used` (this gather's), `before` (the previous
// gather's) and `next` (what this gather gave): where a mean turned back (its step from `used`
// against its step to `used`), halfway (under-relaxation), else as it came. The iteration R -> B
// -> R can swing: high means light the hidden vertices more, so B is higher and R lower, so the
// next means are lower (classroom: the objects' mean 0.69, 0.50, 0.63, 0.55, 0.60, 0.57 over six
// iterations), and the last gather's phase decided R: the staircase's RMSE was 0.086 / 0.065 /
// 0.079 after 5 / 6 / 7 iterations, now 0.072 / 0.071 / 0.072. Where it converges without swinging
// (the Cornell box), the means are taken as they come, as fast as before.
void dampSwings(const std::vector<glm::vec3>& before, const std::vector<glm::vec3>& used, std::vector<glm::vec3>& next) {
  for (std::size_t o = 0; o < next.size(); ++o) // one mean per object in all three
    for (int c = 0; c < 3; ++c) {
      const float step = next[o][c] - used[o][c], last = used[o][c] - before[o][c];
      if (step * last < 0.0f) next[o][c] = used[o][c] + 0.5f * step;
    }
}

} // namespace

std::vector<glm::vec3> estimateReflectance(const std::vector<glm::vec3>& photo, const std::vector<glm::vec3>& direct,
                                           const std::vector<glm::vec3>& indirect) {
  std::vector<glm::vec3> r(photo.size(), glm::vec3(0.0f));
  for (std::size_t p = 0; p < photo.size(); ++p) {
    const glm::vec3 light = direct[p] + indirect[p];
    for (int c = 0; c < 3; ++c)
      if (light[c] > 1e-8f) r[p][c] = photo[p][c] / light[c];
  }
  return r;
}

std::vector<glm::vec3> constantAmbient(const std::vector<glm::vec3>& photo, const std::vector<std::int32_t>& object,
                                       float k) {
  glm::dvec3 sum(0.0);
  std::size_t n = 0;
  for (std::size_t p = 0; p < photo.size(); ++p)
    if (object[p] >= 0) {
      sum += glm::dvec3(photo[p]);
      ++n;
    }
  const glm::vec3 mean = n > 0 ? glm::vec3(sum / static_cast<double>(n)) : glm::vec3(0.0f);
  return std::vector<glm::vec3>(photo.size(), k * mean);
}

std::vector<glm::vec3> objectMeans(const std::vector<glm::vec3>& reflectance, const std::vector<float>& confidence,
                                   const std::vector<std::int32_t>& object, std::size_t objects,
                                   const std::vector<std::uint32_t>* objectMaterial,
                                   const std::vector<std::optional<glm::vec3>>* photographed,
                                   std::optional<float> unseenGrey, const std::vector<bool>* oneColour,
                                   const std::vector<std::optional<glm::vec3>>* modelColour) {
  std::vector<glm::dvec3> sum(objects, glm::dvec3(0.0));
  std::vector<double> weight(objects, 0.0);
  glm::dvec3 all(0.0);
  double allWeight = 0.0;
  for (std::size_t p = 0; p < reflectance.size(); ++p) {
    if (object[p] < 0 || confidence[p] <= 0.0f) continue;
    const auto o = static_cast<std::size_t>(object[p]);
    sum[o] += double(confidence[p]) * glm::dvec3(reflectance[p]);
    weight[o] += confidence[p];
    all += double(confidence[p]) * glm::dvec3(reflectance[p]);
    allWeight += confidence[p];
  }
  // An object whose material no photograph shows has an unknown colour: a neutral grey of the
  // seen pixels' mean luminance. Their mean colour cast the room's dominant material on every
  // unknown surface: the staircase's wood (0.57 / 0.42 / 0.26) on its unseen white paints, steel
  // and the switched-off emitter panel, which lit the wall around the arch warm and recovered it
  // blue (R / T 0.91 / 1.00 / 1.15; BENCHMARKS).
  const glm::vec3 fallback = unseenGrey         ? glm::vec3(*unseenGrey)
                             : allWeight > 0.0 ? glm::vec3(luminance(glm::vec3(all / allWeight)))
                                               : glm::vec3(0.5f);
  // An object no photograph shows takes the mean of the seen objects of its material. The objects
  // of one colour in the model pool their pixels with the others of their material: a sliver lit
  // only by bounces from the wood beside it (the staircase's white trim under its stringer, 149 px,
  // 140 of them lit by no lamp) measured the wood's colour, and its fills took it (11 % of the
  // staircase's squared error; BENCHMARKS "one colour per material").
  std::map<std::uint32_t, std::pair<glm::dvec3, double>> byMaterial, pooled;
  const auto pools = [&](std::size_t o) { return objectMaterial && oneColour && (*oneColour)[o]; };
  const auto add = [&](std::map<std::uint32_t, std::pair<glm::dvec3, double>>& group, std::size_t o) {
    auto& m = group[(*objectMaterial)[o]];
    m.first += sum[o];
    m.second += weight[o];
  };
  if (objectMaterial)
    for (std::size_t o = 0; o < objects; ++o) {
      add(byMaterial, o);
      if (pools(o)) add(pooled, o);
    }
  std::vector<glm::vec3> means(objects);
  for (std::size_t o = 0; o < objects; ++o) {
    if (pools(o)) {
      const auto& m = pooled[(*objectMaterial)[o]];
      if (m.second > 0.0) {
        means[o] = glm::vec3(m.first / m.second);
        continue;
      }
    }
    if (weight[o] > 0.0) {
      means[o] = glm::vec3(sum[o] / weight[o]);
      continue;
    }
    if (photographed && (*photographed)[o]) {
      means[o] = *(*photographed)[o];
      continue;
    }
    means[o] = !unseenGrey && modelColour && (*modelColour)[o] ? *(*modelColour)[o] : fallback;
    if (objectMaterial) {
      const auto& m = byMaterial[(*objectMaterial)[o]];
      if (m.second > 0.0) means[o] = glm::vec3(m.first / m.second);
    }
  }
  return means;
}

std::vector<std::optional<glm::vec3>> photographedRatios(const std::vector<std::vector<glm::vec3>>& photos,
                                                         const std::vector<std::vector<glm::vec3>>& direct,
                                                         const std::vector<std::vector<glm::vec3>>& indirect,
                                                         const std::vector<std::int32_t>& object, std::size_t objects) {
  std::vector<glm::dvec3> photographed(objects, glm::dvec3(0.0)), light(objects, glm::dvec3(0.0));
  for (std::size_t i = 0; i < photos.size(); ++i)
    for (std::size_t p = 0; p < object.size(); ++p) {
      if (object[p] < 0) continue;
      const auto o = static_cast<std::size_t>(object[p]);
      photographed[o] += glm::dvec3(photos[i][p]);
      light[o] += glm::dvec3(direct[i][p] + indirect[i][p]);
    }
  std::vector<std::optional<glm::vec3>> ratios(objects);
  for (std::size_t o = 0; o < objects; ++o)
    if (light[o].x > 0.0 && light[o].y > 0.0 && light[o].z > 0.0)
      ratios[o] = glm::min(glm::vec3(photographed[o] / light[o]), glm::vec3(1.0f));
  return ratios;
}

Lighting traceLighting(const gpu::Context& context, const scene::Scene& room, const bvh::Bvh& bvh,
                       const scene::Camera& camera, const PhotoSet& photos,
                       const std::vector<glm::vec3>& objectReflectance, const RecoveryOptions& options) {
  const auto start = Clock::now();
  const RoomRender roomRender(context, room, bvh, camera, photos, objectReflectance, options);
  const render::ObscuranceRenderer& renderer = *roomRender.renderer;
  const render::Transport transport = renderer.transport();
  const io::Image aov = renderer.image();
  const int albedo = channel(aov, "albedo.R"), normal = channel(aov, "normal.X"),
            position = channel(aov, "position.X"), primitive = channel(aov, "primitive.id");
  const std::vector<std::uint32_t> objectOf = triangleObjects(room);
  const std::size_t pixels = photos.pixels();
  Lighting out;
  out.geometry.width = photos.width;
  out.geometry.height = photos.height;
  out.geometry.object.assign(pixels, -1);
  out.geometry.position.assign(pixels, glm::vec3(0.0f));
  out.geometry.normal.assign(pixels, glm::vec3(0.0f));
  for (std::size_t p = 0; p < pixels; ++p) {
    const float id = aov.pixels[p * aov.channels.size() + std::size_t(primitive)];
    if (id < 0.0f) continue;
    out.geometry.object[p] = static_cast<std::int32_t>(objectOf.at(static_cast<std::size_t>(id)));
    // The pixel's mean point and normal, the normal turned to face the camera (as shading does).
    const glm::vec3 P = pixel3(aov, p, position);
    glm::vec3 n = pixel3(aov, p, normal);
    if (glm::dot(n, camera.position - P) < 0.0f) n = -n;
    out.geometry.position[p] = P;
    out.geometry.normal[p] = n;
  }
  const std::vector<glm::vec3>& emissions = renderer.emissions();
  for (std::size_t i = 0; i < photos.shots.size(); ++i) {
    const Shot& shot = photos.shots[i];
    const std::size_t s = renderer.lightIndex(fmt::format("shot{}", i));
    const glm::vec3 ambientWeight = renderer.ambient().weight.at(s) * emissions[s];
    std::vector<glm::vec3> direct(pixels, glm::vec3(0.0f)), directPerEmission(pixels, glm::vec3(0.0f)),
        indirect(pixels, glm::vec3(0.0f));
    ConfidenceImage visibility{photos.width, photos.height, std::vector<float>(pixels, 0.0f)};
    for (std::size_t p = 0; p < pixels; ++p) {
      const glm::vec3 rho = pixel3(aov, p, albedo);
      if (out.geometry.object[p] < 0 || glm::any(glm::lessThan(rho, glm::vec3(1e-4f)))) continue;
      // D_s and A hold the albedo of the surface (its current estimate): divided out, they are
      // the light per unit reflectance.
      directPerEmission[p] = transport.direct[s][p] / rho;
      direct[p] = directPerEmission[p] * emissions[s];
      indirect[p] = ambientWeight * glm::vec3(transport.ambient[p]) / rho;
      // V = rendered direct / the unoccluded point-light formula I cos(theta) / (pi d^2) at the
      // pixel's mean point and normal.
      const glm::vec3 n = out.geometry.normal[p];
      const glm::vec3 toLamp = shot.position - out.geometry.position[p];
      const float d2 = glm::dot(toLamp, toLamp);
      const float cosine = glm::dot(n, toLamp) / std::sqrt(d2);
      const float unoccluded = shot.intensity * (shot.color.x + shot.color.y + shot.color.z) / 3.0f * cosine /
                               (glm::pi<float>() * d2);
      const float rendered = (direct[p].x + direct[p].y + direct[p].z) / 3.0f;
      visibility.k[p] = cosine > 1e-3f && unoccluded > 0.0f ? std::clamp(rendered / unoccluded, 0.0f, 1.0f) : 0.0f;
    }
    out.direct.push_back(std::move(direct));
    out.directPerEmission.push_back(std::move(directPerEmission));
    out.emission.push_back(emissions[s]);
    out.indirect.push_back(std::move(indirect));
    out.visibility.push_back(std::move(visibility));
  }
  out.seconds = secondsSince(start);
  return out;
}

void saveRecoveredState(const std::string& dir, const std::string& scenePath, const PhotoSet& photos,
                        const Recovery& recovery, const RecoveryOptions& options) {
  const std::size_t pixels = recovery.reflectance.size();
  render::Transport transport;
  transport.width = recovery.width;
  transport.height = recovery.height;
  transport.ambient.assign(pixels, glm::vec4(0.0f)); // no modelled term: every lamp's indirect is its own
  std::vector<relight::LightRecord> lights;
  for (std::size_t i = 0; i < photos.shots.size(); ++i) {
    const glm::vec3 emission = recovery.emission[i];
    lights.push_back({fmt::format("shot{}", i), "point", emission, glm::vec3(0.0f)});
    transport.lights.push_back(lights.back().name);
    // The indirect light per unit emission. A channel the lamp leaves black, which its photograph
    // cannot measure, takes the mean of its lit ones (a grey bounce), so that recolouring the lamp
    // in `relight` still lights that channel's indirect.
    glm::vec3 perEmission(0.0f);
    int lit = 0;
    for (int c = 0; c < 3; ++c)
      if (emission[c] > 0.0f) {
        perEmission[c] = 1.0f / emission[c];
        ++lit;
      }
    std::vector<glm::vec3> direct(pixels), indirect(pixels);
    for (std::size_t p = 0; p < pixels; ++p) {
      const glm::vec3 R = recovery.reflectance[p];
      glm::vec3 own = recovery.indirect[i][p] * perEmission;
      const float grey = lit > 0 ? (own.x + own.y + own.z) / float(lit) : 0.0f;
      for (int c = 0; c < 3; ++c)
        if (emission[c] <= 0.0f) own[c] = grey;
      direct[p] = recovery.directPerEmission[i][p] * R;
      indirect[p] = own * R;
    }
    transport.direct.push_back(std::move(direct));
    transport.seen.emplace_back(pixels, glm::vec3(0.0f)); // the lamps were not in view
    transport.ownIndirect.push_back(std::move(indirect));
  }
  glm::dvec3 sum(0.0);
  std::size_t seen = 0;
  for (std::size_t p = 0; p < pixels; ++p)
    if (recovery.object[p] >= 0) {
      sum += glm::dvec3(recovery.reflectance[p]);
      ++seen;
    }
  const glm::vec3 average = seen > 0 ? glm::vec3(sum / double(seen)) : glm::vec3(0.0f);
  const nlohmann::json settings = {{"made_by", "obscura recover"},
                                   {"photographs", photos.file},
                                   {"seed", options.seed},
                                   {"direct", "per lamp, one exact shadow ray to each point per sample"},
                                   {"indirect", nameString(kIndirectModelNames, options.indirect)},
                                   {"gather_rays", options.gatherRays},
                                   {"hidden_bounces", options.hiddenBounces}};
  relight::saveState(dir, relight::stateJson(scenePath, options.spp, settings, average, lights, transport), transport);
}

Recovery recoverReflectance(const gpu::Context& context, const scene::Scene& room, const bvh::Bvh& bvh,
                            const scene::Camera& camera, const PhotoSet& photos, const RecoveryOptions& options,
                            const RecoveryLog& log) {
  const auto start = Clock::now();
  const std::size_t objects = room.objects.size();
  // Objects no photograph shows take their material's recovered mean (objectMeans): the model's
  // materials say which surfaces are alike, though not their colours.
  const std::vector<std::uint32_t> objectMaterial = objectMaterials(room);
  const std::vector<bool> oneColour = oneColourObjects(room);
  // An object of a material no photograph shows: the colour the model gives it, where it gives
  // one, or a grey. The grey alone made the paths through the staircase's unseen white surfaces
  // too dark (its never-lit wall's B 0.82-0.92 of the photographs' with paths to 8 vertices), and
  // the per-object cut's brightening of dark places had hidden it (BENCHMARKS).
  const std::vector<std::optional<glm::vec3>> modelColour = modelColours(room, objectMaterial);
  const std::optional<float> unseenGrey =
      options.unseenReflectance > 0.0f ? std::optional<float>(options.unseenReflectance) : std::nullopt;
  Recovery out;
  out.width = photos.width;
  out.height = photos.height;
  for (const auto& o : room.objects) out.objectNames.push_back(o.name);

  // The start: grey materials (the direct light per unit reflectance does not depend on them)
  // and the paper's constant ambient.
  auto stepStart = Clock::now();
  Lighting lighting = traceLighting(context, room, bvh, camera, photos, std::vector<glm::vec3>(objects, glm::vec3(0.5f)),
                                    options);
  // The weighted merge filters confidences along surfaces (confidence_filters.h); the paper's
  // merge in image windows. `lighting`'s geometry is the same object when lighting is traced again.
  const Surfaces pixelSurfaces{&lighting.geometry.object, &lighting.geometry.normal};
  const Surfaces* surfaces = options.merge == MergeModel::Weighted ? &pixelSurfaces : nullptr;
  // The device's rays through the renderer's traversal: the pixels' footprints and the gather's.
  const render::SceneBuffers buffers(context, room, bvh);
  render::GpuRayBatch rays(context, buffers, render::TraceShape::forDevice(context, buffers.traversal()));
  // Which surfaces each pixel's footprint covers (the weighted merge's; pixel_footprint.h): the
  // iterations' object means unmix the pixels that cover several, and the kept merge's take the mix
  // of their surfaces at the end.
  std::optional<PixelFootprints> footprints;
  if (options.merge == MergeModel::Weighted) {
    const auto footprintStart = Clock::now();
    std::size_t nearEdge = 0;
    footprints = traceFootprints(room, rays, camera, photos.width, photos.height, &nearEdge);
    if (log)
      log(fmt::format("recover: footprints ({} pixels near an edge traced at {} x {}): {:.1f} s", nearEdge,
                      PixelFootprints::kGrid, PixelFootprints::kGrid, secondsSince(footprintStart)));
  }
  std::vector<std::vector<glm::vec3>> ambient;
  for (const auto& shot : photos.shots)
    ambient.push_back(constantAmbient(shot.radiance, lighting.geometry.object, options.constantReflectance));
  out.estimates = estimatesWith(photos, lighting, ambient);
  out.indirect = ambient;
  out.confidences = filterConfidences(out.estimates, lighting.visibility, options.filters, surfaces);
  std::vector<std::vector<glm::vec3>> radiance; // the photographs, as the merge and the ratios take them
  for (const auto& shot : photos.shots) radiance.push_back(shot.radiance);
  WeightedMerge merged = mergeShots(radiance, lighting, ambient, out.estimates, out.confidences, options);
  // What the photographs say of the objects none of whose pixels merged (the weighted merge's;
  // the paper's gives them their material's mean as it did).
  const auto photographed = [&](const std::vector<std::vector<glm::vec3>>& indirect) {
    std::vector<std::optional<glm::vec3>> ratios(objects);
    if (options.merge == MergeModel::Weighted)
      ratios = photographedRatios(radiance, lighting.direct, indirect, lighting.geometry.object, objects);
    return ratios;
  };
  std::vector<std::optional<glm::vec3>> ratios = photographed(ambient);
  out.iterations.push_back({0, secondsSince(stepStart), 0.0,
                            objectMeans(merged.reflectance, inverseVariance(merged), lighting.geometry.object, objects,
                                        &objectMaterial, &ratios, unseenGrey, &oneColour, &modelColour)});
  if (log) log(fmt::format("recover: constant ambient (k = {}): {:.1f} s", options.constantReflectance, secondsSince(stepStart)));

  std::unique_ptr<PhotoGather> gather;
  if (options.indirect == IndirectModel::Gather) {
    stepStart = Clock::now();
    const std::uint64_t raysBefore = rays.rays();
    const double deviceMsBefore = rays.gpuMs();
    gather = std::make_unique<PhotoGather>(room, rays, camera, lighting.geometry, photos.shots, options.gatherRays,
                                           options.seed, options.gatherSmoothing, options.hiddenBounces);
    out.gatherSeen = gather->seenFraction();
    out.gatherHidden = gather->hiddenFraction();
    if (log)
      log(fmt::format("recover: gather: {} rays, {:.1f} % seen by the camera, {:.1f} % hidden; {} rays traced on the "
                      "device in {:.1f} s of its time; {:.1f} s",
                      gather->rays(), 100.0 * out.gatherSeen, 100.0 * out.gatherHidden, rays.rays() - raysBefore,
                      (rays.gpuMs() - deviceMsBefore) / 1000.0, secondsSince(stepStart)));
  }
  if (options.indirect != IndirectModel::Constant) {
    std::vector<PhotoGather::Cut> cuts; // per shot
    std::vector<std::vector<float>> modelled; // [shot][pixel] B_i's share resting on its longer paths
    for (std::uint32_t it = 1; it <= options.iterations; ++it) {
      stepStart = Clock::now();
      const std::vector<glm::vec3>& means = out.iterations.back().objectReflectance;
      if (gather) {
        // Paths through hidden surfaces are cut with what the last gather's paths found on each
        // object (photo_gather.h); the first, with the constant estimate's mean indirect light.
        if (cuts.empty())
          for (const auto& b : out.indirect)
            cuts.push_back(PhotoGather::uniformCut(objects, constantAmbient(b, lighting.geometry.object, 1.0f).front()));
        std::vector<PhotoGather::Cut> settled;
        out.indirect = gather->indirect(photos.shots, means, cuts, &settled, &modelled);
        cuts = std::move(settled);
      } else {
        lighting = traceLighting(context, room, bvh, camera, photos, means, options);
        out.indirect = lighting.indirect;
      }
      out.estimates = estimatesWith(photos, lighting, out.indirect);
      out.confidences = filterConfidences(out.estimates, lighting.visibility, options.filters, surfaces);
      WeightedMerge next = mergeShots(radiance, lighting, out.indirect, out.estimates, out.confidences, options,
                                      modelled.empty() ? nullptr : &modelled);
      double sum = 0.0;
      std::size_t n = 0;
      for (std::size_t p = 0; p < next.reflectance.size(); ++p)
        if (next.relativeVariance[p] > 0.0f && merged.relativeVariance[p] > 0.0f) {
          const glm::vec3 d = next.reflectance[p] - merged.reflectance[p];
          sum += glm::dot(d, d) / 3.0;
          ++n;
        }
      merged = std::move(next);
      const double change = n > 0 ? std::sqrt(sum / double(n)) : 0.0;
      ratios = photographed(out.indirect);
      // Each object's pixels as its own reflectance: those whose footprint covers other objects
      // too unmixed with these means (the first means, from the constant ambient, mix as they come).
      std::vector<glm::vec3> own = merged.reflectance;
      std::vector<float> weights = inverseVariance(merged);
      if (footprints) unmixFootprints(*footprints, lighting.geometry.object, means, own, weights);
      std::vector<glm::vec3> nextMeans = objectMeans(own, weights,
                                                     lighting.geometry.object, objects, &objectMaterial, &ratios,
                                                     unseenGrey, &oneColour, &modelColour);
      if (out.iterations.size() >= 2) dampSwings(out.iterations[out.iterations.size() - 2].objectReflectance, means, nextMeans);
      out.iterations.push_back({it, secondsSince(stepStart), change, std::move(nextMeans)});
      if (log) log(fmt::format("recover: iteration {}: RMS change of R {:.5f}, {:.1f} s", it, change, secondsSince(stepStart)));
    }
  }

  // The kept merge smoothed over the whole radius, across an object's faces: on a plain surface
  // what a wide window averages out is the indirect light's error, blotches ~10 px across that a
  // 7 x 7 window's pixels share, and on a curved one (the chairs' tubes) the errors of its faces
  // (classroom 0.0499 -> 0.0333 at radius 32, Cornell box 0.0145 -> 0.0084; BENCHMARKS).
  if (options.merge == MergeModel::Weighted && options.weighted.smoothingRadius > kIterationSmoothingRadius)
    merged.reflectance = smoothMerge(merged, lighting.geometry, options.weighted.smoothingRadius,
                                     options.weighted.agreement, true);

  // Pixels no filtered confidence reaches, where some lamp still lights them (the filters removed
  // them): the merged whole pixels of their own surface nearby (surfaceFill), else on a plain
  // object its mean, else the photos' raw visibilities, less the estimates the outlier test
  // rejects on them; lit by no lamp at all, the
  // object's mean (measured better there than the surface's nearby pixels, themselves lit only
  // indirectly: the classroom's shadow RMSE 0.093 against 0.112).
  std::vector<ConfidenceImage> fillWeights = lighting.visibility;
  if (options.filters.outlier)
    outlierTest(out.estimates, fillWeights, options.filters.outlierConfidence, options.filters.outlierDistance);
  out.visibility = lighting.visibility;
  out.direct = lighting.direct;
  out.directPerEmission = lighting.directPerEmission;
  out.emission = lighting.emission;
  out.object = lighting.geometry.object;
  out.reflectance = merged.reflectance;
  out.confidence = merged.directConfidence;
  out.indirectShots = merged.indirectShots;
  out.relativeVariance = merged.relativeVariance;
  out.filled.assign(merged.reflectance.size(), 0);
  const std::vector<glm::vec3> means = out.iterations.back().objectReflectance;
  // The pixels whose footprint lies on one surface: those fill their surface's.
  const std::vector<bool> whole = footprints ? footprints->wholePixels() : std::vector<bool>();
  for (std::size_t p = 0; p < out.reflectance.size(); ++p) {
    if (out.object[p] < 0) continue;
    if (merged.textureOf(out.object[p]) == SurfaceTexture::Textured) ++out.texturedPixels;
    if (out.confidence[p] > 0.0f) ++out.litPixels;
    else if (out.relativeVariance[p] > 0.0f) ++out.indirectOnlyPixels;
    if (out.relativeVariance[p] > 0.0f) continue;
    glm::vec3 sum(0.0f);
    float weight = 0.0f;
    for (std::size_t i = 0; i < out.estimates.size(); ++i) {
      // An estimate above 1 is the lighting model's failure, not a surface (weighted_merge.h).
      const glm::vec3& r = out.estimates[i][p];
      if (options.merge == MergeModel::Weighted && std::max({r.x, r.y, r.z}) > 1.0f) continue;
      sum += fillWeights[i].k[p] * r;
      weight += fillWeights[i].k[p];
    }
    const bool lamplit = weight > 0.0f;
    const std::optional<glm::vec3> surface =
        lamplit && options.merge == MergeModel::Weighted
            ? surfaceFill(merged, lighting.geometry, p, footprints ? &whole : nullptr)
            : std::nullopt;
    // On a surface judged of one colour, the object's mean rather than the raw estimates the
    // filters rejected: those are single photographs' noise (the classroom's chair frames, thin
    // tubes whose pixels the min filter empties: RMSE 0.113 over 458 px from visibility, 0.03 at
    // the mean). Not where too few of the object's pixels merged to judge it (BENCHMARKS: the
    // hall's black door panel, whose few merged pixels are its edges, mixed with the wall).
    const bool plain = merged.textureOf(out.object[p]) == SurfaceTexture::Plain; // the weighted merge's alone
    if (surface) {
      out.reflectance[p] = *surface;
      out.filled[p] = 3;
      ++out.filledFromSurface;
    } else if (lamplit && !plain) {
      out.reflectance[p] = sum / weight;
      out.filled[p] = 1;
      ++out.filledFromVisibility;
    } else {
      out.reflectance[p] = means[static_cast<std::size_t>(out.object[p])];
      out.filled[p] = 2;
      ++out.filledFromObject;
    }
  }
  out.surfaceReflectance = out.reflectance;
  // Pixels whose footprint covers several surfaces: the mix of those surfaces' reflectances
  // (pixel_footprint.h). The paper's merge keeps its own estimate there.
  if (footprints) {
    out.mixedFromFootprint = mixFootprints(*footprints, out.object, means, out.reflectance);
    if (log) log(fmt::format("recover: {} pixels whose footprint covers several surfaces, mixed from theirs",
                             out.mixedFromFootprint));
  }
  out.seconds = secondsSince(start);
  return out;
}

} // namespace obscura::recover
