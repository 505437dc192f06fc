#include "scene.h"

#include <pybind11/stl.h>

#include "app/scene_setup.h"
#include "bindings.h"
#include "render/scene_data/bvh_layout.h"
#include "render/scene_data/free_path.h"
#include "render/scene_data/light_set.h"
#include "render/scene_data/scene_buffers.h"
#include "scene/scene_edit.h"

namespace py = pybind11;

namespace obscura::python {

Scene::Scene(const std::string& path, const std::string& lightGroups)
    : path_(path), lightGroups_(lightGroups),
      scene_(std::make_shared<const scene::Scene>(app::loadScene(path, lightGroups, std::nullopt).scene)) {}

std::shared_ptr<const bvh::Bvh> Scene::treeFor(const gpu::Context& context) const {
  const render::Traversal traversal = render::traversalFor(context);
  std::lock_guard lock(treesMutex_);
  auto& tree = trees_[static_cast<std::uint32_t>(traversal)];
  if (!tree)
    tree = std::make_shared<const bvh::Bvh>(bvh::build(render::triangleSoup(*scene_), render::treeOptionsFor(traversal)));
  return tree;
}

namespace {

py::tuple vec3(const glm::vec3& v) { return py::make_tuple(v.x, v.y, v.z); }

py::list lightsOf(const scene::Scene& s) {
  const render::LightSet lights = render::buildLightSet(s);
  py::list out;
  for (std::size_t i = 0; i < lights.size(); ++i) {
    py::dict light;
    light["name"] = lights.names[i];
    light["type"] = nameString(render::kLightTypeNames, lights.type(i));
    light["emission"] = vec3(lights.emission[i]);
    light["power"] = lights.power[i];
    light["triangles"] = i < s.lightGroups.size() ? s.lightGroups[i].triangles.size() : 0;
    out.append(light);
  }
  return out;
}

py::list objectsOf(const scene::Scene& s) {
  py::list out;
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    const scene::Bounds b = scene::objectBounds(s, i);
    py::dict object;
    object["name"] = s.objects[i].name;
    object["triangles"] = s.objects[i].triangleCount;
    object["bounds"] = py::make_tuple(vec3(b.lo), vec3(b.hi));
    out.append(object);
  }
  return out;
}

py::list camerasOf(const scene::Scene& s) {
  py::list out;
  for (const auto& c : s.cameras) {
    py::dict camera;
    camera["name"] = c.name;
    camera["position"] = vec3(c.position);
    camera["forward"] = vec3(c.forward);
    camera["up"] = vec3(c.up);
    camera["yfov"] = c.yfov;
    camera["aspect_ratio"] = c.aspectRatio;
    out.append(camera);
  }
  return out;
}

} // namespace

void bindScene(py::module_& m) {
  py::class_<Scene, std::shared_ptr<Scene>>(m, "Scene", R"(A glTF 2.0 scene, opened once.

Loading checks the whole file (a bad one raises InputError naming the file and element) and
makes the light groups: "node" (one light per emissive mesh node), "material" (one per emissive
material) or a JSON file of groups. Renders and sessions made from one Scene share it.)")
      .def(py::init([](const std::string& path, const std::string& lightGroups) {
             py::gil_scoped_release release;
             return std::make_shared<Scene>(path, lightGroups);
           }),
           py::arg("path"), py::arg("light_groups") = "node")
      .def_property_readonly("path", &Scene::path, "The glTF file.")
      .def_property_readonly("light_groups", &Scene::lightGroups, "How emissive meshes were grouped into lights.")
      .def_property_readonly(
          "lights", [](const Scene& s) { return lightsOf(s.scene()); },
          "The lights in the renderer's order: name, type (area, point, spot, directional, background), "
          "emission E_s, power, triangles (area lights). Their names are relight()'s and edits' keys.")
      .def_property_readonly(
          "light_names", [](const Scene& s) { return render::buildLightSet(s.scene()).names; }, "The lights' names.")
      .def_property_readonly(
          "objects", [](const Scene& s) { return objectsOf(s.scene()); },
          "The objects (glTF mesh nodes): name, triangles, world bounds ((lo), (hi)); names for move and remove edits.")
      .def_property_readonly(
          "cameras", [](const Scene& s) { return camerasOf(s.scene()); },
          "The glTF cameras (camera=N renders with the N-th): name, position, forward, up, yfov (radians).")
      .def_property_readonly(
          "bounds", [](const Scene& s) { return py::make_tuple(vec3(s.scene().bounds.lo), vec3(s.scene().bounds.hi)); },
          "The scene's world bounds ((lo), (hi)).")
      .def_property_readonly(
          "triangles", [](const Scene& s) { return s.scene().triangles.size(); }, "Triangles (degenerate ones dropped).")
      .def("info", [](const Scene& s) {
             py::dict info;
             const scene::Scene& sc = s.scene();
             info["path"] = s.path();
             info["triangles"] = sc.triangles.size();
             info["materials"] = sc.materials.size();
             info["textures"] = sc.textures.size();
             info["bounds"] = py::make_tuple(vec3(sc.bounds.lo), vec3(sc.bounds.hi));
             info["lights"] = lightsOf(sc);
             info["objects"] = objectsOf(sc);
             info["cameras"] = camerasOf(sc);
             return info;
           },
           "Everything `obscura info SCENE` lists, as a dict.")
      .def("__repr__", [](const Scene& s) {
        return "<obscura.Scene '" + s.path() + "': " + std::to_string(s.scene().triangles.size()) + " triangles, " +
               std::to_string(render::buildLightSet(s.scene()).size()) + " lights>";
      });
}

} // namespace obscura::python
