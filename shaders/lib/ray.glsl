// ray.glsl — spawning secondary rays without self-intersection.
#ifndef OBSCURA_RAY_GLSL
#define OBSCURA_RAY_GLSL

// Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems,
// ch. 6, 2019: move p off its surface along the geometric normal n (facing the side the new ray
// leaves from) by a few ulps of p's own coordinates, so the offset scales with the magnitude of
// p (a scene 1e5 units from the origin needs a larger step than one at the origin) and no scene
// needs a hand-tuned epsilon. Near the origin, where ulps vanish, a small fixed float step is used.
// OURS: that step and its threshold shrink with a scene smaller than one unit (the paper's
// constants suit unit-sized scenes), so a scene scaled by 1e-4 renders like the original: each
// shader sets gSceneScale = min(1, largest bounding-box extent) from its push constants.
const float kOffsetOriginThreshold = 1.0 / 32.0; // x scene size: below this |coordinate| use the float step
const float kOffsetFloatScale = 1.0 / 65536.0;   // x scene size: float step per unit normal
const float kOffsetIntScale = 256.0;             // ulps per unit normal

float gSceneScale = 1.0;

vec3 offsetRayOrigin(vec3 p, vec3 n) {
  float threshold = kOffsetOriginThreshold * gSceneScale, step = kOffsetFloatScale * gSceneScale;
  ivec3 ofi = ivec3(kOffsetIntScale * n);
  vec3 pi = vec3(intBitsToFloat(floatBitsToInt(p.x) + (p.x < 0.0 ? -ofi.x : ofi.x)),
                 intBitsToFloat(floatBitsToInt(p.y) + (p.y < 0.0 ? -ofi.y : ofi.y)),
                 intBitsToFloat(floatBitsToInt(p.z) + (p.z < 0.0 ? -ofi.z : ofi.z)));
  return vec3(abs(p.x) < threshold ? p.x + step * n.x : pi.x,
              abs(p.y) < threshold ? p.y + step * n.y : pi.y,
              abs(p.z) < threshold ? p.z + step * n.z : pi.z);
}

#endif
