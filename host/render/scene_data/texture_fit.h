// texture_fit.h — makes a scene's textures fit the one storage buffer they share on the GPU.
//
// All textures live in one SSBO (shaders/lib/material.glsl), whose size a device limits
// (maxStorageBufferRange: 128 MiB on lavapipe, 4 GiB on NVIDIA). When they do not fit, the
// largest texture is halved (2x2 box filter, in linear space for sRGB textures) until they do:
// blurrier textures rather than a failed render. Each reduction is reported.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace obscura::render {

// Returns the textures to upload (a copy, reduced as needed) and appends one line per reduced
// texture to `notes`.
std::vector<scene::Texture> fitTextures(const std::vector<scene::Texture>& textures, std::uint64_t budgetBytes,
                                        std::vector<std::string>& notes);

// One 2x2 box-filter reduction (odd sizes keep their last row/column folded in).
scene::Texture halveTexture(const scene::Texture& texture);

} // namespace obscura::render
