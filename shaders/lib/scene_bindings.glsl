// scene_bindings.glsl — set 0 bindings 0..6: the scene as every ray-tracing pass sees it.
// Binding numbers come from shared/host_device.h; host/render/scene_buffers.cpp binds them.
#ifndef OBSCURA_SCENE_BINDINGS_GLSL
#define OBSCURA_SCENE_BINDINGS_GLSL

// A texel buffer: lavapipe fetches a texel as one vector gather, an SSBO vec4 as four scalar
// gathers per lane (docs/ARCHITECTURE.md, "lavapipe").
layout(set = 0, binding = kBindingBvhItems) uniform samplerBuffer bvhItems;
// The same for everything a hit looks up (a triangle's shading data, its material, a texture's
// place in `texels`), read through the accessors below: an unused field's fetch is dropped.
layout(set = 0, binding = kBindingShading) uniform samplerBuffer shadingTexels;
layout(set = 0, binding = kBindingMaterials) uniform samplerBuffer materialTexels;
layout(set = 0, binding = kBindingTextures) uniform usamplerBuffer textureTexels;
// RGBA8 texels of every texture, fetched as UNORM (0..1) through the texel view.
layout(set = 0, binding = kBindingTexels) uniform samplerBuffer texels;

// The shading data of triangle `primitive` (its original index).
TriangleShading triangleShadingAt(uint primitive) {
  const int at = int(primitive * kTexelsPerShading);
  return TriangleShading(texelFetch(shadingTexels, at), texelFetch(shadingTexels, at + 1),
                         texelFetch(shadingTexels, at + 2), texelFetch(shadingTexels, at + 3),
                         texelFetch(shadingTexels, at + 4));
}

GpuMaterial materialAt(uint index) {
  const int at = int(index * kTexelsPerMaterial);
  return GpuMaterial(texelFetch(materialTexels, at), texelFetch(materialTexels, at + 1),
                     texelFetch(materialTexels, at + 2), floatBitsToInt(texelFetch(materialTexels, at + 3)),
                     texelFetch(materialTexels, at + 4));
}

GpuTexture textureInfo(int index) { return GpuTexture(texelFetch(textureTexels, index)); }

// status[kStatusTruncated] counts traversals that ran out of steps (never expected; tested).
layout(std430, set = 0, binding = kBindingStatus) buffer StatusBuffer { uint status[]; };

#endif
