#include "chi_square.h"

#include <algorithm>
#include <cmath>

namespace obscura::test {

ChiSquare chiSquareTest(const std::vector<double>& observed, const std::vector<double>& expected) {
  constexpr double kMinExpected = 5.0;
  constexpr double kZ = 3.7190164855; // upper-tail standard normal quantile for p = 1e-4
  ChiSquare out;
  double pooledObserved = 0.0, pooledExpected = 0.0;
  int cells = 0;
  for (std::size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] < kMinExpected) {
      pooledObserved += observed[i];
      pooledExpected += expected[i];
      continue;
    }
    double d = observed[i] - expected[i];
    out.value += d * d / expected[i];
    ++cells;
  }
  if (pooledExpected >= kMinExpected) {
    double d = pooledObserved - pooledExpected;
    out.value += d * d / pooledExpected;
    ++cells;
  } else if (pooledObserved > 10.0 * std::max(pooledExpected, 1.0)) {
    out.value = INFINITY; // many samples where the pdf says there are (almost) none
  }
  out.dof = cells - 1;
  double k = out.dof, q = 2.0 / (9.0 * k);
  out.threshold = k * std::pow(1.0 - q + kZ * std::sqrt(q), 3.0);
  return out;
}

} // namespace obscura::test
