// session.cpp — obscura.Session: the edit session (session/edit_session.h) that `relight --edits`
// and the window drive, driven from Python. Edits are the edits file's JSON entries as dicts
// (relight/light_edits.h); each returns its report, the line `relight --edits` writes to
// edits.jsonl.
#include <chrono>
#include <filesystem>
#include <memory>

#include <fmt/format.h>
#include <pybind11/stl.h>

#include "app/render_options.h"
#include "arrays.h"
#include "bindings.h"
#include "core/error.h"
#include "devices.h"
#include "keyword_options.h"
#include "progress.h"
#include "relight/light_edits.h"
#include "relight/relight_state.h"
#include "render/scene_data/bvh_layout.h"
#include "result.h"
#include "scene.h"
#include "scene/gltf_loader.h"
#include "session/edit_session.h"

namespace py = pybind11;

namespace obscura::python {
namespace {

class Session {
public:
  Session(std::shared_ptr<Scene> scene, const std::vector<std::string>& arguments, std::uint32_t spareLights,
          const py::object& progress)
      : scene_(std::move(scene)), options_(renderOptions(arguments, OptionSet::Session, "Session")) {
    if (options_.method != render::Method::Obscurance)
      throw InputError("Session: method: relighting keeps per-light transport, which only the obscurance method has");
    app::checkRenderOptions(options_);
    options_.scenePath = scene_->path();
    const render::ProgressFn onProgress = progressCallback(progress);
    py::gil_scoped_release release;
    std::lock_guard work(deviceWork());
    context_ = sharedContext(options_.device);
    scene::Scene copy = scene_->scene(); // the session's own: edits change it
    if (!options_.background.empty())
      copy.background = glm::vec3(options_.background[0], options_.background[1], options_.background[2]);
    const scene::Camera camera = app::chooseCamera(copy, options_.camera);
    app::chooseSize(options_, camera);
    const gpu::Context& context = *context_;
    session_ = std::make_unique<session::EditSession>(
        context, std::move(copy), bvh::Bvh(*scene_->treeFor(context)),
        session::editSettings(app::obscuranceSettings(options_, camera), spareLights),
        render::treeOptionsFor(render::traversalFor(context)));
    render::ObscuranceRenderer& renderer = session_->renderer();
    renderer.reset();
    renderer.iterate(renderer.settings().spp, onProgress);
    renderer.composeDisplay(options_.exposure);
  }

  py::object apply(const py::dict& edit) {
    session::EditSession& s = open("apply");
    const std::string where = "Session.apply";
    const nlohmann::json entry = nlohmann::json::parse(py::module_::import("json").attr("dumps")(edit).cast<std::string>());
    session::Edit e = relight::readEdit(entry, io::JsonEntry{where, edits_});
    nlohmann::json line;
    {
      py::gil_scoped_release release;
      if (e.kind == session::Edit::Kind::Insert && !e.inserted) {
        // The path as given (relative to the working directory), loaded and checked before the edit.
        if (!std::filesystem::exists(e.path))
          throw InputError(fmt::format("{}: entry {}: '{}': no such file", where, edits_, e.path));
        e.inserted = std::make_shared<const scene::Scene>(scene::loadGltf(e.path));
      }
      std::lock_guard work(deviceWork());
      session::EditReport report = s.apply(e, fmt::format("{}: entry {}", where, edits_));
      s.composeDisplay(report, options_.exposure);
      line = report.json();
      line["edit"] = edits_++;
    }
    return pythonValue(line);
  }

  Result result() {
    session::EditSession& s = open("result");
    py::gil_scoped_release release;
    std::lock_guard work(deviceWork());
    render::ObscuranceRenderer& renderer = s.renderer();
    std::vector<std::uint32_t> display = renderer.display();
    renderer.compose(options_.exposure);
    auto image = std::make_shared<const io::Image>(renderer.image());
    nlohmann::json stats = {{"edits", edits_}, {"samples", renderer.samples()},
                            {"device_bytes", renderer.deviceBytes()}, {"device", context_->info().name}};
    return resultOf(relight::currentState(renderer, options_.scenePath), std::move(image), std::move(display),
                    std::move(stats));
  }

  void saveState(const std::string& dir) {
    session::EditSession& s = open("save_state");
    py::gil_scoped_release release;
    std::lock_guard work(deviceWork());
    relight::saveState(dir, s.renderer(), options_.scenePath);
  }

  py::array display() {
    session::EditSession& s = open("display");
    const auto& layout = s.renderer().layout();
    return rgba8Array(static_cast<int>(layout.width), static_cast<int>(layout.height), s.renderer().display());
  }

  std::vector<std::string> lightNames() {
    std::vector<std::string> names;
    const auto& lights = open("light_names").lights();
    for (std::size_t i = 0; i < lights.size(); ++i) names.push_back(lights[i].name);
    return names;
  }

  std::vector<std::string> objectNames() {
    std::vector<std::string> names;
    for (const auto& o : open("object_names").scene().objects)
      if (!o.removed) names.push_back(o.name);
    return names;
  }

  void close() {
    if (!session_) return;
    py::gil_scoped_release release;
    std::lock_guard work(deviceWork());
    session_.reset();
  }
  bool closed() const { return !session_; }

private:
  session::EditSession& open(const char* what) {
    if (!session_) throw InputError(fmt::format("Session.{}: the session is closed", what));
    return *session_;
  }

  std::shared_ptr<Scene> scene_;
  app::RenderOptions options_;
  std::shared_ptr<gpu::Context> context_;
  std::unique_ptr<session::EditSession> session_;
  std::size_t edits_ = 0;
};

} // namespace

void bindSession(py::module_& m) {
  py::class_<Session>(m, "Session", R"(A scene rendered once and then edited: the session of `relight --edits` and the window.

Made with the render settings of obscura.render (keyword arguments) and `spare_lights`, the
lights that add_light edits may add (their buffers are reserved up front). The first frame is
rendered when the session is made. apply(edit) takes one entry of an edits file as a dict:
  {"light": NAME, "scale": S}, {"light": NAME, "color": [r, g, b]}   no ray
  {"add_light": {"type": "point" | "spot" | "quad", ...}}             the new light's rays alone
  {"remove_light": NAME}, {"move_light": NAME, "position": [x, y, z]}
  {"move": OBJECT, "translate": [..], "rotate_deg": [..]}, {"remove": OBJECT},
  {"insert": "other.gltf", "name": N, "translate": [..]}              only the pixels it can change
and returns its report (what `relight --edits` writes to edits.jsonl). result() is the frame
now. close(), or leaving a `with` block, frees its device memory.)")
      .def(py::init<std::shared_ptr<Scene>, const std::vector<std::string>&, std::uint32_t, const py::object&>(),
           py::arg("scene"), py::arg("arguments"), py::arg("spare_lights") = 4, py::arg("progress") = py::none())
      .def("apply", &Session::apply, py::arg("edit"),
           "Applies one edit (a dict, an edits file's entry) and returns its report: kind, name, pixels_retraced, "
           "rays and gpu_ms per pass, bvh, reach, host_ms, cpu_ms, total_ms. InputError (the session unchanged) "
           "for a malformed edit or a name that does not exist.")
      .def("result", &Session::result, "The frame now as a Result (AOVs, light stack, relight(), save_state()).")
      .def("save_state", &Session::saveState, py::arg("dir"),
           "Writes the frame's relighting state to `dir` (state.json, transport.exr) with the edited lights' "
           "emissions, as `render --save-state` does: `obscura relight DIR` and obscura.load_state read it.")
      .def_property_readonly("display", &Session::display,
                             "The frame now, tonemapped (uint8 H x W x 4), from the fast compose every edit ends with.")
      .def_property_readonly("light_names", &Session::lightNames, "The lights now, added ones included.")
      .def_property_readonly("object_names", &Session::objectNames, "The objects now: inserted ones included, removed ones not.")
      .def_property_readonly("closed", &Session::closed)
      .def("close", &Session::close, "Frees the session's device memory; later calls raise InputError.")
      .def("__enter__", [](Session& s) -> Session& { return s; }, py::return_value_policy::reference)
      .def("__exit__", [](Session& s, const py::args&) { s.close(); });
}

} // namespace obscura::python
