// `obscura recover` as a user runs it: a run on two of the Cycles photographs writes the
// reflectance (with its confidence layer), the report, a relighting state whose albedo is the
// recovered one (relit with one lamp, it gives back that lamp's photograph) and, with
// --debug/--png, the per-photo images, and `obscura remodel` relights and remodels that folder;
// bad input (photos of different sizes, a lamp inside geometry, another camera, an unreadable
// image, a missing field) is a clear error naming the file, exit 2, nothing written.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/cli_runner.h"
#include "gpu_test.h"
#include "io/image_io.h"

namespace obscura::test {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

class CliRecover : public CliTest {
protected:
  static std::string photosDir() { return sharedScene("../photos/cornell-box"); }
  static std::string scene() { return sharedScene("cornell-box/cornell-box.gltf"); }
  // The photographs' JSON with its first `shots` shots, images as absolute paths.
  static json lights(std::size_t shots) {
    std::ifstream in(photosDir() + "/lights.json");
    json doc = json::parse(in);
    doc["shots"].erase(doc["shots"].begin() + static_cast<std::ptrdiff_t>(shots), doc["shots"].end());
    for (auto& s : doc["shots"]) s["image"] = photosDir() + "/" + s["image"].get<std::string>();
    return doc;
  }
  static json doc0() { return lights(1); }
  std::string write(const json& doc, const std::string& name = "lights.json") {
    std::ofstream(path(name)) << doc.dump(1);
    return path(name);
  }
  // Runs recover on `doc` (plus `extra`) and expects a clear error mentioning `mention`, exit
  // 2 and no output folder.
  void expectBadInput(const json& doc, const std::string& mention, const std::string& extra = "") {
    const std::string file = write(doc);
    const auto r = runObscura("recover " + scene() + " --photos " + file + " -o " + path("out") + " --spp 1 " + extra);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_CONTAINS(r.output, mention);
    EXPECT_FALSE(fs::exists(path("out"))) << "a failed recover wrote its folder";
  }
};

TEST_F(CliRecover, WritesReflectanceWithConfidenceAndThePerPhotoImages) {
  const std::string file = write(lights(2));
  const auto r = runObscura("recover " + scene() + " --photos " + file + " -o " + path("out") +
                            " --spp 1 --gather-rays 8 --iterations 1 --debug --png --truth " + photosDir() + "/albedo.exr");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const io::Image image = io::readImage(path("out/reflectance.exr"));
  EXPECT_EQ(image.width, 256);
  EXPECT_GE(image.channelIndex("R"), 0);
  EXPECT_GE(image.channelIndex("confidence.K"), 0);
  for (const char* f : {"recover.json", "reflectance.png", "confidence.png", "shot-000.exr", "shot-001.exr",
                        "state/state.json", "state/transport.exr"})
    EXPECT_TRUE(fs::exists(path(std::string("out/") + f))) << f;
  EXPECT_FALSE(fs::exists(path("out/shot-002.exr")));
  std::ifstream in(path("out/recover.json"));
  const json report = json::parse(in);
  EXPECT_EQ(report["photos"], 2);
  EXPECT_EQ(report["iterations"].size(), 2u);
  EXPECT_GT(report["accuracy"]["lit"]["pixels"].get<int>(), 0);

  // The relighting state: `relight` composes it, and its direct light for shot 0 is the recovered
  // reflectance times the lamp's direct light per unit reflectance (what the estimate divided by).
  const auto relit = runObscura("relight " + path("out/state") + " --light shot0=0.5 -o " + path("relit.exr"));
  ASSERT_EQ(relit.exitCode, 0) << relit.output;
  const io::Image transport = io::readImage(path("out/state/transport.exr"));
  const io::Image shot = io::readImage(path("out/shot-000.exr"));
  const int d = transport.channelIndex("D.shot0.R"), direct = shot.channelIndex("direct.R"), k = shot.channelIndex("confidence.K");
  ASSERT_GE(d, 0);
  ASSERT_GE(direct, 0);
  const float intensity = doc0()["shots"][0]["gltf_light"]["intensity"].get<float>();
  int checked = 0, agree = 0;
  for (int y = 0; y < 256; y += 4)
    for (int x = 0; x < 256; x += 4) {
      if (shot.at(x, y, k) < 0.99f || shot.at(x, y, direct) < 0.05f) continue; // interior, lit
      ++checked;
      const float expected = image.at(x, y, 0) * shot.at(x, y, direct);
      agree += std::abs(transport.at(x, y, d) * intensity - expected) <= 0.01f * expected ? 1 : 0;
    }
  EXPECT_GT(checked, 500);
  EXPECT_GE(agree, checked * 95 / 100) << agree << " of " << checked;

  // Relit with one photographed lamp alone, the state gives back that lamp's photograph: each lamp
  // carries its own indirect light as the photographs measured it. Within the relighting goal
  // (mean within 2 %, median error of 8x8 block means at most 5 %); at these settings both shots
  // give 0.3-0.6 % and 1.9-2.2 %. The obscurance term the state held before missed by 7-33 %.
  for (int shotIndex = 0; shotIndex < 2; ++shotIndex) {
    const std::string out = path(fmt::format("relit-{}.exr", shotIndex));
    const auto alone = runObscura("relight " + path("out/state") + fmt::format(" --light shot0={} --light shot1={} -o ",
                                                                               shotIndex == 0 ? 1 : 0, shotIndex) + out);
    ASSERT_EQ(alone.exitCode, 0) << alone.output;
    const io::Image relitImage = io::readImage(out);
    const io::Image photo = io::readImage(lights(2)["shots"][shotIndex]["image"].get<std::string>());
    const int combined = relitImage.channelIndex("combined.R");
    ASSERT_GE(combined, 0);
    ASSERT_EQ(photo.width, relitImage.width);
    const auto luminance = [](const io::Image& im, int x, int y, int c0) {
      return (im.at(x, y, c0) + im.at(x, y, c0 + 1) + im.at(x, y, c0 + 2)) / 3.0;
    };
    double relitSum = 0.0, photoSum = 0.0;
    std::vector<double> blockErrors;
    for (int by = 0; by + 8 <= photo.height; by += 8)
      for (int bx = 0; bx + 8 <= photo.width; bx += 8) {
        double a = 0.0, b = 0.0;
        for (int y = by; y < by + 8; ++y)
          for (int x = bx; x < bx + 8; ++x) {
            a += luminance(relitImage, x, y, combined);
            b += luminance(photo, x, y, 0);
          }
        relitSum += a;
        photoSum += b;
        if (b > 0.0) blockErrors.push_back(std::abs(a - b) / b);
      }
    ASSERT_GT(blockErrors.size(), 900u);
    std::nth_element(blockErrors.begin(), blockErrors.begin() + blockErrors.size() / 2, blockErrors.end());
    EXPECT_NEAR(relitSum / photoSum, 1.0, 0.02) << "shot " << shotIndex;
    EXPECT_LE(blockErrors[blockErrors.size() / 2], 0.05) << "shot " << shotIndex;
  }

  // `remodel` on the folder: both photographed lamps off, a new one on, the short box removed.
  const json edits = json::array({{{"light", "shot0"}, {"scale", 0}},
                                  {{"remove_light", "shot1"}},
                                  {{"add_light", {{"type", "point"}, {"name", "lamp"}, {"position", {0.45, 1.55, -0.1}},
                                                  {"color", {1, 1, 1}}, {"intensity", 2.387}}}},
                                  {{"remove", "cube_1"}}});
  std::ofstream(path("edits.json")) << edits.dump();
  const auto remodel = runObscura("remodel " + path("out") + " --edits " + path("edits.json") + " -o " +
                                  path("remodel.exr") + " --spp 1 --gather-rays 8 --bounces 2 --hidden-bounces 2");
  ASSERT_EQ(remodel.exitCode, 0) << remodel.output;
  const io::Image frame = io::readImage(path("remodel.exr"));
  const int synthesized = frame.channelIndex("synthesized.id");
  ASSERT_GE(synthesized, 0);
  for (const char* c : {"R", "reflectance.R", "direct.R", "indirect.R"}) EXPECT_GE(frame.channelIndex(c), 0) << c;
  int filled = 0, lit = 0;
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) {
      filled += frame.at(x, y, synthesized) > 0.5f ? 1 : 0;
      lit += frame.at(x, y, 0) > 0.01f ? 1 : 0;
    }
  EXPECT_GT(filled, 3000); // what the short box covered
  EXPECT_GT(lit, 30000);   // the new lamp lights the room
  // Pixels whose footprint covers two surfaces: R is their mix, surface.RGB the estimate of the
  // centre's surface, and remodel re-lights the latter (an edit changes what a footprint covers).
  const int surface = image.channelIndex("surface.R"), reflectance = frame.channelIndex("reflectance.R");
  ASSERT_GE(surface, 0);
  EXPECT_GT(report["mixed_from_footprint"].get<int>(), 500);
  int mixed = 0, relitAsSurface = 0;
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) {
      const float own = image.at(x, y, surface);
      if (frame.at(x, y, synthesized) > 0.5f || std::abs(own - image.at(x, y, 0)) < 0.01f) continue;
      ++mixed;
      relitAsSurface += std::abs(frame.at(x, y, reflectance) - own) <= 1e-3f * own + 1e-6f ? 1 : 0;
    }
  EXPECT_GT(mixed, 100);
  EXPECT_EQ(relitAsSurface, mixed);

  // Bad remodel input, on the same folder: a clear error naming it, exit 2, nothing written.
  auto refused = [&](const json& bad, const std::string& mention) {
    std::ofstream(path("e.json")) << bad.dump();
    const auto result = runObscura("remodel " + path("out") + " --edits " + path("e.json") + " -o " + path("x.exr"));
    EXPECT_EQ(result.exitCode, 2) << result.output;
    EXPECT_CONTAINS(result.output, mention);
    EXPECT_FALSE(fs::exists(path("x.exr")));
  };
  refused(json::array({{{"move", "cube_1"}, {"translate", {0, 0, 0.1}}}}), "moving a photographed object");
  refused(json::array({{{"remove", "sofa"}}}), "sofa");
  refused(json::array({{{"light", "shot0"}, {"scale", 0}}, {{"light", "shot1"}, {"scale", 0}}}), "no lamp is left on");
  refused(json::array({{{"add_light", {{"type", "point"}, {"name", "lamp"}, {"position", {0.33, 0.3, 0.37}},
                                       {"color", {1, 1, 1}}, {"intensity", 1}}}}}),
          "inside geometry");
  const auto tooDeep = runObscura("remodel " + path("out") + " --edits " + path("edits.json") + " -o " + path("x.exr") +
                                  " --hidden-bounces 9");
  EXPECT_NE(tooDeep.exitCode, 0) << tooDeep.output;
  EXPECT_CONTAINS(tooDeep.output, "--hidden-bounces");
  EXPECT_FALSE(fs::exists(path("x.exr")));
  fs::create_directories(path("notrecovered"));
  const auto notRecovered = runObscura("remodel " + path("notrecovered") + " --edits " + path("e.json") + " -o " + path("x.exr"));
  EXPECT_EQ(notRecovered.exitCode, 2) << notRecovered.output;
  EXPECT_CONTAINS(notRecovered.output, "recover.json: missing");
}

TEST_F(CliRecover, PhotosOfDifferentSizesAreRefusedNamingTheImage) {
  io::Image small;
  small.width = small.height = 8;
  small.channels = {"R", "G", "B"};
  small.pixels.assign(8 * 8 * 3, 0.5f);
  io::writeExr(path("small.exr"), small);
  json doc = lights(2);
  doc["shots"][1]["image"] = path("small.exr");
  expectBadInput(doc, "small.exr: the image is 8x8");
}

TEST_F(CliRecover, AnUnreadableImageIsRefusedNamingIt) {
  std::ofstream(path("broken.exr")) << "not an image";
  json doc = lights(2);
  doc["shots"][0]["image"] = path("broken.exr");
  expectBadInput(doc, "broken.exr: cannot read image");
}

TEST_F(CliRecover, AMissingFieldIsRefusedNamingTheJsonShotAndField) {
  json doc = lights(2);
  doc["shots"][1].erase("position");
  expectBadInput(doc, "lights.json: shots: entry 1: 'position' is missing");
  doc = lights(2);
  doc.erase("camera");
  expectBadInput(doc, "lights.json: 'camera'");
}

TEST_F(CliRecover, ALampInsideGeometryIsRefused) {
  json doc = lights(2);
  doc["shots"][1]["position"] = {0.0, 0.02, 0.0}; // 0.02 above the floor, radius 0.04
  expectBadInput(doc, "shots entry 1: the lamp at (0, 0.02, 0) is inside geometry");
  doc = lights(2);
  doc["shots"][0]["position"] = {0.33, 0.3, 0.37}; // inside the short box
  doc["shots"][0]["radius"] = 0.0;
  expectBadInput(doc, "shots entry 0: the lamp at (0.33, 0.3, 0.37) is inside geometry");
}

TEST_F(CliRecover, ACameraOtherThanTheGltfsIsRefused) {
  json doc = lights(2);
  doc["camera"]["gltf_camera"] = 3;
  expectBadInput(doc, "gltf_camera 3 does not exist");
  doc = lights(2);
  doc["camera"]["yfov"] = 0.5;
  expectBadInput(doc, "yfov 0.5 differs from the glTF camera 0");
  doc = lights(2);
  doc["camera"]["width"] = 320;
  expectBadInput(doc, "the image is 256x256"); // the photos are not the camera's size
  expectBadInput(lights(2), "--camera 1: the photographs", "--camera 1");
}

} // namespace
} // namespace obscura::test
