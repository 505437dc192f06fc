// bvh.glsl — BVH2 traversal (closest hit and any hit) over the item layout of
// shared/host_device.h. Needs scene_bindings.glsl and intersect.glsl.
//
// Shaped for lavapipe, which runs 8 lanes in lock-step and executes both sides of every branch
// (docs/ARCHITECTURE.md, "lavapipe"):
// - ONE loop handles one node or one triangle per pass, so a group of lanes pays for the maximum
//   of their work, not the sum of separate node and triangle loops;
// - ONE fetch path: every pass fetches the 4 texels of one item, a node or a triangle;
// - one push site and one pop site for the (per-lane, dynamically indexed) stack.
#ifndef OBSCURA_BVH_GLSL
#define OBSCURA_BVH_GLSL

#extension GL_KHR_shader_subgroup_arithmetic : require

#include "probe.glsl"

struct RayHit {
  float t;
  float u;          // barycentric of v1
  float v;          // barycentric of v2
  uint primitive;   // original triangle index; kInvalidIndex on miss; kTruncatedHit if cut off
  uint item;        // item index of the hit triangle in bvhItems, valid when hit
  uint steps;       // loop passes used (for tests and statistics)
};

bool rayHitValid(RayHit h) { return h.primitive < kTruncatedHit; }

// Closest hit when anyHit is false (ties in t go to the lower primitive id), else the first hit
// found with t < tmax (occlusion). Stops after `maxSteps` passes and reports kTruncatedHit:
// lavapipe's loop limiter (65,535 passes for ALL loops of an invocation) would otherwise cut the
// loop off silently. A shader that traces several rays passes each the budget its earlier rays
// left (StepBudget below), so the sum stays under kMaxTraversalSteps.
//
// The stack: on lavapipe a per-lane, dynamically indexed array costs ~40 ns per 8-lane pass even
// where no lane touches it (masked gathers/scatters run anyway), about a third of a pass. So the
// main loop keeps the top kBvhRegisterStack (12) entries in three uvec4 registers (a push or pop
// shifts them: 24 vector selects) and never touches memory. (Measured: 8 entries send too many
// Sponza rays to the slow path, 16 or more cost registers and selects on every pass.) A ray
// whose stack would grow deeper stops
// there and is finished by a second loop with the array stack, restarting from the root with the
// hit found so far (re-testing a triangle never changes the result, so this is exact). That loop
// costs every 8-lane group one (masked) pass when no ray overflowed.
RayHit traverseBvh(vec3 origin, vec3 direction, float tmin, float tmax, bool anyHit, uint maxSteps) {
  WatertightRay wr = prepareWatertightRay(origin, direction);
  vec3 invDir = safeReciprocal(direction);
  RayHit hit;
  hit.t = tmax;
  hit.u = 0.0;
  hit.v = 0.0;
  hit.primitive = kInvalidIndex;
  hit.item = kInvalidIndex;
  hit.steps = 0u;

  uvec4 top0 = uvec4(0u), top1 = uvec4(0u), top2 = uvec4(0u); // top0.x = top; kBvhRegisterStack = 12
  uint stackSize = 0u;
  uint node = 0u;                 // next interior node to visit; kInvalidIndex = pop next
  uint triNext = 0u, triEnd = 0u; // pending triangle items of the current leaf
  bool overflow = false;
  for (;;) {
    if (hit.steps >= maxSteps) {
      hit.primitive = kTruncatedHit;
      break;
    }
    hit.steps++;
    bool onTriangle = triNext < triEnd;
    int base = int((onTriangle ? triNext : node) * kTexelsPerItem);
    vec4 a = texelFetch(bvhItems, base);
    vec4 b = texelFetch(bvhItems, base + 1);
    vec4 c = texelFetch(bvhItems, base + 2);
    vec4 d = texelFetch(bvhItems, base + 3);
    if (onTriangle) {
      float t, u, v;
      if (intersectTriangle(wr, a.xyz, b.xyz, c.xyz, tmin, hit.t, t, u, v)) {
        uint primitive = floatBitsToUint(a.w);
        if (anyHit ? t < tmax : (t < hit.t || primitive < hit.primitive)) {
          hit.t = t;
          hit.u = u;
          hit.v = v;
          hit.primitive = primitive;
          hit.item = triNext;
          if (anyHit) break;
        }
      }
      triNext++;
    } else {
      // Interior node: a/b = child 0 box, c/d = child 1 box, refs in a.w and b.w.
      uint ref0 = floatBitsToUint(a.w), ref1 = floatBitsToUint(b.w);
      vec2 s0 = intersectBox(a.xyz, b.xyz, origin, invDir, tmin, hit.t);
      vec2 s1 = intersectBox(c.xyz, d.xyz, origin, invDir, tmin, hit.t);
      bool hit0 = s0.x <= s0.y && ref0 != kInvalidIndex;
      bool hit1 = s1.x <= s1.y && ref1 != kInvalidIndex;
      bool nearFirst = s0.x <= s1.x;
      node = hit0 ? (hit1 && !nearFirst ? ref1 : ref0) : (hit1 ? ref1 : kInvalidIndex);
      if (hit0 && hit1) { // the push site
        if (stackSize == kBvhRegisterStack) {
          overflow = true; // finished by the second loop
          break;
        }
        top2 = uvec4(top1.w, top2.xyz);
        top1 = uvec4(top0.w, top1.xyz);
        top0 = uvec4(nearFirst ? ref1 : ref0, top0.xyz);
        stackSize++;
      }
    }
    if (triNext >= triEnd) {
      if (node == kInvalidIndex) {
        if (stackSize == 0u) break;
        node = top0.x; // the pop site
        top0 = uvec4(top0.yzw, top1.x);
        top1 = uvec4(top1.yzw, top2.x);
        top2 = uvec4(top2.yzw, 0u);
        stackSize--;
      }
      if ((node & kLeafFlag) != 0u) { // a leaf becomes the pending triangle range
        triNext = node & kLeafFirstMask;
        triEnd = triNext + ((node >> kLeafCountShift) & kLeafCountMask) + 1u;
        node = kInvalidIndex;
      }
    }
  }

  // The second loop repeats the first one's pass with an array stack. Factoring the common pass
  // into a function (with an early return for any hit) measured 15 % slower on lavapipe (Sponza
  // closest hit, ratio to Embree 0.330 -> 0.284), so the body is written twice on purpose.
  // lavapipe's loop limiter counts the passes of both loops of the 8-lane group,
  // which ran the first loop for as many passes as its longest ray: an overflowed ray continues
  // counting from there, so the group stays within kMaxTraversalSteps passes in total.
  uint groupSteps = subgroupMax(hit.steps);
  if (overflow) hit.steps = groupSteps;
  uint stack[kBvhStackSize];
  stackSize = 0u;
  node = 0u;
  triNext = 0u;
  triEnd = 0u;
  while (overflow) {
    if (hit.steps >= maxSteps) {
      hit.primitive = kTruncatedHit;
      break;
    }
    hit.steps++;
    bool onTriangle = triNext < triEnd;
    int base = int((onTriangle ? triNext : node) * kTexelsPerItem);
    vec4 a = texelFetch(bvhItems, base);
    vec4 b = texelFetch(bvhItems, base + 1);
    vec4 c = texelFetch(bvhItems, base + 2);
    vec4 d = texelFetch(bvhItems, base + 3);
    if (onTriangle) {
      float t, u, v;
      if (intersectTriangle(wr, a.xyz, b.xyz, c.xyz, tmin, hit.t, t, u, v)) {
        uint primitive = floatBitsToUint(a.w);
        if (anyHit ? t < tmax : (t < hit.t || primitive < hit.primitive)) {
          hit.t = t;
          hit.u = u;
          hit.v = v;
          hit.primitive = primitive;
          hit.item = triNext;
          if (anyHit) break;
        }
      }
      triNext++;
    } else {
      uint ref0 = floatBitsToUint(a.w), ref1 = floatBitsToUint(b.w);
      vec2 s0 = intersectBox(a.xyz, b.xyz, origin, invDir, tmin, hit.t);
      vec2 s1 = intersectBox(c.xyz, d.xyz, origin, invDir, tmin, hit.t);
      bool hit0 = s0.x <= s0.y && ref0 != kInvalidIndex;
      bool hit1 = s1.x <= s1.y && ref1 != kInvalidIndex;
      bool nearFirst = s0.x <= s1.x;
      node = hit0 ? (hit1 && !nearFirst ? ref1 : ref0) : (hit1 ? ref1 : kInvalidIndex);
      if (hit0 && hit1) stack[stackSize++] = nearFirst ? ref1 : ref0; // the push site
    }
    if (triNext >= triEnd) {
      if (node == kInvalidIndex) {
        if (stackSize == 0u) break;
        node = stack[--stackSize]; // the pop site
      }
      if ((node & kLeafFlag) != 0u) {
        triNext = node & kLeafFirstMask;
        triEnd = triNext + ((node >> kLeafCountShift) & kLeafCountMask) + 1u;
        node = kInvalidIndex;
      }
    }
  }
  return hit;
}

RayHit traceClosest(vec3 origin, vec3 direction, float tmin, float tmax) {
  return traverseBvh(origin, direction, tmin, tmax, false, kMaxTraversalSteps);
}

// Occlusion of the open segment (tmin, tmax). A truncated traversal is reported by the caller
// through status[kStatusTruncated].
RayHit traceAny(vec3 origin, vec3 direction, float tmin, float tmax) {
  return traverseBvh(origin, direction, tmin, tmax, true, kMaxTraversalSteps);
}

// The loop budget of a shader that traces several rays per invocation. lavapipe's limiter counts
// the passes of every loop of an 8-lane group together, including traversals that only some
// lanes run (masked lanes still go round). So the passes are counted per SUBGROUP, in shared
// memory: each traversal adds its group-wide pass count (subgroupMax of its steps), and the next
// one may use what is left of kMaxTraversalSteps. Divergent traversals of different lanes add up,
// as they do in the limiter. A truncated ray is counted once in status[] by the caller.
shared uint subgroupPasses[kWorkgroupSize1D]; // indexed by gl_SubgroupID (>= 1 lane per subgroup)

struct StepBudget {
  bool truncated; // some traversal of this invocation ran out of passes
  uint traced;    // traversals this invocation ran (for ray counts)
};

StepBudget newStepBudget() {
  if (subgroupElect()) subgroupPasses[gl_SubgroupID] = 0u;
  subgroupMemoryBarrierShared();
  return StepBudget(false, 0u);
}

// A probing pass's ray (probe.glsl): tested against the changed boxes, not traced; "nothing hit".
RayHit probedRay(vec3 origin, vec3 direction, float tmin, float tmax) {
  probeSegment(origin, direction, tmin, tmax);
  return RayHit(tmax, 0.0, 0.0, kInvalidIndex, 0u, 0u);
}

// A ray traced through the BVH, its passes counted against the subgroup's budget.
RayHit traceBudgeted(inout StepBudget budget, vec3 origin, vec3 direction, float tmin, float tmax, bool anyHit) {
  uint used = subgroupPasses[gl_SubgroupID];
  uint left = used < kMaxTraversalSteps ? kMaxTraversalSteps - used : 0u;
  RayHit h = traverseBvh(origin, direction, tmin, tmax, anyHit, left);
  uint passes = subgroupMax(h.steps);
  if (subgroupElect()) subgroupPasses[gl_SubgroupID] = used + passes;
  subgroupMemoryBarrierShared();
  if (h.primitive == kTruncatedHit) budget.truncated = true;
  budget.traced++;
  return h;
}

// Every ray of the shading passes: traced, or in a probing kernel (kProbe, a specialisation
// constant, so the other branch is compiled out) only tested against the changed boxes.
RayHit traceWithBudget(inout StepBudget budget, vec3 origin, vec3 direction, float tmin, float tmax, bool anyHit) {
  if (kProbe) return probedRay(origin, direction, tmin, tmax);
  return traceBudgeted(budget, origin, direction, tmin, tmax, anyHit);
}

// A ray whose hit a path needs to go on (a specular lobe sample): traced even when probing, and
// then its segment up to the hit tested (to infinity on a miss; a truncated one counts as met).
RayHit traceFollowed(inout StepBudget budget, vec3 origin, vec3 direction, float tmin, float tmax) {
  RayHit h = traceBudgeted(budget, origin, direction, tmin, tmax, false);
  if (kProbe) {
    if (h.primitive == kTruncatedHit) gProbeMet = true;
    probeSegment(origin, direction, tmin, rayHitValid(h) && h.primitive != kInvalidIndex ? h.t : tmax);
  }
  return h;
}

#endif
