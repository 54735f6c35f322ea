#include "cosserat/io/stable_dt_table.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <stdexcept>
#include <utility>

namespace cosserat {

StableDtRow stable_dt_row(const std::string& integrator, StableStep found, double duration) {
  StableDtRow row;
  row.integrator = integrator;
  for (const StabilityTrial& t : found.trials) {
    row.wall_seconds += t.wall_seconds;
    if (!t.stable && t.dt == found.unstable_dt) row.cause = t.cause;
  }
  if (found.unstable_dt == 0.0) row.cause = fmt::format("stable up to dt = T = {} s", duration);
  if (found.fails_near_time)
    row.cause = fmt::format(
        "fails near t = {:.3g} s for every step tried (the model's failure, not the step's); {}",
        *found.fails_near_time, row.cause);
  else if (found.stable_dt == 0.0)
    row.cause = "no stable step down to 1e-6 of the scene's dt; " + row.cause;
  row.found = std::move(found);
  return row;
}

std::string to_csv(const StableDtTable& table) {
  std::string csv =
      "scene,integrator,duration,stable_dt,unstable_dt,cfl_dt,stable_over_cfl,trials,"
      "wall_seconds,cause\n";
  for (const StableDtRow& row : table.rows) {
    const StableStep& found = row.found;
    csv += fmt::format("\"{}\",{},{},{},{},{},{},{},{},\"{}\"\n", table.scene, row.integrator,
                       table.duration, found.stable_dt, found.unstable_dt, table.cfl_dt,
                       found.stable_dt / table.cfl_dt, found.trials.size(), row.wall_seconds,
                       row.cause);
  }
  return csv;
}

void write_csv(const std::string& path, const StableDtTable& table) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (file == nullptr) throw std::runtime_error(fmt::format("cannot write {}", path));
  std::fputs(to_csv(table).c_str(), file);
  std::fclose(file);
}

}  // namespace cosserat
