// host_device.h — the ONE header compiled by both C++ and GLSL.
//
// Every struct that crosses the host/GPU boundary is written here once, in std430 layout built
// from 16-byte rows (vec4, uvec4, or four scalars). No vec3 arrays, no mat3, no bool.
// host/gpu/host_device_test.cpp checks sizeof/offsetof, and tests/shaders/layout_test.comp fills
// every field on the GPU so the host can read it back through these same structs.
#ifndef OBSCURA_HOST_DEVICE_H
#define OBSCURA_HOST_DEVICE_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace obscura::gpu {
using vec2 = glm::vec2;
using vec3 = glm::vec3;
using vec4 = glm::vec4;
using uvec4 = glm::uvec4;
using ivec4 = glm::ivec4;
using mat4 = glm::mat4;
using uint = std::uint32_t;
#define OBS_CONST inline constexpr
#define OBS_FN inline constexpr
#else
#define OBS_CONST const
#define OBS_FN
#endif

// ---- Workgroup sizes. lavapipe runs 8 invocations per SIMD group: keep multiples of 8.
OBS_CONST uint kWorkgroupSize1D = 64;
OBS_CONST uint kWorkgroupSizeX = 8;
OBS_CONST uint kWorkgroupSizeY = 8;
#ifdef __cplusplus
static_assert(kWorkgroupSizeX * kWorkgroupSizeY == kWorkgroupSize1D, "lists are dispatched to 2D passes in 1D groups");
#endif

// ---- BVH limits. The builder guarantees depth <= kBvhMaxDepth for ANY input (it falls back to
// median splits near the limit), so a traversal stack of kBvhStackSize entries never overflows:
// a wide node is never deeper than the binary node it was collapsed from, and each wide node on
// the path pushes at most one stack entry.
OBS_CONST uint kBvhMaxDepth = 48;
OBS_CONST uint kBvhStackSize = 48;
// Stack entries traversal keeps in registers (shaders/lib/bvh.glsl); deeper stacks take a slower path.
OBS_CONST uint kBvhRegisterStack = 8;
// The same registers hold twice as many entries packed into one word each (node index << 16 |
// pending and interior masks) where the BVH has at most kBvhCompactStackNodes nodes. A traversal
// pushes at most depth - 2 entries (one per level of interior nodes below the root that still
// has children to visit), so a BVH within both limits never overflows the register stack and
// its kernels need no slower path (kSpecConstantCompactStack), and a shallower BVH needs fewer
// of the four uvec4 registers: ceil((depth - 2) / 4), at least one.
OBS_CONST uint kBvhCompactStack = 16;
OBS_CONST uint kBvhCompactStackVectors = 4; // uvec4 registers of 4 entries
OBS_CONST uint kBvhCompactStackNodes = 65536;
OBS_CONST uint kBvhCompactStackMaxDepth = kBvhCompactStack + 2;
// Wide BVH: up to 8 children per node; a leaf child holds 1..kLeafMaxTriangles triangles.
OBS_CONST uint kBvhWidth = 8;
OBS_CONST uint kLeafMaxTriangles = 3u;
OBS_CONST uint kInvalidIndex = 0xFFFFFFFFu;

// lavapipe's loop limiter silently ends every loop of one 8-lane SIMD group after 65,535 passes
// in total (docs/ARCHITECTURE.md). Traversal counts its passes and stops by itself well before, and
// reports the ray as truncated, so a cut-off can never go unnoticed.
OBS_CONST uint kMaxTraversalSteps = 60000u;

// ---- BVH on the GPU: ONE RGBA32F texel buffer: the wide nodes [0, nodeCount) of
// kTexelsPerNode texels each, then the triangles in the order the leaves need them, of
// kTexelsPerTriangle texels each. A hit's `item` is the texel of its triangle's v0.
OBS_CONST uint kTexelsPerNode = 5;
OBS_CONST uint kTexelsPerTriangle = 3;

// Wide node with compressed child boxes (Ylitie, Karras & Laine, "Efficient Incoherent Ray
// Traversal on GPUs Through Compressed Wide BVHs", HPG 2017): each child box is stored as 8-bit
// integers q on a per-node grid, plane = origin + q * 2^e per axis, rounded OUTWARD (the decoded
// box strictly contains the exact one: host/bvh/wide_node.cpp). Child slots are ordered by
// octant: slot bit k set = the child lies on the + side of axis k, so a ray visits the children
// in the order slot ^ (its direction's sign bits) and meets near children first.
// Uints ride in the float components as bits (uintBitsToFloat).
struct BvhNode {
  vec4 origin; // 0:  grid origin xyz; w = exponent byte x | y << 8 | z << 16 | internal-child mask << 24
  vec4 refs;   // 16: x = node index of the first internal child (internal children follow in
               //     slot order); y = first triangle of the leaf children (triangle index; a
               //     texel index on the GPU); z, w = meta bytes of slots 0-3 and 4-7:
               //     0 = empty, 0x80 = internal, else a leaf: count (1..3) | triangle offset << 2,
               //     so ((1 << (meta & 3)) - 1) << (meta >> 2 & 31) is its triangles' bit mask
  vec4 qx;     // 32: x axis: lo bytes of slots 0-3, lo 4-7, hi 0-3, hi 4-7
  vec4 qy;     // 48: y axis, same
  vec4 qz;     // 64: z axis, same
};             // 80 bytes = kTexelsPerNode texels

// ---- The binary layout (kBvhLayoutBinary), for GPUs: the same wide tree, each wide node made a
// small binary tree over its children (host/bvh/binary_layout.cpp), in the layout of Aila & Laine,
// "Understanding the Efficiency of Ray Traversal on GPUs", HPG 2009: a node holds the exact boxes
// of its two children and their references, so one node fetch decides both children. The
// triangles follow the nodes, as in the wide layout (a hit's `item` is the same texel). A
// reference is a node index, or a leaf: kBinaryLeafBit | count << kBinaryLeafCountShift | the
// texel of its first triangle. An absent child (a root with fewer than two) has the box of the
// point (+inf, +inf, +inf), which no ray meets.
struct BvhBinaryNode {
  vec4 leftLo;  // 0:  left child's box lo xyz;  w = left reference (uintBitsToFloat)
  vec4 leftHi;  // 16: left child's box hi xyz;  w = right reference
  vec4 rightLo; // 32: right child's box lo xyz; w = unused
  vec4 rightHi; // 48: right child's box hi xyz; w = unused
};              // 64 bytes = kTexelsPerBinaryNode texels
OBS_CONST uint kTexelsPerBinaryNode = 4;
OBS_CONST uint kBinaryLeafBit = 0x80000000u;
OBS_CONST uint kBinaryLeafCountShift = 28u;   // 3 bits: 1..kLeafMaxTriangles triangles
OBS_CONST uint kBinaryLeafTexelMask = 0x0FFFFFFFu;
// The binary traversal's stack (an array per invocation): a traversal pushes at most depth - 1
// entries, and a scene whose binary tree is deeper keeps the wide layout (render/scene_data/bvh_layout.h).
OBS_CONST uint kBinaryStackSize = 64;
// Which layout and traversal loop a kernel is specialised for (kSpecConstantBvhLayout).
OBS_CONST uint kBvhLayoutWide = 0u;
OBS_CONST uint kBvhLayoutBinary = 1u;

// Triangle for intersection, in the order the leaves need them.
struct BvhTriangle {
  vec4 v0; // 0:  xyz, w = original triangle index (uintBitsToFloat)
  vec4 v1; // 16: xyz, w = unused
  vec4 v2; // 32: xyz, w = unused
};         // 48 bytes = kTexelsPerTriangle texels

// ---- Shading attributes of a triangle, indexed by the ORIGINAL triangle index; read once per
// hit, never during traversal.
struct TriangleShading {
  vec4 n0;   // 0:  vertex normal 0 xyz, w = material index (uintBitsToFloat)
  vec4 n1;   // 16: vertex normal 1 xyz, w = light group index or kInvalidIndex (uintBitsToFloat)
  vec4 n2;   // 32: vertex normal 2 xyz, w = 1 on an important secondary reflector (kFlagSecondaryReflectors)
  vec4 uv01; // 48: uv0.xy, uv1.xy
  vec4 uv2;  // 64: uv2.xy, unused
};           // 80 bytes
OBS_CONST uint kTexelsPerShading = 5;

// ---- Material: only what the method uses [SPEC §5].
struct GpuMaterial {
  vec4 baseColor;    // 0:  linear RGBA factor
  vec4 emission;     // 16: emissive radiance RGB (factor x strength), w = 1 if double-sided
  vec4 params;       // 32: metallic, roughness, alphaCutoff, glossy (1) or Lambertian (0)
  ivec4 textures;    // 48: baseColor tex, metallicRoughness tex, emissive tex (-1 = none), unused
  vec4 meanAlbedo;   // 64: rgb mean albedo a-bar of the BRDF with the base colour factor
                     //     [SPEC §1.2, RTO eqs. 10-13], w = unused
};                   // 80 bytes
OBS_CONST uint kTexelsPerMaterial = 5;

// ---- Lights. Each light is one basis buffer D_s [SPEC §3]: an emissive light GROUP (its
// triangles in GpuEmitter[]) or a punctual light. Buffers hold transport at UNIT emission; the
// image is sum_s E_s * D_s, so changing E_s needs no ray.
OBS_CONST uint kLightArea = 0u;
OBS_CONST uint kLightPoint = 1u;
OBS_CONST uint kLightSpot = 2u;
OBS_CONST uint kLightDirectional = 3u;
OBS_CONST uint kLightBackground = 4u; // a constant sky around the scene (unit radiance x E_s)

// How a shadow ray picks its light and its point (lights.glsl) [SPEC §1.3]:
// - Spatial (the default): the light by its importance at the shading point (power, distance and
//   orientation bounds, after Conty Estevez & Kulla 2018), the point on a triangle uniform in solid
//   angle (Arvo 1995), and MIS with BSDF sampling of glossy lobes;
// - Area: the paper's estimator [RTO §4.1]: the light by power, the point uniform by area.
OBS_CONST uint kLightSamplingSpatial = 0u;
OBS_CONST uint kLightSamplingArea = 1u;
// Spatial selection evaluates every light's importance at each shading point, exactly, up to this
// many lights; with more it descends the light tree (GpuLightNode) instead, which visits
// 2 x depth nodes per sample (lavapipe's loop limiter counts each light or node visited).
OBS_CONST uint kMaxSpatialLights = 64u;
// The importance bound of a spot reaches this cosine past its outer cone (rounding slack; no
// cosine factor inside the cone): lights.glsl and its C++ twin, render/scene_data/light_selection.h.
OBS_CONST float kSpotConeSlack = 0.99999f;
// Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013: scaling a box's far distance by 1 + 2 gamma(n)
// makes the float slab test conservative, so rounding never culls a box the ray touches. Ize's
// n = 3 (a subtraction, a product, a correctly rounded reciprocal) holds on the CPU and lavapipe;
// Vulkan lets a GPU divide to 2.5 ulp, five half-ulp roundings instead of one, so n = 7:
// 1 + 2 gamma(7) = 1 + 8.3e-7, rounded up to a float (1 + 8 ulp). An NVIDIA H200 returned a
// farther, nearly coincident triangle instead of the nearer one for 1 Sponza ray in 10^5
// (docs/BENCHMARKS.md); a box culled by the too-tight bound is the likely cause. The GPU's box
// tests (lib/intersect.glsl, lib/bvh.glsl) and the CPU's (host/bvh/wide_node.cpp) share it.
OBS_CONST float kBoxFarScale = 1.000001f;

struct GpuLight {
  vec4 position;  // 0:  point/spot: world position, w = range (0 = infinite); area: centre of the
                  //     emitters' bounding sphere, w = its radius (light importance, lights.glsl)
  vec4 direction; // 16: spot/directional: unit direction the light travels; area: axis of the
                  //     cone holding every emitter's normal, w = cos of its half-angle (-1: any
                  //     direction, e.g. a double-sided emitter)
  uvec4 info;     // 32: type, first emitter, emitter count (area), group area (float bits)
  vec4 params;    // 48: x = selection CDF (up to and including this light), y = selection
                  //     probability, z = cos inner cone, w = cos outer cone
};                // 64 bytes
OBS_CONST uint kTexelsPerLight = 4;

// One emissive triangle of an area light. Radiance is the material's emission divided by the
// group's E_s (so a uniform group has unit radiance).
struct GpuEmitter {
  vec4 v0;        // 0:  xyz, w = CDF within the group (by area, up to and including this one)
  vec4 v1;        // 16: xyz, w = area
  vec4 v2;        // 32: xyz, w = 1 if it emits from both sides
  vec4 radiance;  // 48: rgb unit-emission radiance, w = unused
};                // 64 bytes
OBS_CONST uint kTexelsPerEmitter = 4;

// ---- Light tree: a binary BVH over the bounded lights (area, point, spot) for spatial selection
// with more than kMaxSpatialLights lights (Conty Estevez & Kulla, "Importance Sampling of Many
// Lights with Adaptive Tree Splitting", HPG 2018; pbrt-v4's BVHLightSampler). Built on the host
// (host/render/scene_data/light_tree.cpp), read by lights.glsl. One array of nodes (binding
// kBindingLightTree / kBindingPathLightTree):
// - row 0: the header: refs = (root row or kInvalidIndex when no bounded light has power, the
//   number U of unbounded lights with power, the light count it was built for, the tree's depth);
// - rows 1 + i, i < light count: light i's leaf (its bounds; refs.z, refs.w its trail: bit k is
//   the child taken at depth k from the root, refs.w the depth of the leaf, kInvalidIndex for a
//   light outside the tree: unbounded or without power);
// - the next U rows: refs.x = the k-th unbounded light with power (directional, background);
// - then the internal nodes.
// A trail has 32 bits: the builder keeps every leaf within kLightTreeMaxDepth.
OBS_CONST uint kLightTreeMaxDepth = 32u;
struct GpuLightNode {
  vec4 sphere;   // 0:  bounding sphere of the lights below: centre xyz, w = radius (0: a point)
  vec4 cone;     // 16: axis xyz of the cone that holds their emission normals or spot directions,
                 //     w = cos theta_o (-1: every direction, no orientation bound)
  vec4 emission; // 32: x = power (selection weight: the lights' GpuLight.params.y, summed),
                 //     y = cos theta_e (emission spread beyond theta_o: 0 for area lights), z = 1 if
                 //     uniform within the cone (spots: no cosine factor), w = unused
  uvec4 refs;    // 48: internal: first child row, second child row; leaf: light index,
                 //     kInvalidIndex; z, w: see above
};               // 64 bytes

// ---- Texture table: all textures live in one uint buffer of RGBA8 texels.
struct GpuTexture {
  uvec4 info; // 0: first texel offset, width, height, flags (bit 0 = sRGB)
};            // 16 bytes
OBS_CONST uint kTextureSrgb = 1u;

// ---- Ray for benchmarks and tests: 32 bytes.
struct GpuRay {
  vec4 origin;    // 0:  xyz, w = tmin
  vec4 direction; // 16: xyz, w = tmax
};                // 32 bytes

// ---- Hit record from traversal: 16 bytes.
struct GpuHit {
  float t;        // 0:  distance in units of |direction|; tmax when missed
  float u;        // 4:  barycentric of v1
  float v;        // 8:  barycentric of v2
  uint primitive; // 12: original triangle index or kInvalidIndex; kTruncatedHit if steps ran out
};                // 16 bytes
OBS_CONST uint kTruncatedHit = 0xFFFFFFFEu;

// ---- Camera (pinhole), world space.
struct GpuCamera {
  vec4 origin;  // 0:  xyz, w = tan(yfov / 2)
  vec4 forward; // 16: xyz, w = aspect (width / height)
  vec4 right;   // 32: xyz, w = unused
  vec4 up;      // 48: xyz, w = the light slot of the background (uint bits; kInvalidIndex: none),
                //     which a camera ray that leaves the scene sees (primary.comp, pathtrace.comp)
};              // 64 bytes

// ---- G-buffer texel written by primary.comp, one per pixel per sample.
struct GBufferTexel {
  vec4 position;        // 0:  world-space hit point, w = depth (distance from camera, 0 on miss)
  vec4 geometricNormal; // 16: xyz (unit, faces the camera ray), w = primitive id (uintBitsToFloat)
  vec4 shadingNormal;   // 32: xyz (unit, interpolated, same side as geometric), w = material (bits)
  vec4 albedo;          // 48: rgb base colour x texture, a = 1 on hit, 0 on miss
};                      // 64 bytes: one cache line a pixel (the seen emission goes to the AOVs and
                        // M_s from primary.comp itself; no later pass reads it)
OBS_CONST uint kTexelsPerGBuffer = 4;

// ---- Frame bands. Frame-lifetime storage is split into bands of whole rows so that no buffer
// exceeds the device's per-buffer limit (lavapipe: 128 MiB): a band owns its own G-buffer, AOV,
// basis and compose buffers, and every per-pixel pass is dispatched once per band. Pixels are
// addressed band-locally (index = local row * width + x) but sampled with their FRAME coordinates,
// so a frame rendered in bands is bit-identical to the same frame rendered whole.
// A pass's push constants name the band's first row and rows (firstRow, rows).
//
// Push constants are filled in one place on the host each (render/passes: PrimaryPass::record,
// packShadePush) from a struct with named fields (PrimaryDispatch, ShadeSample + ShadeDispatch);
// flag words carry the dispatch's choices to the shader as the kernel choice reads them.

// ---- Push constants of primary.comp (<= 128 bytes, the guaranteed minimum).
struct PrimaryPush {
  GpuCamera camera;   // 0
  uint width;         // 64: of the whole frame (a band's or a farm part's rows are rows of it)
  uint height;
  uint sampleIndex;   // the sample's index in the frame's sequence (seeds, sub-pixel position)
  uint seed;
  uint firstRow;      // 80: the band's rows
  uint rows;
  uint lightCount;
  uint flags;         // kPrimaryFlag*, and the emission rays' K from kPrimaryEmissionSamplesShift up
  uint firstSample;   // 96: the sample the accumulation started at (0 but for a farm's part,
                      //     render --samples A:B)
  uint unused0;       // to 112 bytes: GLSL rounds the struct to its 16-byte alignment
  uint unused1;
  uint unused2;
};                    // 112 bytes
// The primary pass re-creates the G-buffer of a sample without adding to the AOV and emission
// accumulators (an added light traces its shadow rays from the same primary hits).
OBS_CONST uint kPrimaryFlagGBufferOnly = 1u;
// The frame keeps no primary AOVs (only what compose needs was asked for): M_s is still summed.
OBS_CONST uint kPrimaryFlagNoAovs = 2u;
// Only pixels the dirty mask marks run (a geometry edit retraces them); the others keep their sums.
OBS_CONST uint kPrimaryFlagDirtyOnly = 4u;
// The emission rays only where an emitter's edge crosses the pixel (lib/emission_samples.glsl:
// the pixel's corners, probed at its first sample, see different lights); elsewhere the primary ray.
OBS_CONST uint kPrimaryFlagEmissionAtEdges = 8u;
// The flags' bits from here up: --emission-samples K (K > 1: M_s from K camera rays of their own
// per sample, lib/emission_samples.glsl; 0 or 1: from the primary ray).
OBS_CONST uint kPrimaryEmissionSamplesShift = 8u;
// The largest K: K traversals per sample share the loop limiter's budget (LAVAPIPE.md).
OBS_CONST uint kMaxEmissionSamples = 64u;
// The emission rays' K where they go to emitter edges only (--emission-samples auto, the default):
// the edge pixels are few, so K can be large; 16 cut the Cornell box's edge RMSE 4.9x
// (docs/BENCHMARKS.md, "Emission rays and the split of shading rays").
OBS_CONST uint kEdgeEmissionSamples = 16u;

// ---- Push constants of the bench/trace kernel.
// Rays each invocation of trace.comp traces through one refilling loop (shaders/lib/bvh_stream.glsl):
// on Sponza's random rays 8 gave 0.37 of Embree, 16 0.42, 32 0.46, 64 0.49 (docs/BENCHMARKS.md).
// 64 is the most traverseStream takes (it marks the rays it puts aside in a 64-bit mask). The hits
// wait in shared memory, 8 bytes a ray (12 in the variant that records steps): trace.comp's
// workgroups are smaller than the passes' so that they fit 32 KiB (lavapipe's limit; NVIDIA's is
// 48 KiB).
OBS_CONST uint kTraceRaysPerLane = 64;
OBS_CONST uint kTraceWorkgroupSize = 32;
// ...and on a GPU (any device but a CPU; host/bench/ray_tracer.cpp): 8 rays per invocation in
// workgroups of 32. On an H200 (docs/BENCHMARKS.md, "NVIDIA GPU") that beat one ray per invocation
// (straight through traverseBvh; 128x1: modern-hall 3.06 Grays/s, Sponza 0.76) by 20-37 %
// (3.69, 1.05), and the lavapipe shape (32x64: 0.97, 0.31), whose 24 KiB of shared memory per
// 32 invocations caps the warps an SM holds, by 3-4x. `bench-rays --trace-shape` tries others.
OBS_CONST uint kTraceGpuWorkgroupSize = 32;
OBS_CONST uint kTraceGpuRaysPerLane = 8;
// ...and with the binary layout (one ray per invocation, straight through traverseBvh).
OBS_CONST uint kTraceBinaryWorkgroupSize = 128;
#ifdef __cplusplus
static_assert(kTraceRaysPerLane <= 64, "traverseStream marks the rays it puts aside in a 64-bit mask");
static_assert(kTraceWorkgroupSize * kTraceRaysPerLane * 12 <= 32768, "trace.comp's hits must fit shared memory");
static_assert(kTraceWorkgroupSize % 8 == 0, "lavapipe runs 8 invocations per SIMD group");
#endif
struct TracePush {
  uint rayCount;  // 0
  uint anyHit;    // 0: the closest hit, 1: any hit (a shadow ray)
  uint unused;    // (the steps variant is kSpecConstantTraceSteps)
  uint firstRay;  // the first ray's index in the buffer
};                // 16 bytes

// ---- Descriptor bindings (set 0) shared by every pass that traces rays.
OBS_CONST uint kBindingBvhItems = 0;  // samplerBuffer RGBA32F: nodes, then triangles (64-byte items)
OBS_CONST uint kBindingShading = 1;   // samplerBuffer RGBA32F: TriangleShading[], kTexelsPerShading texels each
OBS_CONST uint kBindingMaterials = 2; // samplerBuffer RGBA32F: GpuMaterial[], kTexelsPerMaterial texels each
OBS_CONST uint kBindingTextures = 3;  // usamplerBuffer RGBA32UI: GpuTexture[], one texel each
OBS_CONST uint kBindingTexels = 4;    // uniform texel buffer, R8G8B8A8_UNORM
OBS_CONST uint kBindingStatus = 5;    // SSBO uint[kStatusWords]
OBS_CONST uint kSceneBindingCount = 6;
OBS_CONST uint kBindingPassFirst = 6; // first binding owned by the pass itself

// ---- status[] words (binding kBindingStatus).
OBS_CONST uint kStatusTruncated = 0;       // traversals stopped by kMaxTraversalSteps
OBS_CONST uint kStatusShadowRays = 1;      // shadow rays traced (for rays/s figures)
OBS_CONST uint kStatusObscuranceRays = 2;  // obscurance rays traced
OBS_CONST uint kStatusSpecularRays = 3;    // rays traced along specular paths
OBS_CONST uint kStatusPathRays = 4;        // rays traced by the path tracer
OBS_CONST uint kStatusDirtyPixels = 5;     // pixels dirty.comp marked for retracing
OBS_CONST uint kStatusEmissionRays = 6;    // camera rays traced for the seen emission alone (the
                                           // emitter-edge probes and the emission rays)
OBS_CONST uint kStatusWords = 8;

// ---- Shading passes (shadow.comp, obscurance.comp): push constants.
OBS_CONST uint kFlagSystematic = 1u; // obscurance rays by systematic sampling [RTO §4.2]
OBS_CONST uint kFlagBleed = 2u;      // colour bleeding: W_c instead of W [RTO eq. 6]
OBS_CONST uint kFlagAreaLightSampling = 4u; // the paper's light sampling (kLightSamplingArea)
// Glossy vertices share their specular lobe between light sampling (N_s shadow rays) and the
// specular pass's lobe sample, weighted by the power heuristic; set when the specular pass runs
// and the light sampling is spatial with selection over all lights.
OBS_CONST uint kFlagGlossyMis = 8u;
// Important secondary reflectors [RTO §2.2, §6]: an obscurance ray from a primary hit that lands
// on a marked triangle (TriangleShading.n2.w) traces that point's direct light too, into D_s, and
// keeps only the share kappa (ShadePush.kappa) of the ambient there.
OBS_CONST uint kFlagSecondaryReflectors = 16u;
// A specular path's vertices gather with N_s and N_obs scaled by the path's throughput there, at
// least one ray each (specular.comp, raysAtVertex); without it, N_s and N_obs at every vertex.
OBS_CONST uint kFlagVertexRaysByThroughput = 32u;
// An obscurance ray that meets nothing within dMax is traced on (an any-hit ray from dMax): one
// that leaves the scene brings no ambient light, for what lies outside is the background, a light
// of its own (lib/obscurance.glsl, gatherObscurance). Set where rays leave the scene (EscapeModel).
OBS_CONST uint kFlagDarkEscapes = 64u;

OBS_CONST uint kRhoSqrt = 0u;        // rho(d) = sqrt(d / dmax)          [RTO §3, SPEC §1.1]
OBS_CONST uint kRhoExp = 1u;         // rho(d) = (1 - e^(-tau d/dmax)) / (1 - e^(-tau))
OBS_CONST uint kRhoAo = 2u;          // rho(d) = 0 below dmax (ambient occlusion)

struct ShadePush {
  // What every dispatch of one sample shares (render/passes/shading_inputs.h, ShadeSample).
  uint width;              // 0: of the whole frame
  uint height;
  uint sampleIndex;        // the sample's index in the frame's sequence
  uint seed;
  uint lightCount;         // 16
  uint shadowRays;         // N_s per hit
  uint obscuranceRays;     // N_obs per hit
  uint renderFlags;        // kFlag*: how the render samples
  float dMax;              // 32
  float tau;               // for kRhoExp
  float rhoKind;           // kRho* (as float)
  float maxDepth;          // a specular path's scattering vertices, the primary hit is 1 (as float)
  vec3 averageReflectance; // 48: R_ave (the reflectance of a miss within dmax, SPEC §1.2)
  float pathDepth;         // the vertex depth of a specular.comp dispatch (as float)
  vec3 eye;                // 64: the camera's position (the view direction at primary hits)
  float sceneSize;         // the largest bounding-box extent: scales the ray-origin offset (ray.glsl)
  // What this dispatch does (ShadeDispatch).
  uint firstRow;           // 80: the band's rows
  uint rows;
  uint dispatchFlags;      // kShadeFlag*
  uint light;              // the light of a per-light dispatch (kShadeFlagPerLight)
  vec3 kappa;              // 96: the share of I_a beyond the first bounce (kFlagSecondaryReflectors)
  float unmarkedFirstBounce; // r: the unmarked surfaces' first bounce against the mean
};                         // 112 bytes
OBS_CONST uint kShadeFlagDirtyOnly = 1u; // only pixels the dirty mask marks run
// shadow.comp samples light `light` alone, the paper's way [IVR §3.1]: kPerLightRays rays per
// sample, up to kPerLightMaxRays where they disagree (a penumbra), one for a point, spot or
// directional light (exact: every ray would go to the same point); one dispatch per light, so each
// D_s is independent of the other lights' powers and each dispatch stays within the loop limiter.
OBS_CONST uint kShadeFlagPerLight = 2u;
// specular.comp gathers the ambient alone along its paths: in a frame with per-light shadow
// sampling every light then follows the same paths in a dispatch of its own (kShadeFlagPerLight),
// so each light's specular transport is independent of the others' powers too.
OBS_CONST uint kShadeFlagNoDirect = 4u;
// The pass probes instead of shading (a geometry edit's dirty test, dirty.comp): it draws the rays
// of the listed pixels from the same seeds as when they were rendered, but tests each against the
// changed boxes (the dirty buffer's tail, dirtyBoxesBase) instead of tracing it, and marks the
// pixel 2 in the dirty mask when one meets a box. Only a specular lobe ray is traced, in the edited
// scene, so that the path goes on, and tested up to its hit. Nothing is accumulated.
OBS_CONST uint kShadeFlagProbe = 8u;
// The frame keeps this sample's rays that a replay would draw again (lib/kept_rays.glsl): the
// specular paths' lobe hits (kBindingPathHits) and the primary hits' shadow rays
// (kBindingKeptShadowRays, light sampling by selection). The plain kernels write them; the kernels
// that follow the same rays again (an added light's per-light gather, a geometry edit's probes)
// read them instead of tracing or drawing them. The host sets it only while they are the frame's.
OBS_CONST uint kShadeFlagKeptRays = 16u;
// Shadow rays per primary hit a frame can keep (N_s up to this; the paper's is 5).
OBS_CONST uint kMaxKeptShadowRays = 8u;
// Lobe rays kept per pixel and sample: a path's scattering vertices after the primary hit, up to
// the paper's depth of 6 (SPEC §1.3). Deeper paths (--max-depth > 6) keep none.
OBS_CONST uint kPathHitsPerSample = 5u;
// A kept hit is one uvec4: t, u, v (float bits) and the hit triangle's texel in bvhItems (its
// original index is that texel's w), or one of these for a lobe ray that found no triangle.
OBS_CONST uint kPathHitMiss = 0xffffffffu;
OBS_CONST uint kPathHitTruncated = 0xfffffffeu;
// The specialisation constant (a bool) that makes a shading kernel its probing variant (kProbe,
// lib/probe.glsl); kShadeFlagProbe dispatches go to that kernel.
OBS_CONST uint kSpecConstantProbe = 0u;
// The specialisation constant (a bool) that compiles the secondary reflectors' light samples into
// gatherObscurance (kReflectors, lib/obscurance.glsl); kFlagSecondaryReflectors dispatches of the
// obscurance pass go to that variant. Left out, the branch costs the pass 40 % of its time on
// lavapipe even when no ray takes it (docs/BENCHMARKS.md, issue 10).
OBS_CONST uint kSpecConstantReflectors = 1u;
// The specialisation constant (a bool) that makes a shading kernel shade one light alone (kPerLight,
// lib/shading_bindings.glsl): kShadeFlagPerLight dispatches that do not probe go to that variant,
// which leaves out the code for all lights at once (the specular pass's ambient gather and light
// selection). Like the reflectors' branch, that code slows the per-light path on lavapipe even
// when no invocation takes it (docs/BENCHMARKS.md, adding a light).
OBS_CONST uint kSpecConstantPerLight = 2u;
// The specialisation constants (bools) that compile into primary.comp the AOV accumulators
// (kSpecConstantPrimaryAovs, dispatches without kPrimaryFlagNoAovs or kPrimaryFlagGBufferOnly) and
// the emission rays of --emission-samples K > 1 (kSpecConstantEmissionRays, a second inlined
// traversal). PrimaryPass picks the variant from the flags; left out, the two cost the camera rays
// 1.5x and 1.2x of their time on lavapipe even where no invocation takes them (docs/BENCHMARKS.md).
OBS_CONST uint kSpecConstantPrimaryAovs = 3u;
OBS_CONST uint kSpecConstantEmissionRays = 4u;
// The specialisation constant (a bool) that makes the specular kernel's per-light and probing
// variants follow the paths by the frame's kept lobe hits, and the shadow kernel's probing variant
// test the kept shadow rays (kShadeFlagKeptRays dispatches), instead of tracing or drawing them
// (kReplayRays, lib/kept_rays.glsl).
OBS_CONST uint kSpecConstantReplayRays = 5u;
// The specialisation constant (a bool) that makes trace.comp record each ray's loop passes (the
// traversal tests and bench-rays' statistics); the timed variant leaves the stores out.
OBS_CONST uint kSpecConstantTraceSteps = 6u;
// The specialisation constant (a bool) that leaves the colour bleeding out of gatherObscurance
// (kGreyObscurance, lib/obscurance.glsl): the obscurance pass's dispatches without kFlagBleed (and
// without reflectors) go to that variant. Left in, the hit's surface and texture lookup, which
// lavapipe runs for every ray whether or not a lane takes the branch, cost the grey pass 13 %.
OBS_CONST uint kSpecConstantGreyObscurance = 7u;
// The specialisation constant (a bool) that leaves the light tree and the selection by power out
// of a shading kernel (kFlatLightSelection, lib/lights.glsl): every light is chosen by the flat
// spatial selection. The host sets it where the render samples lights spatially and its frame
// holds no more than kMaxSpatialLights lights (spares included); lavapipe otherwise runs the
// unused selections masked for every light sample (5 % of the shadow pass).
OBS_CONST uint kSpecConstantFlatLightSelection = 8u;
// trace.comp's shape (kTraceRaysPerLane and kTraceWorkgroupSize above, a GPU's
// kTraceGpuRaysPerLane and kTraceGpuWorkgroupSize, or bench-rays --trace-shape).
OBS_CONST uint kSpecConstantTraceRaysPerLane = 9u;
OBS_CONST uint kSpecConstantTraceWorkgroupSize = 10u;
// The specialisation constant (a uint) of a kernel that only traverses BVHs within the compact
// stack's limits (kBvhCompactStackNodes, kBvhCompactStackMaxDepth): the uvec4 registers of packed
// entries traverseBvh keeps (1..kBvhCompactStackVectors, as deep as the BVH needs), with no
// second loop; 0 (the default) is the general kernel. lavapipe runs a loop's body at least once
// even where no lane enters it, so that loop cost every traversal one full (masked) pass, and
// every live register of the loop counts: spills are a quarter of a pass.
OBS_CONST uint kSpecConstantCompactStack = 11u;
// trace.comp reads the BVH's nodes and triangles from the same buffer bound as an SSBO instead of
// through its texel view (bench-rays --bvh-items storage: which path a GPU fetches faster).
OBS_CONST uint kSpecConstantBvhItemsFromStorage = 12u;
// primary.comp keeps each pixel's box of hits for geometry edits (dirty.comp); a renderer that
// will never edit its scene (ObscuranceSettings::editableGeometry) compiles it out.
OBS_CONST uint kSpecConstantPrimaryHitBounds = 13u;
// The kinds of texture no material of the scene uses (kTexturesAbsent* bits): lib/material.glsl
// compiles their lookups out (four texel fetches and twelve sRGB decodes each, which lavapipe runs
// masked at every hit even where the material has no texture). 0, the default: the general kernel.
OBS_CONST uint kSpecConstantTexturesAbsent = 14u;
OBS_CONST uint kTexturesAbsentBaseColor = 1u;
OBS_CONST uint kTexturesAbsentEmissive = 2u;
// The BVH layout and traversal loop (kBvhLayoutWide, the default, or kBvhLayoutBinary) the
// scene's items buffer holds: render/scene_data/bvh_layout.h chooses per device.
OBS_CONST uint kSpecConstantBvhLayout = 15u;
// The binary traversal's loop (a bool): false, one loop (what lavapipe's loop limiter needs),
// true, Aila & Laine's while-while (lib/bvh.glsl, traverseBinary).
OBS_CONST uint kSpecConstantBinaryLoop = 16u;
// A closest-hit ray of the binary traversal drops a popped child that lies beyond its hit (a bool,
// off by default; bench-rays --cull-on-pop measures it).
OBS_CONST uint kSpecConstantBinaryCullOnPop = 17u;
OBS_CONST uint kPerLightRays = 4u;
OBS_CONST uint kPerLightMaxRays = 64u;

// ---- Bindings of the shading passes (after the scene's 0..5).
OBS_CONST uint kBindingGBuffer = 6;   // samplerBuffer RGBA32F: GBufferTexel[pixels] of the current sample
                                      // (kTexelsPerGBuffer texels each)
OBS_CONST uint kBindingLights = 7;    // samplerBuffer RGBA32F: GpuLight[lights], kTexelsPerLight texels each
OBS_CONST uint kBindingEmitters = 8;  // samplerBuffer RGBA32F: GpuEmitter[], kTexelsPerEmitter texels each
OBS_CONST uint kBindingBasis = 9;     // vec4[lights * pixels]: sums of D_s (unit emission)
OBS_CONST uint kBindingAmbient = 10;  // vec4[pixels]: rgb sums of A = R(P) W_c (or R(P) W), w = W
OBS_CONST uint kBindingSpecularBasis = 11;   // vec4[lights * pixels]: D_s gathered along specular paths
OBS_CONST uint kBindingSpecularAmbient = 12; // vec4[pixels]: A gathered along specular paths
OBS_CONST uint kBindingSpecularQueue = 13;   // uint[]: kQueueHeader words, then glossy pixel indices
OBS_CONST uint kBindingLightScales = 14;     // vec4[lights]: E_s (to make seen emission unit)
OBS_CONST uint kBindingDirty = 15;           // uint[]: the dirty mask and list (kDirtyListBase)
OBS_CONST uint kBindingHitBounds = 16;       // = primary.comp's kBindingPrimaryHitBounds; specular
                                             // paths grow it with their vertices
OBS_CONST uint kBindingLightTree = 17;       // GpuLightNode[]: the light tree (lights.glsl)
OBS_CONST uint kBindingPathHits = 18;        // uvec4[(sample * pixels + pixel) * kPathHitsPerSample + k]:
                                             // specular paths' lobe hits (kShadeFlagKeptRays)
OBS_CONST uint kBindingKeptShadowRays = 19;  // vec4[((sample * pixels + pixel) * 6 + vertex) * N_s + k]:
                                             // direction, length (0: no ray) of the shadow rays at the
                                             // primary hit (vertex 0) and the paths' vertices
OBS_CONST uint kBindingSpecularPaths = 20;    // vec4[pixels * kSpecularPathTexels]: the state of each
                                             // specular path between its vertices (specular.comp)
OBS_CONST uint kShadingBindingCount = 21;

// ---- Bindings of primary.comp after the scene's (0..5).
OBS_CONST uint kBindingPrimaryGBuffer = 6;       // GBufferTexel[pixel]
OBS_CONST uint kBindingPrimaryAovs = 7;          // vec4 pairs [pixel * kAovSlots + slot]
OBS_CONST uint kBindingPrimaryLightScales = 8;   // vec4[lights]: E_s at render time (normaliser)
OBS_CONST uint kBindingPrimaryEmissionBasis = 9; // vec4 pairs [light][pixel]: M_s, the emission
                                                 // the camera sees of light s at unit emission
OBS_CONST uint kBindingPrimaryHitBounds = 10;    // vec4[2 * pixel]: the box of the pixel's primary
                                                 // hits and specular path vertices over samples
                                                 // (min xyz, w = 1 if a specular path left the
                                                 // scene or an obscurance ray reached past dMax;
                                                 // max xyz, w = 1 if any sample hit)
OBS_CONST uint kBindingPrimaryDirty = 11;        // uint[pixel]: 1 = retrace (kPrimaryFlagDirtyOnly)
OBS_CONST uint kBindingPrimarySampleCounts = 12; // uint[pixel]: the samples in the pixel's sums
                                                 // (restarts at its sample 0, as the sums do);
                                                 // compose and resolve divide by it
OBS_CONST uint kBindingPrimaryEmitterEdges = 13; // uint[pixel]: 1 = an emitter's edge crosses the
                                                 // pixel (kPrimaryFlagEmissionAtEdges; written at
                                                 // its first sample)
OBS_CONST uint kPrimaryBindingCount = 14;

// Header of the specular queue: an indirect dispatch (groups x, y, z) and the entry count.
OBS_CONST uint kQueueGroupsX = 0;
OBS_CONST uint kQueueCount = 3;
OBS_CONST uint kQueueHeader = 4;
// The specular pass runs one vertex of its paths per dispatch (a wavefront): the paths that go on
// past depth d are queued for depth d + 1. Two queues of a band's `pixels` entries take turns in
// the queue buffer: depth 1 (filled by specular_queue.comp) at word 0, depth 2 after it, ...
OBS_FN uint specularQueueBase(uint depth, uint pixels) { return (depth & 1u) != 0u ? 0u : kQueueHeader + pixels; }
// A path's state between vertices: 7 vec4 (specular.comp, storePath).
OBS_CONST uint kSpecularPathTexels = 7;

// ---- pathtrace.comp: push constants and its own bindings after the scene's (0..5).
struct PathPush {
  GpuCamera camera;   // 0: camera.right.w = scene size (scales the ray-origin offset, ray.glsl)
  uint width;         // 64
  uint height;
  uint sampleIndex;   // the sample's index in the frame's sequence
  uint seed;
  uint lightCount;    // 80: 0 = no light with power (no light sampling at all)
  uint maxDepth;      // d: scattering vertices of a path
  uint rrDepth;       // Russian roulette from this depth
  uint strategy;      // kPathStrategy*
  uint firstRow;      // 96: the band's rows
  uint rows;
  uint lightSampling; // kLightSampling*
  uint emissionSamples; // K > 1: the camera ray's emission from K rays of their own
  uint emissionAtEdges; // 112: 1 = those K rays only where an emitter's edge crosses the pixel
  uint firstSample;     // the sample the accumulation started at (its edge probes run there)
  uint unused0;
  uint unused1;
};                    // 128 bytes
OBS_CONST uint kPathStrategyMis = 0u;       // MIS of light and BSDF sampling (the reference)
OBS_CONST uint kPathStrategyLightOnly = 1u; // area lights by light sampling only (tests)
OBS_CONST uint kPathStrategyBsdfOnly = 2u;  // area lights by BSDF sampling only (tests)
OBS_CONST uint kBindingPathRadiance = 6u;   // vec4[pixels]: rgb sums, w = dropped samples
OBS_CONST uint kBindingPathLights = 7u;     // as kBindingLights (lib/light_bindings.glsl)
OBS_CONST uint kBindingPathEmitters = 8u;   // as kBindingEmitters
OBS_CONST uint kBindingPathScales = 9u;     // vec4[lights]: E_s, each light's emission scale
OBS_CONST uint kBindingPathLightTree = 10u; // GpuLightNode[] (= kBindingLightTree's contents)
OBS_CONST uint kBindingPathEmitterEdges = 11u; // uint[pixels]: as kBindingPrimaryEmitterEdges
OBS_CONST uint kPathBindingCount = 12u;

// ---- compose.comp: per pixel, AOV slots written (averaged over samples).
OBS_CONST uint kComposeCombined = 0;   // C = sum_s E_s (D_s + M_s) + I_a A (+ specular)
OBS_CONST uint kComposeDirect = 1;     // sum_s E_s D_s at the primary hit
OBS_CONST uint kComposeIndirect = 2;   // I_a * A at the primary hit (albedo I_a W_c)
OBS_CONST uint kComposeSpecular = 3;   // everything gathered along specular paths
OBS_CONST uint kComposeObscurance = 4; // W (grey obscurance), in .x
OBS_CONST uint kComposeEmission = 5;   // sum_s E_s M_s: emission the camera sees, per light scaled
OBS_CONST uint kComposeSlots = 6;

struct ComposePush {
  uint width;      // 0: of the band (samples are counted per pixel)
  uint rows;
  uint lightCount;
  uint slots;      // slots per pixel in the output: kComposeSlots, or 1 (combined only)
  vec3 ambient;    // 16: I_a(E)
  uint specular;   // 1 when the specular buffers hold data
};                 // 32 bytes

// Bindings of compose.comp (its own set; no scene bindings).
OBS_CONST uint kBindingComposeBasis = 0;           // vec4 pairs [light][pixel]: D_s sums
OBS_CONST uint kBindingComposeAmbient = 1;         // vec4 pairs [pixel]: A sums (rgb), W (w)
OBS_CONST uint kBindingComposeEmissionBasis = 2;   // vec4 pairs [light][pixel]: M_s sums
OBS_CONST uint kBindingComposeEmissions = 3;       // vec4[lights]: E_s to compose with
OBS_CONST uint kBindingComposeOutput = 4;          // vec4[pixel * kComposeSlots]
OBS_CONST uint kBindingComposeSpecularBasis = 5;   // vec4 pairs [light][pixel]
OBS_CONST uint kBindingComposeSpecularAmbient = 6; // vec4 pairs [pixel]
OBS_CONST uint kBindingComposeSampleCounts = 7;    // uint[pixel] (primary.comp)
OBS_CONST uint kComposeBindingCount = 8;

// ---- tonemap.comp: composed radiance -> display RGBA8 (exposure, then the sRGB curve).
struct TonemapPush {
  uint width;         // 0: of the band
  uint rows;
  uint slot;          // the composed slot to show
  uint channels;      // 1 or 3
  float exposureScale; // 16: 2^stops
  uint composedSlots; // slots per pixel in the composed buffer (ComposePush.slots)
};                    // 24 bytes
OBS_CONST uint kBindingTonemapInput = 0;  // vec4[pixel * kComposeSlots]
OBS_CONST uint kBindingTonemapOutput = 1; // uint[pixel]: RGBA8, R in the low byte
OBS_CONST uint kTonemapBindingCount = 2;

// ---- resolve.comp and lightmix.comp: the fast relighting path [SPEC §3]. resolve.comp turns the
// Kahan sums into the per-light transport T_s = (D_s + M_s + S_s) / n and the ambient
// A_t = (A + A^spec) / n, as RGB9E5 words (lib/rgb9e5.glsl: 9-bit mantissas, shared exponent),
// [light][pixel] then the ambient after the frame's light slots, at [slots][pixel], each light's
// row kResolvedPixelAlign-aligned (resolvedStride). lightmix.comp composes and tonemaps from them
// in one pass: display = tonemap(sum_s E_s T_s + I_a(E) A_t), four pixels per invocation reading
// one RGBA32UI texel per light (lavapipe: one 16-byte load per lane instead of four 4-byte ones).
// A term keeps 2^-9 of its pixel's largest channel (tests: LightMix.*).
OBS_CONST uint kResolvedPixelAlign = 4;
OBS_FN uint resolvedStride(uint pixels) { return (pixels + kResolvedPixelAlign - 1u) / kResolvedPixelAlign * kResolvedPixelAlign; }
struct ResolvePush {
  uint width;      // 0: of the band (samples are counted per pixel)
  uint rows;
  uint lightCount;
  uint specular;   // 1 when the specular buffers hold data
  uint firstLight; // 16: the first light to resolve (the ones before are current)
  uint ambient;    // 1 to resolve the ambient too
  uint lightSlots; // light slots of the frame (A_t lives after them)
  uint dirtyOnly;  // 1 to resolve only the pixels of the band's dirty list (after a geometry
                   // edit), dispatched indirectly; the others are current
};                 // 32 bytes
OBS_CONST uint kBindingResolveBasis = 0;           // vec4 pairs [light][pixel]: D_s
OBS_CONST uint kBindingResolveEmissionBasis = 1;   // vec4 pairs [light][pixel]: M_s
OBS_CONST uint kBindingResolveSpecularBasis = 2;   // vec4 pairs [light][pixel]: S_s
OBS_CONST uint kBindingResolveAmbient = 3;         // vec4 pairs [pixel]: A
OBS_CONST uint kBindingResolveSpecularAmbient = 4; // vec4 pairs [pixel]: A^spec
OBS_CONST uint kBindingResolveOutput = 5;          // uint [(slots + 1) * resolvedStride(pixels)], RGB9E5
OBS_CONST uint kBindingResolveSampleCounts = 6;    // uint[pixel] (primary.comp)
OBS_CONST uint kBindingResolveDirty = 7;           // uint[]: the dirty mask and list (capacity.y)
OBS_CONST uint kResolveBindingCount = 8;

struct LightMixPush {
  uint width;      // 0: of the band
  uint rows;
  uint lightCount;
  uint lightSlots; // A_t lives after them
  vec3 ambient;    // 16: I_a(E)
  float exposureScale; // 2^stops
};                 // 32 bytes
OBS_CONST uint kBindingLightMixResolved = 0;  // RGBA32UI texels of resolve.comp's words
OBS_CONST uint kBindingLightMixEmissions = 1; // vec4[lights]: E_s
OBS_CONST uint kBindingLightMixOutput = 2;    // uint[pixel]: RGBA8 (as tonemap.comp)
OBS_CONST uint kLightMixBindingCount = 3;

// ---- dirty.comp: the pixels a geometry edit can change [IVR §3.3; SPEC §2], conservatively:
// those whose screen footprint the changed boxes cover (primary rays), those whose hit box lies
// within dMax of a changed box (obscurance is local), those whose segments to a light can meet a
// changed box (shadow rays: the paper's shafts, here the convex hull of the pixel's hit box and the
// light's box, tested against the changed box on separating axes), with a glossy pixel's specular
// path vertices counted in its hit box (every segment of a path lies in the box of its vertices);
// a path that left the scene makes its pixel always dirty. Up to kMaxChangedBoxes boxes (old and
// new places), each padded by more than a ray origin's offset.
// A band's dirty buffer: the mask, uint[pixel] (1 = retrace), then at kDirtyListBase(pixels) a
// list as the specular queue's (kQueueHeader words: indirect groups x, y, z and the count; then
// the dirty pixels' band-local indices). A retrace dispatches its passes over the list, so no SIMD
// lane waits on a clean neighbour.
OBS_FN uint dirtyListBase(uint pixels) { return pixels; }
OBS_CONST uint kMaxChangedBoxes = 4;
// After the list, DirtyPass::record leaves the changed boxes for the probing passes (kShadeFlagProbe):
// per box, lo xyz and w = 1 (used) or 0, then hi xyz (as floatBits).
OBS_FN uint dirtyBoxesBase(uint pixels) { return 2u * pixels + kQueueHeader; }
OBS_CONST uint kDirtyBoxWords = 8u * kMaxChangedBoxes;
// After the boxes, the light bounds of dirty.comp (kBindingDirtyLights' layout, 8 words a light),
// with which a probe skips the light samples of a point none of whose shafts meets a box.
OBS_FN uint dirtyLightsBase(uint pixels) { return dirtyBoxesBase(pixels) + kDirtyBoxWords; }
struct DirtyPush {
  uint width;         // 0:   of the band
  uint rows;
  uint firstRow;
  uint lightCount;
  vec4 boxLo[4];      // 16:  changed boxes, padded: lo xyz, w = 1 (used) or 0 (unused)
  vec4 boxHi[4];      // 80:  hi xyz
  uvec4 rects[4];     // 144: their screen rectangles in frame pixels: x0, y0, x1, y1 (inclusive)
  float dMax;         // 208
  uint all;           // 1: every pixel is dirty
  uint tracedLight;   // a light whose shadow rays are traced anew at every pixel anyway
                      // (kInvalidIndex: none): its shafts are not tested
  uint probing;       // 1 when the probing passes decide the candidates (ShadeDispatch::probe)
};                    // 224 bytes (> 128: passed in a uniform-like storage buffer, not push constants)
// Probing in two steps, one dirty.comp dispatch each (its push constant, stage.x):
// kDirtyStageMark: mask 2 where certain (a changed box covers the pixel on screen), 1 where only a
// bound says a ray may meet a box (a candidate: listed for the probing passes), 0 elsewhere;
// kDirtyStageList, after the probes: mask 1 where it was 2, 0 elsewhere, and the list of those.
// Without probing, kDirtyStageMark marks and lists every candidate as dirty (mask 1).
OBS_CONST uint kDirtyStageMark = 0u;
OBS_CONST uint kDirtyStageList = 1u;
OBS_CONST uint kDirtyCertain = 2u;
struct DirtyStagePush {
  uint stage;         // 0: kDirtyStage*
};                    // 4 bytes
// Light bounds for dirty.comp, two vec4 per light: (centre xyz, w = 1 for a directional light,
// whose segments run to infinity along -direction, else 0) and (the box's half extent xyz, or the
// directional light's direction).
OBS_CONST uint kBindingDirtyParams = 0;    // DirtyPush (one element)
OBS_CONST uint kBindingDirtyHitBounds = 1; // vec4[2 * pixel] (primary.comp)
OBS_CONST uint kBindingDirtyLights = 2;    // vec4[2 * lights]
OBS_CONST uint kBindingDirtyMask = 3;      // uint[pixel] out
OBS_CONST uint kBindingDirtyStatus = 4;    // uint[kStatusWords]: kStatusDirtyPixels counted
OBS_CONST uint kDirtyBindingCount = 5;

// ---- clear.comp: zeroes the shading passes' sums (D_s, S_s, A, A^spec) of the dirty pixels
// before they are retraced (primary.comp restarts the AOV and M_s sums itself at sample 0).
struct ClearPush {
  uint width;      // 0: of the band
  uint rows;
  uint lightCount;
  uint specular;   // 1 when specular buffers are used
};                 // 16 bytes
OBS_CONST uint kBindingClearDirty = 0;
OBS_CONST uint kBindingClearBasis = 1;
OBS_CONST uint kBindingClearAmbient = 2;
OBS_CONST uint kBindingClearSpecularBasis = 3;
OBS_CONST uint kBindingClearSpecularAmbient = 4;
OBS_CONST uint kClearBindingCount = 5;

// ---- The denoiser (host/render/denoise/, shaders/denoise_*.comp): SVGF-style filtering (Schied et
// al., "Spatiotemporal Variance-Guided Filtering", HPG 2017) of the demodulated direct and ambient
// terms and of the specular paths' light. Its buffers cover the whole frame (gathered from the
// bands) in RGBA32UI texels, which the filter reads through uniform texel buffers (on lavapipe a
// texel gathers 16 bytes per lane at once where an SSBO load costs one scalar load per lane and word):
//   guide  one texel: x = octahedral shading normal (snorm16 x 2), y = depth (float bits; 0 = no
//          hit), z = albedo r, g (half x 2), w = albedo b (half, low 16 bits), material (high 16)
//   illum  two texels (2p, 2p + 1): x, y, z = direct rgb then ambient rgb, demodulated, w = their
//          luminance variances (halves); then specular rgb and its variance (halves, x and y),
//          z unused, w = the samples the terms count for (float bits)
struct DenoiseParams {
  GpuCamera camera;   // 0:   the current view (the primary pass's: up.w = the sky's light slot)
  GpuCamera previous; // 64:  the view the history was made with
  uvec4 frame;        // 128: width, height, the most samples a reprojected history counts for,
                      //      1 when the frame has specular paths (else the specular term is 0)
  vec4 weights;       // 144: sigma plane (pixels), sigma albedo, sigma luminance, unused
};                    // 160 bytes (> 128: bound as a storage buffer, not push constants)
// Demodulation divides by max(albedo, kDenoiseAlbedoFloor) and remodulation multiplies by the same,
// so a black surface passes through unchanged.
OBS_CONST float kDenoiseAlbedoFloor = 0.01f;
OBS_CONST uint kDenoiseNoMaterial = 0xFFFFu; // the guide's material on a pixel without a hit
OBS_CONST uint kDenoiseIllumTexels = 2;      // texels per pixel of an illum buffer

struct DenoisePush {
  uint firstRow;      // 0: gather: the band's rows and the composed slots per pixel
  uint rows;
  uint composedSlots;
  uint step;          // a-trous: the filter's step (2^iteration)
};                    // 16 bytes

// Bindings, each pass its own set; binding 0 is the DenoiseParams of every pass.
OBS_CONST uint kBindingDenoiseParams = 0;
// denoise_gather.comp: the band's composed AOVs, primary AOVs and sample counts -> frame buffers
OBS_CONST uint kBindingGatherComposed = 1;     // vec4[pixel * slots] (compose.comp)
OBS_CONST uint kBindingGatherAovs = 2;         // vec4 pairs [pixel * kAovSlots + slot] (primary.comp)
OBS_CONST uint kBindingGatherSampleCounts = 3; // uint[pixel]
OBS_CONST uint kBindingGatherGuide = 4;        // uvec4[frame pixel] out: guide
OBS_CONST uint kBindingGatherIllum = 5;        // uvec4[2 x frame pixel] out: illum, samples = n
OBS_CONST uint kBindingGatherEmission = 6;     // vec4[frame pixel] out: seen emission (not filtered)
OBS_CONST uint kGatherBindingCount = 7;
// denoise_reproject.comp: the history seen from the current camera
OBS_CONST uint kBindingReprojectGuide = 1;        // texels: the current guide
OBS_CONST uint kBindingReprojectHistoryGuide = 2; // texels: the history's guide
OBS_CONST uint kBindingReprojectHistory = 3;      // texels: the history's illum (temporal output)
OBS_CONST uint kBindingReprojectCarry = 4;        // uvec4[2 x pixel] out: illum, samples = h
OBS_CONST uint kReprojectBindingCount = 5;
// denoise_temporal.comp: current mean + carry, and the luminance variances
OBS_CONST uint kBindingTemporalGuide = 1;  // texels: guide
OBS_CONST uint kBindingTemporalNoisy = 2;  // texels: the gathered illum
OBS_CONST uint kBindingTemporalCarry = 3;  // uvec4[2 x pixel]: carry
OBS_CONST uint kBindingTemporalOut = 4;    // uvec4[2 x pixel] out: illum with variances, samples n + h
OBS_CONST uint kTemporalBindingCount = 5;
// denoise_atrous.comp: one wavelet iteration
OBS_CONST uint kBindingAtrousGuide = 1; // texels: guide
OBS_CONST uint kBindingAtrousIn = 2;    // texels: illum
OBS_CONST uint kBindingAtrousOut = 3;   // uvec4[2 x pixel] out: illum
OBS_CONST uint kAtrousBindingCount = 4;
// denoise_remodulate.comp: x albedo + specular + emission -> linear remodulated (denoise_edges.comp's input)
OBS_CONST uint kBindingRemodulateGuide = 1;    // texels: guide
OBS_CONST uint kBindingRemodulateIllum = 2;    // texels: illum
OBS_CONST uint kBindingRemodulateEmission = 3; // vec4[pixel]
OBS_CONST uint kBindingRemodulateOut = 4;      // vec4[pixel] out: remodulated, w = samples
OBS_CONST uint kRemodulateBindingCount = 5;
// denoise_edges.comp: the pixels an edge crosses, resolved from camera rays of their own (set 0:
// the scene's bindings first, as every tracing pass)
OBS_CONST uint kBindingEdgesParams = kBindingPassFirst;          // DenoiseParams
OBS_CONST uint kBindingEdgesGuide = kBindingPassFirst + 1;       // uvec4[pixel]: guide
OBS_CONST uint kBindingEdgesRemodulated = kBindingPassFirst + 2; // vec4[pixel]: remodulate's, w = samples
OBS_CONST uint kBindingEdgesEmission = kBindingPassFirst + 3;    // vec4[pixel]: the seen emission
OBS_CONST uint kBindingEdgesLightScales = kBindingPassFirst + 4; // vec4[light]: render-time emission scales
OBS_CONST uint kBindingEdgesEmissions = kBindingPassFirst + 5;   // vec4[light]: the E_s compose used
OBS_CONST uint kBindingEdgesOut = kBindingPassFirst + 6;         // vec4[pixel] out: combined
OBS_CONST uint kEdgesBindingCount = kBindingPassFirst + 7;

// The most camera rays the edge pass traces in a pixel (DenoiserSettings): they stop early where
// the loop limiter's budget runs low (the rest left to the pixel's own estimate).
OBS_CONST uint kMaxEdgeRays = 256u;
struct DenoiseEdgesPush {
  uint geometryRays;      // camera rays per pixel a geometric edge crosses (0: the pass copies)
  uint emitterRays;       // the most per pixel whose seen emission differs from a neighbour's
  uint lightCount;        // the lights' slots (the sky's is camera.up.w when it is one of them)
  uint ownEmissionRays;   // the renderer's emission rays per sample at an emitter's border
  float ambientLuminance; // of I_a: the scene's radiance scale an emitter's step is measured in
  uint unused0, unused1, unused2;
};                        // 32 bytes

// ---- The path-traced correction (host/render/correction/, shaders/correction_*.comp): the
// obscurance frame plus its difference to a path-traced frame of the same view, that difference
// divided by the albedo and filtered along surfaces (a-trous steps over the guide of
// lib/denoise.glsl), so the frame converges to path tracing's as the paths grow. Whole-frame
// buffers; binding 0 of both passes is a DenoiseParams (camera, frame size, sigma plane).
struct CorrectionPush {
  uint firstRow;      // residual: the band's rows and the composed slots per pixel
  uint rows;
  uint composedSlots;
  uint pathSamples;   // residual: the paths the path tracer's sums hold
  uint step;          // filter: the a-trous step (2^iteration); 0: the residual as it is
  uint lastStep;      // filter: 1 on the last step, which also writes the corrected image
  uint unused0, unused1;
};                    // 32 bytes
OBS_CONST uint kBindingCorrectionParams = 0;
// correction_residual.comp (per band of the obscurance frame)
OBS_CONST uint kBindingResidualComposed = 1;     // vec4[pixel * slots] (compose.comp)
OBS_CONST uint kBindingResidualAovs = 2;         // vec4 pairs [pixel * kAovSlots + slot] (primary.comp)
OBS_CONST uint kBindingResidualSampleCounts = 3; // uint[pixel]
OBS_CONST uint kBindingResidualPaths = 4;        // vec4 pairs [frame pixel]: the path tracer's radiance
                                                 // sums, its bands copied into one buffer
OBS_CONST uint kBindingResidualGuide = 5;        // uvec4[frame pixel] out: guide
OBS_CONST uint kBindingResidualBase = 6;         // vec4[frame pixel] out: the obscurance frame's combined
OBS_CONST uint kBindingResidualOut = 7;          // vec4[frame pixel] out: (paths - base) / albedo, w = 1
                                                 // where filtered, 0 where kept (no hit, seen emission)
OBS_CONST uint kResidualBindingCount = 8;
// correction_filter.comp: one a-trous step of the residual
OBS_CONST uint kBindingCorrectionGuide = 1;  // uvec4[pixel]
OBS_CONST uint kBindingCorrectionBase = 2;   // vec4[pixel]
OBS_CONST uint kBindingCorrectionIn = 3;     // vec4[pixel]: residual
OBS_CONST uint kBindingCorrectionOut = 4;    // vec4[pixel] out: residual filtered
OBS_CONST uint kBindingCorrectionImage = 5;  // vec4[pixel] out (last step): base + residual x albedo
OBS_CONST uint kCorrectionBindingCount = 6;

// ---- Accumulators (shaders/lib/accumulate.glsl): every summed vec4 is a PAIR of vec4 (the sum,
// then its Kahan compensation), so accumulation buffers hold kAccumulatorVec4s vec4 per entry.
OBS_CONST uint kAccumulatorVec4s = 2;

// ---- Per-pixel AOV accumulation of primary.comp: kAovSlots accumulators per pixel, summed over
// samples (slot kAovIds is written by sample 0 only).
OBS_CONST uint kAovAlbedo = 0;   // rgb albedo, a = coverage (1 on hit)
OBS_CONST uint kAovNormal = 1;   // xyz shading normal, w = depth (distance from the camera)
OBS_CONST uint kAovPosition = 2; // xyz world position, w = unused
OBS_CONST uint kAovEmission = 3; // rgb visible emission, w = unused
OBS_CONST uint kAovIds = 4;      // x = primitive id, y = material id (uintBitsToFloat), z, w unused
OBS_CONST uint kAovPreview = 5;  // rgb albedo x |cos| to the eye + emission (a headlight view)
OBS_CONST uint kAovSlots = 6;

#ifdef __cplusplus
} // namespace obscura::gpu
#endif
#endif // OBSCURA_HOST_DEVICE_H
