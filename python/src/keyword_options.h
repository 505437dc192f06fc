// keyword_options.h — a Python call's settings as the command line's options. The package turns
// keyword arguments into the command line's words (obscura/__init__.py, _arguments: width=64 ->
// "--width 64", no_bleed=True -> "--no-bleed"), and they are parsed here by the commands' own
// option definitions, so names, defaults, checks and error messages are the command line's.
#pragma once
#include <string>
#include <vector>

#include "app/render_options.h"

namespace obscura::python {

// What the options are read for: render() takes the frame's (--aov, --exposure, --denoise) too.
enum class OptionSet { Frame, Session };

// InputError "<caller>: <CLI11's message>" for an unknown option or a bad value.
app::RenderOptions renderOptions(const std::vector<std::string>& arguments, OptionSet set, const std::string& caller);

} // namespace obscura::python
