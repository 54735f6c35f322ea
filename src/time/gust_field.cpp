#include "cosserat/time/gust_field.hpp"

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

namespace cosserat {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// The standard fixes std::mt19937_64's output sequence but not the algorithms of its
// distributions, so these are written out: the same seed draws the same modes with any
// standard library (docs/model.md gives the order of the draws).
double uniform(std::mt19937_64& generator) {
  return static_cast<double>(generator() >> 11) * 0x1.0p-53;  // [0, 1), 53 random bits
}

// Box–Muller, the cosine branch only, so that each normal takes two uniforms.
double normal(std::mt19937_64& generator) {
  const double radius = std::sqrt(-2.0 * std::log(1.0 - uniform(generator)));
  return radius * std::cos(kTwoPi * uniform(generator));
}

Vec3 unit_vector(std::mt19937_64& generator) {
  const double z = 2.0 * uniform(generator) - 1.0;
  const double angle = kTwoPi * uniform(generator);
  const double across = std::sqrt(1.0 - z * z);
  return {across * std::cos(angle), across * std::sin(angle), z};
}

// cos θ to 1e-10 from +, − and × alone, so that the loop over the modes vectorises: with
// std::cos, a call per mode, the gusts cost five times as much (S4 with gusts, one thread:
// 1.9 s against 0.37 s over 2000 steps, on top of the 0.55 s of the run without them).
double cosine(double theta) {
  // θ less the nearest multiple of 2π, rounded by adding and removing 1.5·2⁵² (exact for
  // fewer than 2⁵¹ turns): r in [−π, π].
  const double turns = (theta * (1.0 / kTwoPi) + 0x1.8p52) - 0x1.8p52;
  const double r = theta - turns * kTwoPi;
  const double s = r * r;
  // Taylor to r²⁰: the first term left out is below π²²/22! = 7e-11.
  double p = 1.0 / 2432902008176640000.0;
  p = p * s - 1.0 / 6402373705728000.0;
  p = p * s + 1.0 / 20922789888000.0;
  p = p * s - 1.0 / 87178291200.0;
  p = p * s + 1.0 / 479001600.0;
  p = p * s - 1.0 / 3628800.0;
  p = p * s + 1.0 / 40320.0;
  p = p * s - 1.0 / 720.0;
  p = p * s + 1.0 / 24.0;
  p = p * s - 0.5;
  return p * s + 1.0;
}

}  // namespace

GustField::GustField(const Gusts& gusts, const Vec3& mean) {
  std::mt19937_64 generator(gusts.seed);
  // Σ of N unit modes with independent phases has mean square N/2.
  const double scale = gusts.amplitude * std::sqrt(2.0 / kModes);
  for (int j = 0; j < kModes; ++j) {
    const double kx = normal(generator), ky = normal(generator), kz = normal(generator);
    const Vec3 k = Vec3{kx, ky, kz} / gusts.correlation_length;
    const double omega = normal(generator) / gusts.correlation_time;
    phase_[j] = kTwoPi * uniform(generator);
    // Across k, so that every mode, and the field, is divergence-free as the air's velocity is
    // (Kraichnan's random modes); a direction too near k is drawn again.
    Vec3 across;
    do across = cross(k, unit_vector(generator));
    while (!(norm(across) > 1e-6 * norm(k)));
    const Vec3 a = (scale / norm(across)) * across;
    kx_[j] = k.x;
    ky_[j] = k.y;
    kz_[j] = k.z;
    ax_[j] = a.x;
    ay_[j] = a.y;
    az_[j] = a.z;
    rate_[j] = dot(k, mean) + omega;
  }
}

GustField::Phases GustField::phases(double time) const {
  Phases p;
  for (int j = 0; j < kModes; ++j) p.at_origin[j] = phase_[j] - rate_[j] * time;
  return p;
}

Vec3 GustField::velocity(const Vec3& x, const Phases& phases) const {
  double ux = 0.0, uy = 0.0, uz = 0.0;
#pragma omp simd reduction(+ : ux, uy, uz)
  for (int j = 0; j < kModes; ++j) {
    const double c = cosine(kx_[j] * x.x + ky_[j] * x.y + kz_[j] * x.z + phases.at_origin[j]);
    ux += ax_[j] * c;
    uy += ay_[j] * c;
    uz += az_[j] * c;
  }
  return {ux, uy, uz};
}

}  // namespace cosserat
