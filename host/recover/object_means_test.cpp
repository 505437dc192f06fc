// object_means_test.cpp — each object's recovered mean, and the guess for the objects no
// photograph shows (reflectance_recovery.h objectMeans).
#include "recover/reflectance_recovery.h"

#include <gtest/gtest.h>

namespace obscura::recover {
namespace {

TEST(ObjectMeans, AnUnseenObjectTakesItsMaterialsSeenMeanElseTheGreyOfEverySeenPixel) {
  // Four pixels: object 0 (material 7) at 0.2 and 0.4 with confidences 1 and 3, object 1
  // (material 9) at 0.9 (grey, so that the sums below read simply; a colour follows), a pixel of
  // nothing, one of object 0 with no confidence (not counted).
  const std::vector<glm::vec3> reflectance{glm::vec3(0.2f), glm::vec3(0.4f), glm::vec3(0.9f), glm::vec3(5.0f),
                                           glm::vec3(5.0f)};
  const std::vector<float> confidence{1.0f, 3.0f, 4.0f, 1.0f, 0.0f};
  const std::vector<std::int32_t> object{0, 0, 1, -1, 0};
  // Objects 2 (material 7, unseen) and 3 (material 8, which no seen object has).
  const std::vector<std::uint32_t> material{7, 9, 7, 8};
  const std::vector<glm::vec3> means = objectMeans(reflectance, confidence, object, 4, &material);
  EXPECT_FLOAT_EQ(means[0].x, 0.35f);          // (0.2 + 3 x 0.4) / 4
  EXPECT_FLOAT_EQ(means[1].x, 0.9f);
  EXPECT_FLOAT_EQ(means[2].x, 0.35f);          // object 0's material
  EXPECT_FLOAT_EQ(means[3].x, 5.0f / 8.0f);   // every confident pixel: (0.2 + 1.2 + 3.6) / 8
  // Without the materials every unseen object takes the mean of all.
  const std::vector<glm::vec3> plain = objectMeans(reflectance, confidence, object, 4);
  EXPECT_FLOAT_EQ(plain[2].x, 5.0f / 8.0f);
  // A coloured room (warm wood, seen alone): a seen object keeps its colour, an object of an unseen
  // material takes a neutral grey of the seen mean's luminance, not the wood's cast.
  const glm::vec3 wood(0.6f, 0.4f, 0.2f);
  const std::vector<glm::vec3> coloured = objectMeans({wood}, {1.0f}, {0}, 2, &material);
  EXPECT_FLOAT_EQ(coloured[0].z, 0.2f);
  const float grey = 0.2126f * 0.6f + 0.7152f * 0.4f + 0.0722f * 0.2f;
  EXPECT_NEAR(coloured[1].x, grey, 1e-6f);
  EXPECT_NEAR(coloured[1].z, grey, 1e-6f);
}

} // namespace
} // namespace obscura::recover
