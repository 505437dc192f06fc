// chi_square.h — chi-square goodness of fit for the sampling tests (every sample/pdf pair).
#pragma once
#include <vector>

namespace obscura::test {

// Cells whose expected count is below 5 are pooled into one (the usual validity rule), the
// degrees of freedom are (cells used - 1), and the critical value for the upper tail p comes from
// Wilson & Hilferty, "The Distribution of Chi-Square", PNAS 17(12), 1931:
// chi2_p(k) ~ k (1 - 2/(9k) + z_p sqrt(2/(9k)))^3, within ~1% for k >= 10.
struct ChiSquare {
  double value = 0.0;
  int dof = 0;
  double threshold = 0.0;
  bool passed() const { return dof > 0 && value < threshold; }
};

ChiSquare chiSquareTest(const std::vector<double>& observed, const std::vector<double>& expected);

} // namespace obscura::test
