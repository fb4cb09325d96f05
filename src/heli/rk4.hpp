#pragma once
// The classical Runge-Kutta weighting shared by the built-in ground truths (aircraft.cpp, quadrotor.cpp):
// (k1 + 2 k2 + 2 k3 + k4) / 6 for each part of a derivative, in this order of operations.
namespace pegasus::heli {

template <class T>
T rk4_mean(const T& k1, const T& k2, const T& k3, const T& k4) {
  return (k1 + 2 * k2 + 2 * k3 + k4) / 6;
}

}  // namespace pegasus::heli
