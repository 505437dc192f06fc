#include "io/oiio_codec.h"

#ifdef OBSCURA_HAVE_OPENIMAGEIO
#include <dlfcn.h>

#include <filesystem>
#include <mutex>
#include <vector>

#include <fmt/core.h>

#include "core/error.h"

namespace obscura::io {
namespace {
namespace fs = std::filesystem;

constexpr const char* kModule = "libobscura_oiio.so";

// Where to look: beside the object that holds this code (the executable, or a Python module that
// links the core), beside the executable, then wherever dlopen looks for a bare name.
std::vector<std::string> candidates() {
  std::vector<std::string> paths;
  Dl_info info{};
  if (dladdr(reinterpret_cast<const void*>(&oiioCodec), &info) != 0 && info.dli_fname != nullptr)
    paths.push_back((fs::path(info.dli_fname).parent_path() / kModule).string());
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const std::string beside = (exe.parent_path() / kModule).string();
    if (paths.empty() || paths.front() != beside) paths.push_back(beside);
  }
  paths.emplace_back(kModule);
  return paths;
}

struct Loaded {
  const OiioCodec* codec = nullptr;
  std::string failures;
};

Loaded load() {
  Loaded loaded;
  for (const std::string& path : candidates()) {
    if (void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL)) {
      using Entry = const OiioCodec* (*)();
      if (auto entry = reinterpret_cast<Entry>(dlsym(handle, "obscura_oiio_codec"))) {
        loaded.codec = entry();
        return loaded;
      }
      loaded.failures += fmt::format("{}{}: no obscura_oiio_codec", loaded.failures.empty() ? "" : "; ", path);
      dlclose(handle);
      continue;
    }
    const char* why = dlerror();
    loaded.failures += fmt::format("{}{}", loaded.failures.empty() ? "" : "; ", why ? why : path);
  }
  return loaded;
}

} // namespace

const OiioCodec& oiioCodec(const std::string& forPath) {
  static std::once_flag once;
  static Loaded loaded;
  std::call_once(once, [] { loaded = load(); });
  if (loaded.codec == nullptr)
    throw InputError(fmt::format("{}: cannot read or write this format: OpenImageIO's module {} did not load ({})",
                                 forPath, kModule, loaded.failures));
  return *loaded.codec;
}

} // namespace obscura::io
#endif
