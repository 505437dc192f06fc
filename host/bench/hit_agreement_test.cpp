#include "bench/hit_agreement.h"

#include <gtest/gtest.h>

namespace obscura::bench {
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

// Two overlapping coplanar 200-unit quads of Sponza's floor, met 0.3 units from the ray's origin
// about 100 units from the scene's: the CPU's float t (0.31728432, triangle 0) and a GPU's
// (0.31728795, triangle 1) differ by 1.1e-5 relative where the exact t's are equal (0.317287812).
TEST(HitAgreement, ATieOfExactTsIsWithinPrecisionWhereTheFloatTsDiffer) {
  bvh::TriangleSoup soup;
  soup.v0 = {{-108.642f, 131.639f, -40.8146f}, {-108.642f, 90.7745f, -40.8146f}};
  soup.v1 = {{99.7596f, 90.7745f, -40.8146f}, {99.7596f, 130.623f, -40.8146f}};
  soup.v2 = {{-108.642f, 90.7745f, -40.8146f}, {-108.642f, 130.623f, -40.8146f}};
  const bvh::Ray ray{glm::vec3(-83.189156f, 112.65945f, -40.886795f), glm::vec3(-0.9284117f, -0.29373616f, 0.22753191f)};
  const bvh::Hit cpu = cpuHit(0.31728432f, 0.12072014f, 0.3460115f, 0);
  const gpu::GpuHit gpu = gpuHit(0.31728795f, 0.120720126f, 0.4261448f, 1);
  EXPECT_NEAR(exactHit(ray, soup, 0).t, 0.3172880, 1e-6); // (the vertices here are rounded to 7 digits)
  EXPECT_EQ(exactHit(ray, soup, 0).t, exactHit(ray, soup, 1).t);
  EXPECT_TRUE(exactHit(ray, soup, 0).inside && exactHit(ray, soup, 1).inside);
  EXPECT_EQ(closestHitAgreement(ray, cpu, gpu), HitAgreement::Different); // the float t's alone
  EXPECT_EQ(closestHitAgreement(ray, cpu, gpu, &soup), HitAgreement::WithinPrecision);
  // The same quad lifted 1e-3 above the other: the nearer one lost is a traversal error.
  for (auto* v : {&soup.v0, &soup.v1, &soup.v2}) (*v)[1].z -= 1e-3f;
  EXPECT_EQ(closestHitAgreement(ray, cpu, gpuHit(0.3217f, 0.12f, 0.42f, 1), &soup), HitAgreement::Different);
  EXPECT_GT(exactHit(ray, soup, 0).t - exactHit(ray, soup, 1).t, 1e-3);
  // A triangle that the ray does not meet inside is no partner of a tie.
  EXPECT_FALSE(exactHit(bvh::Ray{glm::vec3(200.0f, 112.0f, -41.0f), glm::vec3(0.0f, 0.0f, 1.0f)}, soup, 0).inside);
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
} // namespace obscura::bench
