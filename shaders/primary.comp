#version 460
// primary.comp — one camera ray per pixel per dispatch (sample `frame.z` of --spp): traces it,
// writes the G-buffer for later passes, and accumulates the AOVs [RTO §4.1, step 1].
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/scene_bindings.glsl"
#include "lib/intersect.glsl"
#include "lib/bvh.glsl"
#include "lib/surface.glsl"
#include "lib/material.glsl"
#include "lib/rng.glsl"
#include "lib/camera.glsl"
#include "lib/accumulate.glsl"
#include "lib/band.glsl"

layout(local_size_x = kWorkgroupSizeX, local_size_y = kWorkgroupSizeY) in;
layout(push_constant) uniform Push { PrimaryPush pc; };
layout(std430, set = 0, binding = kBindingPrimaryGBuffer) writeonly buffer GBuffer { GBufferTexel gbuffer[]; };
layout(std430, set = 0, binding = kBindingPrimaryAovs) buffer AovBuffer { vec4 aov[]; };
layout(std430, set = 0, binding = kBindingPrimaryLightScales) readonly buffer LightScales { vec4 lightScales[]; };
layout(std430, set = 0, binding = kBindingPrimaryEmissionBasis) buffer EmissionBasis { vec4 emissionBasis[]; };
layout(std430, set = 0, binding = kBindingPrimaryHitBounds) buffer HitBounds { vec4 hitBounds[]; };
layout(std430, set = 0, binding = kBindingPrimaryDirty) readonly buffer DirtyMask { uint dirty[]; };
layout(std430, set = 0, binding = kBindingPrimarySampleCounts) buffer SampleCounts { uint sampleCounts[]; };
layout(std430, set = 0, binding = kBindingPrimaryEmitterEdges) buffer EmitterEdges { uint emitterEdges[]; };
#include "lib/emission_samples.glsl"

// Kernel variants (PrimaryPass picks one per dispatch from its flags): the code a dispatch never
// takes is left out, because on lavapipe it still costs (registers are allocated over the whole
// shader, and both sides of a branch run).
layout(constant_id = kSpecConstantPrimaryAovs) const bool kAovs = false;
layout(constant_id = kSpecConstantEmissionRays) const bool kEmissionRays = false;
layout(constant_id = kSpecConstantPrimaryHitBounds) const bool kHitBounds = true;

void accumulate(uint pixel, uint slot, vec4 value, bool first) {
  uint i = pixel * kAovSlots + slot;
  if (first) OBS_ACCUMULATE_FIRST(aov, i, value) else OBS_ACCUMULATE(aov, i, value)
}

void main() {
  uvec2 size = uvec2(pc.width, pc.height);
  // Every pixel of the band, or (a retrace) the band's dirty list, dispatched indirectly.
  BandPixel bp;
  if ((pc.flags & kPrimaryFlagDirtyOnly) == 0u) {
    bp = bandPixel(gl_GlobalInvocationID.xy, size, uvec2(pc.firstRow, pc.rows));
  } else {
    const uint base = dirtyListBase(size.x * pc.rows), entry = listEntry(), count = dirty[base + kQueueCount];
    bp = listedPixel(entry, count, entry < count ? dirty[base + kQueueHeader + entry] : 0u, size, uvec2(pc.firstRow, pc.rows));
  }
  if (!bp.inside) return;
  uvec2 p = bp.frame;
  uint pixel = bp.index;
  uint sampleIndex = pc.sampleIndex;
  // A farm's part (render --samples A:B) accumulates from sample A of the frame's sequence.
  const uint firstSample = pc.firstSample;
  bool first = sampleIndex == firstSample;
  const uint lightCount = pc.lightCount;
  const bool accumulateSums = (pc.flags & kPrimaryFlagGBufferOnly) == 0u;
  const bool accumulateAovs = kAovs && accumulateSums && (pc.flags & kPrimaryFlagNoAovs) == 0u;
  // --emission-samples K: K > 1 estimates M_s from K rays of their own (lib/emission_samples.glsl).
  const uint emissionSamples = min(pc.flags >> kPrimaryEmissionSamplesShift, kMaxEmissionSamples);

  uint rng = rngSeed(p, 0u, pc.seed); // the shift is per pixel, fixed over samples
  vec2 shift = vec2(rngNext(rng), rngNext(rng));
  vec2 position = vec2(p) + pixelSampleOffset(sampleIndex, shift);
  vec3 origin = pc.camera.origin.xyz;
  vec3 direction = cameraRayDirection(pc.camera, position, vec2(size));

  // One loop budget for the camera ray and the emission rays (the loop limiter, LAVAPIPE.md).
  StepBudget budget = newStepBudget();
  RayHit hit = traceWithBudget(budget, origin, direction, 0.0, 1.0 / 0.0, false);
  if (hit.primitive == kTruncatedHit) atomicAdd(status[kStatusTruncated], 1u);

  GBufferTexel g;
  vec3 seenEmission = vec3(0.0); // the AOV's; the G-buffer does not keep it
  vec3 preview = vec3(0.0);
  uint lightGroup = kInvalidIndex;
  vec3 unitSeen = vec3(0.0);
  if (rayHitValid(hit) && hit.primitive != kInvalidIndex) {
    Surface s = surfaceAt(hit, origin, direction);
    GpuMaterial m = materialAt(s.material);
    vec3 albedo = materialBaseColor(m, s.uv).rgb;
    vec3 emission = materialEmission(m, s.uv, s.frontFacing);
    float depth = distance(origin, s.position);
    g.position = vec4(s.position, depth);
    g.geometricNormal = vec4(s.geometricNormal, uintBitsToFloat(hit.primitive));
    g.shadingNormal = vec4(s.shadingNormal, uintBitsToFloat(s.material));
    g.albedo = vec4(albedo, 1.0);
    seenEmission = emission;
    lightGroup = s.lightGroup;
    if (lightGroup != kInvalidIndex) unitSeen = unitEmission(emission, lightScales[lightGroup].rgb);
    // A light at the eye: enough to see shapes before any lighting pass runs.
    preview = albedo * abs(dot(s.shadingNormal, direction)) + emission;
  } else {
    // The sky, when there is one: unit radiance in the background light's M_s.
    uint sky = floatBitsToUint(pc.camera.up.w);
    if (hit.primitive != kTruncatedHit && sky < lightCount) { // a miss, not a truncation
      lightGroup = sky;
      unitSeen = vec3(1.0);
    }
    g.position = vec4(0.0);
    g.geometricNormal = vec4(0.0, 0.0, 0.0, uintBitsToFloat(kInvalidIndex));
    g.shadingNormal = vec4(0.0, 0.0, 0.0, uintBitsToFloat(kInvalidIndex));
    g.albedo = vec4(0.0);
  }
  gbuffer[pixel] = g;
  if (!accumulateSums) return;
  // Every sum of the pixel restarts at its first sample (a whole frame's, or a dirty pixel's retrace),
  // and so does its count, which is therefore the sample index + 1 - first (a store, not a load and a
  // store): compose divides each pixel by its own.
  sampleCounts[pixel] = sampleIndex + 1u - firstSample;

  // The box of the pixel's hits over its samples, for the dirty pixels of a geometry edit
  // (specular.comp adds its paths' vertices, and w = 1 when one left the scene).
  if (kHitBounds) {
    bool hitSomething = g.albedo.a != 0.0;
    vec4 lo = vec4(hitSomething ? g.position.xyz : vec3(1e30), 0.0);
    vec4 hi = vec4(hitSomething ? g.position.xyz : vec3(-1e30), hitSomething ? 1.0 : 0.0);
    if (!first) {
      lo = vec4(min(lo.xyz, hitBounds[2u * pixel].xyz), max(lo.w, hitBounds[2u * pixel].w));
      hi = vec4(max(hi.xyz, hitBounds[2u * pixel + 1u].xyz), max(hi.w, hitBounds[2u * pixel + 1u].w));
    }
    hitBounds[2u * pixel] = lo;
    hitBounds[2u * pixel + 1u] = hi;
  }

  // M_s: the emission the camera sees, per light at unit emission, so that relighting scales a
  // lamp the camera looks at with its light [SPEC §3]. Each sample adds the mean over its emission
  // rays (the camera ray itself when K <= 1) of their unit emission to the light each one sees;
  // consecutive rays on the same light are summed first.
  // A whole frame's sample 0 follows ObscuranceRenderer::reset(), which has zeroed every light's
  // sum; a dirty pixel's retrace restarts its own here (a store per light per pixel).
  if (first && (pc.flags & kPrimaryFlagDirtyOnly) != 0u)
    for (uint s = 0u; s < lightCount; ++s) OBS_ACCUMULATE_FIRST(emissionBasis, s * bp.count + pixel, vec4(0.0))
  bool ownRays = kEmissionRays && emissionSamples > 1u;
  uint emissionRays = 0u; // traced for the seen emission alone (the status word counts them)
  // Only where an emitter's edge crosses the pixel (--emission-samples auto).
  if (ownRays && (pc.flags & kPrimaryFlagEmissionAtEdges) != 0u)
    ownRays = emissionRaysAtEdge(budget, pc.camera, p, vec2(size), lightCount, pixel, first, emissionRays);
  const uint rays = ownRays ? emissionSamples : 1u;
  if (ownRays) emissionRays += rays;
  if (emissionRays > 0u) atomicAdd(status[kStatusEmissionRays], emissionRays);
  const uint sky = floatBitsToUint(pc.camera.up.w);
  bool emissionTruncated = false;
  uint runLight = kInvalidIndex;
  vec3 run = vec3(0.0);
  // Without emission rays of its own (K <= 1) the loop below adds the camera ray's unit emission
  // once, to its light: the same sum, without the loop.
  if (!kEmissionRays && lightGroup != kInvalidIndex)
    OBS_ACCUMULATE(emissionBasis, lightGroup * bp.count + pixel, vec4(unitSeen, 0.0))
  for (uint j = 0u; kEmissionRays && j <= rays; ++j) {
    uint light = kInvalidIndex;
    vec3 unit = vec3(0.0);
    if (j < rays && !ownRays) {
      light = lightGroup;
      unit = unitSeen;
    } else if (j < rays) {
      SeenEmitter e = traceEmissionSample(budget, pc.camera, p, vec2(size), sampleIndex, j, rays, shift, lightCount);
      light = e.lightGroup;
      if (light != kInvalidIndex) unit = e.sky ? e.radiance : unitEmission(e.radiance, lightScales[light].rgb);
    }
    if (light != runLight || j == rays) {
      if (runLight != kInvalidIndex) OBS_ACCUMULATE(emissionBasis, runLight * bp.count + pixel, vec4(run / float(rays), 0.0))
      runLight = light;
      run = vec3(0.0);
    }
    run += unit;
  }
  if (budget.truncated && hit.primitive != kTruncatedHit) atomicAdd(status[kStatusTruncated], 1u);

  if (!accumulateAovs) return;
  accumulate(pixel, kAovAlbedo, g.albedo, first);
  accumulate(pixel, kAovNormal, vec4(g.shadingNormal.xyz, g.position.w), first);
  accumulate(pixel, kAovPosition, vec4(g.position.xyz, 0.0), first);
  accumulate(pixel, kAovEmission, vec4(seenEmission, 0.0), first);
  accumulate(pixel, kAovPreview, vec4(preview, 0.0), first);
  if (first) OBS_ACCUMULATE_FIRST(aov, pixel * kAovSlots + kAovIds, vec4(g.geometricNormal.w, g.shadingNormal.w, 0.0, 0.0))
}
