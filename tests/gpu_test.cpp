#include "gpu_test.h"

namespace obscura::test {

gpu::Context& testContext() {
  static gpu::Context context(gpu::ContextOptions{.validate = true});
  return context;
}

std::string sharedScene(const std::string& relative) { return std::string(OBSCURA_SHARED_SCENES) + "/" + relative; }
std::string repoPath(const std::string& relative) { return std::string(OBSCURA_SOURCE_DIR) + "/" + relative; }

} // namespace obscura::test
