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

#endif
