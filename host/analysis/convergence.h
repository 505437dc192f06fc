// convergence.h — speed against error [SPEC §4]: error curves of several methods over GPU time
// and the figures drawn from them (equal-noise speed-up, bias floor, crossover).
#pragma once
#include <string>
#include <vector>

#include "analysis/image_error.h"

namespace obscura::analysis {

struct CurvePoint {
  unsigned spp = 0;            // primary samples per pixel
  double raysPerPixel = 0.0;   // rays of every kind traced per pixel
  double gpuMs = 0.0;          // GPU time of the render (all passes)
  ImageError noise;            // against the same method converged
  ImageError total;            // against converged path tracing: bias + noise
};

struct Curve {
  std::string method;
  std::vector<CurvePoint> points; // in increasing time
};

enum class ErrorKind { Noise, AgainstReference };
// Which error measure a figure is read in (image_error.h).
enum class Metric { Rmse, RmseTrimmed, Mae };

struct TimeAt {
  double ms = 0.0;
  bool extrapolated = false; // the curve never reached the target: extended with slope -1/2
  bool valid = false;
};

double errorOf(const CurvePoint& p, ErrorKind kind, Metric metric = Metric::Rmse);
double errorOf(const ImageError& e, Metric metric);

// GPU time at which the curve's error falls to `target`: interpolated linearly in log-log between
// the two measured points around it; past the last point, extrapolated along error ~ time^(-1/2),
// the Monte Carlo rate of an unbiased estimator (only meaningful for noise).
TimeAt timeToReach(const Curve& curve, double target, ErrorKind kind, Metric metric = Metric::Rmse);

// The curve's error at GPU time `ms`: interpolated in log-log between the measured points around
// it; outside them, extended from the nearest point along error ~ time^(-1/2). Invalid (ms 0) for
// an empty curve.
struct ErrorAt {
  double error = 0.0;
  bool extrapolated = false;
  bool valid = false;
};
ErrorAt errorAtTime(const Curve& curve, double ms, ErrorKind kind, Metric metric = Metric::Rmse);

} // namespace obscura::analysis
