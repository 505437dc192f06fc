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
  // A grey the user knows (--unseen-reflectance) replaces only that guess: not a seen object's
  // mean, nor an unseen object's material mean.
  const std::vector<glm::vec3> told = objectMeans(reflectance, confidence, object, 4, &material, nullptr, 0.8f);
  EXPECT_FLOAT_EQ(told[0].x, 0.35f);
  EXPECT_FLOAT_EQ(told[2].x, 0.35f);
  EXPECT_FLOAT_EQ(told[3].x, 0.8f);
  EXPECT_FLOAT_EQ(told[3].z, 0.8f);
  // The colour the model gives an object of a material no photograph shows replaces the grey
  // (object 3); not a seen object's mean, nor an unseen object's material mean (object 2); and the
  // user's grey comes first.
  const glm::vec3 white(0.8f, 0.8f, 0.75f);
  const std::vector<std::optional<glm::vec3>> model{glm::vec3(0.1f), glm::vec3(0.1f), glm::vec3(0.1f), white};
  const std::vector<glm::vec3> modelled =
      objectMeans(reflectance, confidence, object, 4, &material, nullptr, std::nullopt, nullptr, &model);
  EXPECT_FLOAT_EQ(modelled[0].x, 0.35f);
  EXPECT_FLOAT_EQ(modelled[2].x, 0.35f);
  EXPECT_FLOAT_EQ(modelled[3].z, 0.75f);
  const std::vector<std::optional<glm::vec3>> textured{std::nullopt, std::nullopt, std::nullopt, std::nullopt};
  EXPECT_FLOAT_EQ(objectMeans(reflectance, confidence, object, 4, &material, nullptr, std::nullopt, nullptr, &textured)[3].x,
                  5.0f / 8.0f);
  EXPECT_FLOAT_EQ(objectMeans(reflectance, confidence, object, 4, &material, nullptr, 0.8f, nullptr, &model)[3].z, 0.8f);
}

TEST(ObjectMeans, ObjectsOfOneColourInTheModelShareTheirMaterialsMeanAndTexturedOnesKeepTheirOwn) {
  // Objects 0 and 1 are of one untextured material (7): a wall merged at 0.6 with weight 9 and a
  // sliver beside wood that measured the wood's 0.3 with weight 1; objects 2 and 3 share a
  // textured material (8, not one colour): 0.2 and 0.8 stay apart. Object 4, of material 7 too but
  // not one colour (part of it another material), keeps its own 0.9.
  const std::vector<glm::vec3> reflectance{glm::vec3(0.6f), glm::vec3(0.3f), glm::vec3(0.2f), glm::vec3(0.8f),
                                           glm::vec3(0.9f)};
  const std::vector<float> confidence{9.0f, 1.0f, 1.0f, 1.0f, 1.0f};
  const std::vector<std::int32_t> object{0, 1, 2, 3, 4};
  const std::vector<std::uint32_t> material{7, 7, 8, 8, 7};
  const std::vector<bool> oneColour{true, true, false, false, false};
  const std::vector<glm::vec3> means =
      objectMeans(reflectance, confidence, object, 5, &material, nullptr, std::nullopt, &oneColour);
  EXPECT_FLOAT_EQ(means[0].x, 0.57f); // (9 x 0.6 + 0.3) / 10
  EXPECT_FLOAT_EQ(means[1].x, 0.57f);
  EXPECT_FLOAT_EQ(means[2].x, 0.2f);
  EXPECT_FLOAT_EQ(means[3].x, 0.8f);
  EXPECT_FLOAT_EQ(means[4].x, 0.9f);
  // Without the flags each object keeps its own.
  EXPECT_FLOAT_EQ(objectMeans(reflectance, confidence, object, 5, &material)[1].x, 0.3f);
}

TEST(ObjectMeans, AnObjectSeenButNeverMergedTakesWhatItsPhotographsSayNotTheUnknownGrey) {
  // Object 0 merged at 0.5; object 1 seen in two pixels, neither merged (a sliver in a penumbra),
  // nearly black; object 2 seen in one pixel nothing lights.
  const std::vector<std::int32_t> object{0, 1, 1, 2};
  const std::vector<glm::vec3> reflectance{glm::vec3(0.5f), glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f)};
  const std::vector<float> confidence{1.0f, 0.0f, 0.0f, 0.0f};
  // Two shots: the photographs' sums over object 1 are 0.01 + 0.03 and 0.02 + 0.02; its light's
  // (D + B) 0.2 + 0.6 and 0.4 + 0.4: the ratio 0.08 / 1.6 = 0.05, whatever the split.
  const std::vector<std::vector<glm::vec3>> photos{{glm::vec3(0.6f), glm::vec3(0.01f), glm::vec3(0.03f), glm::vec3(0.0f)},
                                                   {glm::vec3(0.6f), glm::vec3(0.02f), glm::vec3(0.02f), glm::vec3(0.0f)}};
  const std::vector<std::vector<glm::vec3>> direct{{glm::vec3(0.8f), glm::vec3(0.1f), glm::vec3(0.0f), glm::vec3(0.0f)},
                                                   {glm::vec3(0.8f), glm::vec3(0.0f), glm::vec3(0.4f), glm::vec3(0.0f)}};
  const std::vector<std::vector<glm::vec3>> indirect{{glm::vec3(0.2f), glm::vec3(0.1f), glm::vec3(0.6f), glm::vec3(0.0f)},
                                                     {glm::vec3(0.2f), glm::vec3(0.4f), glm::vec3(0.0f), glm::vec3(0.0f)}};
  const auto ratios = photographedRatios(photos, direct, indirect, object, 3);
  ASSERT_TRUE(ratios[1]);
  EXPECT_NEAR(ratios[1]->x, 0.05f, 1e-6f);
  EXPECT_FALSE(ratios[2]); // nothing lights it: the photographs say nothing
  const std::vector<glm::vec3> means = objectMeans(reflectance, confidence, object, 3, nullptr, &ratios);
  EXPECT_FLOAT_EQ(means[0].x, 0.5f);                 // its merged pixel, not its ratio (0.6)
  EXPECT_NEAR(means[1].x, 0.05f, 1e-6f);             // without the ratio: the grey of all, 0.5
  EXPECT_NEAR(means[2].x, 0.5f, 1e-6f);              // the unknown grey
}

} // namespace
} // namespace obscura::recover
