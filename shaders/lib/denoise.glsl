// denoise.glsl — what the denoiser's passes share (shaders/denoise_*.comp): the packed guide and
// illumination texels (shared/host_device.h, "The denoiser"), the camera's pixel <-> world maps,
// and the edge-stopping weights.
#ifndef OBSCURA_DENOISE_GLSL
#define OBSCURA_DENOISE_GLSL

#include "lib/camera.glsl"

// ---- Unit normals in two snorm16: the octahedral map (Cigolle et al., "A Survey of Efficient
// Representations for Independent Unit Vectors", JCGT 2014): the sphere onto the octahedron
// |x| + |y| + |z| = 1, its lower half folded over the upper.
vec2 octWrap(vec2 v) { return (1.0 - abs(v.yx)) * vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0); }

uint encodeNormal(vec3 n) {
  n /= abs(n.x) + abs(n.y) + abs(n.z);
  vec2 e = n.z >= 0.0 ? n.xy : octWrap(n.xy);
  return packSnorm2x16(e);
}

vec3 decodeNormal(uint bits) {
  vec2 e = unpackSnorm2x16(bits);
  vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
  if (n.z < 0.0) n.xy = octWrap(n.xy);
  return normalize(n);
}

// ---- The guide of a pixel: what the filter and the reprojection compare.
struct Guide {
  vec3 normal;   // unit shading normal (the pixel's mean)
  float depth;   // mean distance from the camera along its rays; 0 = no hit
  vec3 albedo;   // mean albedo (coverage included: a pixel half on the sky has half its albedo)
  uint material; // of the pixel's first sample; kDenoiseNoMaterial without a hit
};

uvec4 encodeGuide(Guide g) {
  return uvec4(encodeNormal(g.normal), floatBitsToUint(g.depth), packHalf2x16(g.albedo.rg),
               (packHalf2x16(vec2(g.albedo.b, 0.0)) & 0xFFFFu) | (min(g.material, kDenoiseNoMaterial) << 16));
}

Guide decodeGuide(uvec4 t) {
  Guide g;
  g.normal = decodeNormal(t.x);
  g.depth = uintBitsToFloat(t.y);
  g.albedo = vec3(unpackHalf2x16(t.z), unpackHalf2x16(t.w & 0xFFFFu).x);
  g.material = t.w >> 16;
  return g;
}

bool guideHit(Guide g) { return g.depth > 0.0; }

// The guide of a pixel from its primary AOV means (primary.comp's sums over its samples): albedo
// (a = coverage), normal and depth (w), and the first sample's material id (kInvalidIndex: no hit).
// The depth is the hits' mean: divided by the coverage.
Guide pixelGuide(vec4 albedo, vec4 normalDepth, uint material) {
  Guide g;
  g.depth = albedo.a > 0.0 ? normalDepth.w / albedo.a : 0.0;
  g.normal = dot(normalDepth.xyz, normalDepth.xyz) > 0.0 ? normalize(normalDepth.xyz) : vec3(0.0, 0.0, 1.0);
  g.albedo = albedo.rgb;
  g.material = material == kInvalidIndex ? kDenoiseNoMaterial : min(material, kDenoiseNoMaterial - 1u);
  return g;
}

// The edge-stopping weight of two normals: max(0, d)^128 (Schied et al.'s sigma_n) by seven
// squarings (pow costs a log and an exp per tap on lavapipe).
float normalWeight(float d) {
  float w = max(d, 0.0);
  for (int i = 0; i < 7; ++i) w *= w;
  return w;
}

// What demodulation divides by and remodulation multiplies by.
vec3 demodulationAlbedo(Guide g) { return max(g.albedo, vec3(kDenoiseAlbedoFloor)); }

// ---- The terms a pixel's filter works on, in two RGBA32UI texels (shared/host_device.h): the
// demodulated direct and ambient terms, the specular paths' light (not demodulated: what a glossy
// surface reflects is another surface's texture), their luminance variances, and a sample count.
// Values past the half range are clamped (a term that large is far beyond any display exposure).
struct Illum {
  vec3 direct;
  vec3 ambient;
  vec3 specular;
  vec3 variance; // of luminance(direct), luminance(ambient), luminance(specular)
  float samples; // what it counts for (the gathered frame: n; the carry: h; integrated: n + h)
};

const float kHalfMax = 65000.0;

uint packHalves(float a, float b) { return packHalf2x16(min(vec2(a, b), vec2(kHalfMax))); }

uvec4 illumTexel0(Illum i) {
  return uvec4(packHalves(i.direct.r, i.direct.g), packHalves(i.direct.b, i.ambient.r),
               packHalves(i.ambient.g, i.ambient.b), packHalves(i.variance.x, i.variance.y));
}
uvec4 illumTexel1(Illum i) {
  return uvec4(packHalves(i.specular.r, i.specular.g), packHalves(i.specular.b, i.variance.z), 0u,
               floatBitsToUint(i.samples));
}

Illum decodeIllum(uvec4 t0, uvec4 t1) {
  Illum i;
  vec2 a = unpackHalf2x16(t0.x), b = unpackHalf2x16(t0.y), c = unpackHalf2x16(t0.z), v = unpackHalf2x16(t0.w);
  vec2 s = unpackHalf2x16(t1.x), sv = unpackHalf2x16(t1.y);
  i.direct = vec3(a, b.x);
  i.ambient = vec3(b.y, c);
  i.specular = vec3(s, sv.x);
  i.variance = vec3(v, sv.y);
  i.samples = uintBitsToFloat(t1.w);
  return i;
}

Illum noIllum() {
  Illum i;
  i.direct = vec3(0.0);
  i.ambient = vec3(0.0);
  i.specular = vec3(0.0);
  i.variance = vec3(0.0);
  i.samples = 0.0;
  return i;
}

// Reads and writes pixel `p`'s two texels (texels 2p and 2p + 1). Without specular paths the
// second texel is read only for the sample count, where asked (`full`).
Illum readIllum(usamplerBuffer texels, uint p, bool full) {
  return decodeIllum(texelFetch(texels, 2 * int(p)), full ? texelFetch(texels, 2 * int(p) + 1) : uvec4(0u));
}
#define OBS_WRITE_ILLUM(array, p, value)         \
  {                                              \
    array[2u * (p)] = illumTexel0(value);        \
    array[2u * (p) + 1u] = illumTexel1(value);   \
  }

// Rec. 709 luminance: what the variance and the luminance weight are measured in.
float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

// ---- Pixels and the world. A pixel's point lies at its mean depth along the ray through its centre.
vec3 pixelPoint(GpuCamera camera, ivec2 pixel, uvec2 size, float depth) {
  return camera.origin.xyz + depth * cameraRayDirection(camera, vec2(pixel) + 0.5, vec2(size));
}

// Where world point `x` lands in the image of `camera`, in pixels (the inverse of
// cameraRayDirection); false when it lies behind the camera.
bool projectToImage(GpuCamera camera, vec3 x, uvec2 size, out vec2 image) {
  vec3 v = x - camera.origin.xyz;
  float z = dot(v, camera.forward.xyz);
  float tanHalf = camera.origin.w, aspect = camera.forward.w;
  image = vec2(0.0);
  if (z <= 0.0) return false;
  float sx = dot(v, camera.right.xyz) / (z * tanHalf * aspect);
  float sy = dot(v, camera.up.xyz) / (z * tanHalf);
  image = vec2((sx + 1.0) * 0.5 * float(size.x), (1.0 - sy) * 0.5 * float(size.y));
  return true;
}

// The width of a pixel in world units at distance `depth` (the vertical field of view over the rows).
float pixelFootprint(GpuCamera camera, float depth, uvec2 size) { return depth * 2.0 * camera.origin.w / float(size.y); }

// How far `q` lies off the plane through `p` with normal `n`, in units of `scale`: 0 on the same
// plane (a slanted floor too, where depth alone would differ), large across a geometric edge.
float planeDistance(vec3 p, vec3 n, vec3 q, float scale) { return abs(dot(n, q - p)) / scale; }

// Whether the point `pb` of guide `b` lies on the surface of `a` at `pa`: a hit of the same
// material, normals within ~25 degrees, and off `a`'s plane by less than `planeTolerance` (world
// units). Reprojection and the variance estimate keep only such neighbours.
const float kSameSurfaceCos = 0.9;
bool sameSurface(Guide a, vec3 pa, Guide b, vec3 pb, float planeTolerance) {
  return guideHit(b) && a.material == b.material && dot(a.normal, b.normal) > kSameSurfaceCos &&
         planeDistance(pa, a.normal, pb, planeTolerance) < 1.0;
}

#endif
