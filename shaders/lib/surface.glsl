// surface.glsl — the surface at a ray hit: position, normals, uv, material.
// Needs scene_bindings.glsl and bvh.glsl.
#ifndef OBSCURA_SURFACE_GLSL
#define OBSCURA_SURFACE_GLSL

struct Surface {
  vec3 position;
  vec3 geometricNormal; // unit, faces the incoming ray (reflection is two-sided, SPEC §5)
  vec3 shadingNormal;   // unit, interpolated, flipped to the geometric normal's side
  vec2 uv;
  uint material;
  uint lightGroup;      // kInvalidIndex when not emissive
  bool frontFacing;     // the ray arrived on the side the CCW winding's normal faces
};

Surface surfaceAt(RayHit hit, vec3 origin, vec3 direction) {
  Surface s;
  int base = triangleTexel(hit);
  vec3 p0 = texelFetch(bvhItems, base).xyz;
  vec3 p1 = texelFetch(bvhItems, base + 1).xyz;
  vec3 p2 = texelFetch(bvhItems, base + 2).xyz;
  float w = 1.0 - hit.u - hit.v;
  // Interpolating the vertices is more accurate than origin + t * direction far from the origin.
  s.position = w * p0 + hit.u * p1 + hit.v * p2;
  vec3 ng = normalize(cross(p1 - p0, p2 - p0));
  s.frontFacing = dot(ng, direction) < 0.0;
  s.geometricNormal = s.frontFacing ? ng : -ng;

  TriangleShading sh = triangleShadingAt(hit.primitive);
  vec3 ns = w * sh.n0.xyz + hit.u * sh.n1.xyz + hit.v * sh.n2.xyz;
  float len = length(ns);
  ns = len > 0.0 ? ns / len : s.geometricNormal;
  s.shadingNormal = dot(ns, s.geometricNormal) < 0.0 ? -ns : ns;
  s.uv = w * sh.uv01.xy + hit.u * sh.uv01.zw + hit.v * sh.uv2.xy;
  s.material = floatBitsToUint(sh.n0.w);
  s.lightGroup = floatBitsToUint(sh.n1.w);
  return s;
}

#endif
