#pragma once
// The wind's gusts (docs/model.md "Wind and gusts"): a sum of random Fourier modes drawn from
// the scene's seed, advected by the mean wind. The gust is a function of position, time and
// seed alone, so every rank, thread count and restart that asks for it at (x, t) gets the same
// bits, and a checkpoint carries nothing for it.

#include <array>

#include "cosserat/grid/vec3.hpp"
#include "cosserat/scene/scene.hpp"

namespace cosserat {

class GustField {
 public:
  // Enough for the field to look irregular at every point; each mode costs a cosine per node
  // and force evaluation.
  static constexpr int kModes = 16;

  // The modes of `gusts` (its seed, amplitude, correlation time and length), carried along by
  // the mean wind `mean`.
  GustField(const Gusts& gusts, const Vec3& mean);

  // Each mode's phase at x = 0 at one time: computed once per force evaluation and shared by
  // every node.
  struct Phases {
    std::array<double, kModes> at_origin;
  };
  Phases phases(double time) const;

  // The gust u_g at position x, at the time `phases` belongs to (m/s).
  Vec3 velocity(const Vec3& x, const Phases& phases) const;

 private:
  // One array per component, so that the loop over the modes vectorises.
  std::array<double, kModes> kx_, ky_, kz_;  // wavevector k_j (1/m)
  std::array<double, kModes> ax_, ay_, az_;  // A sqrt(2/N) a_j (m/s)
  std::array<double, kModes> phase_;         // φ_j
  std::array<double, kModes> rate_;          // k_j·U + ω_j (1/s)
};

}  // namespace cosserat
