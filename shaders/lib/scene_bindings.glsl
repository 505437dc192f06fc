// scene_bindings.glsl — set 0 bindings 0..6: the scene as every ray-tracing pass sees it.
// Binding numbers come from shared/host_device.h; host/render/scene_buffers.cpp binds them.
#ifndef OBSCURA_SCENE_BINDINGS_GLSL
#define OBSCURA_SCENE_BINDINGS_GLSL

// A texel buffer: lavapipe fetches a texel as one vector gather, an SSBO vec4 as four scalar
// gathers per lane (docs/ARCHITECTURE.md, "lavapipe").
layout(set = 0, binding = kBindingBvhItems) uniform samplerBuffer bvhItems;
layout(std430, set = 0, binding = kBindingShading) readonly buffer ShadingBuffer { TriangleShading triangleShading[]; };
layout(std430, set = 0, binding = kBindingMaterials) readonly buffer MaterialBuffer { GpuMaterial materials[]; };
layout(std430, set = 0, binding = kBindingTextures) readonly buffer TextureBuffer { GpuTexture textures[]; };
// RGBA8 texels of every texture, fetched as UNORM (0..1) through the texel view.
layout(set = 0, binding = kBindingTexels) uniform samplerBuffer texels;
// status[kStatusTruncated] counts traversals that ran out of steps (never expected; tested).
layout(std430, set = 0, binding = kBindingStatus) buffer StatusBuffer { uint status[]; };

#endif
