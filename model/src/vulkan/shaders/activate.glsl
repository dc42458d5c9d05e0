// The activations the product shaders fuse (params/activation.h's codes), in fp32.
#include "params/activation.h"
float erf_approx(float x) {
  // Abramowitz & Stegun 7.1.26 refined (|error| < 1.2e-7): GLSL has no erf.
  float t = 1.0 / (1.0 + 0.5 * abs(x));
  float y = 1.0 - t * exp(-x * x - 1.26551223 + t * (1.00002368 + t * (0.37409196 + t * (0.09678418 +
            t * (-0.18628806 + t * (0.27886807 + t * (-1.13520398 + t * (1.48851587 +
            t * (-0.82215223 + t * 0.17087277)))))))));
  return x >= 0.0 ? y : -y;
}

float activate(float v, int act) {
  if (act == kActLeakyRelu) return v > 0.0 ? v : 0.1 * v;          // LeakyReLU(0.1)
  if (act == kActRelu) return max(v, 0.0);                     // ReLU
  if (act == kActClamp4) return clamp(v, -4.0, 4.0);          // Hardtanh(-4, 4)
  if (act == kActGelu) return 0.5 * v * (1.0 + erf_approx(v * 0.70710678118654752)); // exact GELU
  return v;
}
