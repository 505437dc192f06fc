// light_bindings.glsl — the lights and their emissive triangles (bindings kBindingLights and
// kBindingEmitters, which the path tracer's kBindingPathLights and kBindingPathEmitters equal), as
// RGBA32F texel buffers read through the accessors below, which lights.glsl and shade.glsl use.
// A light sample reads the light it chose and one of its triangles at an index that differs from
// lane to lane: lavapipe fetches a texel as one vector gather, an SSBO vec4 as four scalar loads
// per lane (docs/ARCHITECTURE.md, "lavapipe"). A field the caller does not use is not fetched.
#ifndef OBSCURA_LIGHT_BINDINGS_GLSL
#define OBSCURA_LIGHT_BINDINGS_GLSL

layout(set = 0, binding = kBindingLights) uniform samplerBuffer lightTexels;
layout(set = 0, binding = kBindingEmitters) uniform samplerBuffer emitterTexels;

GpuLight lightAt(uint i) {
  const int at = int(i * kTexelsPerLight);
  return GpuLight(texelFetch(lightTexels, at), texelFetch(lightTexels, at + 1),
                  floatBitsToUint(texelFetch(lightTexels, at + 2)), texelFetch(lightTexels, at + 3));
}

GpuEmitter emitterAt(uint i) {
  const int at = int(i * kTexelsPerEmitter);
  return GpuEmitter(texelFetch(emitterTexels, at), texelFetch(emitterTexels, at + 1), texelFetch(emitterTexels, at + 2),
                    texelFetch(emitterTexels, at + 3));
}

#endif
