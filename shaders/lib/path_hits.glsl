// path_hits.glsl — the specular paths' lobe hits a frame keeps (kShadeFlagPathHits), so that the
// passes which follow the same paths again need not trace them.
//
// A path is a function of its lobe samples (their own generator in specular.comp) and of what its
// lobe rays hit. The plain specular kernel writes each lobe ray's hit; an added light's gather
// (the per-light variant) and a geometry edit's probe draw the same lobe samples and read the hit
// instead of tracing the ray, so they follow the path the frame followed, vertex for vertex, at
// the cost of one 16-byte load per vertex instead of a closest-hit traversal. A probe tests the
// kept segment up to the kept hit against the changed boxes: if it meets neither the old nor the
// new place of what moved, the edited scene has the same first hit on that ray (lib/probe.glsl).
#ifndef OBSCURA_PATH_HITS_GLSL
#define OBSCURA_PATH_HITS_GLSL

// A variant of the specular kernel (kSpecConstantReplayHits) that takes the kept hits instead of
// tracing: a specialisation, not a run-time flag, so that the traversal of the lobe rays is not
// compiled in (on lavapipe a branch no lane takes still runs at least one pass of its loops).
layout(constant_id = kSpecConstantReplayHits) const bool kReplayHits = false;

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
  if (kProbe) {
    if (h.primitive == kTruncatedHit) gProbeMet = true;
    probeSegment(origin, direction, 0.0, rayHitValid(h) && h.primitive != kInvalidIndex ? h.t : 1.0 / 0.0);
  }
  return h;
}

#endif
