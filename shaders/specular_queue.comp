#version 460
// specular_queue.comp — compacts the pixels whose primary hit is glossy into a queue and sizes
// the indirect dispatch of specular.comp, so only those pixels pay for specular paths
// [RTO §4.1 step 4]. The host resets the header to (0, 1, 1, 0) before each iteration.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"
#include "lib/scene_bindings.glsl"
#include "lib/shading_bindings.glsl"
#include "lib/band.glsl"
#include "lib/queue_append.glsl"

layout(local_size_x = kWorkgroupSizeX, local_size_y = kWorkgroupSizeY) in;

void main() {
  BandPixel bp = bandPixel(gl_GlobalInvocationID.xy, uvec2(pc.width, pc.height), uvec2(pc.firstRow, pc.rows));
  if (!bp.inside) return;
  uvec2 p = bp.frame;
  uint pixel = bp.index;
  if (skipClean(pixel)) return;
  GBufferTexel g = gbufferAt(pixel);
  if (g.albedo.a == 0.0 || materialAt(floatBitsToUint(g.shadingNormal.w)).params.w == 0.0) return;
  OBS_QUEUE_APPEND(queue, 0u, pixel)
}
