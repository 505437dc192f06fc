#include "gpu/timestamps.h"

#include <stdexcept>

namespace obscura::gpu {

Timestamps::Timestamps(const Context& context, std::uint32_t capacity)
    : context_(&context), available_(context.info().timestamps && context.info().timestampPeriodNs > 0),
      capacity_(capacity) {
  if (!available_) return;
  pool_ = context.device().createQueryPool(
      {.queryType = vk::QueryType::eTimestamp, .queryCount = capacity_ * 2});
}

void Timestamps::reset(const vk::raii::CommandBuffer& cmd) {
  labels_.clear();
  if (available_) cmd.resetQueryPool(*pool_, 0, capacity_ * 2);
}

void Timestamps::begin(const vk::raii::CommandBuffer& cmd, const std::string& label) {
  if (!available_) return;
  if (labels_.size() >= capacity_) throw std::logic_error("Timestamps: too many queries in one submission");
  labels_.push_back(label);
  cmd.writeTimestamp(vk::PipelineStageFlagBits::eTopOfPipe, *pool_,
                     static_cast<std::uint32_t>(labels_.size() - 1) * 2);
}

void Timestamps::end(const vk::raii::CommandBuffer& cmd, const std::string& label) {
  if (!available_) return;
  if (labels_.empty() || labels_.back() != label)
    throw std::logic_error("Timestamps: end(" + label + ") without matching begin");
  cmd.writeTimestamp(vk::PipelineStageFlagBits::eBottomOfPipe, *pool_,
                     static_cast<std::uint32_t>(labels_.size() - 1) * 2 + 1);
}

void Timestamps::collect() {
  if (!available_ || labels_.empty()) return;
  auto count = static_cast<std::uint32_t>(labels_.size() * 2);
  auto [result, values] = pool_.getResults<std::uint64_t>(
      0, count, count * sizeof(std::uint64_t), sizeof(std::uint64_t),
      vk::QueryResultFlagBits::e64 | vk::QueryResultFlagBits::eWait);
  (void)result;
  double periodMs = static_cast<double>(context_->info().timestampPeriodNs) * 1e-6;
  for (std::size_t i = 0; i < labels_.size(); ++i)
    totalsMs_[labels_[i]] += static_cast<double>(values[2 * i + 1] - values[2 * i]) * periodMs;
  labels_.clear();
}

std::map<std::string, double> Timestamps::msSince(const std::map<std::string, double>& before,
                                                 const std::string& prefix) const {
  std::map<std::string, double> added;
  for (const auto& [label, ms] : totalsMs_) {
    if (label.compare(0, prefix.size(), prefix) != 0) continue;
    const auto it = before.find(label);
    const double delta = ms - (it == before.end() ? 0.0 : it->second);
    if (delta > 0.0) added[label.substr(prefix.size())] = delta;
  }
  return added;
}

double sumMs(const std::map<std::string, double>& ms) {
  double total = 0.0;
  for (const auto& [label, value] : ms) total += value;
  return total;
}

} // namespace obscura::gpu
