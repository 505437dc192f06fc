// bvh_stream.glsl — several rays per invocation through ONE traversal loop, each lane taking its
// next ray as soon as its current one is done ("refill"; Aila & Laine, "Understanding the
// Efficiency of Ray Traversal on GPUs", HPG 2009, §4). Needs bvh.glsl, and the including shader
// defines, before including this file:
//   GpuRay streamRay(uint k);          // ray k (< count) of this invocation
//   void streamHit(uint k, RayHit h);  // its result
//
// Why: lavapipe runs 8 lanes in lock-step, so a loop costs its slowest lane's passes. Tracing
// the rays one after the other costs the sum over rays of the slowest lane's passes; here it is
// the slowest lane's sum over its rays, which for incoherent rays is much closer to the mean.
// The price: the ray set-up below runs (masked) on every pass, as lavapipe runs both sides of
// every branch.
//
// The pass is traverseBvh's (bvh.glsl), with its register stack. A ray whose stack would grow
// deeper than the register stack holds is put aside and traced again afterwards by traverseBvh,
// whose second loop has the array stack (rare: exact either way; never with kCompactStack).
#ifndef OBSCURA_BVH_STREAM_GLSL
#define OBSCURA_BVH_STREAM_GLSL

// Traces rays 0 .. count - 1 of this invocation (count <= 64: the rays put aside are a bit mask).
// Returns how many of them ran out of passes (reported as kTruncatedHit).
uint traverseStream(uint count, bool anyHit, uint maxSteps) {
  WatertightRay wr;
  vec3 origin = vec3(0.0), invDir = vec3(0.0);
  uint octant = 0u;
  float tmin = 0.0, tmax = 0.0;
  RayHit hit;
  uvec2 group = uvec2(0u);
  uint triangleBase = 0u, triangleBits = 0u;
  uint queuedBase = 0u, queuedBits = 0u;
  uvec4 s0 = uvec4(0u), s1 = uvec4(0u), s2 = uvec4(0u), s3 = uvec4(0u);
  uint stackSize = 0u;
  uint laneSteps = 0u;    // passes this lane has used, all its rays together
  uvec2 overflowed = uvec2(0u);   // bit k: ray k is traced again by traverseBvh
  uint truncated = 0u;
  uint k = 0u;
  bool needRay = true;
  for (;;) {
    if (needRay) { // the one set-up site
      if (k >= count) break;
      GpuRay ray = streamRay(k);
      origin = ray.origin.xyz;
      tmin = ray.origin.w;
      tmax = ray.direction.w;
      wr = prepareWatertightRay(origin, ray.direction.xyz);
      invDir = safeReciprocal(ray.direction.xyz);
      octant = rayOctant(ray.direction.xyz);
      hit = RayHit(tmax, 0.0, 0.0, kInvalidIndex, kInvalidIndex, 0u);
      group = uvec2(0u, (1u << octant) | (1u << 8));
      triangleBits = 0u;
      queuedBits = 0u;
      stackSize = 0u;
      s0.x = 0u; // the compact stack's "empty"
      needRay = false;
    }
    // Out of passes: this ray ends as truncated, and so will the lane's next ones, without a pass.
    const bool outOfPasses = laneSteps >= maxSteps;
    if (outOfPasses) {
      hit.primitive = kTruncatedHit;
      triangleBits = 0u;
      queuedBits = 0u;
      group.y = 0u;
      stackSize = 0u;
      s0.x = 0u;
    } else {
      laneSteps++;
      hit.steps++;
    }
    PassItems it = fetchPassItems(triangleBase, triangleBits, queuedBase, queuedBits, group, octant);
    bool done = it.onTriangle && testPassTriangle(it, wr, tmin, tmax, anyHit, hit) && anyHit;
    bool overflow = false;
    if (it.onNode && !done) {
      uvec2 children = visitPassNode(it, group, triangleBase, triangleBits, queuedBase, queuedBits, origin, invDir,
                                     octant, tmin, hit.t);
      if ((children.y & 0xFFu) != 0u) {
        if ((group.y & 0xFFu) != 0u) { // the push site
          overflow = registerStackFull(stackSize);
          pushRegisterStack(s0, s1, s2, s3, group);
          stackSize++;
        }
        group = children;
      }
    }
    if ((group.y & 0xFFu) == 0u) {
      if (registerStackEmpty(stackSize, s0)) {
        done = done || triangleBits == 0u;
      } else { // the pop site
        group = popRegisterStack(s0, s1, s2, s3);
        stackSize--;
      }
    }
    if (done || overflow) {
      if (outOfPasses) ++truncated;
      if (overflow) overflowed[k >> 5] |= 1u << (k & 31u);
      else streamHit(k, hit); // the one store site
      ++k;
      needRay = true;
    }
  }
  // The rays put aside, each by the single-ray traversal (its array stack takes any depth),
  // within what is left of the group's passes (lavapipe's limiter counts the group's loops).
  uint used = subgroupMax(laneSteps);
  while (any(notEqual(overflowed, uvec2(0u)))) {
    uint j = overflowed.x != 0u ? uint(findLSB(overflowed.x)) : 32u + uint(findLSB(overflowed.y));
    if (overflowed.x != 0u) overflowed.x &= overflowed.x - 1u;
    else overflowed.y &= overflowed.y - 1u;
    GpuRay ray = streamRay(j);
    RayHit h = traverseBvh(ray.origin.xyz, ray.direction.xyz, ray.origin.w, ray.direction.w, anyHit,
                           used < maxSteps ? maxSteps - used : 0u);
    used += subgroupMax(h.steps);
    if (h.primitive == kTruncatedHit) ++truncated;
    streamHit(j, h);
  }
  return truncated;
}

// The same refill over the binary layout (bvh.glsl, traverseBinary's one loop): a pass visits a
// node or tests a triangle of the lane's current ray, and a lane whose ray is done sets up its
// next one in the same pass site. The array stack takes any depth the host lets through
// (kBinaryStackSize), so no ray is put aside. Returns how many rays ran out of passes.
uint traverseBinaryStream(uint count, bool anyHit, uint maxSteps) {
  const bool cull = kBinaryCullOnPop && !anyHit;
  WatertightRay wr;
  vec3 origin = vec3(0.0), invDir = vec3(0.0);
  float tmin = 0.0, tmax = 0.0;
  RayHit hit;
  uint stack[kBinaryStackSize];
  float stackNear[kBinaryStackSize];
  uint sp = 0u;
  uint ref = 0u;
  uint laneSteps = 0u;
  uint truncated = 0u;
  uint k = 0u;
  bool needRay = true;
  for (;;) {
    if (needRay) { // the one set-up site
      if (k >= count) break;
      GpuRay ray = streamRay(k);
      origin = ray.origin.xyz;
      tmin = ray.origin.w;
      tmax = ray.direction.w;
      wr = prepareWatertightRay(origin, ray.direction.xyz);
      invDir = safeReciprocal(ray.direction.xyz);
      hit = RayHit(tmax, 0.0, 0.0, kInvalidIndex, kInvalidIndex, 0u);
      sp = 0u;
      ref = 0u;
      needRay = false;
    }
    bool done = false;
    uint next = kInvalidIndex;
    if (laneSteps >= maxSteps) { // out of passes: this ray and the lane's next ones end truncated
      hit.primitive = kTruncatedHit;
      done = true;
    } else {
      laneSteps++;
      hit.steps++;
      if (ref == kInvalidIndex) { // a dropped child: only the pop below
      } else if (!isBinaryLeaf(ref)) {
        float farNear;
        uvec2 children = visitBinaryNode(ref, origin, invDir, tmin, hit.t, farNear);
        if (children.y != kInvalidIndex) {
          stack[sp] = children.y;
          if (cull) stackNear[sp] = farNear;
          sp++;
        }
        next = children.x;
      } else {
        done = testBinaryTriangle(ref & kBinaryLeafTexelMask, wr, tmin, tmax, anyHit, hit) && anyHit;
        next = restOfLeaf(ref);
      }
      if (!done && next == kInvalidIndex) {
        if (sp == 0u) {
          done = true;
        } else {
          sp--;
          next = !cull || stackNear[sp] <= hit.t ? stack[sp] : kInvalidIndex;
        }
      }
      ref = next;
    }
    if (done) {
      if (hit.primitive == kTruncatedHit) ++truncated;
      streamHit(k, hit); // the one store site
      ++k;
      needRay = true;
    }
  }
  return truncated;
}

#endif
