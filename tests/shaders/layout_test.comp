#version 460
// Fills every field of the shared structs with a distinct value (its word index) so the host can
// read them back through the C++ definitions of the same header: catches any layout drift.
#extension GL_GOOGLE_include_directive : require
#include "shared/host_device.h"

layout(local_size_x = 1) in;
layout(std430, binding = 0) writeonly buffer Out {
  BvhNode node;
  BvhTriangle triangle;
  TriangleShading shading;
  GpuMaterial material;
  GpuTexture texture;
  GpuRay ray;
  GpuHit hit;
  GpuCamera camera;
  GBufferTexel gtexel;
  PrimaryPush primaryPush;
  TracePush tracePush;
  GpuLight light;
  GpuEmitter emitter;
  ShadePush shadePush;
};

vec4 f4(float base) { return vec4(base, base + 1.0, base + 2.0, base + 3.0); }
uvec4 u4(uint base) { return uvec4(base, base + 1u, base + 2u, base + 3u); }

void main() {
  node = BvhNode(f4(0.0), f4(4.0), f4(8.0), f4(12.0), f4(16.0));
  triangle = BvhTriangle(f4(20.0), f4(24.0), f4(28.0));
  shading = TriangleShading(f4(32.0), f4(36.0), f4(40.0), f4(44.0), f4(48.0));
  material = GpuMaterial(f4(52.0), f4(56.0), f4(60.0), ivec4(64, 65, 66, 67), f4(68.0));
  texture = GpuTexture(u4(72u));
  ray = GpuRay(f4(76.0), f4(80.0));
  hit = GpuHit(84.0, 85.0, 86.0, 87u);
  camera = GpuCamera(f4(88.0), f4(92.0), f4(96.0), f4(100.0));
  gtexel = GBufferTexel(f4(104.0), f4(108.0), f4(112.0), f4(116.0));
  primaryPush = PrimaryPush(GpuCamera(f4(120.0), f4(124.0), f4(128.0), f4(132.0)), 136u, 137u, 138u, 139u, 140u,
                            141u, 142u, 143u, 144u, 145u, 146u, 147u);
  tracePush = TracePush(148u, 149u, 150u, 151u);
  light = GpuLight(f4(152.0), f4(156.0), u4(160u), f4(164.0));
  emitter = GpuEmitter(f4(168.0), f4(172.0), f4(176.0), f4(180.0));
  shadePush = ShadePush(184u, 185u, 186u, 187u, 188u, 189u, 190u, 191u, 192.0, 193.0, 194.0, 195.0,
                        vec3(196.0, 197.0, 198.0), 199.0, vec3(200.0, 201.0, 202.0), 203.0, 204u, 205u, 206u, 207u,
                        vec3(208.0, 209.0, 210.0), 211.0);
}
