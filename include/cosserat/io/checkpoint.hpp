#pragma once
// Checkpoints: the whole state of a run in one HDF5 file, written collectively, from which a
// restart continues bitwise as if never interrupted (on any number of ranks: the fields are
// stored as whole-grid arrays, not per rank).

#include <stdexcept>
#include <optional>
#include <string>

#include "cosserat/scene/scene.hpp"
#include "cosserat/time/simulation.hpp"

namespace cosserat {

// A file that is not a checkpoint of this scene: bad input, reported before any step.
class CheckpointError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// `<output stem>.checkpoint.h5` beside the output file.
std::string checkpoint_path(const std::string& output_path);

// Writes the state of `simulation` to `path`: first to `path`.partial, renamed over `path` only
// once complete and closed, so a run killed while writing leaves the previous checkpoint
// valid. Collective. Throws std::runtime_error on I/O failure. `rest_peak`: the peak kinetic
// energy so far of a run with --until-rest, which its restart must continue from;
// `adaptive_scale`: what roll-backs left of adaptive steps' estimate (docs/stability.md).
void write_checkpoint(const std::string& path, Simulation& simulation, const Scene& scene,
                      const std::string& version, std::optional<double> rest_peak = {},
                      std::optional<double> adaptive_scale = {});

// Loads a checkpoint into `simulation`, built for `scene` on any decomposition, and returns its
// step. Throws CheckpointError, on every rank alike and naming the file, if the file cannot be
// read as a checkpoint, was written for a different grid, integrator or time step, or holds
// what this scene cannot continue from: a step outside its steps, fields of another shape or
// with a value that is not finite, constraints other than its fixes' (nodes outside the grid
// or fixed by no [[fix]], components no fix holds, values not finite, fixed nodes missing), a
// peak kinetic energy that is not finite or negative. Collective.
// With `rest_peak`, also the peak kinetic energy the checkpoint carries (empty if none); with
// `adaptive_scale`, what roll-backs left of adaptive steps' estimate.
long read_checkpoint(const std::string& path, Simulation& simulation, const Scene& scene,
                     std::optional<double>* rest_peak = nullptr,
                     double* adaptive_scale = nullptr);

}  // namespace cosserat
