// remodel.cpp — see remodel.h.
#include "recover/remodel.h"

#include <chrono>

#include "recover/reflectance_recovery.h"
#include "recover/texture_fill.h"

namespace obscura::recover {
namespace {

// Pixels within this many of an uncovered pixel, on the same surface, are synthesized too: the
// recovered reflectance at the removed object's silhouette mixes it with the surface behind.
constexpr int kSilhouetteBand = 2;

} // namespace

RecoveredRoom recoveredRoom(const Recovery& recovery) {
  RecoveredRoom room;
  room.width = recovery.width;
  room.height = recovery.height;
  room.reflectance = recovery.surfaceReflectance; // the edit decides what each footprint covers now
  room.object = recovery.object;
  room.objectReflectance = recovery.iterations.back().objectReflectance;
  room.measured.assign(recovery.reflectance.size(), 0);
  for (std::size_t p = 0; p < recovery.reflectance.size(); ++p)
    room.measured[p] = recovery.filled[p] == 0 && recovery.confidence[p] > 0.0f ? 1 : 0;
  return room;
}

RemodelledFrame renderRemodelled(const gpu::Context& context, const RecoveredRoom& room, const scene::Scene& edited,
                                 const bvh::Bvh& editedBvh, const scene::Camera& camera, const std::vector<Shot>& lamps,
                                 const RemodelOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  // Every object's reflectance: recovered means, then the inserted objects' base colours.
  std::vector<glm::vec3> objectReflectance = room.objectReflectance;
  for (std::size_t o = objectReflectance.size(); o < edited.objects.size(); ++o) {
    const auto& obj = edited.objects[o];
    const glm::vec4 base = obj.triangleCount > 0 ? edited.materials.at(edited.triangleMaterial.at(obj.firstTriangle)).baseColor
                                                 : glm::vec4(0.5f);
    objectReflectance.push_back(glm::vec3(base));
  }
  PhotoSet lighting;
  lighting.width = room.width;
  lighting.height = room.height;
  lighting.shots = lamps;
  RecoveryOptions render;
  render.spp = options.spp;
  render.seed = options.seed;
  const Lighting light = traceLighting(context, edited, editedBvh, camera, lighting, objectReflectance, render);
  const PixelGeometry& view = light.geometry;
  const std::size_t pixels = view.object.size();

  RemodelledFrame out;
  out.width = room.width;
  out.height = room.height;
  out.object = view.object;
  out.direct.assign(pixels, glm::vec3(0.0f));
  out.obscurance.assign(pixels, glm::vec3(0.0f));
  for (std::size_t i = 0; i < lamps.size(); ++i)
    for (std::size_t p = 0; p < pixels; ++p) {
      out.direct[p] += light.direct[i][p];
      out.obscurance[p] += light.indirect[i][p];
    }

  // R: the recovered one where the view still sees what the photographs saw, the inserted
  // objects' own, and holes (uncovered surfaces and their silhouette band) to synthesize.
  const auto original = static_cast<std::int32_t>(room.objectReflectance.size());
  std::vector<std::uint8_t> uncovered(pixels, 0);
  out.reflectance.assign(pixels, glm::vec3(0.0f));
  for (std::size_t p = 0; p < pixels; ++p) {
    const std::int32_t o = view.object[p];
    if (o < 0) continue;
    if (o >= original) out.reflectance[p] = objectReflectance[static_cast<std::size_t>(o)];
    else if (o == room.object[p]) out.reflectance[p] = room.reflectance[p];
    else {
      // Synthesized below; a pixel whose surface has nothing photographed to copy from (a mixed
      // normal at an edge between two planes) keeps its object's mean.
      uncovered[p] = 1;
      out.reflectance[p] = objectReflectance[static_cast<std::size_t>(o)];
    }
  }
  TextureFillInput fill;
  fill.width = room.width;
  fill.height = room.height;
  fill.reflectance = out.reflectance;
  fill.object = view.object;
  fill.normal = view.normal;
  fill.source.assign(pixels, 0);
  fill.hole = uncovered;
  fill.seed = options.seed;
  for (std::size_t p = 0; p < pixels; ++p) fill.source[p] = room.measured[p] && view.object[p] == room.object[p];
  for (int y = 0; y < room.height; ++y)
    for (int x = 0; x < room.width; ++x) {
      const std::size_t p = std::size_t(y) * room.width + x;
      if (!uncovered[p]) continue;
      for (int wy = std::max(0, y - kSilhouetteBand); wy <= std::min(room.height - 1, y + kSilhouetteBand); ++wy)
        for (int wx = std::max(0, x - kSilhouetteBand); wx <= std::min(room.width - 1, x + kSilhouetteBand); ++wx) {
          const std::size_t q = std::size_t(wy) * room.width + wx;
          if (view.object[q] == view.object[p] && view.object[q] < original) fill.hole[q] = 1;
        }
    }
  out.reflectance = fillByTexture(fill);
  out.synthesized = fill.hole;
  for (std::size_t p = 0; p < pixels; ++p) out.synthesizedPixels += fill.hole[p];

  // B by successive gathers of the relit radiance (remodel.h).
  const PhotoGather gather = PhotoGather::onDevice(context, edited, editedBvh, camera, view, lamps, options.gatherRays,
                                                   options.seed, options.gatherSmoothing, options.hiddenBounces);
  std::vector<glm::vec3> lampColour;
  for (const Shot& lamp : lamps) lampColour.push_back(lamp.color);
  out.indirect.assign(pixels, glm::vec3(0.0f));
  std::vector<glm::vec3> radiance(pixels);
  // Paths through hidden surfaces cut as recover cuts them, settling with the bounces.
  PhotoGather::Cut cut = PhotoGather::uniformCut(objectReflectance.size(), glm::vec3(0.0f));
  for (std::uint32_t bounce = 0; bounce <= options.bounces; ++bounce) {
    for (std::size_t p = 0; p < pixels; ++p) radiance[p] = out.reflectance[p] * (out.direct[p] + out.indirect[p]);
    if (bounce == options.bounces) break;
    PhotoGather::Cut settled;
    out.indirect = gather.gather(radiance, lampColour, objectReflectance, cut, &settled);
    cut = std::move(settled);
  }
  out.radiance = std::move(radiance);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

} // namespace obscura::recover
