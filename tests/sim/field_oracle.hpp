// SPDX-License-Identifier: MIT
// Independent high-precision flights for the field tests: the textbook guiding-centre form
// x0 + u_d t + S (v0 - u_d) + C J(v0 - u_d) (S = sin(theta)/w, C = (1 - cos theta)/w), which the code
// under test avoids because it cancels for small w t, evaluated where that does not matter:
//   * in 50 decimal digits (Boost.Multiprecision), the reference for positions and velocities;
//   * in long double, fast enough for dense root searches, with the Taylor series of the equation
//     of motion itself (x''' = w J(x''), from dv/dt = a + w J(v)) wherever |w t| <= 1/2.
#pragma once

#include <boost/multiprecision/cpp_bin_float.hpp>
#include <cmath>
#include <limits>
#include <random>

#include "turtlegas/sim/field_flight.hpp"
#include "turtlegas/sim/seeded_rng.hpp"

namespace field_oracle {

using Mp = boost::multiprecision::cpp_bin_float_50;
using turtlegas::sim::FieldFlight;
using turtlegas::sim::Vec2;

template <class T>
struct V2 {
  T x{}, y{};
  friend V2 operator+(V2 a, V2 b) { return {a.x + b.x, a.y + b.y}; }
  friend V2 operator-(V2 a, V2 b) { return {a.x - b.x, a.y - b.y}; }
  friend V2 operator*(T s, V2 a) { return {s * a.x, s * a.y}; }
};
template <class T>
V2<T> lift(Vec2 v) {
  return {T(v.x), T(v.y)};
}
template <class T>
V2<T> jcw(V2<T> v) {
  return {v.y, -v.x};
}
template <class T>
T dot2(V2<T> a, V2<T> b) {
  return a.x * b.x + a.y * b.y;
}

template <class T>
struct State {
  V2<T> x, v;
};

// The textbook closed form, any precision (w != 0).
template <class T>
State<T> textbook(V2<T> x0, const FieldFlight& f, T t) {
  using std::cos;
  using std::sin;
  using boost::multiprecision::cos;
  using boost::multiprecision::sin;
  const T w = T(f.w);
  const V2<T> v0 = lift<T>(f.v), a = lift<T>(f.a);
  const V2<T> ud = (T(1) / w) * jcw(a);
  const V2<T> rot = v0 - ud;
  const T th = w * t;
  const T s = sin(th), c = cos(th);
  const T S = s / w, C = (T(1) - c) / w;
  return {x0 + t * ud + S * rot + C * jcw(rot), ud + c * rot + s * jcw(rot)};
}

// 50 digits. w == 0: the parabola.
inline State<Mp> mp_state(Vec2 x0, const FieldFlight& f, const Mp& t) {
  if (f.w == 0.0) {
    const V2<Mp> v0 = lift<Mp>(f.v), a = lift<Mp>(f.a);
    return {lift<Mp>(x0) + t * v0 + (t * t / 2) * a, v0 + t * a};
  }
  return textbook<Mp>(lift<Mp>(x0), f, t);
}

// long double: Taylor series of the equation of motion for |w t| <= 1/2 (terms fall by 1/2 per order
// at least; 40 orders leave < 1e-25), the textbook form beyond (it loses log2(1/|w t|) <= 1 bit).
inline State<long double> ld_state(Vec2 x0, const FieldFlight& f, long double t) {
  using L = long double;
  const L w = f.w;
  if (std::fabs(w * t) <= 0.5L) {
    V2<L> x = lift<L>(x0), v = lift<L>(f.v);
    const V2<L> v0 = v;
    V2<L> d = lift<L>(f.a) + w * jcw(v0);  // x''(0)
    x = x + t * v0;
    L p = t;  // t^(n-1) / (n-1)!
    for (int n = 2; n <= 42; ++n) {
      const L q = p * t / L(n);  // t^n / n!
      x = x + q * d;
      v = v + p * d;
      p = q;
      d = w * jcw(d);
    }
    return {x, v};
  }
  return textbook<L>(lift<L>(x0), f, t);
}

/// The seeded scene generator, shared with bench/field_toi_bench.cpp.
using Rng = turtlegas::sim::SeededRng;

}  // namespace field_oracle
