// probe.glsl — a shading pass in probing mode (kShadeFlagProbe): the dirty test of a geometry edit
// that replays a pixel's rays instead of bounding them.
//
// A pixel's rays are a function of its seeds and of what the rays before them hit. If no ray the
// pixel traced meets the boxes an edit changed (its old and new place), every ray found the same
// hit in the edited scene, so the pixel's sums would come out bit for bit the same: it need not be
// retraced. The shading passes run as they would, from the same seeds, but traceWithBudget tests
// the segment against the changed boxes and answers "nothing hit" (a shadow ray then reaches its
// light, an obscurance ray misses). Only a specular path's lobe ray must know its hit to go on: it
// is traced in the edited scene, and its segment up to that hit tested (if that segment meets
// neither box, the old scene had the same first hit on it). Answering "nothing hit" only takes
// fewer branches than the render did where its rays were blocked, and the one loop that depends on
// visibility (directLightFromOne, more rays in a penumbra) runs to its maximum when probing.
#ifndef OBSCURA_PROBE_GLSL
#define OBSCURA_PROBE_GLSL

// A probing kernel: the same shader, specialised (kSpecConstantProbe = 1), so that neither the
// traversal of its probed rays nor the shading after them is compiled in.
layout(constant_id = kSpecConstantProbe) const bool kProbe = false;
bool gProbeMet = false; // one of this invocation's rays met a changed box
vec3 gProbeLo[kMaxChangedBoxes];
vec3 gProbeHi[kMaxChangedBoxes];
bool gProbeUsed[kMaxChangedBoxes];

// Whether the segment origin + t direction, t in [t0, t1] (t1 may be infinite), meets the box:
// the slab test, with an axis the direction runs parallel to tested on the origin alone.
bool segmentMeetsBox(vec3 origin, vec3 direction, float t0, float t1, vec3 lo, vec3 hi) {
  for (int axis = 0; axis < 3; ++axis) {
    float o = origin[axis], d = direction[axis];
    if (d == 0.0) {
      if (o < lo[axis] || o > hi[axis]) return false;
      continue;
    }
    float a = (lo[axis] - o) / d, b = (hi[axis] - o) / d;
    t0 = max(t0, min(a, b));
    t1 = min(t1, max(a, b));
    if (t0 > t1) return false;
  }
  return true;
}

// Tests one segment of a probed ray against every changed box (loaded by beginProbe).
void probeSegment(vec3 origin, vec3 direction, float t0, float t1) {
  for (uint b = 0u; b < kMaxChangedBoxes; ++b)
    if (gProbeUsed[b] && segmentMeetsBox(origin, direction, t0, t1, gProbeLo[b], gProbeHi[b])) gProbeMet = true;
}

#endif
