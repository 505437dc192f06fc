#include "result.h"

#include <cmath>

#include <fmt/format.h>
#include <pybind11/stl.h>

#include "app/render_frame.h"
#include "arrays.h"
#include "bindings.h"
#include "core/error.h"
#include "devices.h"
#include "keyword_options.h"
#include "progress.h"
#include "render/aovs.h"
#include "render/transport.h"
#include "scene.h"

namespace py = pybind11;

namespace obscura::python {

const relight::RelightState& Result::relightState(const char* what) const {
  if (!state)
    throw InputError(fmt::format("{}: this result has no per-light transport (only the obscurance method keeps "
                                 "it; --method pathtrace does not)",
                                 what));
  return *state;
}

Result resultOf(relight::RelightState state, std::shared_ptr<const io::Image> aovs, std::vector<std::uint32_t> display,
                nlohmann::json stats) {
  Result r;
  r.width = state.transport.width;
  r.height = state.transport.height;
  r.aovs = std::move(aovs);
  r.state = std::move(state);
  r.display = std::move(display);
  r.stats = std::move(stats);
  return r;
}

namespace {

// A light's scale: a float, or an (r, g, b) triple of multipliers; finite and >= 0.
glm::vec3 lightScale(const std::string& name, const py::handle& value) {
  glm::vec3 scale;
  try {
    if (py::isinstance<py::str>(value)) throw py::cast_error();
    if (py::isinstance<py::sequence>(value)) {
      const auto rgb = value.cast<std::vector<float>>();
      if (rgb.size() != 3) throw py::cast_error();
      scale = glm::vec3(rgb[0], rgb[1], rgb[2]);
    } else {
      scale = glm::vec3(value.cast<float>());
    }
  } catch (const py::cast_error&) {
    throw InputError(fmt::format("relight: light '{}': expected a float or an (r, g, b) triple, got {}", name,
                                 py::repr(value).cast<std::string>()));
  }
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(scale[c]) || scale[c] < 0.0f)
      throw InputError(fmt::format("relight: light '{}': scales must be finite and >= 0", name));
  return scale;
}

// The composed AOVs with each named light's emission times its scale (the others as rendered).
io::Image relit(const relight::RelightState& state, const py::dict& scales) {
  std::vector<glm::vec3> emissions = state.emissions();
  std::vector<std::pair<std::size_t, glm::vec3>> changes;
  for (const auto& [key, value] : scales) {
    const std::string name = py::str(key);
    const std::size_t i = state.lightIndex(name, "relight");
    changes.emplace_back(i, lightScale(name, value));
  }
  py::gil_scoped_release release;
  for (const auto& [i, scale] : changes) emissions[i] = state.lights[i].emission * scale;
  return render::composeTransport(state.transport, emissions, state.ambientWeights());
}

std::shared_ptr<const io::Image> lightLayersOf(const Result& r) {
  if (!r.layers) {
    const relight::RelightState& state = r.relightState("light_stack");
    r.layers = std::make_shared<const io::Image>(
        render::lightLayers(state.transport, state.emissions(), state.ambientWeights()));
  }
  return r.layers;
}

Result render(const std::shared_ptr<Scene>& scene, const std::vector<std::string>& arguments, const py::object& progress) {
  app::RenderOptions o = renderOptions(arguments, OptionSet::Frame, "render");
  o.scenePath = scene->path();
  const render::ProgressFn onProgress = progressCallback(progress);
  py::gil_scoped_release release;
  app::checkFrameOptions(o);
  std::lock_guard work(deviceWork());
  const std::shared_ptr<gpu::Context> context = sharedContext(o.device);
  const auto tree = scene->treeFor(*context);
  std::optional<scene::Scene> withSky; // --background gives the scene a sky light: a copy of its own
  if (!o.background.empty()) {
    withSky = scene->scene();
    withSky->background = glm::vec3(o.background[0], o.background[1], o.background[2]);
  }
  const bool obscurance = o.method == render::Method::Obscurance;
  app::RenderedFrame frame = app::renderFrame(o, withSky ? *withSky : scene->scene(), *tree, *context,
                                              {.lightLayers = false, .state = obscurance, .allAovs = true}, onProgress);
  app::checkTraversals(frame.stats);
  nlohmann::json stats = app::statsJson(frame.stats);
  stats["method"] = frame.method;
  stats["notes"] = frame.stats.notes;
  stats["device"] = context->info().name;
  stats["width"] = o.width;
  stats["height"] = o.height;
  stats["spp"] = o.spp;
  auto image = std::make_shared<const io::Image>(std::move(frame.image));
  if (frame.state) return resultOf(std::move(*frame.state), image, std::move(frame.display), std::move(stats));
  Result r;
  r.width = image->width;
  r.height = image->height;
  r.aovs = image;
  r.stats = std::move(stats);
  return r;
}

} // namespace

void bindResult(py::module_& m) {
  py::class_<Result>(m, "Result", R"(A finished frame on the host.

aovs          dict of AOV name -> float32 array (H x W x C): "combined" and, for the obscurance
              method, direct, indirect, specular, obscurance, emission, albedo, normal, depth, ...
light_names   the lights, in the order of light_stack
light_stack   float32 array L x H x W x 3: each light's whole contribution (its share of the
              indirect term included), so that they sum to combined
relight(s)    combined again with each named light scaled by a float or an (r, g, b) triple: no
              ray, the compose of `obscura relight DIR`
The arrays are views of the result's memory (no copy; changing one changes the result's).)")
      .def_property_readonly(
          "aovs", [](const Result& r) { return aovViews(r.aovs, {"light."}); },
          "AOV name -> float32 array H x W x C (views, no copy).")
      .def_property_readonly("width", [](const Result& r) { return r.width; })
      .def_property_readonly("height", [](const Result& r) { return r.height; })
      .def_property_readonly(
          "light_names",
          [](const Result& r) {
            std::vector<std::string> names;
            if (r.state)
              for (const auto& l : r.state->lights) names.push_back(l.name);
            return names;
          },
          "The lights' names, in light_stack's order (empty for a path-traced result).")
      .def_property_readonly(
          "light_stack", [](const Result& r) { return lightStackView(lightLayersOf(r)); },
          "float32 array L x H x W x 3, one RGB layer per light at its rendered emission; they sum to "
          "aovs['combined'].")
      .def_property_readonly(
          "emissions",
          [](const Result& r) {
            py::dict out;
            for (const auto& l : r.relightState("emissions").lights)
              out[py::str(l.name)] = py::make_tuple(l.emission.x, l.emission.y, l.emission.z);
            return out;
          },
          "Each light's emission E_s (RGB) as rendered.")
      .def(
          "relight",
          [](const Result& r, const py::dict& scales, const std::string& aov) {
            const auto image = std::make_shared<const io::Image>(relit(r.relightState("relight"), scales));
            const auto channels = render::aovChannels(aov);
            const int first = image->channelIndex(channels.front());
            if (first < 0)
              throw InputError(fmt::format("relight: aov '{}': relighting composes combined, direct, indirect, "
                                           "specular, obscurance and emission",
                                           aov));
            return channelView(image, first, static_cast<int>(channels.size()));
          },
          py::arg("scales"), py::arg("aov") = "combined",
          "The frame relit: `scales` maps light names to a float or an (r, g, b) triple that multiplies "
          "the light's rendered emission (absent lights keep theirs). Returns the composed `aov` (H x W x "
          "3), equal to the sum of light_stack's layers with the same scales. No ray is traced.")
      .def_property_readonly(
          "display",
          [](const Result& r) -> py::object {
            if (r.display.empty()) return py::none();
            return rgba8Array(r.width, r.height, r.display);
          },
          "The tonemapped combined image as uint8 H x W x 4 (sRGB, what the PNG holds); None for a loaded state.")
      .def_property_readonly(
          "stats", [](const Result& r) { return pythonValue(r.stats); },
          "The render's figures: per-pass GPU ms and rays, wall seconds, device bytes, the method's settings.")
      .def(
          "save_state",
          [](const Result& r, const std::string& dir) {
            const auto& state = r.relightState("save_state");
            py::gil_scoped_release release;
            relight::saveState(dir, state);
          },
          py::arg("dir"),
          "Writes the relighting state to `dir` (state.json, transport.exr), as `render --save-state` "
          "does: `obscura relight DIR` and obscura.load_state read it.")
      .def("__repr__", [](const Result& r) {
        return fmt::format("<obscura.Result {}x{}, {} lights>", r.width, r.height, r.state ? r.state->lights.size() : 0);
      });

  m.def("_render", &render, py::arg("scene"), py::arg("arguments"), py::arg("progress") = py::none());
  m.def(
      "load_state",
      [](const std::string& dir) {
        py::gil_scoped_release release;
        relight::RelightState state = relight::loadState(dir);
        auto aovs = std::make_shared<const io::Image>(
            render::composeTransport(state.transport, state.emissions(), state.ambientWeights()));
        nlohmann::json stats = {{"samples", state.samples}, {"settings", state.settings}, {"scene", state.scene}};
        return resultOf(std::move(state), std::move(aovs), {}, std::move(stats));
      },
      py::arg("dir"),
      "A relighting state saved by `obscura render --save-state DIR` or Result.save_state, as a Result: its "
      "aovs composed from the transport (combined, direct, indirect, specular, obscurance, emission), "
      "light_stack and relight(). InputError naming the file when it is missing or malformed.");
}

} // namespace obscura::python
