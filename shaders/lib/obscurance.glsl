// obscurance.glsl — rho(d) and the obscurance estimate [RTO §3, eqs. 2 and 6; SPEC §1.1-1.2].
#ifndef OBSCURA_OBSCURANCE_GLSL
#define OBSCURA_OBSCURANCE_GLSL

// rho(d) for d < dMax; rho = 1 from dMax on (a miss within dMax).
float rho(float d, float dMax, uint kind, float tau) {
  float x = clamp(d / dMax, 0.0, 1.0);
  if (kind == kRhoAo) return x >= 1.0 ? 1.0 : 0.0;
  // OURS: normalised so rho(dMax) = 1 [SPEC §1.1].
  if (kind == kRhoExp) return (1.0 - exp(-tau * x)) / (1.0 - exp(-tau));
  return sqrt(x); // the paper's choice
}

#endif
