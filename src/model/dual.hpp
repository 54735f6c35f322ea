#pragma once
// Forward-mode automatic differentiation for the energy's Hessian (docs/semi-implicit.md, "The
// Jacobian"): a Dual carries a value and its derivatives along N seeded directions, and
// DualVec3 is Vec3's counterpart. Running the energy's exact gradient on them gives the
// gradient's derivatives, the Hessian's columns, exact to round-off. Only the operations the
// energy's gradient uses are defined.

#include <array>
#include <cmath>

namespace cosserat::energy {

template <int N>
struct Dual {
  double value = 0.0;
  std::array<double, N> d{};

  Dual() = default;
  Dual(double v) : value(v) {}  // NOLINT: a constant, as the double code writes them

  Dual& operator+=(const Dual& o) {
    value += o.value;
    for (int i = 0; i < N; ++i) d[i] += o.d[i];
    return *this;
  }
  Dual& operator-=(const Dual& o) {
    value -= o.value;
    for (int i = 0; i < N; ++i) d[i] -= o.d[i];
    return *this;
  }
  Dual& operator*=(const Dual& o) {
    for (int i = 0; i < N; ++i) d[i] = d[i] * o.value + value * o.d[i];
    value *= o.value;
    return *this;
  }
  Dual& operator/=(const Dual& o) {
    const double inverse = 1.0 / o.value, quotient = value * inverse;
    for (int i = 0; i < N; ++i) d[i] = (d[i] - quotient * o.d[i]) * inverse;
    value = quotient;
    return *this;
  }
};

template <int N> Dual<N> operator+(Dual<N> a, const Dual<N>& b) { return a += b; }
template <int N> Dual<N> operator-(Dual<N> a, const Dual<N>& b) { return a -= b; }
template <int N> Dual<N> operator*(Dual<N> a, const Dual<N>& b) { return a *= b; }
template <int N> Dual<N> operator/(Dual<N> a, const Dual<N>& b) { return a /= b; }
template <int N> Dual<N> operator+(Dual<N> a, double b) { return a += Dual<N>(b); }
template <int N> Dual<N> operator+(double a, Dual<N> b) { return b += Dual<N>(a); }
template <int N> Dual<N> operator-(Dual<N> a, double b) { return a -= Dual<N>(b); }
template <int N> Dual<N> operator-(double a, const Dual<N>& b) { return Dual<N>(a) -= b; }
template <int N> Dual<N> operator-(Dual<N> a) {
  a.value = -a.value;
  for (double& x : a.d) x = -x;
  return a;
}
template <int N> Dual<N> operator*(Dual<N> a, double s) {
  a.value *= s;
  for (double& x : a.d) x *= s;
  return a;
}
template <int N> Dual<N> operator*(double s, Dual<N> a) { return a * s; }
template <int N> Dual<N> operator/(Dual<N> a, double s) { return a * (1.0 / s); }
template <int N> Dual<N> operator/(double a, const Dual<N>& b) { return Dual<N>(a) /= b; }
template <int N> bool operator<(const Dual<N>& a, double b) { return a.value < b; }
template <int N> bool operator>(const Dual<N>& a, double b) { return a.value > b; }

template <int N> Dual<N> sqrt(Dual<N> a) {
  const double root = std::sqrt(a.value), half_inverse = 0.5 / root;
  a.value = root;
  for (double& x : a.d) x *= half_inverse;
  return a;
}

template <int N>
struct DualVec3 {
  Dual<N> x, y, z;

  DualVec3& operator+=(const DualVec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
  DualVec3& operator-=(const DualVec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
};

template <int N> DualVec3<N> operator+(DualVec3<N> a, const DualVec3<N>& b) { return a += b; }
template <int N> DualVec3<N> operator-(DualVec3<N> a, const DualVec3<N>& b) { return a -= b; }
template <int N> DualVec3<N> operator-(const DualVec3<N>& a) { return {-a.x, -a.y, -a.z}; }
template <int N> DualVec3<N> operator*(const Dual<N>& s, const DualVec3<N>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <int N> DualVec3<N> operator*(const DualVec3<N>& a, const Dual<N>& s) { return s * a; }
template <int N> DualVec3<N> operator*(double s, const DualVec3<N>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <int N> DualVec3<N> operator*(const DualVec3<N>& a, double s) { return s * a; }
template <int N> Dual<N> dot(const DualVec3<N>& a, const DualVec3<N>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <int N> DualVec3<N> cross(const DualVec3<N>& a, const DualVec3<N>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

}  // namespace cosserat::energy
