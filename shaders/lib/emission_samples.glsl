// emission_samples.glsl — camera rays of their own for the emission the camera sees
// (--emission-samples K; obscurances' M_s in primary.comp, the path tracer's camera-ray emission in
// pathtrace.comp).
//
// Where an emitter's edge crosses a pixel, the pixel's seen emission is its covered fraction times
// a radiance far above everything around it: with N primary samples the fraction is estimated
// from N points, and those few pixels can hold most of an image's squared error (the Cornell
// box's ceiling lamp: docs/BENCHMARKS.md). The emission needs no shading, only the hit's material,
// so K cheap rays per primary sample (a closest hit and, on an emitter only, its surface) estimate
// it instead of the primary ray alone: the mean of their emissions is an unbiased estimate of the
// pixel's box-filtered seen emission [SPEC §5], like the primary ray's, with K times the points.
//
// Most pixels see no emitter's edge, and there the K rays buy nothing: with --emission-samples
// auto (the default) only the pixels an edge crosses trace them (emitterEdgeCrossesPixel), the
// rest keep the primary ray's estimate.
// Requires scene_bindings.glsl, bvh.glsl, surface.glsl, material.glsl, camera.glsl, and the
// includer's `uint emitterEdges[]` buffer (one word per pixel) declared before it.
#ifndef OBSCURA_EMISSION_SAMPLES_GLSL
#define OBSCURA_EMISSION_SAMPLES_GLSL

// What a camera ray sees of the lights: the light group (kInvalidIndex: nothing that emits) and
// the radiance, a surface's emission or, for the sky (`sky`), unit radiance the caller scales by
// the sky's E_s.
struct SeenEmitter {
  uint lightGroup;
  vec3 radiance;
  bool sky;
};

// Sub-pixel position of emission ray j of primary sample `sampleIndex`, K per sample: element
// sampleIndex K + j of the pixel's R2 sequence (camera.glsl), so the rays of the first N samples
// are its first N K elements, as well stratified over the pixel as N K primary samples would be.
vec2 emissionSampleOffset(uint sampleIndex, uint j, uint count, vec2 shift) {
  return pixelSampleOffset(sampleIndex * count + j, shift);
}

// The emitter `hit` (a camera ray's closest hit) shows. `skySlot`: the background light's slot
// (>= lightCount: none). A surface's geometry is only rebuilt when its material emits.
SeenEmitter emitterSeen(RayHit hit, vec3 origin, vec3 direction, uint skySlot, uint lightCount) {
  SeenEmitter e = SeenEmitter(kInvalidIndex, vec3(0.0), false);
  if (rayHitValid(hit) && hit.primitive != kInvalidIndex) {
    uint material = floatBitsToUint(triangleShadingAt(hit.primitive).n0.w);
    if (all(equal(materialAt(material).emission.rgb, vec3(0.0)))) return e;
    Surface s = surfaceAt(hit, origin, direction);
    e.lightGroup = s.lightGroup;
    e.radiance = materialEmission(materialAt(s.material), s.uv, s.frontFacing);
  } else if (hit.primitive != kTruncatedHit && skySlot < lightCount) { // a miss, not a truncation
    e.lightGroup = skySlot;
    e.radiance = vec3(1.0);
    e.sky = true;
  }
  return e;
}

// Traces emission ray j of sample `sampleIndex` (K = `count` per sample) through pixel `p`.
SeenEmitter traceEmissionSample(inout StepBudget budget, GpuCamera camera, uvec2 p, vec2 size, uint sampleIndex,
                                uint j, uint count, vec2 shift, uint lightCount) {
  vec2 position = vec2(p) + emissionSampleOffset(sampleIndex, j, count, shift);
  vec3 direction = cameraRayDirection(camera, position, size);
  RayHit hit = traceWithBudget(budget, camera.origin.xyz, direction, 0.0, 1.0 / 0.0, false);
  return emitterSeen(hit, camera.origin.xyz, direction, floatBitsToUint(camera.up.w), lightCount);
}

// The camera rays an edge probe traces: the pixel's four corners.
const uint kEdgeProbeRays = 4u;

// Does an emitter's edge cross pixel `p` [ours]? Camera rays through the pixel's four corners,
// and whether they see different lights (an emitter against a surface that emits nothing, the sky
// against the scene, or two lights): a straight edge through the pixel's inside leaves corners on
// both sides, however close to the border it runs (where a bright emitter's edge is a thirtieth of
// a pixel inside, the primary ray misses it one sample in thirty: one such pixel at 1 spp held a
// Cornell box frame's largest error). An edge exactly on the border may be seen by the corners
// of the pixels on both sides, which then trace the rays for nothing. The corners are fixed
// points, not samples, so the answer does not depend on the rays that estimate the pixel's
// emission, and that estimate stays unbiased either way: a pixel it misses (an emitter smaller
// than a pixel, between its corners) keeps the primary ray's.
bool emitterEdgeCrossesPixel(inout StepBudget budget, GpuCamera camera, uvec2 p, vec2 size, uint lightCount) {
  const uint skySlot = floatBitsToUint(camera.up.w);
  uint seen = kInvalidIndex;
  bool differ = false;
  for (uint c = 0u; c < kEdgeProbeRays; ++c) {
    vec3 direction = cameraRayDirection(camera, vec2(p) + vec2(float(c & 1u), float(c >> 1u)), size);
    RayHit hit = traceWithBudget(budget, camera.origin.xyz, direction, 0.0, 1.0 / 0.0, false);
    uint light = emitterSeen(hit, camera.origin.xyz, direction, skySlot, lightCount).lightGroup;
    differ = differ || (c > 0u && light != seen);
    seen = light;
  }
  return differ;
}

// --emission-samples auto: do pixel `p`'s samples take the emission rays? Probed at its first
// sample (`first`) and kept in emitterEdges[pixel] for the later ones; `probeRays` counts the rays
// the answer traced (none but at the first sample, none without a light: no edge to find).
bool emissionRaysAtEdge(inout StepBudget budget, GpuCamera camera, uvec2 p, vec2 size, uint lightCount, uint pixel,
                        bool first, out uint probeRays) {
  probeRays = 0u;
  if (lightCount == 0u) return false;
  if (!first) return emitterEdges[pixel] != 0u;
  const bool edge = emitterEdgeCrossesPixel(budget, camera, p, size, lightCount);
  emitterEdges[pixel] = edge ? 1u : 0u;
  probeRays = kEdgeProbeRays;
  return edge;
}

#endif
