// virtual_display.h — an X server of our own for window tests: Xvfb on a free display number
// (it picks one and tells us through -displayfd), ended with the test.
#pragma once
#include <string>

#include <sys/types.h>

namespace obscura::test {

class VirtualDisplay {
public:
  // Starts Xvfb; a test fails (ADD_FAILURE) when it cannot, and display() is then empty.
  VirtualDisplay();
  ~VirtualDisplay();
  VirtualDisplay(const VirtualDisplay&) = delete;
  VirtualDisplay& operator=(const VirtualDisplay&) = delete;

  // ":N", for DISPLAY.
  const std::string& display() const { return display_; }

private:
  pid_t pid_ = -1;
  std::string display_;
};

} // namespace obscura::test
