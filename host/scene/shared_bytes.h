// shared_bytes.h — bytes that copies share until one of them writes (copy on write). A scene's
// textures hold their texels this way: an edit's history keeps two versions of the scene while
// the renderer moves from one to the other, and copying modern-hall's texels (~0.2 GB) cost
// every move 36 ms of host work (2 cores) for bytes no edit changes.
#pragma once
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <vector>

namespace obscura::scene {

class SharedBytes {
public:
  SharedBytes() = default;
  SharedBytes(std::initializer_list<std::uint8_t> bytes)
      : bytes_(std::make_shared<std::vector<std::uint8_t>>(bytes)) {}

  std::size_t size() const { return bytes_ ? bytes_->size() : 0; }
  bool empty() const { return size() == 0; }
  const std::uint8_t* data() const { return bytes_ ? bytes_->data() : nullptr; }
  std::uint8_t operator[](std::size_t i) const { return (*bytes_)[i]; }
  // Writing makes the bytes this copy's own first.
  std::uint8_t& operator[](std::size_t i) { return writable()[i]; }
  template <class It> void assign(It first, It last) {
    bytes_ = std::make_shared<std::vector<std::uint8_t>>(first, last);
  }
  void assign(std::size_t count, std::uint8_t value) {
    bytes_ = std::make_shared<std::vector<std::uint8_t>>(count, value);
  }
  void resize(std::size_t count) { writable().resize(count); }

  bool operator==(const std::vector<std::uint8_t>& other) const {
    return bytes_ ? *bytes_ == other : other.empty();
  }
  friend bool operator==(const SharedBytes& a, const SharedBytes& b) {
    return a.bytes_ == b.bytes_ || (a.size() == b.size() && (a.empty() || *a.bytes_ == *b.bytes_));
  }

private:
  std::vector<std::uint8_t>& writable() {
    if (!bytes_) bytes_ = std::make_shared<std::vector<std::uint8_t>>();
    else if (bytes_.use_count() > 1) bytes_ = std::make_shared<std::vector<std::uint8_t>>(*bytes_);
    return *bytes_;
  }
  std::shared_ptr<std::vector<std::uint8_t>> bytes_;
};

} // namespace obscura::scene
