#pragma once
// The standard normal quantile, so that uniform scenario numbers p in (0, 1) become Gaussian noise through
// the inverse CDF (thesis Eq 5.6).
namespace pegasus {

// Phi^{-1}(u) for u in (0, 1): Acklam's rational approximation refined by one Halley step on erfc, relative
// error below 1e-14 over (1e-300, 1 - 1e-16). u outside (0, 1) is clamped to the nearest representable
// open-interval value.
double normal_quantile(double u);

}  // namespace pegasus
