// obscura recover — reflectance from photographs of one view, one lamp per shot [IVR §4]:
//   obscura recover SCENE --photos lights.json -o DIR [--camera N] [--debug] [--png]
// writes DIR/reflectance.exr (R, G, B, confidence.K = sum of the filtered K_i, filled.id, object.id,
// surface.RGB: the reflectance before the footprints' mix, of the surface each pixel's centre sees,
// which remodel re-lights),
// DIR/recover.json (the scene, camera and lamps, how the estimate converged, what was filled,
// times; with reflectance.exr what `obscura remodel DIR` reads), DIR/state (a relighting
// state of the photographed room with the recovered albedo, for `obscura relight`), with --debug one
// DIR/shot-NNN.exr per photo (its estimate R_i, V_i, filtered K_i, direct and indirect light per
// unit reflectance) and with --png reflectance.png and confidence.png.
// Everything is read and checked before the folder is made: bad input writes nothing.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/named_option.h"
#include "app/render_options.h"
#include "app/scene_setup.h"
#include "core/error.h"
#include "io/image_io.h"
#include "recover/photo_set.h"
#include "recover/recovery_accuracy.h"
#include "recover/recovery_scene.h"
#include "recover/reflectance_recovery.h"

namespace obscura::app {
namespace {
namespace fs = std::filesystem;

struct RecoverOptions {
  std::string scene, photos, output;
  int camera = -1;
  bool noMin = false, noLowerSmoothing = false, noOutlier = false, noFinalSmoothing = false;
  bool debug = false, png = false;
  std::string truth; // an answer key (synthetic photographs): accuracy in recover.json
  recover::RecoveryOptions recovery;
  DeviceOptions device;
};

// The glTF camera the photographs name, checked against --camera and the JSON's size and yfov.
scene::Camera photographedCamera(const scene::Scene& scene, const recover::PhotoSet& photos, int option) {
  if (photos.gltfCamera >= static_cast<int>(scene.cameras.size()))
    throw InputError(fmt::format("{}: camera: gltf_camera {} does not exist: the scene {} has {} cameras", photos.file,
                                 photos.gltfCamera, scene.sourcePath, scene.cameras.size()));
  if (option >= 0 && option != photos.gltfCamera)
    throw InputError(fmt::format("--camera {}: the photographs of {} were taken with the glTF's camera {}", option,
                                 photos.file, photos.gltfCamera));
  const scene::Camera& camera = scene.cameras[static_cast<std::size_t>(photos.gltfCamera)];
  if (photos.yfov > 0.0f && std::abs(photos.yfov - camera.yfov) > 1e-4f * camera.yfov + 1e-6f)
    throw InputError(fmt::format("{}: camera: yfov {} differs from the glTF camera {}'s {} in {}", photos.file, photos.yfov,
                                 photos.gltfCamera, camera.yfov, scene.sourcePath));
  const float aspect = float(photos.width) / float(photos.height);
  if (camera.aspectRatio > 0.0f && std::abs(aspect - camera.aspectRatio) > 1e-3f * camera.aspectRatio)
    throw InputError(fmt::format("{}: camera: {}x{} has aspect {:.4f}, the glTF camera {} has {:.4f} ({})", photos.file,
                                 photos.width, photos.height, aspect, photos.gltfCamera, camera.aspectRatio,
                                 scene.sourcePath));
  return camera;
}

io::Image rgbImage(int width, int height, const std::vector<std::string>& names) {
  io::Image image;
  image.width = width;
  image.height = height;
  image.channels = names;
  image.pixels.assign(std::size_t(width) * height * names.size(), 0.0f);
  return image;
}

void put(io::Image& image, std::size_t p, int first, const glm::vec3& v) {
  for (int c = 0; c < 3; ++c) image.pixels[p * image.channels.size() + std::size_t(first + c)] = v[c];
}
void put(io::Image& image, std::size_t p, int c, float v) { image.pixels[p * image.channels.size() + std::size_t(c)] = v; }

nlohmann::json regionJson(const recover::RegionError& e) { return {{"rmse", e.rmse}, {"pixels", e.pixels}}; }

// RMSE against the answer key per light region (recovery_accuracy.h).
nlohmann::json accuracyJson(const recover::Recovery& r, const std::vector<glm::vec3>& truth) {
  const auto a = recover::recoveryAccuracy(r.reflectance, truth, recover::lightRegions(r.visibility, r.object));
  return {{"lit", regionJson(a.lit)},       {"penumbra", regionJson(a.penumbra)}, {"shadow", regionJson(a.shadow)},
          {"direct", regionJson(a.direct)}, {"all", regionJson(a.all)}};
}

void writeOutputs(const RecoverOptions& o, const recover::Recovery& r, const recover::PhotoSet& photos,
                  const nlohmann::json& accuracy) {
  const fs::path dir(o.output);
  io::Image out = rgbImage(r.width, r.height,
                           {"R", "G", "B", "confidence.K", "filled.id", "object.id", "indirect.shots", "variance.rel",
                            "surface.R", "surface.G", "surface.B"});
  for (std::size_t p = 0; p < r.reflectance.size(); ++p) {
    put(out, p, 0, r.reflectance[p]);
    put(out, p, 3, r.confidence[p]);
    put(out, p, 4, float(r.filled[p]));
    put(out, p, 5, float(r.object[p]));
    put(out, p, 6, r.indirectShots[p]);
    put(out, p, 7, r.relativeVariance[p]);
    put(out, p, 8, r.surfaceReflectance[p]);
  }
  io::writeExr((dir / "reflectance.exr").string(), out);
  if (o.png) {
    io::writePng((dir / "reflectance.png").string(), out, 0, 0.0f, 3);
    io::Image k = rgbImage(r.width, r.height, {"K"});
    for (std::size_t p = 0; p < r.confidence.size(); ++p) put(k, p, 0, r.confidence[p] / float(photos.shots.size()));
    io::writePng((dir / "confidence.png").string(), k, 0, 0.0f, 1);
  }
  if (o.debug) {
    for (std::size_t i = 0; i < photos.shots.size(); ++i) {
      io::Image shot = rgbImage(r.width, r.height, {"estimate.R", "estimate.G", "estimate.B", "visibility.V", "confidence.K",
                                                        "direct.R", "direct.G", "direct.B", "indirect.R", "indirect.G",
                                                        "indirect.B"});
      for (std::size_t p = 0; p < r.reflectance.size(); ++p) {
        put(shot, p, 0, r.estimates[i][p]);
        put(shot, p, 3, r.visibility[i].k[p]);
        put(shot, p, 4, r.confidences[i].k[p]);
        put(shot, p, 5, r.direct[i][p]);
        put(shot, p, 8, r.indirect[i][p]);
      }
      io::writeExr((dir / fmt::format("shot-{:03}.exr", i)).string(), shot);
    }
  }
  nlohmann::json iterations = nlohmann::json::array();
  for (const auto& it : r.iterations) {
    nlohmann::json objects = nlohmann::json::object();
    for (std::size_t k = 0; k < it.objectReflectance.size(); ++k)
      objects[r.objectNames[k]] = {it.objectReflectance[k].x, it.objectReflectance[k].y, it.objectReflectance[k].z};
    iterations.push_back({{"iteration", it.iteration}, {"seconds", it.seconds}, {"rms_change", it.rmsChange},
                          {"object_reflectance", objects}});
  }
  // What `obscura remodel DIR` needs besides reflectance.exr: the scene, camera and lamps.
  nlohmann::json lamps = nlohmann::json::array();
  for (std::size_t i = 0; i < photos.shots.size(); ++i) {
    const recover::Shot& shot = photos.shots[i];
    lamps.push_back({{"name", fmt::format("shot{}", i)},
                     {"position", {shot.position.x, shot.position.y, shot.position.z}},
                     {"intensity", shot.intensity},
                     {"color", {shot.color.x, shot.color.y, shot.color.z}}});
  }
  std::size_t surface = 0;
  for (auto o2 : r.object) surface += o2 >= 0 ? 1 : 0;
  nlohmann::json report = {{"scene", fs::absolute(o.scene).string()},
                           {"gltf_camera", photos.gltfCamera},
                           {"lamps", lamps},
                           {"photos", photos.shots.size()},
                                 {"width", r.width},
                                 {"height", r.height},
                                 {"indirect", nameString(recover::kIndirectModelNames, o.recovery.indirect)},
                                 {"merge", nameString(recover::kMergeModelNames, o.recovery.merge)},
                                 {"surface_pixels", surface},
                                 {"lit_pixels", r.litPixels},
                                 {"indirect_only_pixels", r.indirectOnlyPixels},
                                 {"filled_from_surface", r.filledFromSurface},
                                 {"filled_from_visibility", r.filledFromVisibility},
                                 {"filled_from_object_mean", r.filledFromObject},
                                 {"mixed_from_footprint", r.mixedFromFootprint},
                                 {"textured_pixels", r.texturedPixels},
                                 {"gather_rays_seen", r.gatherSeen},
                                 {"gather_rays_hidden", r.gatherHidden},
                                 {"iterations", iterations},
                                 {"seconds", r.seconds}};
  if (!accuracy.is_null()) report["accuracy"] = accuracy;
  std::ofstream((dir / "recover.json").string()) << report.dump(1) << "\n";
}

void runRecover(RecoverOptions& o) {
  recover::RecoveryOptions& rec = o.recovery;
  rec.filters.minFilter = !o.noMin;
  rec.filters.lowerSmoothing = !o.noLowerSmoothing;
  rec.filters.outlier = !o.noOutlier;
  rec.filters.finalSmoothing = !o.noFinalSmoothing;
  if (!std::isfinite(rec.dMax) || rec.dMax < 0.0f) throw InputError("--dmax must be finite and >= 0");
  if (!(rec.constantReflectance >= 0.0f) || !std::isfinite(rec.constantReflectance))
    throw InputError("--ambient-reflectance must be finite and >= 0");
  // Everything is read and checked before anything is written.
  LoadedScene loaded = loadScene(o.scene);
  const recover::PhotoSet photos = recover::readPhotoSet(o.photos);
  const scene::Camera camera = photographedCamera(loaded.scene, photos, o.camera);
  recover::checkLamps(loaded.scene, loaded.bvh, photos);
  std::vector<glm::vec3> truth;
  if (!o.truth.empty()) {
    int w = 0, h = 0;
    truth = recover::readRadiance(o.truth, 1.0f, w, h);
    if (w != photos.width || h != photos.height)
      throw InputError(fmt::format("{}: the answer key is {}x{}, the photographs {}x{}", o.truth, w, h, photos.width,
                                   photos.height));
  }
  const std::shared_ptr<gpu::Context> contextHandle = commandContext(o.device);
  const gpu::Context& context = *contextHandle;
  const recover::Recovery r = recover::recoverReflectance(
      context, loaded.scene, loaded.bvh, camera, photos, rec, [](const std::string& line) { fmt::print(stderr, "{}\n", line); });
  std::error_code ec;
  fs::create_directories(o.output, ec);
  if (ec || !fs::is_directory(o.output)) throw InputError(fmt::format("{}: cannot create the output folder", o.output));
  nlohmann::json accuracy;
  if (!truth.empty()) {
    accuracy = accuracyJson(r, truth);
    fmt::print(stderr,
               "recover: RMSE against {}: lit {:.4f}, penumbra {:.4f}, shadow {:.4f}; lit in some photo {:.4f}, all {:.4f}\n",
               o.truth, accuracy["lit"]["rmse"].get<double>(), accuracy["penumbra"]["rmse"].get<double>(),
               accuracy["shadow"]["rmse"].get<double>(), accuracy["direct"]["rmse"].get<double>(),
               accuracy["all"]["rmse"].get<double>());
  }
  writeOutputs(o, r, photos, accuracy);
  const auto stateStart = std::chrono::steady_clock::now();
  recover::saveRecoveredState((fs::path(o.output) / "state").string(), loaded.scene.sourcePath, photos, r, rec);
  fmt::print(stderr, "recover: relighting state (lights shot0..shot{}) in {:.1f} s -> {}/state\n",
             photos.shots.size() - 1,
             std::chrono::duration<double>(std::chrono::steady_clock::now() - stateStart).count(), o.output);
  fmt::print(stderr, "recover: {} photos, {}x{}, {} iterations; {} pixels from lit estimates, {} from indirect light "
                     "only; {} filled from their surface nearby, {} from visibility, {} from their object's mean; "
                     "{} mixed from the surfaces their footprint covers; {} on textured objects (smoothed within the "
                     "photographs' noise); {:.1f} s -> {}\n",
             photos.shots.size(), r.width, r.height, r.iterations.size() - 1, r.litPixels, r.indirectOnlyPixels,
             r.filledFromSurface, r.filledFromVisibility, r.filledFromObject, r.mixedFromFootprint, r.texturedPixels,
             r.seconds, o.output);
}

} // namespace

void addRecoverCommand(CLI::App& app) {
  auto o = std::make_shared<RecoverOptions>();
  CLI::App* cmd = app.add_subcommand("recover", "Recover per-pixel reflectance from photographs of one view, one lamp per "
                                                "shot (SCENE --photos lights.json -o DIR)");
  cmd->add_option("scene", o->scene, "the glTF model of the photographed room")->required();
  cmd->add_option("--photos", o->photos, "JSON listing each photograph and its lamp (see host/recover/photo_set.h)")
      ->required();
  cmd->add_option("-o,--output", o->output, "output folder")->required();
  cmd->add_option("--camera", o->camera, "the glTF camera (must be the one the JSON names)");
  cmd->add_option("--spp", o->recovery.spp, "samples per pixel of each lighting render")->check(CLI::Range(1u, 4096u));
  cmd->add_option("--obs-rays", o->recovery.obscuranceRays, "obscurance rays per sample")->check(CLI::Range(1u, 256u));
  cmd->add_option("--seed", o->recovery.seed, "random seed");
  cmd->add_option("--dmax", o->recovery.dMax, "obscurance distance (0: the renderer's default)");
  addNamedOption(*cmd, "--indirect", o->recovery.indirect, recover::kIndirectModelNames,
                 "the indirect light B: gather (from the photographs, iterated), obscurance (the obscurance term with "
                 "the estimate, iterated) or constant (the paper's ambient)");
  cmd->add_option("--iterations", o->recovery.iterations, "estimates after the constant start (gather, obscurance)")
      ->check(CLI::Range(1u, 50u));
  cmd->add_option("--gather-rays", o->recovery.gatherRays, "gather: rays per pixel")->check(CLI::Range(1u, 4096u));
  cmd->add_option("--gather-smoothing", o->recovery.gatherSmoothing,
                  "gather: radius of the window B is averaged over on each surface (0: none)")
      ->check(CLI::Range(0, 32));
  cmd->add_option("--ambient-reflectance", o->recovery.constantReflectance,
                  "k of the constant ambient B = k x mean photo colour");
  addNamedOption(*cmd, "--ambient", o->recovery.ambient, recover::kRecoveryAmbientNames, "I_a model: reached or global");
  cmd->add_option("--eps1", o->recovery.filters.outlierConfidence, "outlier test: confidence a photo needs to vote")
      ->check(CLI::Range(0.0f, 1.0f));
  cmd->add_option("--eps2", o->recovery.filters.outlierDistance, "outlier test: distance from the median that rejects")
      ->check(CLI::Range(0.0f, 100.0f));
  cmd->add_option("--hidden-bounces", o->recovery.hiddenBounces,
                  "gather: path vertices through surfaces the camera does not see before the mean indirect light "
                  "stands in (0: at once)")
      ->check(CLI::Range(0u, recover::kMaxHiddenBounces));
  cmd->add_option("--unseen-reflectance", o->recovery.unseenReflectance,
                  "the grey of objects no photograph shows and no seen object shares a material with (0: the colour "
                  "the model gives them, or for a textured material the seen pixels' mean luminance)")
      ->check(CLI::Range(0.0f, 1.0f));
  addNamedOption(*cmd, "--merge", o->recovery.merge, recover::kMergeModelNames,
                 "how the photos' estimates merge: weighted (by their expected error, pixels no lamp lights recovered "
                 "from their indirect light, smoothed along surfaces by their noise) or paper (IVR eq. 3)");
  cmd->add_option("--indirect-uncertainty", o->recovery.weighted.indirectUncertainty,
                  "weighted: relative error assumed of the modelled indirect light")
      ->check(CLI::Range(0.001f, 10.0f));
  cmd->add_option("--smoothing-radius", o->recovery.weighted.smoothingRadius,
                  "weighted: window radius of the kept merge's smoothing over each object (the iterations' at most 3; 0: none)")
      ->check(CLI::Range(0, 32));
  cmd->add_flag("--no-min-filter", o->noMin, "skip the 5x5 min filter");
  cmd->add_flag("--no-lower-smoothing", o->noLowerSmoothing, "skip the 5x5 lowering smoothing");
  cmd->add_flag("--no-outlier", o->noOutlier, "skip the outlier test");
  cmd->add_flag("--no-final-smoothing", o->noFinalSmoothing, "skip the 3x3 smoothing");
  cmd->add_flag("--debug", o->debug, "also write shot-NNN.exr: each photo's estimate, visibility, filtered confidence, direct and indirect light per unit reflectance");
  cmd->add_flag("--png", o->png, "also write reflectance.png and confidence.png");
  cmd->add_option("--truth", o->truth,
                  "the true reflectance (EXR; synthetic photographs only): RMSE per light region in recover.json");
  addDeviceOptions(*cmd, o->device);
  cmd->callback([o] { runRecover(*o); });
}

} // namespace obscura::app
