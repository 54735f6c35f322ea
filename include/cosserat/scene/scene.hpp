#pragma once
// A validated scene: the only thing the rest of the solver reads from a scene file
// (docs/scene-format.md). Data flows one way: file -> Scene -> Simulation.

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "cosserat/contact/solid.hpp"
#include "cosserat/model/borders.hpp"
#include "cosserat/model/model_spec.hpp"
#include "cosserat/model/material.hpp"
#include "cosserat/grid/vec3.hpp"
#include "cosserat/time/integrator.hpp"

namespace cosserat {

// Bad input. what() is the full message: file, key, line where known, what is allowed.
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct NodeIndex {
  int k = 0;
  int l = 0;
  bool operator==(const NodeIndex&) const = default;
};

// A set of grid nodes, already expanded from its scene form (list, rect, disk, row, column)
// and checked to lie inside the grid.
struct NodeSet {
  std::vector<NodeIndex> nodes;
};

// When a fix or load acts, both bounds inclusive: during the step from step s at time t when
// start <= s <= end and start_time <= t <= end_time. A fixed step may give either; adaptive
// steps only the times, since there the step index depends on the steps taken.
struct Window {
  long start = 0;
  long end = std::numeric_limits<long>::max();
  double start_time = 0.0;
  double end_time = std::numeric_limits<double>::infinity();

  bool contains(long step, double time) const {
    return start <= step && step <= end && start_time <= time && time <= end_time;
  }
};

struct Fix {
  NodeSet nodes;
  std::array<bool, 3> axes{true, true, true};
  Window window;
  // m/s: the held components move at this velocity from the moment they are held (0 on every
  // axis the fix does not hold).
  Vec3 velocity{};
  // rad/s: the held nodes turn rigidly about the fixed axis through `center` along this vector
  // (all three components held; no `velocity`), from where they are when held.
  Vec3 angular_velocity{};
  Vec3 center{};  // m
};

struct Load {
  NodeSet nodes;
  // Newtons on each node (docs/equations.md §1); with `per_area`, newtons per square metre of
  // rest area, each node taking it times its dual area (docs/scene-format.md, "Fixes and loads").
  Vec3 force;
  bool per_area = false;
  Window window;
};

// Variable steps. time.dt = { adaptive = true, ... }, or no time.dt: the step follows the
// stability estimate of the current state (docs/stability.md, "Adaptive steps").
// time.dt = { sequence = "random", min, max, seed }: each step drawn from [min, max], the same
// for every run of the seed (docs/stability.md, "Random steps").
struct AdaptiveStep {
  double min = 0.0;     // s; a run that needs a smaller step is unstable (exit 3)
  double max = 0.0;     // s
  double safety = 0.5;  // the fraction of the estimate taken
  bool random = false;  // the steps are the seed's random sequence, not the estimate's
  std::uint64_t seed = 0;
};

// Gusts on top of the mean wind: a sum of random Fourier modes drawn from the seed
// (docs/model.md "Wind and gusts").
struct Gusts {
  double amplitude = 0.0;           // m/s: the rms of the gust velocity, all components
  double correlation_time = 0.0;    // s: T
  double correlation_length = 0.0;  // m: L
  std::uint64_t seed = 0;
};

// The fluid term of docs/equations.md §1, which scenes call wind: [environment.wind], or its older
// name [environment.fluid].
struct Fluid {
  double viscosity = 0.0;  // rho_R, N s/m^3 (the scene's `drag`)
  Vec3 velocity;           // u: the mean wind, m/s
  std::optional<Gusts> gusts;  // none, or amplitude 0: u is constant
};

// [time.solver]: the linear solver of the semi-implicit integrator, in PETSc's names. PETSc's
// own -ksp_* and -pc_* options (command line or PETSC_OPTIONS) override these.
struct LinearSolver {
  // Empty: the baseline chooses by the grid and its Jacobian (default_linear_solver in
  // cosserat/baseline/semi_implicit.hpp).
  std::string ksp;
  std::string pc;
  double rtol = 1e-10;
  double atol = 1e-50;  // PETSc's default: the relative test decides
  long max_iterations = 1000;
  long jacobian_every = 1;  // steps a Jacobian and its preconditioner serve
};

// [self_contact]: the cloth kept off its own cells (docs/contact.md, "Self-contact").
struct SelfContactSpec {
  double thickness = 0.0;  // m: material.thickness, or its preset's
  double friction = 0.3;   // Coulomb's μ between the layers
  bool every_edge = true;  // edges = "all": every edge against every other; "border": the border's
};

// The per-node fields a run can write beside its positions (docs/output.md, "Fields"), in the
// order they are written.
// broken_springs is no choice of [output]: a mass-spring scene that can tear writes it always
// (docs/output.md, "Fields").
enum class OutputField { velocity, area_ratio, curvature, energy_density, broken_springs };

// As written in scene files and as the datasets /fields/<name> are named.
const char* output_field_name(OutputField field);
std::vector<OutputField> all_output_fields();

// Without output.fields a grid of at most this many nodes writes every field, a larger one
// none: at 250 000 nodes (500 x 500) a frame's positions take 6 MB and its fields 12 MB more
// (docs/output.md, "Fields").
inline constexpr long kOutputFieldsDefaultMaxNodes = 250'000;

struct Scene {
  std::string path;   // the file it came from
  std::string text;   // the scene text as read
  std::string name;   // file stem: default output name
  std::string title;
  std::vector<std::string> overrides;  // the --set arguments applied, as given

  // [grid]
  int m = 0;  // nodes along x1
  int n = 0;  // nodes along x2
  double size1 = 0.0;
  double size2 = 0.0;
  Vec3 origin;
  Vec3 u{1.0, 0.0, 0.0};  // normalised
  Vec3 v{0.0, 0.0, 1.0};  // normalised

  // [material], after the preset and overrides; mass = total kg (density converted)
  Material material;

  // [model]
  ModelKind model_kind = ModelKind::cosserat;
  SpringSpec springs;  // mass-spring only
  Discretisation discretisation = Discretisation::energy;
  Borders borders = Borders::symmetric;  // flux form only

  // [environment]
  Vec3 gravity;
  double damping = 0.0;
  Vec3 initial_velocity;
  std::optional<Fluid> fluid;

  // [time]
  Integrator integrator = Integrator::verlet;
  // With a fixed step: dt, steps and output_every, duration = steps x dt. With adaptive steps:
  // duration and output_dt; dt is the first step's bound, steps the most a run may take.
  double dt = 0.0;
  long steps = 0;
  long output_every = 1;  // write a frame every N steps (the last step always)
  std::optional<AdaptiveStep> adaptive;
  double duration = 0.0;   // simulated seconds
  double output_dt = 0.0;  // adaptive: a frame every output_dt simulated seconds (and the last)
  LinearSolver solver;

  std::vector<Fix> fixes;
  std::vector<Load> loads;
  // [output]: the fields written beside the positions, in OutputField order.
  std::vector<OutputField> output_fields;

  // [[solid]]: rigid solids the cloth meets (docs/scene-format.md "Solids"); none: no contact
  // code runs.
  std::vector<SolidSpec> solids;
  // None: the cloth passes through itself, as it did before self-contact.
  std::optional<SelfContactSpec> self_contact;

  // Warnings the loader found (e.g. a coupling that breaks positive definiteness).
  std::vector<std::string> warnings;
  // φ² ≥ 4ζξ in some component: the stored energy has directions that cost nothing or less
  // (docs/equations.md §1), so grid-scale creases may grow whatever the step.
  bool energy_indefinite = false;

  double h1() const { return size1 / (m - 1); }
  double h2() const { return size2 / (n - 1); }
  double areal_density() const { return material.mass / (size1 * size2); }  // μ0, kg/m²
  // What the force model is built from (make_force_model, rest_step_estimate).
  ModelSpec model_spec() const {
    return ModelSpec{discretisation, borders, material, h1(), h2(), u, v, areal_density(),
                     model_kind,     springs, material.mass / (static_cast<double>(m) * n)};
  }
};

// Reads and validates a scene file. `overrides` are "dotted.key=toml-value" strings applied
// on top of the file before validation. Throws SceneError on any bad input.
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {});

// Same, from text already in memory (`path` is used in messages only).
Scene parse_scene(const std::string& text, const std::string& path,
                  const std::vector<std::string>& overrides = {});

}  // namespace cosserat
