// gltf_loader_fuzzer.cc — libFuzzer target for obscura::scene::loadGltf (issue #4, "Bad input").
//
// Each input is written to a scratch folder as a .glb (when it starts with the GLB magic "glTF")
// or a .gltf, and loaded. Next to it lie the files the seed corpus refers to (tests/fuzz/corpus,
// made by make_corpus.py), so that mutated JSON still reaches the accessor, index, material and
// image code instead of stopping at "missing .bin":
//   buffer.bin   a quad: 4 float3 positions, 4 float3 normals, 4 float2 UVs, 6 ushort + 6 uint indices
//   tex.png      a 2x2 RGBA PNG      tex.jpg  a 2x2 JPEG
//
// obscura::InputError is the loader's documented answer to bad input and is fine. Anything else
// is a finding: a crash, an ASan/UBSan report, any other exception (libFuzzer reports it as an
// uncaught exception), a time-out (-timeout=10) or running out of memory (-rss_limit_mb).
//
// Built by CMakeLists.txt (the "Loader fuzzer" block) with clang++ -fsanitize=fuzzer,address,undefined;
// run by tests/fuzz/run_fuzzer.sh.
#include <cstddef>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

#include "core/error.h"
#include "scene/gltf_loader.h"

namespace {
namespace fs = std::filesystem;

fs::path gDir;        // the scratch folder, removed at exit
bool gVerbose = false; // OBSCURA_FUZZ_VERBOSE=1: print each input's outcome (for triage)

void writeBytes(const fs::path& file, const void* data, std::size_t size) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out) {
    std::fprintf(stderr, "gltf_loader_fuzzer: cannot write %s\n", file.c_str());
    std::abort();
  }
}

template <typename T> void append(std::vector<unsigned char>& bytes, const T& value) {
  const auto* p = reinterpret_cast<const unsigned char*>(&value);
  bytes.insert(bytes.end(), p, p + sizeof(T));
}

// The same bytes as make_corpus.py's quad_bin(): the seeds' bufferViews index into it.
std::vector<unsigned char> quadBin() {
  std::vector<unsigned char> bin;
  const float positions[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  for (const auto& p : positions) for (float f : p) append(bin, f);           // 0..47
  for (int i = 0; i < 4; ++i) { append(bin, 0.0f); append(bin, 0.0f); append(bin, 1.0f); } // 48..95
  const float uvs[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (const auto& uv : uvs) for (float f : uv) append(bin, f);               // 96..127
  const std::uint16_t shortIndices[6] = {0, 1, 2, 0, 2, 3};
  for (auto i : shortIndices) append(bin, i);                                 // 128..139
  append(bin, std::uint32_t{0});                                              // pad to 144
  const std::uint32_t intIndices[6] = {0, 1, 2, 0, 2, 3};
  for (auto i : intIndices) append(bin, i);                                   // 144..167
  return bin;
}

void removeScratch() {
  std::error_code ignored;
  if (!gDir.empty()) fs::remove_all(gDir, ignored);
}

void writeImage(void* context, void* data, int size) {
  static_cast<std::vector<unsigned char>*>(context)->insert(
      static_cast<std::vector<unsigned char>*>(context)->end(), static_cast<unsigned char*>(data),
      static_cast<unsigned char*>(data) + size);
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  std::string pattern = (fs::temp_directory_path() / "obscura_fuzz_XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    std::perror("gltf_loader_fuzzer: mkdtemp");
    std::abort();
  }
  gDir = pattern;
  gVerbose = std::getenv("OBSCURA_FUZZ_VERBOSE") != nullptr;
  std::atexit(removeScratch);
  const std::vector<unsigned char> bin = quadBin();
  writeBytes(gDir / "buffer.bin", bin.data(), bin.size());
  const unsigned char pixels[2 * 2 * 4] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 128};
  std::vector<unsigned char> png, jpg;
  stbi_write_png_to_func(writeImage, &png, 2, 2, 4, pixels, 8);
  stbi_write_jpg_to_func(writeImage, &jpg, 2, 2, 4, pixels, 90);
  writeBytes(gDir / "tex.png", png.data(), png.size());
  writeBytes(gDir / "tex.jpg", jpg.data(), jpg.size());
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const fs::path file = gDir / (glb ? "input.glb" : "input.gltf");
  writeBytes(file, data, size);
  try {
    (void)obscura::scene::loadGltf(file.string());
  } catch (const obscura::InputError& e) {
    // The documented answer to bad input.
    if (gVerbose) std::fprintf(stderr, "InputError: %s\n", e.what());
    return 0;
  }
  if (gVerbose) std::fprintf(stderr, "loaded\n");
  return 0;
}
