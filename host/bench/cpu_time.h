// cpu_time.h — CPU time of the whole process (all threads), in ms. On lavapipe the "GPU" is this
// process's threads, so the CPU time of a trace is a measure that other load on the shared
// machine hardly affects (the benchmarks report ratios by it beside those by wall time).
#pragma once
#include <sys/resource.h>

namespace obscura::bench {

inline double processCpuMs() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  auto ms = [](const timeval& t) { return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_usec) * 1e-3; };
  return ms(u.ru_utime) + ms(u.ru_stime);
}

} // namespace obscura::bench
