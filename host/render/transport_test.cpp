// The per-light transport on the host: a light's own indirect layer I_s (measured, as a
// recovered room's photographs give it) is composed into indirect and combined and into the
// light's layer, and survives the EXR channels; a transport without one writes none.
#include "render/transport.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace obscura::render {
namespace {

// Two lights over two pixels, every term distinct so that a misplaced one shows.
Transport twoLights(bool ownIndirect) {
  Transport t;
  t.width = 2;
  t.height = 1;
  t.lights = {"a", "b"};
  t.direct = {{{0.1f, 0.2f, 0.3f}, {0.4f, 0.5f, 0.6f}}, {{0.7f, 0.8f, 0.9f}, {1.0f, 1.1f, 1.2f}}};
  t.seen = {{glm::vec3(0.0f), {2.0f, 0.0f, 0.0f}}, {glm::vec3(0.0f), glm::vec3(0.0f)}};
  if (ownIndirect) t.ownIndirect = {{{0.01f, 0.02f, 0.03f}, {0.04f, 0.05f, 0.06f}}, {{0.07f, 0.08f, 0.09f}, {0.1f, 0.2f, 0.3f}}};
  t.ambient = {{0.5f, 0.5f, 0.5f, 0.9f}, {0.25f, 0.5f, 0.75f, 0.8f}};
  return t;
}

glm::vec3 rgb(const io::Image& image, std::size_t pixel, const std::string& first) {
  const int c = image.channelIndex(first);
  EXPECT_GE(c, 0) << first;
  const float* v = &image.pixels[pixel * image.channels.size() + std::size_t(c)];
  return {v[0], v[1], v[2]};
}

void expectNear(const glm::vec3& a, const glm::vec3& b) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-6f) << c;
}

TEST(Transport, ALightsOwnIndirectIsComposedIntoIndirectCombinedAndItsLayer) {
  const Transport t = twoLights(true);
  const std::vector<glm::vec3> emissions = {{2.0f, 1.0f, 0.5f}, {1.0f, 3.0f, 1.0f}};
  const std::vector<glm::vec3> weights = {{0.1f, 0.1f, 0.1f}, {0.0f, 0.0f, 0.0f}};
  const glm::vec3 ia = emissions[0] * weights[0]; // RTO eq. 12
  const io::Image image = composeTransport(t, emissions, weights);
  const io::Image layers = lightLayers(t, emissions, weights);
  for (std::size_t p = 0; p < 2; ++p) {
    const glm::vec3 a = glm::vec3(t.ambient[p]);
    const glm::vec3 direct = emissions[0] * t.direct[0][p] + emissions[1] * t.direct[1][p];
    const glm::vec3 indirect = emissions[0] * t.ownIndirect[0][p] + emissions[1] * t.ownIndirect[1][p] + ia * a;
    const glm::vec3 seen = emissions[0] * t.seen[0][p];
    expectNear(rgb(image, p, "direct.R"), direct);
    expectNear(rgb(image, p, "indirect.R"), indirect);
    expectNear(rgb(image, p, "combined.R"), direct + indirect + seen);
    expectNear(rgb(layers, p, "light.a.R"), emissions[0] * (t.direct[0][p] + t.seen[0][p] + t.ownIndirect[0][p]) + ia * a);
    expectNear(rgb(layers, p, "light.b.R"), emissions[1] * (t.direct[1][p] + t.ownIndirect[1][p]));
  }
}

TEST(Transport, OwnIndirectLayersRoundTripThroughTheChannelsAndAreAbsentWhereNoneWasMeasured) {
  const Transport measured = twoLights(true);
  const io::Image image = measured.toImage();
  EXPECT_GE(image.channelIndex("I.b.B"), 0);
  const Transport back = Transport::fromImage(image, measured.lights, false, "t.exr");
  ASSERT_TRUE(back.hasOwnIndirect());
  for (std::size_t l = 0; l < 2; ++l)
    for (std::size_t p = 0; p < 2; ++p) {
      expectNear(back.ownIndirect[l][p], measured.ownIndirect[l][p]);
      expectNear(back.direct[l][p], measured.direct[l][p]);
    }

  const io::Image plain = twoLights(false).toImage();
  EXPECT_LT(plain.channelIndex("I.a.R"), 0);
  EXPECT_FALSE(Transport::fromImage(plain, measured.lights, false, "t.exr").hasOwnIndirect());

  // One light with the layer and one without is a broken file, not a silent zero.
  const auto drop = static_cast<std::size_t>(image.channelIndex("I.b.R"));
  const auto kept = [drop](std::size_t c) { return c < drop || c >= drop + 3; };
  io::Image cut;
  cut.width = image.width;
  cut.height = image.height;
  for (std::size_t c = 0; c < image.channels.size(); ++c)
    if (kept(c)) cut.channels.push_back(image.channels[c]);
  for (std::size_t p = 0; p < 2; ++p)
    for (std::size_t c = 0; c < image.channels.size(); ++c)
      if (kept(c)) cut.pixels.push_back(image.pixels[p * image.channels.size() + c]);
  try {
    (void)Transport::fromImage(cut, measured.lights, false, "t.exr");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("I.b.R"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("t.exr"), std::string::npos) << e.what();
  }
}

} // namespace
} // namespace obscura::render
