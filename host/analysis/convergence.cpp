#include "analysis/convergence.h"

#include <cmath>

namespace obscura::render {

double rmseOf(const CurvePoint& p, ErrorKind kind) {
  return kind == ErrorKind::Noise ? p.rmseNoise : p.rmseReference;
}

TimeAt timeToReach(const Curve& curve, double target, ErrorKind kind) {
  TimeAt out;
  if (curve.points.empty() || target <= 0.0) return out;
  const auto& first = curve.points.front();
  if (rmseOf(first, kind) <= target) return {.ms = first.gpuMs, .extrapolated = false, .valid = true};
  for (std::size_t i = 1; i < curve.points.size(); ++i) {
    const auto& a = curve.points[i - 1];
    const auto& b = curve.points[i];
    double ea = rmseOf(a, kind), eb = rmseOf(b, kind);
    if (eb > target) continue;
    // log-log interpolation between a and b.
    double la = std::log(ea), lb = std::log(eb), lt = std::log(target);
    double f = la == lb ? 1.0 : (lt - la) / (lb - la);
    double ms = std::exp(std::log(a.gpuMs) + f * (std::log(b.gpuMs) - std::log(a.gpuMs)));
    return {.ms = ms, .extrapolated = false, .valid = true};
  }
  const auto& last = curve.points.back();
  double e = rmseOf(last, kind);
  if (e <= 0.0) return out;
  // RMSE ~ t^(-1/2): t = t_last (e / target)^2.
  return {.ms = last.gpuMs * (e / target) * (e / target), .extrapolated = true, .valid = true};
}

} // namespace obscura::render
