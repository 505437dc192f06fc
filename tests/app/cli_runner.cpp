#include "app/cli_runner.h"

#include <algorithm>
#include <cctype>
#include <utility>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include "app/command_line.h"
#include "app/commands.h"

#include "gpu_test.h"

namespace obscura::test {
namespace fs = std::filesystem;

namespace {

RunResult runInShell(const std::string& args, const std::string& prefix) {
  const std::string command = prefix + std::string(OBSCURA_BINARY_PATH) + " " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  RunResult r{-1, ""};
  if (!pipe) return r;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) r.output += buffer.data();
  const int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// Words separated by blanks, and nothing a shell would read otherwise (quotes, variables,
// redirections, globs): only such a command line means the same in-process.
std::optional<std::vector<std::string>> plainWords(const std::string& args) {
  if (args.find_first_of("'\"\\$`|;&<>*?(){}[]~#\n") != std::string::npos) return std::nullopt;
  std::vector<std::string> words;
  std::istringstream in(args);
  for (std::string word; in >> word;) words.push_back(word);
  return words;
}

// Runs `obscura words` through app::runCommandLine with this process's stdout and stderr sent
// to one file (as the shell's 2>&1 does), then read back.
RunResult runInProcess(const std::vector<std::string>& words) {
  // As a program that runs many commands: each device choice's context, and its compiled
  // pipelines, serve every later command of the test process (app/commands.h).
  app::keepCommandContexts(true);
  std::vector<const char*> argv{"obscura"};
  for (const std::string& w : words) argv.push_back(w.c_str());
  std::FILE* capture = std::tmpfile();
  if (!capture) return {-1, "tmpfile failed"};
  std::cout.flush();
  std::cerr.flush();
  std::fflush(stdout);
  std::fflush(stderr);
  const int savedOut = ::dup(1), savedErr = ::dup(2);
  ::dup2(::fileno(capture), 1);
  ::dup2(::fileno(capture), 2);
  RunResult r{-1, ""};
  r.exitCode = app::runCommandLine(static_cast<int>(argv.size()), argv.data());
  std::cout.flush();
  std::cerr.flush();
  std::fflush(stdout);
  std::fflush(stderr);
  ::dup2(savedOut, 1);
  ::dup2(savedErr, 2);
  ::close(savedOut);
  ::close(savedErr);
  std::rewind(capture);
  std::array<char, 4096> buffer;
  for (std::size_t n; (n = std::fread(buffer.data(), 1, buffer.size(), capture)) > 0;) r.output.append(buffer.data(), n);
  std::fclose(capture);
  return r;
}

// A prefix of environment assignments alone (NAME=value ...), as name and value pairs.
std::optional<std::vector<std::pair<std::string, std::string>>> assignments(const std::string& prefix) {
  const auto words = plainWords(prefix);
  if (!words) return std::nullopt;
  std::vector<std::pair<std::string, std::string>> out;
  for (const std::string& w : *words) {
    const std::size_t eq = w.find('=');
    if (eq == 0 || eq == std::string::npos ||
        !std::all_of(w.begin(), w.begin() + static_cast<std::ptrdiff_t>(eq), [](unsigned char c) { return std::isupper(c) || c == '_'; }))
      return std::nullopt;
    out.emplace_back(w.substr(0, eq), w.substr(eq + 1));
  }
  return out;
}

// Sets the variables for this process while it lives, then puts back what was there.
class ScopedEnvironment {
public:
  explicit ScopedEnvironment(const std::vector<std::pair<std::string, std::string>>& vars) {
    for (const auto& [name, value] : vars) {
      const char* old = std::getenv(name.c_str());
      saved_.emplace_back(name, old ? std::optional<std::string>(old) : std::nullopt);
      ::setenv(name.c_str(), value.c_str(), 1);
    }
  }
  ~ScopedEnvironment() {
    for (auto it = saved_.rbegin(); it != saved_.rend(); ++it) {
      if (it->second) ::setenv(it->first.c_str(), it->second->c_str(), 1);
      else ::unsetenv(it->first.c_str());
    }
  }

private:
  std::vector<std::pair<std::string, std::optional<std::string>>> saved_;
};

} // namespace

RunResult runObscura(const std::string& args, const std::string& prefix) {
  const char* subprocess = std::getenv("OBSCURA_CLI_SUBPROCESS");
  const auto env = assignments(prefix);
  const bool inShell = !env || (subprocess && std::string(subprocess) == "1");
  const auto words = inShell ? std::nullopt : plainWords(args);
  RunResult r;
  if (words) {
    const ScopedEnvironment scoped(*env);
    r = runInProcess(*words);
  } else {
    r = runInShell(args, prefix);
  }
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
