// ray.glsl — spawning secondary rays without self-intersection.
#ifndef OBSCURA_RAY_GLSL
#define OBSCURA_RAY_GLSL

// Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems,
// ch. 6, 2019: move p off its surface along the geometric normal n (facing the side the new ray
// leaves from) by a few ulps of p's own coordinates, so the offset scales with the magnitude of
// p (a scene 1e5 units from the origin needs a larger step than one at the origin) and no scene
// needs a hand-tuned epsilon. Near the origin, where ulps vanish, a small fixed float step is used.
const float kOffsetOriginThreshold = 1.0 / 32.0; // below this |coordinate| use the float step
const float kOffsetFloatScale = 1.0 / 65536.0;   // float step per unit normal
const float kOffsetIntScale = 256.0;             // ulps per unit normal

vec3 offsetRayOrigin(vec3 p, vec3 n) {
  ivec3 ofi = ivec3(kOffsetIntScale * n);
  vec3 pi = vec3(intBitsToFloat(floatBitsToInt(p.x) + (p.x < 0.0 ? -ofi.x : ofi.x)),
                 intBitsToFloat(floatBitsToInt(p.y) + (p.y < 0.0 ? -ofi.y : ofi.y)),
                 intBitsToFloat(floatBitsToInt(p.z) + (p.z < 0.0 ? -ofi.z : ofi.z)));
  return vec3(abs(p.x) < kOffsetOriginThreshold ? p.x + kOffsetFloatScale * n.x : pi.x,
              abs(p.y) < kOffsetOriginThreshold ? p.y + kOffsetFloatScale * n.y : pi.y,
              abs(p.z) < kOffsetOriginThreshold ? p.z + kOffsetFloatScale * n.z : pi.z);
}

#endif
