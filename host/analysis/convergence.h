// convergence.h — speed against error [SPEC §4]: error curves of several methods over GPU time
// and the figures drawn from them (equal-noise speed-up, bias floor).
#pragma once
#include <string>
#include <vector>

namespace obscura::render {

struct CurvePoint {
  unsigned spp = 0;            // primary samples per pixel
  double raysPerPixel = 0.0;   // rays of every kind traced per pixel
  double gpuMs = 0.0;          // GPU time of the render (all passes)
  double rmseNoise = 0.0;      // against the same method converged: noise
  double relMseNoise = 0.0;
  double rmseReference = 0.0;  // against converged path tracing: bias + noise
  double relMseReference = 0.0;
};

struct Curve {
  std::string method;
  std::vector<CurvePoint> points; // in increasing time
};

enum class ErrorKind { Noise, AgainstReference };

struct TimeAt {
  double ms = 0.0;
  bool extrapolated = false; // the curve never reached the target: extended with slope -1/2
  bool valid = false;
};

// GPU time at which the curve's RMSE falls to `target`: interpolated linearly in log-log between
// the two measured points around it; past the last point, extrapolated along RMSE ~ time^(-1/2),
// the Monte Carlo rate of an unbiased estimator (only meaningful for noise).
TimeAt timeToReach(const Curve& curve, double target, ErrorKind kind);

double rmseOf(const CurvePoint& p, ErrorKind kind);

} // namespace obscura::render
