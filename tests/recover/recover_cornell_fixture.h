// recover_cornell_fixture.h — the six Blender Cycles photographs of the Cornell box
// (shared/photos/cornell-box), the room, the answer key, and one recovery at the tests' default
// settings computed once for every test that only reads it (it takes ~10 s on lavapipe).
#pragma once
#include <memory>

#include "app/scene_setup.h"
#include "gpu_test.h"
#include "recover/photo_set.h"
#include "recover/recovery_accuracy.h"
#include "recover/reflectance_recovery.h"

namespace obscura::test {

class RecoverCornell : public GpuTest {
protected:
  static void SetUpTestSuite() {
    room_ = std::make_unique<app::LoadedScene>(app::loadScene(sharedScene("cornell-box/cornell-box.gltf")));
    photos_ = std::make_unique<recover::PhotoSet>(recover::readPhotoSet(sharedScene("../photos/cornell-box/lights.json")));
    int w = 0, h = 0;
    truth_ = std::make_unique<std::vector<glm::vec3>>(
        recover::readRadiance(sharedScene("../photos/cornell-box/albedo.exr"), 1.0f, w, h));
  }
  static void TearDownTestSuite() {
    room_.reset();
    photos_.reset();
    truth_.reset();
  }
  // The tests' settings: spp 4 (0.0015 of overall RMSE from the default 16, BENCHMARKS).
  static recover::RecoveryOptions options() {
    recover::RecoveryOptions o;
    o.spp = 4;
    return o;
  }
  recover::Recovery recover(const recover::RecoveryOptions& o, const recover::PhotoSet& photos) {
    return recover::recoverReflectance(context(), room_->scene, room_->bvh, camera(), photos, o);
  }
  // The recovery from all six photographs at options(), made on first use and kept for the
  // whole test program (a pure function of the inputs).
  const recover::Recovery& standardRecovery() {
    if (!standard_) standard_ = std::make_shared<recover::Recovery>(recover(options(), *photos_));
    return *standard_;
  }
  static const scene::Camera& camera() { return room_->scene.cameras.at(0); }
  static recover::RecoveryAccuracy accuracy(const recover::Recovery& r) {
    return recover::recoveryAccuracy(r.reflectance, *truth_, recover::lightRegions(r.visibility, r.object));
  }
  static inline std::unique_ptr<app::LoadedScene> room_;
  static inline std::unique_ptr<recover::PhotoSet> photos_;
  static inline std::unique_ptr<std::vector<glm::vec3>> truth_;
  static inline std::shared_ptr<recover::Recovery> standard_;
};

} // namespace obscura::test
