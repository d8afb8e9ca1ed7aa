// SPDX-License-Identifier: MIT
#include "turtlegas/sim/field_flight.hpp"

#include <cmath>
#include <numbers>

namespace turtlegas::sim {
namespace {

// (theta - sin theta) / theta^3 = sum_k (-x)^k / (2k + 3)!, x = theta^2, for |theta| < 2: the
// direct form loses up to log2(theta / (theta - sin theta)) bits, all of them as theta -> 0. Twelve
// terms: the first one left out is below 4^12 / 27! = 1.5e-21 of the sum (>= 0.14).
double theta_minus_sin_over_cube_series(double x) {
  constexpr double kInvFact[12] = {
      1.0 / 6.0,
      1.0 / 120.0,
      1.0 / 5040.0,
      1.0 / 362880.0,
      1.0 / 39916800.0,
      1.0 / 6227020800.0,
      1.0 / 1307674368000.0,
      1.0 / 355687428096000.0,
      1.0 / 121645100408832000.0,
      1.0 / 51090942171709440000.0,
      1.0 / 25852016738884976640000.0,
      1.0 / 15511210043330985984000000.0,
  };
  double sum = 0.0;
  for (int k = 11; k >= 0; --k) sum = kInvFact[k] - x * sum;
  return sum;
}

}  // namespace

FlightCoefficients flight_coefficients(double w, double t) {
  if (w == 0.0) return {1.0, 0.0, t, 0.0, 0.5 * t * t, 0.0};
  // theta carries half an ulp of rounding (w and t are exact): a phase error of eps |theta| / 2,
  // which is the conditioning of the problem itself (w known to half an ulp is worth as much).
  // std::sin/cos reduce their argument exactly, so no reduction modulo 2 pi is done here: it
  // could only add the error of 2 pi's representation, k times.
  const double theta = w * t;
  const double h = 0.5 * theta;
  const double sh = std::sin(h), ch = std::cos(h);
  const double sinc_h = h == 0.0 ? 1.0 : sh / h;  // sin(h)/h: exact to a few ulps for every h
  const double f1 = sinc_h * ch;                   // sin(theta)/theta = sinc(h) cos(h)
  const double f2 = 0.5 * sinc_h * sinc_h;         // (1 - cos theta)/theta^2 = 2 sin^2(h)/theta^2
  const double f3 = std::abs(theta) < 2.0 ? theta_minus_sin_over_cube_series(theta * theta)
                                          : (theta - 2.0 * sh * ch) / (theta * theta * theta);
  FlightCoefficients k;
  k.cos_theta = 1.0 - 2.0 * sh * sh;  // absolute error ~eps at every theta
  k.sin_theta = 2.0 * sh * ch;
  k.s = t * f1;
  k.c = t * (theta * f2);
  k.ca = t * (t * f2);
  k.da = t * (t * (theta * f3));
  return k;
}

Vec2 field_displacement(const FieldFlight& f, double t) {
  const FlightCoefficients k = flight_coefficients(f.w, t);
  return k.s * f.v + k.c * turn_cw(f.v) + k.ca * f.a + k.da * turn_cw(f.a);
}

Vec2 field_velocity(const FieldFlight& f, double t) {
  const FlightCoefficients k = flight_coefficients(f.w, t);
  return k.cos_theta * f.v + k.sin_theta * turn_cw(f.v) + k.s * f.a + k.c * turn_cw(f.a);
}

FieldState field_advance(Vec2 x, const FieldFlight& f, double t) {
  const FlightCoefficients k = flight_coefficients(f.w, t);
  const Vec2 jv = turn_cw(f.v), ja = turn_cw(f.a);
  return {x + (k.s * f.v + k.c * jv + k.ca * f.a + k.da * ja),
          k.cos_theta * f.v + k.sin_theta * jv + k.s * f.a + k.c * ja};
}

double gyration_period(double w) { return w == 0.0 ? kNever : 2.0 * std::numbers::pi / std::abs(w); }

Vec2 drift_velocity(const FieldFlight& f) { return turn_cw(f.a) / f.w; }

double gyration_radius(const FieldFlight& f) { return norm(field_acceleration(f)) / (f.w * f.w); }

Vec2 guiding_centre(Vec2 x, const FieldFlight& f) {
  // x - perp(v - u_d)/w with perp(J(a)) = a: the offset (w perp(v) - a)/w^2 has length radius.
  return x - (f.w * perp(f.v) - f.a) / (f.w * f.w);
}

Vec2 field_kick(Vec2 v, Vec2 a, double w, double dt) { return field_velocity({v, a, w}, dt); }

Vec2 rotation_kick(Vec2 v, double w, double dt) {
  const double theta = w * dt;
  const double c = std::cos(theta), s = std::sin(theta);
  return c * v + s * turn_cw(v);
}

}  // namespace turtlegas::sim
