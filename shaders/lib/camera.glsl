// camera.glsl — pinhole camera rays with stratified sub-pixel positions.
#ifndef OBSCURA_CAMERA_GLSL
#define OBSCURA_CAMERA_GLSL

// Sub-pixel position of sample s: the R2 sequence (Roberts 2018, "The Unreasonable Effectiveness
// of Quasirandom Sequences"), shifted per pixel by a random offset (Cranley-Patterson rotation).
// Any prefix of it is well stratified over the pixel, so every --spp gets a box-filtered
// [SPEC §5] low-discrepancy estimate.
vec2 pixelSampleOffset(uint sampleIndex, vec2 shift) {
  const vec2 kR2 = vec2(0.7548776662466927, 0.5698402909980532);
  return fract(shift + float(sampleIndex) * kR2);
}

// Unit direction through image position `pixel` (in pixels, y down).
vec3 cameraRayDirection(GpuCamera camera, vec2 pixel, vec2 size) {
  float tanHalf = camera.origin.w, aspect = camera.forward.w;
  float sx = (2.0 * pixel.x / size.x - 1.0) * tanHalf * aspect;
  float sy = (1.0 - 2.0 * pixel.y / size.y) * tanHalf;
  return normalize(camera.forward.xyz + sx * camera.right.xyz + sy * camera.up.xyz);
}

#endif
