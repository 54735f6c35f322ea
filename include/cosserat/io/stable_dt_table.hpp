#pragma once
// The table of `cosserat stable-dt`: one row per integrator, printed and written as CSV. Scripts
// that compare integrators read the CSV by its header, so its columns do not change.

#include <string>
#include <vector>

#include "cosserat/time/stability.hpp"

namespace cosserat {

struct StableDtRow {
  std::string integrator;
  StableStep found;
  double wall_seconds = 0.0;  // all its trials together
  // What made found.unstable_dt unstable, or why the search ended without bracketing the limit.
  std::string cause;
};

// The row of one integrator's search over the simulated time `duration`.
StableDtRow stable_dt_row(const std::string& integrator, StableStep found, double duration);

struct StableDtTable {
  std::string scene;  // its title, else its name
  double duration = 0.0;
  double cfl_dt = 0.0;  // the CFL estimate the stable steps are compared with
  std::vector<StableDtRow> rows;
};

std::string to_csv(const StableDtTable& table);

// Throws std::runtime_error naming path when the file cannot be opened.
void write_csv(const std::string& path, const StableDtTable& table);

}  // namespace cosserat
