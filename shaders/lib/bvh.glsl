// bvh.glsl — BVH2 traversal (closest hit and any hit) over the texel-buffer layout of
// shared/host_device.h. Needs scene_bindings.glsl and intersect.glsl.
//
// ONE loop handles one node or one triangle per pass: lavapipe runs both sides of every branch
// for 8 lanes at once, so separate inner loops for nodes and triangles would cost the sum of the
// lanes' work instead of the maximum (measured 1.7x faster, docs/ARCHITECTURE.md).
#ifndef OBSCURA_BVH_GLSL
#define OBSCURA_BVH_GLSL

struct RayHit {
  float t;
  float u;          // barycentric of v1
  float v;          // barycentric of v2
  uint primitive;   // original triangle index; kInvalidIndex on miss; kTruncatedHit if cut off
  uint triangle;    // index into bvhTriangles (leaf order), valid when hit
  uint steps;       // loop passes used (for tests and statistics)
};

bool rayHitValid(RayHit h) { return h.primitive < kTruncatedHit; }

// Closest hit when anyHit is false (ties in t go to the lower primitive id), else the first hit
// found with t < tmax (occlusion). Stops after kMaxTraversalSteps passes and reports
// kTruncatedHit, well before lavapipe's loop limiter would cut the loop off silently.
RayHit traverseBvh(vec3 origin, vec3 direction, float tmin, float tmax, bool anyHit) {
  WatertightRay wr = prepareWatertightRay(origin, direction);
  vec3 invDir = safeReciprocal(direction);
  RayHit hit;
  hit.t = tmax;
  hit.u = 0.0;
  hit.v = 0.0;
  hit.primitive = kInvalidIndex;
  hit.triangle = kInvalidIndex;
  hit.steps = 0u;

  uint stack[kBvhStackSize];
  uint stackSize = 0u;
  uint current = 0u;          // node index, leaf reference, or kInvalidIndex when done
  uint triNext = 0u, triEnd = 0u;
  bool done = false;
  while (!done) {
    if (hit.steps >= kMaxTraversalSteps) {
      hit.primitive = kTruncatedHit;
      break;
    }
    hit.steps++;
    if (triNext < triEnd) {
      int base = int(triNext * kTexelsPerTriangle);
      vec4 a = texelFetch(bvhTriangles, base);
      vec4 b = texelFetch(bvhTriangles, base + 1);
      vec4 c = texelFetch(bvhTriangles, base + 2);
      float t, u, v;
      if (intersectTriangle(wr, a.xyz, b.xyz, c.xyz, tmin, hit.t, t, u, v)) {
        uint primitive = floatBitsToUint(a.w);
        bool better = anyHit ? t < tmax : (t < hit.t || primitive < hit.primitive);
        if (better) {
          hit.t = t;
          hit.u = u;
          hit.v = v;
          hit.primitive = primitive;
          hit.triangle = triNext;
          if (anyHit) break;
        }
      }
      triNext++;
    } else if (current == kInvalidIndex) {
      done = true;
    } else {
      // Interior node: both children's boxes are stored in it (Aila & Laine 2009).
      int base = int(current * kTexelsPerNode);
      vec4 lo0 = texelFetch(bvhNodes, base);
      vec4 hi0 = texelFetch(bvhNodes, base + 1);
      vec4 lo1 = texelFetch(bvhNodes, base + 2);
      vec4 hi1 = texelFetch(bvhNodes, base + 3);
      uint ref0 = floatBitsToUint(lo0.w), ref1 = floatBitsToUint(hi0.w);
      vec2 s0 = intersectBox(lo0.xyz, hi0.xyz, origin, invDir, tmin, hit.t);
      vec2 s1 = intersectBox(lo1.xyz, hi1.xyz, origin, invDir, tmin, hit.t);
      bool hit0 = s0.x <= s0.y && ref0 != kInvalidIndex;
      bool hit1 = s1.x <= s1.y && ref1 != kInvalidIndex;
      if (hit0 && hit1) {
        bool swapOrder = s1.x < s0.x; // nearer child first
        current = swapOrder ? ref1 : ref0;
        stack[stackSize++] = swapOrder ? ref0 : ref1;
      } else if (hit0) {
        current = ref0;
      } else if (hit1) {
        current = ref1;
      } else {
        current = stackSize > 0u ? stack[--stackSize] : kInvalidIndex;
      }
    }
    // A leaf becomes the pending triangle range in the same pass it is reached.
    if (triNext >= triEnd && current != kInvalidIndex && (current & kLeafFlag) != 0u) {
      triNext = current & kLeafFirstMask;
      triEnd = triNext + ((current >> kLeafCountShift) & kLeafCountMask) + 1u;
      current = stackSize > 0u ? stack[--stackSize] : kInvalidIndex;
    }
  }
  return hit;
}

RayHit traceClosest(vec3 origin, vec3 direction, float tmin, float tmax) {
  return traverseBvh(origin, direction, tmin, tmax, false);
}

// True when something blocks the segment (tmin, tmax). A truncated traversal counts as occluded
// and is reported through status[] by the caller.
RayHit traceAny(vec3 origin, vec3 direction, float tmin, float tmax) {
  return traverseBvh(origin, direction, tmin, tmax, true);
}

#endif
