// band.glsl — the pixel an invocation of a per-pixel pass handles, in a frame split into bands
// of rows (shared/host_device.h, "Frame bands"). Storage is indexed band-locally; sampling and
// camera rays use the frame coordinates, so banding never changes a pixel's value.
#ifndef OBSCURA_BAND_GLSL
#define OBSCURA_BAND_GLSL

struct BandPixel {
  uvec2 frame;  // pixel coordinates in the whole frame (seeds, camera rays)
  uint index;   // band-local index into the band's buffers
  uint count;   // pixels in the band (the stride of per-light buffers)
  bool inside;  // false for the invocations past the band's edge
};

// `size` = (frame width, frame height), `band` = (first row, rows).
BandPixel bandPixel(uvec2 local, uvec2 size, uvec2 band) {
  BandPixel b;
  b.inside = local.x < size.x && local.y < band.y;
  b.frame = uvec2(local.x, local.y + band.x);
  b.index = local.y * size.x + local.x;
  b.count = size.x * band.y;
  return b;
}

// The band-local pixel `index` as a BandPixel (passes that read pixel indices from a queue).
BandPixel bandPixelFromIndex(uint index, uvec2 size, uvec2 band) {
  return bandPixel(uvec2(index % size.x, index / size.x), size, band);
}

// Entry `entry` of a list of `count` band-local pixel indices, `index` being its value (read by
// the caller when entry < count): the pixel of an invocation dispatched over a list.
BandPixel listedPixel(uint entry, uint count, uint index, uvec2 size, uvec2 band) {
  BandPixel b = bandPixelFromIndex(index, size, band);
  b.inside = b.inside && entry < count;
  return b;
}

// The entry an invocation of a kWorkgroupSizeX x kWorkgroupSizeY workgroup handles in a 1D
// indirect dispatch over a list sized in groups of kWorkgroupSize1D (the same count). Not
// gl_WorkGroupSize: it is (1, 1, 1) where read before the shader's local_size declaration.
uint listEntry() { return gl_WorkGroupID.x * kWorkgroupSize1D + gl_LocalInvocationIndex; }

#endif
