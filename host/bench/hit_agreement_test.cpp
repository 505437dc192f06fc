#include "bench/hit_agreement.h"

#include <gtest/gtest.h>

namespace obscura::render {
namespace {

const bvh::Ray kRay{glm::vec3(0.0f), glm::vec3(0.0f, 0.0f, 1.0f), 0.0f, 10.0f};

bvh::Hit cpuHit(float t, float u, float v, std::uint32_t primitive) { return {t, u, v, primitive}; }
gpu::GpuHit gpuHit(float t, float u, float v, std::uint32_t primitive) { return {t, u, v, primitive}; }
const bvh::Hit kCpuMiss{};
const gpu::GpuHit kGpuMiss{10.0f, 0.0f, 0.0f, gpu::kInvalidIndex};

TEST(HitAgreement, TheSameTriangleAgrees) {
  EXPECT_EQ(closestHitAgreement(kRay, cpuHit(2.0f, 0.3f, 0.3f, 7), gpuHit(2.0f, 0.3f, 0.3f, 7)), HitAgreement::Same);
  EXPECT_EQ(closestHitAgreement(kRay, kCpuMiss, kGpuMiss), HitAgreement::Same);
}

TEST(HitAgreement, ATieInTOrAGrazedEdgeIsWithinPrecision) {
  // Two triangles sharing the edge the ray meets: the same t, either is right.
  EXPECT_EQ(closestHitAgreement(kRay, cpuHit(2.0f, 0.5f, 0.5f, 7), gpuHit(2.000001f, 0.0f, 0.5f, 8)),
            HitAgreement::WithinPrecision);
  // The GPU missed a triangle the CPU hit at its edge, and saw the one behind it.
  EXPECT_EQ(closestHitAgreement(kRay, cpuHit(2.0f, 0.00002f, 0.4f, 7), gpuHit(5.0f, 0.3f, 0.3f, 9)),
            HitAgreement::WithinPrecision);
  // ...or missed everything; or saw a grazed edge the CPU missed.
  EXPECT_EQ(closestHitAgreement(kRay, cpuHit(2.0f, 0.4f, 0.59999f, 7), kGpuMiss), HitAgreement::WithinPrecision);
  EXPECT_EQ(closestHitAgreement(kRay, kCpuMiss, gpuHit(2.0f, 0.4f, 0.00001f, 7)), HitAgreement::WithinPrecision);
  // A hit at the ray's far end.
  EXPECT_EQ(closestHitAgreement(kRay, kCpuMiss, gpuHit(9.99999f, 0.3f, 0.3f, 7)), HitAgreement::WithinPrecision);
}

TEST(HitAgreement, ALostInteriorHitIsATraversalError) {
  EXPECT_EQ(closestHitAgreement(kRay, cpuHit(2.0f, 0.3f, 0.3f, 7), kGpuMiss), HitAgreement::Different);
  EXPECT_EQ(closestHitAgreement(kRay, cpuHit(2.0f, 0.3f, 0.3f, 7), gpuHit(5.0f, 0.0f, 0.3f, 9)),
            HitAgreement::Different); // the GPU's farther hit grazes an edge, but the nearer one is lost
  EXPECT_EQ(closestHitAgreement(kRay, kCpuMiss, gpuHit(2.0f, 0.3f, 0.3f, 7)), HitAgreement::Different);
  EXPECT_EQ(closestHitAgreement(kRay, cpuHit(2.0f, 0.3f, 0.3f, 7), gpuHit(2.0f, 0.3f, 0.3f, gpu::kTruncatedHit)),
            HitAgreement::Different);
}

TEST(HitAgreement, ShadowRaysDisagreeWithinPrecisionOnlyAtAnEdgeOrAnEnd) {
  EXPECT_EQ(anyHitAgreement(kRay, true, cpuHit(2.0f, 0.3f, 0.3f, 7), gpuHit(4.0f, 0.2f, 0.2f, 9)), HitAgreement::Same);
  EXPECT_EQ(anyHitAgreement(kRay, true, cpuHit(2.0f, 0.3f, 0.00001f, 7), kGpuMiss), HitAgreement::WithinPrecision);
  EXPECT_EQ(anyHitAgreement(kRay, false, kCpuMiss, gpuHit(2.0f, 0.99995f, 0.00001f, 7)),
            HitAgreement::WithinPrecision);
  EXPECT_EQ(anyHitAgreement(kRay, true, cpuHit(2.0f, 0.3f, 0.3f, 7), kGpuMiss), HitAgreement::Different);
  EXPECT_EQ(anyHitAgreement(kRay, false, kCpuMiss, gpuHit(2.0f, 0.3f, 0.3f, 7)), HitAgreement::Different);
}

} // namespace
} // namespace obscura::render
