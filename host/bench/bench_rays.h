// bench_rays.h — the benchmark ray sets of `obscura bench-rays`, reproducible from a seed so other
// ray tracers can shoot exactly the same rays (`--save-rays` writes them).
//
// (a) closest hit: origin uniform in the scene's bounding box, direction uniform on the sphere,
//     tmin 0, tmax = +inf.
// (b) shadow (any hit): two points p, q uniform in the box; origin p, unit direction (q - p)/|q - p|,
//     tmin 0, tmax = |q - p|.
// Generator: std::mt19937_64(seed); each ray draws, in order, floats u = (x >> 40) * 2^-24 for
// (a) ox oy oz, then z = 1 - 2u, phi = 2 pi u; (b) px py pz qx qy qz.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "shared/host_device.h"
#include "scene/scene.h"

namespace obscura::bench {

std::vector<gpu::GpuRay> closestBenchRays(const scene::Bounds& bounds, std::size_t count, std::uint64_t seed);
std::vector<gpu::GpuRay> shadowBenchRays(const scene::Bounds& bounds, std::size_t count, std::uint64_t seed);

// Binary file: count x 8 little-endian float32 (ox oy oz tmin dx dy dz tmax), i.e. GpuRay[].
void saveRays(const std::string& path, const std::vector<gpu::GpuRay>& rays);

} // namespace obscura::bench
