// bvh.glsl — wide-BVH traversal (closest hit and any hit) over the texel layout of
// shared/host_device.h: 8-wide nodes with 8-bit quantised child boxes (Ylitie, Karras & Laine,
// "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs", HPG 2017). Needs
// scene_bindings.glsl and intersect.glsl. The CPU twin is host/bvh/cpu_traverse.cpp.
//
// Shaped for lavapipe, which runs 8 lanes in lock-step and executes both sides of every branch
// (docs/ARCHITECTURE.md, "lavapipe"):
// - ONE loop; each pass tests one triangle of the current triangle group AND visits one node of
//   the current node group, since a lane pays for both halves of the pass anyway;
// - a node group is the paper's compact stack entry: the node index of a wide node's first
//   interior child, and a mask of its interior children still to visit (in octant order) with
//   the node's interior mask, which turns a child's slot into its node index;
// - one push site and one pop site for the stack.
#ifndef OBSCURA_BVH_GLSL
#define OBSCURA_BVH_GLSL

#extension GL_KHR_shader_subgroup_arithmetic : require

#include "probe.glsl"

// Texel i of the BVH's items (scene_bindings.glsl: nodes, then triangles). A kernel that defines
// OBS_BVH_ITEMS_STORAGE_BINDING (trace.comp) also sees the same buffer as an SSBO there and reads
// it that way where specialised with kSpecConstantBvhItemsFromStorage: lavapipe gathers a texel
// per lane as one vector, a GPU may serve the two paths from different caches.
#ifdef OBS_BVH_ITEMS_STORAGE_BINDING
layout(std430, set = 0, binding = OBS_BVH_ITEMS_STORAGE_BINDING) readonly buffer BvhItemStorage { vec4 bvhItemStorage[]; };
layout(constant_id = kSpecConstantBvhItemsFromStorage) const bool kBvhItemsFromStorage = false;
vec4 bvhItem(int i) { return kBvhItemsFromStorage ? bvhItemStorage[i] : texelFetch(bvhItems, i); }
#else
vec4 bvhItem(int i) { return texelFetch(bvhItems, i); }
#endif

struct RayHit {
  float t;
  float u;          // barycentric of v1
  float v;          // barycentric of v2
  uint primitive;   // original triangle index; kInvalidIndex on miss; kTruncatedHit if cut off
  uint item;        // texel of the hit triangle's v0 in bvhItems (triangleTexel), valid when hit
  uint steps;       // loop passes used (for tests and statistics)
};

bool rayHitValid(RayHit h) { return h.primitive < kTruncatedHit; }

// The texel of the hit triangle's first vertex; v1 and v2 follow it.
int triangleTexel(RayHit hit) { return int(hit.item); }

// Bits i of the 4 slots 4h..4h+3 (h: which word of each pair) whose decoded boxes the ray meets
// within [tmin, tmax]. `nearWords` / `farWords`: per axis, the q word of the planes the ray
// enters / leaves through (lo or hi, picked by the direction's sign, so an empty slot's
// all-zero point box at the origin is just a box; empty slots are masked by the caller).
// plane = fma(q, 2^e, origin) is exact to what the host evaluated when it rounded the boxes
// outward (host/bvh/wide_node.cpp); the slab test after it is the robust one of intersectBox.
uint hitQuad(uvec3 nearWords, uvec3 farWords, vec3 nodeOrigin, vec3 scale, vec3 rayOrigin, vec3 invDir,
             float tmin, float tmax) {
  const uvec4 kShift = uvec4(0u, 8u, 16u, 24u);
  precise vec4 nx = fma(vec4(ivec4((uvec4(nearWords.x) >> kShift) & 0xFFu)), vec4(scale.x), vec4(nodeOrigin.x));
  precise vec4 ny = fma(vec4(ivec4((uvec4(nearWords.y) >> kShift) & 0xFFu)), vec4(scale.y), vec4(nodeOrigin.y));
  precise vec4 nz = fma(vec4(ivec4((uvec4(nearWords.z) >> kShift) & 0xFFu)), vec4(scale.z), vec4(nodeOrigin.z));
  precise vec4 fx = fma(vec4(ivec4((uvec4(farWords.x) >> kShift) & 0xFFu)), vec4(scale.x), vec4(nodeOrigin.x));
  precise vec4 fy = fma(vec4(ivec4((uvec4(farWords.y) >> kShift) & 0xFFu)), vec4(scale.y), vec4(nodeOrigin.y));
  precise vec4 fz = fma(vec4(ivec4((uvec4(farWords.z) >> kShift) & 0xFFu)), vec4(scale.z), vec4(nodeOrigin.z));
  precise vec4 tNear = max(max((nx - rayOrigin.x) * invDir.x, (ny - rayOrigin.y) * invDir.y),
                           max((nz - rayOrigin.z) * invDir.z, vec4(tmin)));
  precise vec4 tFar = min(min((fx - rayOrigin.x) * invDir.x, (fy - rayOrigin.y) * invDir.y),
                          min((fz - rayOrigin.z) * invDir.z, vec4(tmax))) * kBoxFarScale;
  bvec4 h = lessThanEqual(tNear, tFar);
  return (h.x ? 1u : 0u) | (h.y ? 2u : 0u) | (h.z ? 4u : 0u) | (h.w ? 8u : 0u);
}

// The octant of a direction: bit k set where its component k is negative, as safeReciprocal picks
// the sign (so the near plane of axis k is the box's hi side).
uint rayOctant(vec3 direction) {
  bvec3 negative = lessThan(direction, vec3(0.0));
  return (negative.x ? 1u : 0u) | (negative.y ? 2u : 0u) | (negative.z ? 4u : 0u);
}

// Moves bit s of an 8-bit slot mask to bit s ^ octant: the order in which a ray of that octant
// visits the slots (host_device.h: slot bit k = the + side of axis k).
uint slotsToVisitOrder(uint m, uint octant) {
  m = (octant & 1u) != 0u ? ((m & 0x55u) << 1) | ((m >> 1) & 0x55u) : m;
  m = (octant & 2u) != 0u ? ((m & 0x33u) << 2) | ((m >> 2) & 0x33u) : m;
  m = (octant & 4u) != 0u ? ((m & 0x0Fu) << 4) | ((m >> 4) & 0x0Fu) : m;
  return m;
}

// What one node visit yields: the leaf triangles hit (a triangle group) and the interior
// children hit (a node group).
struct NodeVisit {
  uint triangleBase;  // texel of the node's first leaf triangle
  uint triangleBits;  // bit i: test the triangle at triangleBase + 3 i
  uvec2 group;        // x: node index of the first interior child; y: pending (visit order) | interior mask << 8
};

NodeVisit visitNode(vec4 n0, vec4 n1, vec4 n2, vec4 n3, vec4 n4, vec3 rayOrigin, vec3 invDir, uint octant,
                    float tmin, float tmax) {
  // The direction's signs from its octant, not carried: every live value of a traversal loop is a
  // register per lane on lavapipe.
  bvec3 negative = notEqual(uvec3(octant) & uvec3(1u, 2u, 4u), uvec3(0u));
  uint bits = floatBitsToUint(n0.w);
  vec3 scale = uintBitsToFloat(uvec3(bits & 0xFFu, (bits >> 8) & 0xFFu, (bits >> 16) & 0xFFu) << 23);
  uint imask = bits >> 24;
  uvec4 refs = floatBitsToUint(n1);
  // Per axis: .xy = the q words of the planes the ray enters through, .zw = those it leaves by.
  uvec4 qx = floatBitsToUint(n2), qy = floatBitsToUint(n3), qz = floatBitsToUint(n4);
  qx = negative.x ? qx.zwxy : qx;
  qy = negative.y ? qy.zwxy : qy;
  qz = negative.z ? qz.zwxy : qz;
  uint slots = hitQuad(uvec3(qx.x, qy.x, qz.x), uvec3(qx.z, qy.z, qz.z), n0.xyz, scale, rayOrigin, invDir, tmin, tmax) |
               (hitQuad(uvec3(qx.y, qy.y, qz.y), uvec3(qx.w, qy.w, qz.w), n0.xyz, scale, rayOrigin, invDir, tmin, tmax) << 4);
  // Leaf slots: meta = count | offset << 2 gives the triangles' bits; interior and empty slots
  // (count 0) give none.
  const uvec4 kShift = uvec4(0u, 8u, 16u, 24u);
  uvec4 m0 = (uvec4(refs.z) >> kShift) & 0xFFu, m1 = (uvec4(refs.w) >> kShift) & 0xFFu;
  uvec4 b0 = ((uvec4(1u) << (m0 & 3u)) - 1u) << ((m0 >> 2) & 31u);
  uvec4 b1 = ((uvec4(1u) << (m1 & 3u)) - 1u) << ((m1 >> 2) & 31u);
  uvec4 lo = uvec4(1u, 2u, 4u, 8u);
  b0 = mix(uvec4(0u), b0, notEqual(uvec4(slots) & lo, uvec4(0u)));
  b1 = mix(uvec4(0u), b1, notEqual(uvec4(slots) & (lo << 4), uvec4(0u)));
  uvec4 b = b0 | b1;
  NodeVisit v;
  v.triangleBase = refs.y;
  v.triangleBits = (b.x | b.y) | (b.z | b.w);
  v.group = uvec2(refs.x, slotsToVisitOrder(slots & imask, octant) | (imask << 8));
  return v;
}

// Bits set in an 8-bit value, by SWAR additions: lavapipe (Mesa 22.3) does not enable the
// CPU's vector popcount, and bitCount() measured slower.
uint bitCount8(uint x) {
  x = x - ((x >> 1) & 0x55u);
  x = (x & 0x33u) + ((x >> 2) & 0x33u);
  return (x + (x >> 4)) & 0x0Fu;
}

// The node index of the next child of a group (its lowest pending bit), and that bit.
uint groupChild(uvec2 group, uint octant, out uint bit) {
  uint key = uint(findLSB(group.y & 0xFFu));
  bit = 1u << key;
  uint slot = key ^ octant;
  return group.x + bitCount8((group.y >> 8) & ((1u << slot) - 1u));
}

// What one traversal pass works on: the next triangle of the triangle group (which moves on, the
// queued group taking its place when it empties) and the next child of the node group, both
// fetched. A lane with no triangle or no node fetches texel 0 (lavapipe runs both halves anyway).
// Shared by every traversal loop (here and in bvh_stream.glsl), so they cannot drift apart.
struct PassItems {
  bool onTriangle;
  uint triangle; // texel of the triangle's v0
  vec4 p0, p1, p2;
  bool onNode;
  uint bit;      // the node's pending bit in group.y
  vec4 n0, n1, n2, n3, n4;
};

PassItems fetchPassItems(inout uint triangleBase, inout uint triangleBits, inout uint queuedBase,
                         inout uint queuedBits, uvec2 group, uint octant) {
  PassItems it;
  it.onTriangle = triangleBits != 0u;
  it.triangle = triangleBase + kTexelsPerTriangle * uint(findLSB(triangleBits));
  triangleBits &= triangleBits - 1u;
  if (triangleBits == 0u) { // the queued triangle group moves up
    triangleBase = queuedBase;
    triangleBits = queuedBits;
    queuedBits = 0u;
  }
  it.onNode = (group.y & 0xFFu) != 0u && queuedBits == 0u;
  uint node = groupChild(group, octant, it.bit);
  int tb = it.onTriangle ? int(it.triangle) : 0;
  it.p0 = bvhItem(tb);
  it.p1 = bvhItem(tb + 1);
  it.p2 = bvhItem(tb + 2);
  int nb = it.onNode ? int(node * kTexelsPerNode) : 0;
  it.n0 = bvhItem(nb);
  it.n1 = bvhItem(nb + 1);
  it.n2 = bvhItem(nb + 2);
  it.n3 = bvhItem(nb + 3);
  it.n4 = bvhItem(nb + 4);
  return it;
}

// The pass's triangle test: true when it found a nearer hit (closest) or any hit within tmax
// (anyHit), which `hit` then holds; an any-hit ray is done there.
// The triangle test of every traversal loop: the triangle (p0, p1, p2) at texel `item`.
bool testTriangle(vec4 p0, vec4 p1, vec4 p2, uint item, WatertightRay wr, float tmin, float tmax, bool anyHit,
                  inout RayHit hit) {
  float t, u, v;
  if (!intersectTriangle(wr, p0.xyz, p1.xyz, p2.xyz, tmin, hit.t, t, u, v)) return false;
  uint primitive = floatBitsToUint(p0.w);
  if (!(anyHit ? t < tmax : (t < hit.t || primitive < hit.primitive))) return false;
  hit.t = t;
  hit.u = u;
  hit.v = v;
  hit.primitive = primitive;
  hit.item = item;
  return true;
}

bool testPassTriangle(PassItems it, WatertightRay wr, float tmin, float tmax, bool anyHit, inout RayHit hit) {
  return testTriangle(it.p0, it.p1, it.p2, it.triangle, wr, tmin, tmax, anyHit, hit);
}

// The pass's node visit: the node leaves the node group, and its leaf triangles hit become the
// triangle group (or the queued one behind it). Returns the node group of its interior children
// hit (none where y & 0xFF is 0); pushing what is left of `group` is the caller's (its stack).
uvec2 visitPassNode(PassItems it, inout uvec2 group, inout uint triangleBase, inout uint triangleBits,
                    inout uint queuedBase, inout uint queuedBits, vec3 origin, vec3 invDir, uint octant,
                    float tmin, float tmax) {
  group.y &= ~it.bit;
  NodeVisit visit = visitNode(it.n0, it.n1, it.n2, it.n3, it.n4, origin, invDir, octant, tmin, tmax);
  if (triangleBits == 0u) {
    triangleBase = visit.triangleBase;
    triangleBits = visit.triangleBits;
  } else {
    queuedBase = visit.triangleBase;
    queuedBits = visit.triangleBits;
  }
  return visit.group;
}

// A kernel specialised for BVHs within the compact stack's limits (host_device.h,
// kSpecConstantCompactStack): its register stack of kCompactStackVectors uvec4 cannot overflow,
// so traverseBvh has no second loop. The default (0) is the general kernel, right for every BVH.
layout(constant_id = kSpecConstantCompactStack) const uint kCompactStackVectors = 0u;
const bool kCompactStack = kCompactStackVectors > 0u;

// The register stack: entries e0 (top) .. e7 as (s0.xy, s0.zw, s1.xy, ..., s3.zw), or compact,
// e0 .. e15 as s0.x .. s3.w, each entry packed as node index << 16 | group.y (pending and
// interior masks, 16 bits), of which a kernel keeps the first kCompactStackVectors (the others
// are never written, and the compiler drops them). A push or a pop shifts them all (vector
// selects; an indexed array would be a per-lane gather on lavapipe).
void pushRegisterStack(inout uvec4 s0, inout uvec4 s1, inout uvec4 s2, inout uvec4 s3, uvec2 entry) {
  if (kCompactStack) {
    if (kCompactStackVectors > 3u) s3 = uvec4(s2.w, s3.xyz);
    if (kCompactStackVectors > 2u) s2 = uvec4(s1.w, s2.xyz);
    if (kCompactStackVectors > 1u) s1 = uvec4(s0.w, s1.xyz);
    s0 = uvec4((entry.x << 16) | entry.y, s0.xyz);
  } else {
    s3 = uvec4(s2.zw, s3.xy);
    s2 = uvec4(s1.zw, s2.xy);
    s1 = uvec4(s0.zw, s1.xy);
    s0 = uvec4(entry, s0.xy);
  }
}

// Whether the register stack is empty: stackSize entries, or, compact, a zero top entry (an entry
// is never 0, its pending mask being non-empty; a pop shifts in zeros), which needs no counter.
bool registerStackEmpty(uint stackSize, uvec4 s0) {
  return kCompactStack ? s0.x == 0u : stackSize == 0u;
}

// Whether a push would overflow the register stack (never where kCompactStack).
bool registerStackFull(uint stackSize) {
  return !kCompactStack && stackSize == kBvhRegisterStack;
}

uvec2 popRegisterStack(inout uvec4 s0, inout uvec4 s1, inout uvec4 s2, inout uvec4 s3) {
  if (kCompactStack) {
    uint top = s0.x;
    s0 = uvec4(s0.yzw, kCompactStackVectors > 1u ? s1.x : 0u);
    if (kCompactStackVectors > 1u) s1 = uvec4(s1.yzw, kCompactStackVectors > 2u ? s2.x : 0u);
    if (kCompactStackVectors > 2u) s2 = uvec4(s2.yzw, kCompactStackVectors > 3u ? s3.x : 0u);
    if (kCompactStackVectors > 3u) s3 = uvec4(s3.yzw, 0u);
    return uvec2(top >> 16, top & 0xFFFFu);
  }
  uvec2 top = s0.xy;
  s0 = uvec4(s0.zw, s1.xy);
  s1 = uvec4(s1.zw, s2.xy);
  s2 = uvec4(s2.zw, s3.xy);
  s3 = uvec4(s3.zw, 0u, 0u);
  return top;
}

// ---- The binary layout (kBvhLayoutBinary, shared/host_device.h), for GPUs: a node holds both
// children's exact boxes, so one fetch of 64 bytes decides both (Aila & Laine, "Understanding the
// Efficiency of Ray Traversal on GPUs", HPG 2009), the nearer child is visited first and the
// other pushed on a per-invocation array of kBinaryStackSize (which the host keeps deeper trees
// from: render/scene_data/bvh_layout.cpp). The CPU twin is host/bvh/binary_layout.cpp.
layout(constant_id = kSpecConstantBvhLayout) const uint kBvhLayout = kBvhLayoutWide;
const bool kBinaryLayout = kBvhLayout == kBvhLayoutBinary;
// The binary loop's shape (kSpecConstantBinaryLoop): false, ONE loop whose pass visits a node or
// tests a triangle, so that every pass is counted against lavapipe's loop limiter exactly as the
// wide loop's are; true, Aila & Laine's while-while (a loop over nodes until a leaf, then one over
// the leaf's triangles, inside an outer loop), for GPUs, which have no loop limiter: its step
// count bounds each lane's passes, not the passes of lavapipe's 8-lane group.
layout(constant_id = kSpecConstantBinaryLoop) const bool kBinaryWhileWhile = false;
// Where on, a closest-hit ray keeps each pushed child's entry distance beside it and drops the
// child when it is popped beyond the hit found since, instead of fetching its node to find that
// out (kSpecConstantBinaryCullOnPop). Off by default: on an H200 it was 2-3 % slower (the second
// array's stores cost more than the node fetches saved; docs/BENCHMARKS.md); bench-rays
// --cull-on-pop measures it.
layout(constant_id = kSpecConstantBinaryCullOnPop) const bool kBinaryCullOnPop = false;

// One node: x = the child to visit next (the nearer one met), y = the other one met, to push;
// kInvalidIndex where none. `farNear` gets the pushed child's entry distance.
// An absent child's box is never met.
uvec2 visitBinaryNode(uint node, vec3 origin, vec3 invDir, float tmin, float tmax, out float farNear) {
  int b = int(node * kTexelsPerBinaryNode);
  vec4 leftLo = bvhItem(b), leftHi = bvhItem(b + 1), rightLo = bvhItem(b + 2), rightHi = bvhItem(b + 3);
  vec2 l = intersectBox(leftLo.xyz, leftHi.xyz, origin, invDir, tmin, tmax);
  vec2 r = intersectBox(rightLo.xyz, rightHi.xyz, origin, invDir, tmin, tmax);
  bool hitL = l.x <= l.y, hitR = r.x <= r.y;
  uint left = floatBitsToUint(leftLo.w), right = floatBitsToUint(leftHi.w);
  farNear = max(l.x, r.x);
  if (hitL && hitR) return r.x < l.x ? uvec2(right, left) : uvec2(left, right);
  if (hitL) return uvec2(left, kInvalidIndex);
  if (hitR) return uvec2(right, kInvalidIndex);
  return uvec2(kInvalidIndex);
}

bool isBinaryLeaf(uint ref) { return (ref & kBinaryLeafBit) != 0u; }

// The rest of leaf `ref` once its first triangle is tested: the same leaf one triangle shorter,
// or kInvalidIndex where that was its last (the one-loop traversals test one triangle a pass).
uint restOfLeaf(uint ref) {
  uint left = ((ref >> kBinaryLeafCountShift) & 7u) - 1u;
  return left == 0u ? kInvalidIndex
                    : kBinaryLeafBit | (left << kBinaryLeafCountShift) | ((ref & kBinaryLeafTexelMask) + kTexelsPerTriangle);
}

// The triangle at `texel`, tested as every loop tests one.
bool testBinaryTriangle(uint texel, WatertightRay wr, float tmin, float tmax, bool anyHit, inout RayHit hit) {
  int i = int(texel);
  return testTriangle(bvhItem(i), bvhItem(i + 1), bvhItem(i + 2), texel, wr, tmin, tmax, anyHit, hit);
}

// Same contract as traverseBvh below (the wide loop): closest hit or the first hit, cut off after
// `maxSteps` passes and reported as kTruncatedHit.
RayHit traverseBinary(vec3 origin, vec3 direction, float tmin, float tmax, bool anyHit, uint maxSteps) {
  WatertightRay wr = prepareWatertightRay(origin, direction);
  vec3 invDir = safeReciprocal(direction);
  RayHit hit = RayHit(tmax, 0.0, 0.0, kInvalidIndex, kInvalidIndex, 0u);
  const bool cull = kBinaryCullOnPop && !anyHit;
  uint stack[kBinaryStackSize];
  float stackNear[kBinaryStackSize]; // written and read only where `cull`
  uint sp = 0u;
  uint ref = 0u; // the root
  if (kBinaryWhileWhile) {
    for (;;) {
      while (!isBinaryLeaf(ref)) {
        if (hit.steps >= maxSteps) {
          hit.primitive = kTruncatedHit;
          return hit;
        }
        hit.steps++;
        float farNear;
        uvec2 next = visitBinaryNode(ref, origin, invDir, tmin, hit.t, farNear);
        if (next.y != kInvalidIndex) {
          stack[sp] = next.y;
          if (cull) stackNear[sp] = farNear;
          sp++;
        }
        ref = next.x;
        // Popped until a child still nearer than the hit (every child where not `cull`).
        while (ref == kInvalidIndex && sp > 0u) {
          sp--;
          if (!cull || stackNear[sp] <= hit.t) ref = stack[sp];
        }
        if (ref == kInvalidIndex) return hit;
      }
      uint first = ref & kBinaryLeafTexelMask;
      uint end = first + kTexelsPerTriangle * ((ref >> kBinaryLeafCountShift) & 7u);
      for (uint texel = first; texel < end; texel += kTexelsPerTriangle) {
        if (hit.steps >= maxSteps) {
          hit.primitive = kTruncatedHit;
          return hit;
        }
        hit.steps++;
        if (testBinaryTriangle(texel, wr, tmin, tmax, anyHit, hit) && anyHit) return hit;
      }
      ref = kInvalidIndex;
      while (ref == kInvalidIndex && sp > 0u) {
        sp--;
        if (!cull || stackNear[sp] <= hit.t) ref = stack[sp];
      }
      if (ref == kInvalidIndex) return hit;
    }
  }
  // One loop: a pass visits a node, or tests the first triangle of a leaf and leaves the rest of
  // the leaf (a leaf reference one triangle shorter) for the next pass. A pop that meets a child
  // beyond the hit drops it and pops again at the next pass (no inner loop: every pass counted).
  for (;;) {
    if (hit.steps >= maxSteps) {
      hit.primitive = kTruncatedHit;
      break;
    }
    hit.steps++;
    uint next = kInvalidIndex;
    if (ref == kInvalidIndex) { // a dropped child: nothing this pass but the pop below
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
      if (testBinaryTriangle(ref & kBinaryLeafTexelMask, wr, tmin, tmax, anyHit, hit) && anyHit) break;
      next = restOfLeaf(ref);
    }
    if (next == kInvalidIndex) {
      if (sp == 0u) break;
      sp--;
      next = !cull || stackNear[sp] <= hit.t ? stack[sp] : kInvalidIndex;
    }
    ref = next;
  }
  return hit;
}

// Closest hit when anyHit is false (ties in t go to the lower primitive id), else the first hit
// found with t < tmax (occlusion). Stops after `maxSteps` passes and reports kTruncatedHit:
// lavapipe's loop limiter (65,535 passes for ALL loops of an invocation) would otherwise cut the
// loop off silently. A shader that traces several rays passes each the budget its earlier rays
// left (StepBudget below), so the sum stays under kMaxTraversalSteps.
//
// A pass: the triangle half tests the next triangle of the triangle group; the node half visits
// the next child of the node group, as long as the one-deep queue of triangle groups behind it
// is free, because the visited node's leaf triangles hit become a triangle group. A node's
// interior children hit form a new node group; what is left of the old one is pushed.
//
// The stack: on lavapipe a per-lane, dynamically indexed array costs ~40 ns per 8-lane pass even
// where no lane touches it (masked gathers/scatters run anyway). So the main loop keeps the top
// kBvhRegisterStack (8) groups in four uvec4 registers (a push or pop shifts them) and never
// touches memory. A ray whose stack would grow deeper stops there and is finished by a second
// loop with an array stack, restarting from the root with the hit found so far (re-testing a
// triangle never changes the result, so this is exact). That loop costs every 8-lane group one
// (masked) pass when no ray overflowed; a compact-stack kernel (kCompactStack: up to 16 packed
// entries in the same registers, for a BVH that cannot overflow them) has none.
RayHit traverseBvh(vec3 origin, vec3 direction, float tmin, float tmax, bool anyHit, uint maxSteps) {
  if (kBinaryLayout) return traverseBinary(origin, direction, tmin, tmax, anyHit, maxSteps);
  WatertightRay wr = prepareWatertightRay(origin, direction);
  vec3 invDir = safeReciprocal(direction);
  uint octant = rayOctant(direction);
  RayHit hit;
  hit.t = tmax;
  hit.u = 0.0;
  hit.v = 0.0;
  hit.primitive = kInvalidIndex;
  hit.item = kInvalidIndex;
  hit.steps = 0u;

  // The root as the one interior slot (slot 0) of a virtual parent whose first child is node 0.
  const uvec2 kRootGroup = uvec2(0u, (1u << octant) | (1u << 8));
  uvec2 group = kRootGroup;
  uint triangleBase = 0u, triangleBits = 0u; // the triangle group being tested
  uint queuedBase = 0u, queuedBits = 0u;      // the next one (empty while the first is)
  // Register stack (pushRegisterStack): e0 (top) .. e7.
  uvec4 s0 = uvec4(0u), s1 = uvec4(0u), s2 = uvec4(0u), s3 = uvec4(0u);
  uint stackSize = 0u;
  bool overflow = false;
  for (;;) {
    if (hit.steps >= maxSteps) {
      hit.primitive = kTruncatedHit;
      break;
    }
    hit.steps++;
    PassItems it = fetchPassItems(triangleBase, triangleBits, queuedBase, queuedBits, group, octant);
    if (it.onTriangle && testPassTriangle(it, wr, tmin, tmax, anyHit, hit) && anyHit) break;
    if (it.onNode) {
      uvec2 children = visitPassNode(it, group, triangleBase, triangleBits, queuedBase, queuedBits, origin, invDir,
                                     octant, tmin, hit.t);
      if ((children.y & 0xFFu) != 0u) {
        if ((group.y & 0xFFu) != 0u) { // the push site
          if (registerStackFull(stackSize)) {
            overflow = true; // finished by the second loop
            break;
          }
          pushRegisterStack(s0, s1, s2, s3, group);
          stackSize++;
        }
        group = children;
      }
    }
    if ((group.y & 0xFFu) == 0u) {
      if (registerStackEmpty(stackSize, s0)) {
        if (triangleBits == 0u) break;
      } else { // the pop site
        group = popRegisterStack(s0, s1, s2, s3);
        stackSize--;
      }
    }
  }

  // The second loop repeats the first one's pass (the same fetchPassItems, testPassTriangle and
  // visitPassNode) with an array stack; only the push and pop sites differ. lavapipe's loop
  // limiter counts the passes of both loops of the 8-lane group, which ran the first loop for as
  // many passes as its longest ray: an overflowed ray continues counting from there, so the
  // group stays within kMaxTraversalSteps passes in total.
  //
  // A compact-stack kernel leaves the second loop out (kCompactStack is a constant): lavapipe runs
  // a loop's body at least once, masked, even where no lane overflowed.
  if (kCompactStack) return hit;
  uint groupSteps = subgroupMax(hit.steps);
  if (overflow) hit.steps = groupSteps;
  uvec2 stack[kBvhStackSize];
  stackSize = 0u;
  group = kRootGroup;
  triangleBits = 0u;
  queuedBits = 0u;
  while (overflow) {
    if (hit.steps >= maxSteps) {
      hit.primitive = kTruncatedHit;
      break;
    }
    hit.steps++;
    PassItems it = fetchPassItems(triangleBase, triangleBits, queuedBase, queuedBits, group, octant);
    if (it.onTriangle && testPassTriangle(it, wr, tmin, tmax, anyHit, hit) && anyHit) break;
    if (it.onNode) {
      uvec2 children = visitPassNode(it, group, triangleBase, triangleBits, queuedBase, queuedBits, origin, invDir,
                                     octant, tmin, hit.t);
      if ((children.y & 0xFFu) != 0u) {
        if ((group.y & 0xFFu) != 0u) stack[stackSize++] = group; // the push site
        group = children;
      }
    }
    if ((group.y & 0xFFu) == 0u) {
      if (stackSize == 0u) {
        if (triangleBits == 0u) break;
      } else {
        group = stack[--stackSize]; // the pop site
      }
    }
  }
  return hit;
}

// The whole hit of a ray from what a traversal kept of it: t and the hit triangle's texel
// (kInvalidIndex: a miss, t = tmax; kTruncatedHit: cut off). The barycentrics and the triangle's
// index come from the same test again, which gives the same t (a loop that keeps u and v for
// every ray pays their divisions and registers on every pass).
RayHit storedHit(vec3 origin, vec3 direction, float tmin, float t, uint item) {
  RayHit h = RayHit(t, 0.0, 0.0, item == kTruncatedHit ? kTruncatedHit : kInvalidIndex, item, 0u);
  if (item >= kTruncatedHit) return h;
  vec4 p0 = bvhItem(int(item));
  vec4 p1 = bvhItem(int(item) + 1);
  vec4 p2 = bvhItem(int(item) + 2);
  float tAgain;
  intersectTriangle(prepareWatertightRay(origin, direction), p0.xyz, p1.xyz, p2.xyz, tmin, t, tAgain, h.u, h.v);
  h.primitive = floatBitsToUint(p0.w);
  return h;
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
// A probing kernel's test of such a ray whose hit `h` is known (traced, or kept: lib/kept_rays.glsl).
void probeFollowedSegment(RayHit h, vec3 origin, vec3 direction, float tmin, float tmax) {
  if (!kProbe) return;
  if (h.primitive == kTruncatedHit) gProbeMet = true;
  probeSegment(origin, direction, tmin, rayHitValid(h) && h.primitive != kInvalidIndex ? h.t : tmax);
}

RayHit traceFollowed(inout StepBudget budget, vec3 origin, vec3 direction, float tmin, float tmax) {
  RayHit h = traceBudgeted(budget, origin, direction, tmin, tmax, false);
  probeFollowedSegment(h, origin, direction, tmin, tmax);
  return h;
}

#endif
