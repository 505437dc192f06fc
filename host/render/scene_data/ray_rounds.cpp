#include "render/scene_data/ray_rounds.h"

namespace obscura::render {

std::vector<bvh::Hit> RayRounds::Member::closest(std::span<const bvh::Ray> rays) {
  std::vector<bvh::Hit> hits;
  rounds_->take({true, rays, &hits, nullptr});
  return hits;
}

std::vector<float> RayRounds::Member::blockedAt(std::span<const bvh::Ray> rays) {
  std::vector<float> blocked;
  rounds_->take({false, rays, nullptr, &blocked});
  return blocked;
}

void RayRounds::take(Request request) {
  std::unique_lock lock(mutex_);
  if (failed_) std::rethrow_exception(failed_);
  waiting_.push_back(request);
  const std::uint64_t round = round_;
  if (waiting_.size() == active_) traceRound();
  else done_.wait(lock, [&] { return round_ != round; });
  if (failed_) std::rethrow_exception(failed_);
}

void RayRounds::leave() {
  std::unique_lock lock(mutex_);
  --active_;
  if (!waiting_.empty() && waiting_.size() == active_) traceRound();
}

void RayRounds::traceRound() {
  // Every waiting member's rays of one kind, in one call, each member's results cut back out.
  try {
    for (const bool closest : {true, false}) {
      std::vector<bvh::Ray> rays;
      for (const Request& r : waiting_)
        if (r.closest == closest) rays.insert(rays.end(), r.rays.begin(), r.rays.end());
      if (rays.empty()) continue;
      std::size_t at = 0;
      if (closest) {
        const std::vector<bvh::Hit> hits = device_->closest(rays);
        for (const Request& r : waiting_) {
          if (!r.closest) continue;
          r.hits->assign(hits.begin() + static_cast<std::ptrdiff_t>(at), hits.begin() + static_cast<std::ptrdiff_t>(at + r.rays.size()));
          at += r.rays.size();
        }
      } else {
        const std::vector<float> blocked = device_->blockedAt(rays);
        for (const Request& r : waiting_) {
          if (r.closest) continue;
          r.blocked->assign(blocked.begin() + static_cast<std::ptrdiff_t>(at),
                            blocked.begin() + static_cast<std::ptrdiff_t>(at + r.rays.size()));
          at += r.rays.size();
        }
      }
    }
  } catch (...) {
    failed_ = std::current_exception();
  }
  waiting_.clear();
  ++round_;
  done_.notify_all();
}

} // namespace obscura::render
