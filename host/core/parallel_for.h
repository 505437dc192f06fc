// parallel_for.h — fn(i) for every i in [0, n), on as many threads as the machine has cores (the
// calling thread one of them), each index taken once from a shared counter. For independent work
// items of similar size (a recovery's shots). An exception stops the remaining items and the
// first one is rethrown once every thread is done.
#pragma once
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

namespace obscura {

template <class Fn> void parallelFor(std::size_t n, Fn&& fn) {
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr first;
  std::mutex firstMutex;
  auto work = [&] {
    for (std::size_t i; !failed && (i = next++) < n;) {
      try {
        fn(i);
      } catch (...) {
        const std::lock_guard lock(firstMutex);
        if (!first) first = std::current_exception();
        failed = true;
      }
    }
  };
  const std::size_t threads = std::min<std::size_t>(n, std::max(1u, std::thread::hardware_concurrency()));
  std::vector<std::future<void>> helpers;
  for (std::size_t t = 1; t < threads; ++t) helpers.push_back(std::async(std::launch::async, work));
  work();
  for (auto& h : helpers) h.get();
  if (first) std::rethrow_exception(first);
}

} // namespace obscura
