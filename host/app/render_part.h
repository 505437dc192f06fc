// render_part.h — `obscura render --samples A:B --tile I/T -o part.exr`: one part of a frame for a
// render farm (host/farm/part.h), the sums of its samples and pixels with the job's identity.
#pragma once
#include <nlohmann/json.hpp>

#include "app/render_options.h"

namespace obscura::app {

// Whether the options ask for a part (--samples or --tile).
bool isPartRender(const RenderOptions& o);
// What identifies the job the options describe (farm::Part::job): every setting that changes a
// pixel, the scene's hash, never where the files lie or how the part is cut. Needs the size chosen.
nlohmann::json jobIdentity(const RenderOptions& o);
// Renders the part the options ask for and writes it to o.output (an .exr).
void renderPart(RenderOptions& o);

} // namespace obscura::app
