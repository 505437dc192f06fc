// cli_runner.h — running the `obscura` binary as a user does, in a fresh folder per test.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace obscura::test {

struct RunResult {
  int exitCode; // -1 when killed by a signal
  std::string output; // stdout and stderr together
};

// Runs `prefix obscura args` as a user does. The command line runs in this process
// (app::runCommandLine, what main() is; a prefix of NAME=value assignments set for the call), its
// stdout and stderr captured, which spares each case a process start (the Vulkan loader and the
// validation layer) and, with the contexts kept (app::keepCommandContexts), the compile of every
// kernel an earlier case compiled. With another prefix (limits, env -u),
// shell syntax in `args`, or OBSCURA_CLI_SUBPROCESS=1 in the environment, the obscura binary
// runs in a shell. ctest runs every test with OBSCURA_VALIDATE=1, which both
// inherit: a validation message either prints fails the test.
RunResult runObscura(const std::string& args, const std::string& prefix = "");

#define EXPECT_CONTAINS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

// A test with its own empty folder, removed afterwards.
class CliTest : public ::testing::Test {
protected:
  void SetUp() override;
  void TearDown() override;
  // Everything in the test folder (recursively) that is not one of `inputs`: a failed command
  // must leave no partial output.
  std::vector<std::string> strayFiles(const std::vector<std::string>& inputs = {}) const;
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  static std::string cornellBox();
  std::filesystem::path dir_;
};

} // namespace obscura::test
