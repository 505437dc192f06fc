#include "analysis/convergence.h"

#include <cmath>

namespace obscura::analysis {

double errorOf(const ImageError& e, Metric metric) {
  switch (metric) {
  case Metric::RmseTrimmed: return e.rmseTrimmed;
  case Metric::Mae: return e.mae;
  case Metric::Rmse: break;
  }
  return e.rmse;
}

double errorOf(const CurvePoint& p, ErrorKind kind, Metric metric) {
  return errorOf(kind == ErrorKind::Noise ? p.noise : p.total, metric);
}

TimeAt timeToReach(const Curve& curve, double target, ErrorKind kind, Metric metric) {
  TimeAt out;
  if (curve.points.empty() || target <= 0.0) return out;
  const auto& first = curve.points.front();
  if (errorOf(first, kind, metric) <= target) return {.ms = first.gpuMs, .extrapolated = false, .valid = true};
  for (std::size_t i = 1; i < curve.points.size(); ++i) {
    const auto& a = curve.points[i - 1];
    const auto& b = curve.points[i];
    double ea = errorOf(a, kind, metric), eb = errorOf(b, kind, metric);
    if (eb > target) continue;
    // log-log interpolation between a and b.
    double la = std::log(ea), lb = std::log(eb), lt = std::log(target);
    double f = la == lb ? 1.0 : (lt - la) / (lb - la);
    double ms = std::exp(std::log(a.gpuMs) + f * (std::log(b.gpuMs) - std::log(a.gpuMs)));
    return {.ms = ms, .extrapolated = false, .valid = true};
  }
  const auto& last = curve.points.back();
  double e = errorOf(last, kind, metric);
  if (e <= 0.0) return out;
  // error ~ t^(-1/2): t = t_last (e / target)^2.
  return {.ms = last.gpuMs * (e / target) * (e / target), .extrapolated = true, .valid = true};
}

ErrorAt errorAtTime(const Curve& curve, double ms, ErrorKind kind, Metric metric) {
  if (curve.points.empty() || ms <= 0.0) return {};
  const auto& first = curve.points.front();
  const auto& last = curve.points.back();
  // error ~ t^(-1/2) from point p: e_p sqrt(t_p / t).
  auto along = [&](const CurvePoint& p) {
    return ErrorAt{.error = errorOf(p, kind, metric) * std::sqrt(p.gpuMs / ms), .extrapolated = true, .valid = true};
  };
  if (ms < first.gpuMs) return along(first);
  for (std::size_t i = 1; i < curve.points.size(); ++i) {
    const auto& a = curve.points[i - 1];
    const auto& b = curve.points[i];
    if (ms > b.gpuMs) continue;
    const double f = a.gpuMs == b.gpuMs ? 1.0 : (std::log(ms) - std::log(a.gpuMs)) / (std::log(b.gpuMs) - std::log(a.gpuMs));
    const double ea = errorOf(a, kind, metric), eb = errorOf(b, kind, metric);
    if (ea <= 0.0 || eb <= 0.0) return {.error = ea + f * (eb - ea), .extrapolated = false, .valid = true};
    return {.error = std::exp(std::log(ea) + f * (std::log(eb) - std::log(ea))), .extrapolated = false, .valid = true};
  }
  return ms == first.gpuMs ? ErrorAt{.error = errorOf(first, kind, metric), .valid = true} : along(last);
}

} // namespace obscura::analysis
