#include "app/cli_runner.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <sys/wait.h>
#include <unistd.h>

#include "gpu_test.h"

namespace obscura::test {
namespace fs = std::filesystem;

RunResult runObscura(const std::string& args, const std::string& prefix) {
  const std::string command = prefix + std::string(OBSCURA_BINARY_PATH) + " " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  RunResult r{-1, ""};
  if (!pipe) return r;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) r.output += buffer.data();
  const int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  EXPECT_EQ(r.output.find("obscura: validation:"), std::string::npos) << r.output;
  return r;
}

void CliTest::SetUp() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = std::string(info->test_suite_name()) + "_" + info->name();
  for (char& c : name)
    if (c == '/') c = '_';
  dir_ = fs::temp_directory_path() / ("obscura_cli_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir_);
  fs::create_directories(dir_);
}

void CliTest::TearDown() { fs::remove_all(dir_); }

std::vector<std::string> CliTest::strayFiles(const std::vector<std::string>& inputs) const {
  std::vector<std::string> out;
  for (const auto& entry : fs::recursive_directory_iterator(dir_)) {
    const std::string rel = fs::relative(entry.path(), dir_).string();
    if (std::find(inputs.begin(), inputs.end(), rel) == inputs.end()) out.push_back(rel);
  }
  return out;
}

std::string CliTest::cornellBox() { return repoPath("scenes/cornell-box/cornell-box.gltf"); }

} // namespace obscura::test
