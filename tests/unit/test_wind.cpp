// The wind (docs/model.md "Wind and gusts"): the gust field has the documented mean, rms and
// correlation in space and time, is a function of (x, t, seed) alone, and a wind without gusts
// runs bitwise as the fluid term did before it was called wind.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "cosserat/baseline/semi_implicit.hpp"
#include "cosserat/time/gust_field.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

constexpr double kAmplitude = 2.0;    // m/s
constexpr double kTime = 0.7;         // s
constexpr double kLength = 1.5;       // m
const Vec3 kMean{3.0, 0.0, 1.0};      // m/s

Gusts gusts(std::uint64_t seed) { return Gusts{kAmplitude, kTime, kLength, seed}; }

// Ensemble statistics of the gust over many seeds, each sampled at points spread over a box
// much larger than the correlation length and over many correlation times.
struct Sampler {
  static constexpr int kSeeds = 1000;
  static constexpr int kPointsPerSeed = 20;

  // The mean of `statistic(field, x, t)` over every seed and point.
  template <class Statistic>
  static double mean(Statistic&& statistic) {
    std::mt19937_64 points(12345);
    const auto uniform = [&](double lo, double hi) {
      return lo + (hi - lo) * static_cast<double>(points() >> 11) * 0x1.0p-53;
    };
    double sum = 0.0;
    for (int seed = 0; seed < kSeeds; ++seed) {
      const GustField field(gusts(static_cast<std::uint64_t>(seed)), kMean);
      for (int i = 0; i < kPointsPerSeed; ++i) {
        const Vec3 x{uniform(-50.0, 50.0), uniform(-50.0, 50.0), uniform(-50.0, 50.0)};
        sum += statistic(field, x, uniform(0.0, 100.0));
      }
    }
    return sum / (static_cast<double>(kSeeds) * kPointsPerSeed);
  }
};

Vec3 gust_at(const GustField& field, const Vec3& x, double t) {
  return field.velocity(x, field.phases(t));
}

TEST(Gusts, MeanIsZeroAndRmsIsTheAmplitude) {
  for (int c = 0; c < 3; ++c) {
    const double mean = Sampler::mean(
        [&](const GustField& f, const Vec3& x, double t) { return gust_at(f, x, t)[c]; });
    EXPECT_NEAR(mean, 0.0, 0.03 * kAmplitude) << "component " << c;
    // Isotropic: each component carries a third of the mean square.
    const double square = Sampler::mean([&](const GustField& f, const Vec3& x, double t) {
      const double u = gust_at(f, x, t)[c];
      return u * u;
    });
    EXPECT_NEAR(std::sqrt(square), kAmplitude / std::sqrt(3.0), 0.02 * kAmplitude)
        << "component " << c;
  }
  const double square = Sampler::mean([](const GustField& f, const Vec3& x, double t) {
    const Vec3 u = gust_at(f, x, t);
    return dot(u, u);
  });
  EXPECT_NEAR(std::sqrt(square), kAmplitude, 0.01 * kAmplitude);
}

// ⟨u_g(x, t)·u_g(x + r, t + τ)⟩ / A² = exp(−|r − Uτ|²/(2L²) − τ²/(2T²)): the gusts are
// carried by the mean wind U and forget themselves over T and L.
TEST(Gusts, CorrelationFallsOffOverTheCorrelationTimeAndLength) {
  struct Lag {
    Vec3 r;
    double tau;
    const char* what;
  };
  const Lag lags[] = {
      {{0.0, 0.0, 0.0}, 0.0, "none"},
      {{kLength, 0.0, 0.0}, 0.0, "L along x"},
      {{0.0, 2.0 * kLength, 0.0}, 0.0, "2L along y"},
      {{0.0, 0.0, 3.0 * kLength}, 0.0, "3L along z"},
      {kTime * kMean, kTime, "T, carried by the wind"},
      {(2.0 * kTime) * kMean, 2.0 * kTime, "2T, carried by the wind"},
      {{0.0, 0.0, 0.0}, kTime, "T at a fixed point"},
  };
  for (const Lag& lag : lags) {
    const double correlation = Sampler::mean([&](const GustField& f, const Vec3& x, double t) {
      return dot(gust_at(f, x, t), gust_at(f, x + lag.r, t + lag.tau));
    }) / (kAmplitude * kAmplitude);
    const Vec3 moved = lag.r - lag.tau * kMean;
    const double expected = std::exp(-dot(moved, moved) / (2.0 * kLength * kLength) -
                                     lag.tau * lag.tau / (2.0 * kTime * kTime));
    EXPECT_NEAR(correlation, expected, 0.02) << "lag " << lag.what;
  }
}

// The gust depends on (x, t, seed) alone: a field built again from the same seed gives the
// same bits, whatever was evaluated before; another seed another field.
TEST(Gusts, AFunctionOfPositionTimeAndSeedAlone) {
  const GustField first(gusts(7), kMean);
  const Vec3 x{0.3, -1.2, 2.5};
  const Vec3 before = gust_at(first, x, 4.25);
  for (int i = 0; i < 100; ++i) gust_at(first, {0.1 * i, 0.0, 0.0}, 0.01 * i);
  const GustField again(gusts(7), kMean);
  const Vec3 after = gust_at(again, x, 4.25);
  EXPECT_EQ(before.x, after.x);
  EXPECT_EQ(before.y, after.y);
  EXPECT_EQ(before.z, after.z);
  const Vec3 other = gust_at(GustField(gusts(8), kMean), x, 4.25);
  EXPECT_GT(norm(other - before), 1e-3);
}

// The field is the sum docs/model.md writes, with the modes drawn in the order it gives: a
// user can rebuild a run's wind from its seed. Here with std::cos, to the 1e-10 of the cosine
// the solver computes.
TEST(Gusts, IsTheDocumentedSumOfModes) {
  const double two_pi = 2.0 * std::numbers::pi;
  std::mt19937_64 g(11);
  const auto uniform = [&] { return static_cast<double>(g() >> 11) * 0x1.0p-53; };
  const auto normal = [&] {
    const double radius = std::sqrt(-2.0 * std::log(1.0 - uniform()));
    return radius * std::cos(two_pi * uniform());
  };
  const Vec3 x{0.7, 1.9, -0.4};
  const double t = 3.3;
  Vec3 sum;
  for (int j = 0; j < GustField::kModes; ++j) {
    const double k1 = normal(), k2 = normal(), k3 = normal();
    const Vec3 k = Vec3{k1, k2, k3} / kLength;
    const double omega = normal() / kTime;
    const double phase = two_pi * uniform();
    Vec3 across;
    do {
      const double z = 2.0 * uniform() - 1.0;
      const double angle = two_pi * uniform();
      const double s = std::sqrt(1.0 - z * z);
      across = cross(k, Vec3{s * std::cos(angle), s * std::sin(angle), z});
    } while (!(norm(across) > 1e-6 * norm(k)));
    sum += std::cos(dot(k, x - t * kMean) - omega * t + phase) * (across / norm(across));
  }
  const Vec3 expected = (kAmplitude * std::sqrt(2.0 / GustField::kModes)) * sum;
  const Vec3 u = gust_at(GustField(gusts(11), kMean), x, t);
  EXPECT_LT(norm(u - expected), 1e-9 * kAmplitude) << u.x << " " << expected.x;
}

// ---------------------------------------------------------------------------------------------
// The wind in a run

std::string s4_text() {
  std::ifstream file(COSSERAT_SOURCE_DIR "/scenes/s4_flag.toml");
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

std::vector<Vec3> final_positions(const Scene& scene, long steps) {
  Simulation sim(scene, MPI_COMM_SELF, any_scheme);
  EXPECT_TRUE(testing::advance(sim, steps));
  std::vector<Vec3> out;
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) out.push_back(sim.positions()(k, l));
  return out;
}

bool bitwise_equal(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!(a[i].x == b[i].x && a[i].y == b[i].y && a[i].z == b[i].z)) return false;
  return true;
}

// S4 as shipped ([environment.fluid] with viscosity) against the same wind written as
// [environment.wind] with drag, with a gust table of amplitude 0: the same run, bit for bit,
// for a scheme of each kind.
TEST(Wind, WithoutGustsRunsBitwiseAsTheFluidTerm) {
  const std::string fluid = s4_text();
  const std::string wind = replaced(
      replaced(fluid, "[environment.fluid]\nviscosity", "[environment.wind]\ndrag"),
      "velocity = [100.0, 0.0, 0.0]\n",
      "velocity = [100.0, 0.0, 0.0]\n"
      "gust = { amplitude = 0.0, correlation_time = 1.0, correlation_length = 2.0, seed = 9 }\n");
  for (const char* integrator : {"verlet", "rk4", "velocity-verlet"}) {
    const std::vector<std::string> set{"time.steps=60",
                                       std::string("time.integrator=\"") + integrator + "\""};
    const Scene before = parse_scene(fluid, "s4_flag.toml", set);
    const Scene after = parse_scene(wind, "s4_flag.toml", set);
    ASSERT_TRUE(after.fluid && after.fluid->gusts);
    EXPECT_TRUE(bitwise_equal(final_positions(before, 60), final_positions(after, 60)))
        << integrator;
  }
}

// The same scene with gusts moves differently: the gust term is on.
TEST(Wind, GustsChangeTheRun) {
  const std::string fluid = s4_text();
  const std::vector<std::string> calm{"time.steps=60"};
  std::vector<std::string> gusty = calm;
  for (const char* key : {"amplitude=5.0", "correlation_time=0.5", "correlation_length=3.0"})
    gusty.push_back(std::string("environment.fluid.gust.") + key);
  const auto still = final_positions(parse_scene(fluid, "s4_flag.toml", calm), 60);
  const auto moved = final_positions(parse_scene(fluid, "s4_flag.toml", gusty), 60);
  double largest = 0.0;
  for (std::size_t i = 0; i < still.size(); ++i)
    largest = std::max(largest, norm(moved[i] - still[i]));
  EXPECT_GT(largest, 1e-3);
}

}  // namespace
}  // namespace cosserat
