// timestamps.h — GPU timestamps around passes, read back as milliseconds per label.
//
// A pass records begin(label)/end(label) around its dispatches; results() sums the time of every
// begin/end pair with the same label ("primary", "bench.closest", …).
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/context.h"

namespace obscura::gpu {

class Timestamps {
public:
  Timestamps(const Context& context, std::uint32_t capacity = 256);

  // Must be recorded outside of any query use; resets the pool for a new command buffer.
  void reset(const vk::raii::CommandBuffer& cmd);
  void begin(const vk::raii::CommandBuffer& cmd, const std::string& label);
  void end(const vk::raii::CommandBuffer& cmd, const std::string& label);
  // Records `work()` between begin(label) and end(label): the pair is written once, here.
  template <class Work> void time(const vk::raii::CommandBuffer& cmd, const std::string& label, Work&& work) {
    begin(cmd, label);
    work();
    end(cmd, label);
  }

  // Reads the queries written since reset() and adds them to the running totals.
  void collect();
  // Milliseconds per label, summed over everything collected so far.
  const std::map<std::string, double>& totalsMs() const { return totalsMs_; }
  // What each label starting with `prefix` added since `before` (an earlier totalsMs()), the
  // prefix taken off its name: one submission's passes. Labels that added nothing are left out.
  std::map<std::string, double> msSince(const std::map<std::string, double>& before, const std::string& prefix) const;
  bool available() const { return available_; }

private:
  const Context* context_;
  bool available_ = false;
  std::uint32_t capacity_;
  vk::raii::QueryPool pool_ = nullptr;
  std::vector<std::string> labels_; // label of query pair i
  std::map<std::string, double> totalsMs_;
};

// The sum of a map of milliseconds (msSince's).
double sumMs(const std::map<std::string, double>& ms);

} // namespace obscura::gpu
