// luminance.h — relative luminance of linear Rec. 709 RGB (ITU-R BT.709 weights), the C++ twin of
// shaders/lib/denoise.glsl's luminance(): the denoiser's scale of ambient light and the recovery's
// photo statistics weigh colours the same way.
#pragma once
#include <glm/glm.hpp>

namespace obscura {

inline float luminance(const glm::vec3& rgb) { return glm::dot(rgb, glm::vec3(0.2126f, 0.7152f, 0.0722f)); }

} // namespace obscura
