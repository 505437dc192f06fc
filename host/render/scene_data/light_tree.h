// light_tree.h — the light tree: a binary BVH over the bounded lights (area lights, points, spots)
// that lets the spatial selection choose among many lights by their importance at the shading
// point without weighing each one (shaders/lib/lights.glsl, selectLightFromTree; the layout is
// GpuLightNode's, shaders/shared/host_device.h).
//
// Each node bounds the lights below it as lights.glsl's importance needs them: a bounding sphere,
// a cone of emission directions (axis, theta_o), an emission spread theta_e and the summed power,
// after Conty Estevez & Kulla, "Importance Sampling of Many Lights with Adaptive Tree Splitting"
// (HPG 2018), and pbrt-v4's LightBounds. Splits minimise a surface-area cost weighted by power and
// by the solid-angle measure of the emission cone (the same paper's §4.4, as pbrt-v4's
// BVHLightSampler::EvaluateCost); one light per leaf.
#pragma once
#include <vector>

#include "shared/host_device.h"

namespace obscura::render {

// The tree of `lights` (their selection weights GpuLight.params.y must be set: updateSelection).
// Lights that are unbounded (directional, background) or have no power stay out of the tree;
// the unbounded ones with power are listed after the leaves. Always at least the header row.
std::vector<gpu::GpuLightNode> buildLightTree(const std::vector<gpu::GpuLight>& lights);

// The solid-angle measure of an emission cone of half-angle theta_o widened by theta_e (the
// orientation factor of the split cost; 4 pi for a cone of every direction).
double orientationMeasure(float cosO, float cosE);

} // namespace obscura::render
