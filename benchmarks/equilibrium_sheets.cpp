// The return-to-equilibrium experiments of the mass-spring source (docs/models.md, "The
// source's experiments"): each scene named on the command line runs on one rank to its end,
// and at steps 5000 and 20 000 (or the last step, if sooner) prints the largest difference of
// any coordinate from the rest position, the largest distance from it and the standard
// deviation of the distances over the particles. run_equilibrium.sh runs the four sheets.

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "cosserat/scene/scene.hpp"
#include "cosserat/time/simulation.hpp"
#include "cosserat/time/step_loop.hpp"

namespace {

using namespace cosserat;

struct Departure {
  long step = 0;
  double time = 0.0;
  double coordinate = 0.0;  // m, the largest |r − r0| of any component
  double distance = 0.0;    // m, the largest |r − r0|
  double spread = 0.0;      // m, the standard deviation of |r − r0| over the particles
};

Departure departure(Simulation& sim, const Field<Vec3>& rest) {
  const Block& b = sim.block();
  Departure d{sim.step_index(), sim.time()};
  std::vector<double> distances;
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) {
      const Vec3 move = sim.positions()(k, l) - rest(k, l);
      d.coordinate =
          std::max({d.coordinate, std::abs(move.x), std::abs(move.y), std::abs(move.z)});
      distances.push_back(norm(move));
    }
  double mean = 0.0;
  for (const double x : distances) mean += x / static_cast<double>(distances.size());
  double variance = 0.0;
  for (const double x : distances)
    variance += (x - mean) * (x - mean) / static_cast<double>(distances.size());
  d.distance = *std::max_element(distances.begin(), distances.end());
  d.spread = std::sqrt(variance);
  return d;
}

class AtSteps : public StepObserver {
 public:
  AtSteps(Simulation& sim, const Field<Vec3>& rest) : sim_(sim), rest_(rest) {}
  void frame() override {}
  void checkpoint(const LoopCarry&) override {}
  void progress(long step) override {
    if (step == 5000 || step == 20000) found.push_back(departure(sim_, rest_));
  }
  std::vector<Departure> found;

 private:
  Simulation& sim_;
  const Field<Vec3>& rest_;
};

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int status = 0;
  try {
    std::printf("| scene | step | t (s) | largest coordinate difference (m) | largest distance (m) "
                "| std of distances (m) | wall (s) |\n|---|---|---|---|---|---|---|\n");
    for (int i = 1; i < argc; ++i) {
      const Scene scene = load_scene(argv[i]);
      Simulation sim(scene, MPI_COMM_SELF);
      const Field<Vec3> rest = sim.positions();  // the sheets start at rest
      AtSteps observer(sim, rest);
      const StepLoopResult result = run_step_loop(sim, scene, {}, observer);
      if (result.failure) std::printf("%s: stopped, unstable\n", scene.name.c_str());
      if (observer.found.empty() || observer.found.back().step != sim.step_index())
        observer.found.push_back(departure(sim, rest));
      for (const Departure& d : observer.found)
        std::printf("| %s | %ld | %.2f | %.3e | %.3e | %.3e | %.1f |\n", scene.name.c_str(), d.step,
                    d.time, d.coordinate, d.distance, d.spread, result.wall_seconds);
      std::fflush(stdout);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    status = 1;
  }
  MPI_Finalize();
  return status;
}
