// sha256.h — SHA-256 (FIPS 180-4), for naming what a render was made from: a farm's parts carry
// the hash of their scene's files so that `merge` refuses a part rendered from another scene.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace obscura {

class Sha256 {
public:
  Sha256();
  void update(const void* data, std::size_t bytes);
  void update(std::string_view text) { update(text.data(), text.size()); }
  // The digest as 64 lower-case hex digits; the object is spent after it.
  std::string hexDigest();

private:
  void compress(const unsigned char* block);
  std::uint32_t state_[8];
  unsigned char block_[64];
  std::size_t blockBytes_ = 0;
  std::uint64_t totalBytes_ = 0;
};

// The hash of a file's bytes; InputError naming the file when it cannot be read.
std::string sha256OfFile(const std::string& path);

} // namespace obscura
