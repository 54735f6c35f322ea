#include "cosserat/io/checkpoint.hpp"

#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <system_error>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "hdf5_file.hpp"

namespace cosserat {

using hdf5::Handle;

namespace {

constexpr const char* kFormat = "cosserat checkpoint 1";

Handle create_dataset(const hdf5::File& file, const std::string& name, hid_t type,
                      const std::vector<hsize_t>& dims) {
  const std::string what = fmt::format("create dataset {}", name);
  const Handle space = file.open(
      H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose, what);
  return file.open(H5Dcreate2(file.get(), name.c_str(), type, space.get(), H5P_DEFAULT,
                              H5P_DEFAULT, H5P_DEFAULT),
                   H5Dclose, what);
}

// Rows [offset, offset + rows) of a dataset [total][columns] from this rank; collective.
void write_rows(const hdf5::File& file, const Handle& dataset, hid_t memory_type,
                hsize_t offset, hsize_t rows, hsize_t columns, const void* values,
                const std::string& what) {
  const Handle file_space = file.open(H5Dget_space(dataset.get()), H5Sclose, what);
  const std::array<hsize_t, 2> start{offset, 0}, count{rows, columns};
  const int rank = H5Sget_simple_extent_ndims(file_space.get());
  const Handle memory_space =
      file.open(H5Screate_simple(rank, count.data(), nullptr), H5Sclose, what);
  if (rows > 0)
    file.check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr,
                                   count.data(), nullptr),
               what + " (select)");
  else
    file.check(H5Sselect_none(file_space.get()), what + " (select)");
  if (rows == 0) file.check(H5Sselect_none(memory_space.get()), what + " (select)");
  file.check(H5Dwrite(dataset.get(), memory_type, memory_space.get(), file_space.get(),
                      file.collective(), values),
             what);
}

template <class T>
std::vector<T> read_all(const hdf5::File& file, const std::string& name, hid_t memory_type,
                        std::size_t values_per_row) {
  const std::string what = fmt::format("read {}", name);
  const Handle dataset =
      file.open(H5Dopen2(file.get(), name.c_str(), H5P_DEFAULT), H5Dclose, what);
  const Handle space = file.open(H5Dget_space(dataset.get()), H5Sclose, what);
  const hssize_t points = H5Sget_simple_extent_npoints(space.get());
  file.check(static_cast<hid_t>(points), what);
  std::vector<T> values(static_cast<std::size_t>(points));
  if (values.size() != 0)
    file.check(H5Dread(dataset.get(), memory_type, H5S_ALL, H5S_ALL, file.independent(),
                       values.data()),
               what);
  if (values.size() % values_per_row != 0) file.fail(what + " (shape)");
  return values;
}

// The constraints of every rank as one list, each rank writing its own stretch.
void write_constraints(const hdf5::File& file, const Constraints& constraints, MPI_Comm comm) {
  const std::vector<Constraints::NodeState> local = constraints.state();
  const long count = static_cast<long>(local.size());
  long offset = 0, total = 0;
  MPI_Exscan(&count, &offset, 1, MPI_LONG, MPI_SUM, comm);
  if (rank_in(comm) == 0) offset = 0;
  MPI_Allreduce(&count, &total, 1, MPI_LONG, MPI_SUM, comm);

  std::vector<std::int32_t> nodes;
  std::vector<std::uint8_t> held;
  std::vector<double> values, since, velocities, spins, pivots;
  for (const Constraints::NodeState& s : local) {
    nodes.insert(nodes.end(), {s.k, s.l});
    held.push_back(s.held);
    values.insert(values.end(), {s.value.x, s.value.y, s.value.z});
    since.insert(since.end(), {s.since.x, s.since.y, s.since.z});
    velocities.insert(velocities.end(), {s.velocity.x, s.velocity.y, s.velocity.z});
    spins.insert(spins.end(), {s.spin.x, s.spin.y, s.spin.z});
    pivots.insert(pivots.end(), {s.pivot.x, s.pivot.y, s.pivot.z});
  }
  const auto rows = static_cast<hsize_t>(count), at = static_cast<hsize_t>(offset);
  const auto all = static_cast<hsize_t>(total);
  const Handle node_set = create_dataset(file, "/constraint_nodes", H5T_STD_I32LE, {all, 2});
  const Handle held_set = create_dataset(file, "/constraint_held", H5T_STD_U8LE, {all, 1});
  const Handle value_set = create_dataset(file, "/constraint_values", H5T_IEEE_F64LE, {all, 3});
  const Handle since_set = create_dataset(file, "/constraint_since", H5T_IEEE_F64LE, {all, 3});
  const Handle velocity_set =
      create_dataset(file, "/constraint_velocities", H5T_IEEE_F64LE, {all, 3});
  const Handle spin_set = create_dataset(file, "/constraint_spins", H5T_IEEE_F64LE, {all, 3});
  const Handle pivot_set = create_dataset(file, "/constraint_pivots", H5T_IEEE_F64LE, {all, 3});
  if (all == 0) return;
  write_rows(file, node_set, H5T_NATIVE_INT32, at, rows, 2, nodes.data(), "write constraints");
  write_rows(file, held_set, H5T_NATIVE_UINT8, at, rows, 1, held.data(), "write constraints");
  write_rows(file, value_set, H5T_NATIVE_DOUBLE, at, rows, 3, values.data(), "write constraints");
  write_rows(file, since_set, H5T_NATIVE_DOUBLE, at, rows, 3, since.data(), "write constraints");
  write_rows(file, velocity_set, H5T_NATIVE_DOUBLE, at, rows, 3, velocities.data(),
             "write constraints");
  write_rows(file, spin_set, H5T_NATIVE_DOUBLE, at, rows, 3, spins.data(), "write constraints");
  write_rows(file, pivot_set, H5T_NATIVE_DOUBLE, at, rows, 3, pivots.data(), "write constraints");
}

std::vector<Constraints::NodeState> read_constraints(const hdf5::File& file) {
  const auto nodes = read_all<std::int32_t>(file, "/constraint_nodes", H5T_NATIVE_INT32, 2);
  const auto held = read_all<std::uint8_t>(file, "/constraint_held", H5T_NATIVE_UINT8, 1);
  const auto values = read_all<double>(file, "/constraint_values", H5T_NATIVE_DOUBLE, 3);
  // Checkpoints written before fixes had velocities lack these: every fix was still, so each
  // held component moves at 0 (and when it was taken does not matter).
  const auto optional = [&](const char* name) {
    const bool present = file.check(H5Lexists(file.get(), name, H5P_DEFAULT), "look for " +
                                    std::string(name)) > 0;
    return present ? read_all<double>(file, name, H5T_NATIVE_DOUBLE, 3)
                   : std::vector<double>(3 * held.size(), 0.0);
  };
  const auto since = optional("/constraint_since");
  const auto velocities = optional("/constraint_velocities");
  // Those written before fixes could turn lack these: no node turned.
  const auto spins = optional("/constraint_spins");
  const auto pivots = optional("/constraint_pivots");
  if (nodes.size() != 2 * held.size() || values.size() != 3 * held.size() ||
      since.size() != 3 * held.size() || velocities.size() != 3 * held.size() ||
      spins.size() != 3 * held.size() || pivots.size() != 3 * held.size())
    file.fail("read constraints (lengths differ)");
  const auto vec3 = [](const std::vector<double>& v, std::size_t i) {
    return Vec3{v[3 * i], v[3 * i + 1], v[3 * i + 2]};
  };
  std::vector<Constraints::NodeState> states;
  for (std::size_t i = 0; i < held.size(); ++i)
    states.push_back({nodes[2 * i], nodes[2 * i + 1], held[i], vec3(values, i), vec3(since, i),
                      vec3(velocities, i), vec3(spins, i), vec3(pivots, i)});
  return states;
}

// The grid, integrator and time step the checkpoint was written for, its step and the peak
// kinetic energy it carries: what is wrong with them, or nothing.
std::optional<std::string> check_header(const hdf5::File& file, const std::string& path,
                                        const Scene& scene, long& step,
                                        std::optional<double>& peak) {
  if (file.read_string_attribute("format") != kFormat)
    return fmt::format("'{}' is not a cosserat checkpoint", path);
  const long m = file.read_int_attribute("m"), n = file.read_int_attribute("n");
  const std::string integrator = file.read_string_attribute("integrator");
  const double dt = file.read_double_attribute("dt");
  const bool adaptive = file.has_attribute("adaptive_scale");
  if (adaptive != scene.adaptive.has_value())
    return fmt::format("checkpoint '{}' was written with {} steps; this scene's steps are {}",
                       path, adaptive ? "adaptive" : "fixed",
                       scene.adaptive ? "adaptive" : "fixed");
  if (m != scene.m || n != scene.n || integrator != integrator_name(scene.integrator) ||
      dt != scene.dt)
    return fmt::format(
        "checkpoint '{}' was written for a {} x {} grid with {} at dt = {} s; this scene has "
        "{} x {} with {} at dt = {} s",
        path, m, n, integrator, dt, scene.m, scene.n, integrator_name(scene.integrator),
        scene.dt);
  step = file.read_int_attribute("step");
  if (step < 0 || step > scene.steps)
    return fmt::format("checkpoint '{}' is at step {}, outside this scene's steps 0 .. {}", path,
                       step, scene.steps);
  if (file.has_attribute("peak_kinetic_energy")) {
    peak = file.read_double_attribute("peak_kinetic_energy");
    if (!(std::isfinite(*peak) && *peak >= 0.0))
      return fmt::format("checkpoint '{}': its peak kinetic energy is {}, not a finite number "
                         ">= 0",
                         path, *peak);
  }
  return std::nullopt;
}

// Adaptive steps: where the run stands in time, the step that ended there (tc-verlet's previous
// step) and what roll-backs left of the estimate.
struct AdaptiveState {
  double time = 0.0, last_dt = 0.0, scale = 1.0;
};

std::optional<std::string> read_adaptive_state(const hdf5::File& file, const std::string& path,
                                               const Scene& scene, AdaptiveState& state) {
  state.time = file.read_double_attribute("time");
  state.last_dt = file.read_double_attribute("last_dt");
  state.scale = file.read_double_attribute("adaptive_scale");
  if (!(state.time >= 0.0 && state.time <= scene.duration))
    return fmt::format("checkpoint '{}' is at t = {} s, outside this scene's duration of {} s",
                       path, state.time, scene.duration);
  if (!(state.last_dt > 0.0 && std::isfinite(state.last_dt) && state.scale > 0.0 &&
        state.scale <= 1.0))
    return fmt::format("checkpoint '{}': its last step {} s or its roll-back factor {} is not "
                       "a step or a factor in (0, 1]",
                       path, state.last_dt, state.scale);
  // A random sequence continues bitwise only as the same seed's between the same bounds.
  const bool random = file.has_attribute("random_seed");
  const AdaptiveStep& steps = *scene.adaptive;
  if (random != steps.random ||
      (random && (file.read_int_attribute("random_seed") !=
                      static_cast<long>(steps.seed) ||
                  file.read_double_attribute("dt_min") != steps.min)))
    return fmt::format("checkpoint '{}' was written with other variable steps than this "
                       "scene's ({})",
                       path, steps.random ? fmt::format("random, seed {}, {} to {} s", steps.seed,
                                                        steps.min, steps.max)
                                          : "adaptive");
  return std::nullopt;
}

// A state field is a whole-grid [m][n][3] array; another shape would select outside the file's
// array on some ranks only.
std::optional<std::string> check_shape(const hdf5::File& file, const Handle& dataset,
                                       const std::string& path, const std::string& name,
                                       const Scene& scene) {
  const std::string what = "read the shape of /" + name;
  const Handle space = file.open(H5Dget_space(dataset.get()), H5Sclose, what);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  file.check(rank, what);
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  file.check(H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr), what);
  const std::vector<hsize_t> expected{static_cast<hsize_t>(scene.m),
                                      static_cast<hsize_t>(scene.n), 3};
  if (dims == expected) return std::nullopt;
  return fmt::format("checkpoint '{}': /{} is [{}], not the [{}, {}, 3] of this grid", path, name,
                     fmt::join(dims, ", "), scene.m, scene.n);
}

// The constraints must be those of the scene's [[fix]] tables: every fixed node once, inside
// the grid, holding only components some fix of it holds, at finite values. The list is the
// same on every rank.
std::optional<std::string> check_constraints(const std::vector<Constraints::NodeState>& states,
                                             const std::string& path, const Scene& scene) {
  std::map<std::pair<int, int>, std::uint8_t> axes_of;  // by (k, l): the components fixes hold
  for (const Fix& fix : scene.fixes) {
    std::uint8_t axes = 0;
    for (int c = 0; c < 3; ++c)
      if (fix.axes[static_cast<std::size_t>(c)]) axes |= static_cast<std::uint8_t>(1u << c);
    for (const NodeIndex& node : fix.nodes.nodes) axes_of[{node.k, node.l}] |= axes;
  }
  std::set<std::pair<int, int>> seen;
  for (const Constraints::NodeState& s : states) {
    const std::string node = fmt::format("checkpoint '{}': constraint node [{}, {}]", path, s.k, s.l);
    if (s.k < 0 || s.k >= scene.m || s.l < 0 || s.l >= scene.n)
      return fmt::format("{} is outside the {} x {} grid", node, scene.m, scene.n);
    const auto fixed = axes_of.find({s.k, s.l});
    if (fixed == axes_of.end()) return node + " is held by no [[fix]] of this scene";
    if (!seen.insert({s.k, s.l}).second) return node + " is listed twice";
    if ((s.held & ~fixed->second) != 0)
      return fmt::format("{} holds components {:#05b}, beyond the {:#05b} this scene's fixes "
                         "hold",
                         node, s.held, fixed->second);
    if (s.turns() && s.held != 7u)
      return node + " turns but does not hold all three components";
    if (!(is_finite(s.spin) && is_finite(s.pivot)))
      return fmt::format("{} turns at ({}, {}, {}) rad/s about ({}, {}, {}) m: not finite", node,
                         s.spin.x, s.spin.y, s.spin.z, s.pivot.x, s.pivot.y, s.pivot.z);
    if (!(is_finite(s.value) && is_finite(s.since) && is_finite(s.velocity)))
      return fmt::format("{} is held at ({}, {}, {}), from t = ({}, {}, {}) s, at ({}, {}, {}) "
                         "m/s: not finite",
                         node, s.value.x, s.value.y, s.value.z, s.since.x, s.since.y, s.since.z,
                         s.velocity.x, s.velocity.y, s.velocity.z);
  }
  for (const auto& [kl, axes] : axes_of)
    if (!seen.contains(kl))
      return fmt::format("checkpoint '{}' lacks node [{}, {}], which this scene fixes", path,
                         kl.first, kl.second);
  return std::nullopt;
}

// The first node of this rank's block, in (l, k) order, whose value is not finite.
std::optional<std::string> check_finite(const Field<Vec3>& field, const std::string& path,
                                        const std::string& name) {
  const Block& b = field.block();
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) {
      const Vec3 r = field(k, l);
      if (!(std::isfinite(r.x) && std::isfinite(r.y) && std::isfinite(r.z)))
        return fmt::format("checkpoint '{}': /{} at node [{}, {}] is ({}, {}, {}), not finite",
                           path, name, k, l, r.x, r.y, r.z);
    }
  return std::nullopt;
}

// The problem of the lowest rank that found one, on every rank: a rank that refused alone
// would leave the others waiting in the run's first collective call.
std::optional<std::string> first_of_any_rank(const std::optional<std::string>& problem,
                                             MPI_Comm comm) {
  const int mine = problem ? rank_in(comm) : size_of(comm);
  int first = 0;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == size_of(comm)) return std::nullopt;
  std::string text = problem.value_or("");
  int length = static_cast<int>(text.size());
  MPI_Bcast(&length, 1, MPI_INT, first, comm);
  text.resize(static_cast<std::size_t>(length));
  MPI_Bcast(text.data(), length, MPI_CHAR, first, comm);
  return text;
}

}  // namespace

std::string checkpoint_path(const std::string& output_path) {
  std::filesystem::path path(output_path);
  path.replace_extension(".checkpoint.h5");
  return path.string();
}

void write_checkpoint(const std::string& path, Simulation& simulation, const Scene& scene,
                      const std::string& version, std::optional<double> rest_peak,
                      std::optional<double> adaptive_scale) {
  const Block& b = simulation.block();
  const std::string partial = path + ".partial";
  {
    const hdf5::File file(partial, b.comm, hdf5::File::Mode::create);
    file.write_attribute("format", std::string(kFormat));
    file.write_attribute("version", version);
    file.write_attribute("scene", scene.text);
    file.write_attribute("integrator", std::string(integrator_name(scene.integrator)));
    file.write_attribute("m", std::int64_t{scene.m});
    file.write_attribute("n", std::int64_t{scene.n});
    file.write_attribute("dt", scene.dt);
    file.write_attribute("step", std::int64_t{simulation.step_index()});
    file.write_attribute("time", simulation.time());
    if (rest_peak) file.write_attribute("peak_kinetic_energy", *rest_peak);
    if (scene.adaptive) {
      // Adaptive steps continue bitwise only from the same step history and roll-back factor.
      file.write_attribute("last_dt", simulation.stepper().last_dt());
      file.write_attribute("adaptive_scale", adaptive_scale.value_or(1.0));
      if (scene.adaptive->random) {
        file.write_attribute("random_seed", static_cast<std::int64_t>(scene.adaptive->seed));
        file.write_attribute("dt_min", scene.adaptive->min);
      }
    }
    const std::vector<hsize_t> shape{static_cast<hsize_t>(b.m), static_cast<hsize_t>(b.n), 3};
    for (const Stepper::StateField& f : simulation.stepper().state_fields()) {
      const Handle dataset = create_dataset(file, "/" + f.name, H5T_IEEE_F64LE, shape);
      file.write_block(dataset.get(), *f.field, {}, "write /" + f.name);
    }
    write_constraints(file, simulation.stepper().constraints(), b.comm);
    // The solids' motion and what contact found so far: replicated, so every rank writes the
    // same numbers.
    const std::vector<std::vector<double>> actions = simulation.stepper().action_states();
    for (std::size_t i = 0; i < actions.size(); ++i)
      file.write_attribute(fmt::format("action_state_{}", i), actions[i]);
    file.flush();
  }
  // Every rank has closed the file; only then does it replace the previous checkpoint.
  MPI_Barrier(b.comm);
  int renamed = 1;
  std::string reason;
  if (rank_in(b.comm) == 0) {
    std::error_code error;
    std::filesystem::rename(partial, path, error);
    renamed = error ? 0 : 1;
    reason = error.message();
  }
  MPI_Bcast(&renamed, 1, MPI_INT, 0, b.comm);
  if (renamed == 0)
    throw std::runtime_error(fmt::format("cannot rename checkpoint '{}' to '{}': {}", partial,
                                         path, reason.empty() ? "see rank 0" : reason));
}

long read_checkpoint(const std::string& path, Simulation& simulation, const Scene& scene,
                     std::optional<double>* rest_peak, double* adaptive_scale) {
  const Block& b = simulation.block();
  std::optional<std::string> problem;
  long step = 0;
  std::optional<double> peak;
  std::vector<Constraints::NodeState> constraints;
  std::vector<std::vector<double>> actions;
  AdaptiveState adaptive;
  try {
    const hdf5::File file(path, b.comm, hdf5::File::Mode::read);
    // Every rank reads the same attributes and shapes, so each check below fails on all ranks
    // alike, before the collective reads of the fields.
    problem = check_header(file, path, scene, step, peak);
    if (!problem && scene.adaptive)
      problem = read_adaptive_state(file, path, scene, adaptive);
    for (const Stepper::StateField& f : simulation.stepper().state_fields()) {
      if (problem) break;
      const Handle dataset = file.open(H5Dopen2(file.get(), ("/" + f.name).c_str(), H5P_DEFAULT),
                                       H5Dclose, "open /" + f.name);
      problem = check_shape(file, dataset, path, f.name, scene);
      if (!problem) file.read_block(dataset.get(), *f.field, "read /" + f.name);
    }
    if (!problem) constraints = read_constraints(file);
    const std::size_t count = simulation.stepper().action_states().size();
    for (std::size_t i = 0; i < count && !problem; ++i) {
      const std::string name = fmt::format("action_state_{}", i);
      if (!file.has_attribute(name)) {
        problem = fmt::format(
            "cannot restart from '{}': it holds no state of the solids, the springs or "
            "self-contact ({}); it was written for a scene without them",
            path, name);
        break;
      }
      actions.push_back(file.read_doubles_attribute(name));
      for (const double x : actions.back())
        if (!std::isfinite(x)) {
          problem = fmt::format(
              "cannot restart from '{}': the state of the solids, the springs or self-contact "
              "({}) holds a value that is not finite",
              path, name);
          break;
        }
    }
  } catch (const std::runtime_error& e) {
    problem = fmt::format("cannot restart from '{}': {}", path, e.what());
  }
  if (!problem) problem = check_constraints(constraints, path, scene);
  for (const Stepper::StateField& f : simulation.stepper().state_fields())
    if (!problem) problem = check_finite(*f.field, path, f.name);
  if (const auto refused = first_of_any_rank(problem, b.comm)) throw CheckpointError(*refused);

  simulation.stepper().constraints().restore(constraints);
  try {
    simulation.stepper().restore_action_states(actions);
  } catch (const std::invalid_argument& e) {
    throw CheckpointError(fmt::format("cannot restart from '{}': {}", path, e.what()));
  }
  if (scene.adaptive) {
    simulation.stepper().resume(step, adaptive.time, adaptive.last_dt);
    if (adaptive_scale != nullptr) *adaptive_scale = adaptive.scale;
  } else {
    simulation.stepper().resume(step);
  }
  if (rest_peak != nullptr) *rest_peak = peak;
  return step;
}

}  // namespace cosserat
