// Inverse error function in single precision, the same code on host and device: Beckmann's
// visible-normal sampling inverts erf, and the C++ library has no erfinv. Giles' polynomial
// fit (Giles, "Approximating the erfinv function", GPU Computing Gems Jade, 2011), whose
// relative error is a few float ulps over (-1, 1).
#pragma once

#include "core/Common.h"

namespace envgi {

ENVGI_INLINE float erfInv(float x) {
  float w = -std::log((1.f - x) * (1.f + x));
  float p;
  if (w < 5.f) {
    w -= 2.5f;
    p = 2.81022636e-08f;
    p = 3.43273939e-07f + p * w;
    p = -3.5233877e-06f + p * w;
    p = -4.39150654e-06f + p * w;
    p = 0.00021858087f + p * w;
    p = -0.00125372503f + p * w;
    p = -0.00417768164f + p * w;
    p = 0.246640727f + p * w;
    p = 1.50140941f + p * w;
  } else {
    w = std::sqrt(w) - 3.f;
    p = -0.000200214257f;
    p = 0.000100950558f + p * w;
    p = 0.00134934322f + p * w;
    p = -0.00367342844f + p * w;
    p = 0.00573950773f + p * w;
    p = -0.0076224613f + p * w;
    p = 0.00943887047f + p * w;
    p = 1.00167406f + p * w;
    p = 2.83297682f + p * w;
  }
  return p * x;
}

}  // namespace envgi
