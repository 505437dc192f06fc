// host_cpu_time.h — the CPU time the host spends on a piece of work, on every thread it uses.
//
// An edit's host work (EditReport::cpuMs) is what a GPU's edit waits for: the BVH update, the
// reach's rays and sums, read-backs, bookkeeping. On lavapipe part of it overlaps the "GPU" (the
// same process's other threads), so wall time hides it; on a GPU nothing does. So it is counted as
// CPU time, whether or not it overlapped anything: the calling thread's own (CLOCK_THREAD_CPUTIME_ID,
// which leaves out lavapipe's worker threads, the device's work there) plus that of the helper
// threads the work started (the BVH builder's, the reach's), which add theirs when they end
// (HelperThreadCpu).
#pragma once
#include <atomic>
#include <cstdint>
#include <ctime>

namespace obscura {

// CPU time of the calling thread, in ms.
inline double threadCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

// The CPU time of every helper thread that has ended so far, in ns (the process's total).
inline std::atomic<std::uint64_t>& helperThreadCpuNs() {
  static std::atomic<std::uint64_t> ns{0};
  return ns;
}

inline double helperThreadCpuMs() { return static_cast<double>(helperThreadCpuNs().load()) * 1e-6; }

// Put on the stack of a helper thread's body: adds the thread's CPU time since to the total.
class HelperThreadCpu {
public:
  HelperThreadCpu() : start_(threadCpuMs()) {}
  ~HelperThreadCpu() {
    helperThreadCpuNs() += static_cast<std::uint64_t>((threadCpuMs() - start_) * 1e6);
  }
  HelperThreadCpu(const HelperThreadCpu&) = delete;
  HelperThreadCpu& operator=(const HelperThreadCpu&) = delete;

private:
  double start_;
};

// The host's CPU time from construction to now: this thread's plus helpers that ended meanwhile
// (a helper still running when read is counted when it ends, by the next reading).
class HostCpuClock {
public:
  HostCpuClock() : thread_(threadCpuMs()), helpers_(helperThreadCpuMs()) {}
  double ms() const { return (threadCpuMs() - thread_) + (helperThreadCpuMs() - helpers_); }

private:
  double thread_, helpers_;
};

} // namespace obscura
