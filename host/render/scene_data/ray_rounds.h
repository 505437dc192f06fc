// ray_rounds.h — several measurements (one per light) on threads of their own, whose stages are
// traced together: each hands its stage's rays to the round and waits; the last to arrive traces
// the round through the device (one submission per kind of ray) and wakes the others. An edit
// that measures every light again (an emissive quad: 14 lights on modern-hall) then makes a few
// submissions instead of a few per light, and draws the lights' rays on every core.
//
// The device's RayBatch is called by one thread at a time (the one completing a round), while the
// thread that made the rounds waits for them all.
#pragma once
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <span>
#include <vector>

#include "render/scene_data/ray_batch.h"

namespace obscura::render {

class RayRounds {
public:
  RayRounds(RayBatch& device, std::size_t members) : device_(&device), active_(members) {}

  // One measurement's handle: its RayBatch calls join the rounds; it leaves them when destroyed
  // (a member that is done, or threw, must not hold a round up).
  class Member final : public RayBatch {
  public:
    explicit Member(RayRounds& rounds) : rounds_(&rounds) {}
    ~Member() override { rounds_->leave(); }
    Member(const Member&) = delete;
    Member& operator=(const Member&) = delete;
    std::vector<bvh::Hit> closest(std::span<const bvh::Ray> rays) override;
    std::vector<float> blockedAt(std::span<const bvh::Ray> rays) override;

  private:
    RayRounds* rounds_;
  };

private:
  struct Request {
    bool closest;
    std::span<const bvh::Ray> rays;
    std::vector<bvh::Hit>* hits;
    std::vector<float>* blocked;
  };
  void take(Request request);
  void leave();
  void traceRound(); // with mutex_ held

  RayBatch* device_;
  std::mutex mutex_;
  std::condition_variable done_;
  std::size_t active_;
  std::vector<Request> waiting_;
  std::uint64_t round_ = 0;
  std::exception_ptr failed_; // a round's device error, rethrown to every member after it
};

} // namespace obscura::render
