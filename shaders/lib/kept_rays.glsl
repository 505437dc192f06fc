// kept_rays.glsl — the rays a frame keeps (kShadeFlagKeptRays), so that the passes which follow
// the same rays again need neither trace nor draw them: the specular paths' lobe hits and the
// primary hits' shadow rays.
//
// A path is a function of its lobe samples (their own generator in specular.comp) and of what its
// lobe rays hit. The plain specular kernel writes each lobe ray's hit; an added light's gather
// (the per-light variant) and a geometry edit's probe draw the same lobe samples and read the hit
// instead of tracing the ray, so they follow the path the frame followed, vertex for vertex, at
// the cost of one 16-byte load per vertex instead of a closest-hit traversal. A probe tests the
// kept segment up to the kept hit against the changed boxes: if it meets neither the old nor the
// new place of what moved, the edited scene has the same first hit on that ray (lib/probe.glsl).
//
// A shading point's shadow rays are a function of the point and of its light samples, whose
// drawing (light selection over every light's importance, a point on the light by solid angle)
// is what a probe spent most of its time on: the plain shadow and specular kernels keep each ray's
// direction and length, at the primary hit and at every path vertex, and the probes test those
// segments, from the origin the G-buffer or the path's kept hit gives, against the changed boxes.
#ifndef OBSCURA_KEPT_RAYS_GLSL
#define OBSCURA_KEPT_RAYS_GLSL

// A variant of a kernel (kSpecConstantReplayRays) that takes the kept rays instead of tracing or
// drawing them: a specialisation, not a run-time flag, so that the code it skips is not compiled
// in (on lavapipe a branch no lane takes still runs at least one pass of its loops).
layout(constant_id = kSpecConstantReplayRays) const bool kReplayRays = false;

// Where lobe ray `depth` (1 = the one leaving the primary hit) of `pixel`'s sample `s` is kept.
uint pathHitSlot(uint s, uint pixel, uint pixelCount, uint depth) {
  return (s * pixelCount + pixel) * kPathHitsPerSample + depth - 1u;
}

void keepPathHit(uint slot, RayHit h) {
  uint item = h.primitive == kTruncatedHit ? kPathHitTruncated : h.primitive == kInvalidIndex ? kPathHitMiss : h.item;
  pathHits[slot] = uvec4(floatBitsToUint(h.t), floatBitsToUint(h.u), floatBitsToUint(h.v), item);
}

// The kept hit as traceWithBudget returned it (steps: none taken).
RayHit keptPathHit(uint slot) {
  uvec4 k = pathHits[slot];
  RayHit h;
  h.t = uintBitsToFloat(k.x);
  h.u = uintBitsToFloat(k.y);
  h.v = uintBitsToFloat(k.z);
  h.item = k.w;
  h.steps = 0u;
  if (k.w == kPathHitMiss) {
    h.primitive = kInvalidIndex;
    h.item = kInvalidIndex;
  } else if (k.w == kPathHitTruncated) {
    h.primitive = kTruncatedHit;
    h.item = kInvalidIndex;
  } else {
    h.primitive = floatBitsToUint(texelFetch(bvhItems, int(k.w)).w); // the triangle's original index
  }
  return h;
}

// A kept lobe ray in a probing kernel: its segment up to the kept hit (to infinity on a miss)
// tested as traceFollowed tests a traced one; a truncated ray counts as met.
RayHit probedPathHit(uint slot, vec3 origin, vec3 direction) {
  RayHit h = keptPathHit(slot);
  probeFollowedSegment(h, origin, direction, 0.0, 1.0 / 0.0);
  return h;
}

// Where shadow ray `k` of `pixel`'s sample `s` is kept, at its primary hit (`vertex` 0) or at a
// specular path's vertex (1..kPathHitsPerSample): N_s = pc.shadowRays per vertex.
uint keptShadowRaySlot(uint s, uint pixel, uint pixelCount, uint vertex, uint k) {
  return ((s * pixelCount + pixel) * (kPathHitsPerSample + 1u) + vertex) * pc.shadowRays + k;
}

// A probe's test of the `count` kept shadow rays of a shading point whose rays leave from `origin`.
void probeKeptShadowRays(vec3 origin, uint s, uint pixel, uint pixelCount, uint vertex, uint count) {
  for (uint k = 0u; k < count; ++k) {
    const vec4 ray = keptShadowRays[keptShadowRaySlot(s, pixel, pixelCount, vertex, k)];
    if (ray.w > 0.0) probeSegment(origin, ray.xyz, 0.0, ray.w);
  }
}

#endif
