// gpu_test.h — the Vulkan context shared by GPU tests, and the rule that any validation message
// fails the test that caused it.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gpu/context.h"
#include "io/image_io.h"

namespace obscura::test {

// One context per test binary (device creation on lavapipe costs ~50 ms). The validation layer is
// on: CMake runs every test with OBSCURA_VALIDATE=1, and GpuTest forces it anyway.
gpu::Context& testContext();

class GpuTest : public ::testing::Test {
protected:
  void SetUp() override { messagesBefore_ = gpu::Context::validationMessageCount(); }
  void TearDown() override {
    EXPECT_EQ(gpu::Context::validationMessageCount(), messagesBefore_)
        << "the Vulkan validation layer reported a problem during this test (see stderr)";
  }
  gpu::Context& context() { return testContext(); }

private:
  std::uint64_t messagesBefore_ = 0;
};

// The largest difference, in levels of 255, between the R, G or B bytes of two displays (RGBA8
// words of the same size, such as ObscuranceRenderer::display()).
int largestChannelDifference(const std::vector<std::uint32_t>& a, const std::vector<std::uint32_t>& b);

// Three channels of an image from channel `first` on, named combined.R/G/B (what
// analysis::imageError compares): a layer of a renderer's image() set beside another image.
io::Image channelsOf(const io::Image& all, const std::string& first = "combined.R");

// Path of a scene in ../shared/scenes (the real test scenes nobody here wrote).
std::string sharedScene(const std::string& relative);
// Path of a file in the repository.
std::string repoPath(const std::string& relative);

} // namespace obscura::test
