// method.h — the two ways Obscura renders a frame: ray-traced obscurances (the obscurance paper's
// method, ObscuranceRenderer) or path tracing (the reference, PathTracer).
#pragma once
#include "core/names.h"

namespace obscura::render {

enum class Method { Obscurance, PathTrace };
// --method, the window's panel and scripts, job descriptions and merged EXRs ("method").
inline constexpr NameTable<Method, 2> kMethodNames{{{"obscurance", Method::Obscurance}, {"pathtrace", Method::PathTrace}}};

} // namespace obscura::render
