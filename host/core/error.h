// error.h — the one exception type for input the user gave us.
//
// Bad input (a scene file, a flag) is reported as "<file>: <element>: <problem>" and ends the
// program with a non-zero exit in main(); it is never a crash, a hang or a NaN image.
#pragma once
#include <stdexcept>
#include <string>

namespace obscura {

class InputError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// A failure of the Vulkan device or driver (no device, out of memory, device lost).
class DeviceError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

} // namespace obscura
