// material.glsl — material and texture lookups at a hit. Needs scene_bindings.glsl.
#ifndef OBSCURA_MATERIAL_GLSL
#define OBSCURA_MATERIAL_GLSL

// A kernel specialised for its scene (SceneSpecialisation on the host) leaves out the lookups of
// the texture kinds no material uses (kSpecConstantTexturesAbsent).
layout(constant_id = kSpecConstantTexturesAbsent) const uint kTexturesAbsent = 0u;
const bool kBaseColorTextures = (kTexturesAbsent & kTexturesAbsentBaseColor) == 0u;
const bool kEmissiveTextures = (kTexturesAbsent & kTexturesAbsentEmissive) == 0u;

vec3 srgbToLinear(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

vec4 fetchTexel(GpuTexture tex, int x, int y) {
  uint width = tex.info.y;
  vec4 c = texelFetch(texels, int(tex.info.x + uint(y) * width + uint(x)));
  if ((tex.info.w & kTextureSrgb) != 0u) c.rgb = srgbToLinear(c.rgb);
  return c;
}

// Bilinear lookup with repeat wrapping (glTF's default sampler); uv (0,0) is the top-left texel.
// Texels are decoded to linear before filtering.
vec4 sampleTexture(int index, vec2 uv) {
  GpuTexture tex = textureInfo(index);
  ivec2 size = ivec2(tex.info.yz);
  vec2 p = fract(uv) * vec2(size) - 0.5;
  vec2 f = fract(p);
  ivec2 i0 = ivec2(floor(p));
  // The texel pair with repeat: i0 lies in [-1, size - 1] (fract(uv) in [0, 1)), so the wrap is a
  // select, not the integer modulo ((i0 % size + size) % size, (a + 1) % size) it equals there:
  // lavapipe has no vector integer division and runs a % per lane. The clamp only keeps a NaN uv's
  // texel inside the texture.
  ivec2 a = clamp(mix(i0, i0 + size, lessThan(i0, ivec2(0))), ivec2(0), size - 1);
  ivec2 b = mix(a + 1, ivec2(0), equal(a + 1, size));
  vec4 c00 = fetchTexel(tex, a.x, a.y), c10 = fetchTexel(tex, b.x, a.y);
  vec4 c01 = fetchTexel(tex, a.x, b.y), c11 = fetchTexel(tex, b.x, b.y);
  return mix(mix(c00, c10, f.x), mix(c01, c11, f.x), f.y);
}

// Base colour (albedo) = baseColorFactor x baseColorTexture.
vec4 materialBaseColor(GpuMaterial m, vec2 uv) {
  vec4 c = m.baseColor;
  if (kBaseColorTextures && m.textures.x >= 0) c *= sampleTexture(m.textures.x, uv);
  return c;
}

// Emitted radiance = emissiveFactor x strength x emissiveTexture [SPEC §5]; one-sided unless the
// material is double-sided: `frontFacing` is true when the ray arrives on the side the
// counter-clockwise winding's normal faces.
vec3 materialEmission(GpuMaterial m, vec2 uv, bool frontFacing) {
  if (!frontFacing && m.emission.w == 0.0) return vec3(0.0);
  vec3 e = m.emission.rgb;
  if (kEmissiveTextures && m.textures.z >= 0 && any(greaterThan(e, vec3(0.0))))
    e *= sampleTexture(m.textures.z, uv).rgb;
  return e;
}

// Emission in unit-emission terms for a light whose render-time scale is `scale` (E_s): divided
// by it per channel, 1 where E_s is 0 (the rule of render/scene_data/light_set.cpp unitRadiance), so
// that compose's sum_s E_s M_s gives back the emission with the scene's own E_s.
vec3 unitEmission(vec3 emission, vec3 scale) {
  return emission / mix(scale, vec3(1.0), equal(scale, vec3(0.0)));
}

#endif
