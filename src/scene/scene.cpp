// Scene loader: TOML text -> validated Scene (docs/scene-format.md). This file holds the
// sections: what each accepts, its defaults, and the order they depend on one another.
//
// Every rejection is one line that starts with the file (and the line the value came from, or
// "(from --set)"), names the full dotted key and says what is allowed, so a user can fix a
// scene without reading this file. checked_toml.hpp gives every message that shape, and
// overrides.hpp applies --set before any section is read, so overrides are checked alike.

#include "cosserat/scene/scene.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <limits>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>

#include "checked_toml.hpp"
#include "cosserat/model/model_spec.hpp"
#include "overrides.hpp"
#include "solids.hpp"

namespace cosserat {
namespace {

using namespace scene_detail;

std::string joined(const std::vector<std::string>& words) {
  return fmt::format("{}", fmt::join(words, ", "));
}

int node_count(const Entry& entry) {
  const long count = entry.integer();
  if (count < 3) {
    entry.fail(fmt::format("must be >= 3 (grids smaller than 3x3 are rejected), got {}", count));
  }
  if (count > INT_MAX) entry.fail(fmt::format("must be <= {}, got {}", INT_MAX, count));
  return static_cast<int>(count);
}

// A direction of the rest sheet, normalised. Scaled by its largest entry first so that huge
// or tiny entries neither overflow nor underflow the norm.
Vec3 unit_direction(const Entry& entry) {
  const Vec3 given = entry.vector3();
  const double largest = std::max({std::abs(given.x), std::abs(given.y), std::abs(given.z)});
  if (largest == 0.0) entry.fail("must not be zero-length: it is the direction of a grid axis");
  const Vec3 scaled = given / largest;
  return scaled / norm(scaled);
}

// The spacing L / (nodes - 1), as Scene::h1 and h2 give it. The bending rate of the explicit step grows as
// 1/h⁴ (docs/stability.md) and node masses scale as h²: h⁴ and 1/h⁴ must both be normal
// doubles, or the first step's forces overflow or vanish (a run then stopped unstable at step 1).
void check_spacing(const Entry& size, double length, int nodes) {
  const double h = length / (nodes - 1);
  // Compared with the bounds on h itself: h⁴ would overflow, which traps in the debug build.
  const double lowest = std::pow(std::numeric_limits<double>::min(), 0.25);
  const double highest = 1.0 / lowest;
  if (!(h >= lowest && h <= highest)) {
    size.fail(fmt::format("gives a grid spacing of {:.6g} m over {} nodes, whose fourth power "
                          "{} a double; the spacing must be between {:.3g} and {:.3g} m",
                          h, nodes, h < lowest ? "underflows" : "overflows", lowest, highest));
  }
}

// Rest positions are doubles, origin + k h1 u + l h2 v, and the rest metric is their
// differences, each exact only to ε times the largest coordinate. That error must stay below
// 1e-6 of a spacing: beyond, neighbours merge (origin + h == origin) or the rest sheet carries
// strains of round-off larger than the ones a run resolves.
void check_resolvable(const Scene& scene, const std::optional<Entry>& origin,
                      const std::vector<Entry>& size) {
  double reach = 0.0, extent = 0.0;
  for (const int k : {0, scene.m - 1})
    for (const int l : {0, scene.n - 1}) {
      const Vec3 along = (k * scene.h1()) * scene.u + (l * scene.h2()) * scene.v;
      const Vec3 r = scene.origin + along;
      for (int c = 0; c < 3; ++c) {
        reach = std::max(reach, std::abs(r[c]));
        extent = std::max(extent, std::abs(along[c]));
      }
    }
  const double spacing = std::min(scene.h1(), scene.h2());
  const double error = reach * std::numeric_limits<double>::epsilon();
  if (error <= 1e-6 * spacing) return;
  const std::string what = fmt::format(
      "puts nodes {:.3g} m from 0, where doubles resolve {:.3g} m, more than 1e-6 of the grid "
      "spacing {:.3g} m",
      reach, error, spacing);
  if (origin && reach > 2.0 * extent) origin->fail(what + ": move the origin nearer to 0");
  size[scene.h1() <= scene.h2() ? 0 : 1].fail(what +
                                              ": the cells are too narrow for the sheet's extent");
}

void read_grid(const Table& grid, Scene& scene) {
  grid.allow({"nodes", "size", "origin", "u", "v"});

  const auto nodes = grid.require("nodes", "an array of 2 integers [m, n], each >= 3")
                         .elements(2, "an array of 2 integers [m, n], each >= 3");
  scene.m = node_count(nodes[0]);
  scene.n = node_count(nodes[1]);

  const auto size = grid.require("size", "an array of 2 numbers [L1, L2] in metres, each > 0")
                        .elements(2, "an array of 2 numbers [L1, L2] in metres, each > 0");
  scene.size1 = positive(size[0]);
  scene.size2 = positive(size[1]);
  check_spacing(size[0], scene.size1, scene.m);
  check_spacing(size[1], scene.size2, scene.n);

  const auto origin = grid.find("origin");
  if (origin) scene.origin = origin->vector3();

  const auto u = grid.find("u");
  const auto v = grid.find("v");
  if (u) scene.u = unit_direction(*u);
  if (v) scene.v = unit_direction(*v);
  // Relative to |u||v| = 1 after normalisation.
  if (norm(cross(scene.u, scene.v)) < 1e-12) {
    // The defaults are perpendicular, so at least one of the two was given.
    const Entry& blamed = v ? *v : *u;
    blamed.fail(fmt::format("must not be parallel to grid.{} (u and v span the rest sheet)",
                            v ? "u" : "v"));
  }
  check_resolvable(scene, origin, size);
}

Preset preset_named(const Entry& entry) {
  const std::string name = entry.string();
  if (auto preset = find_preset(name)) return *preset;
  std::vector<std::string> names;
  for (const auto& preset : material_presets()) names.push_back(preset.name);
  entry.fail(fmt::format("unknown preset \"{}\"; allowed: {}", name, joined(names)));
}

enum class Bound { positive, non_negative, any };

// zeta, xi or phi: from the table when given, else from the preset, else required.
Sym2 material_tensor(const Table& material, std::string_view name,
                     std::optional<Sym2> from_preset, Bound bound) {
  const auto given = material.find(name);
  if (!given) {
    if (!from_preset) {
      material.missing(name, "a number or an array of 3 numbers [t11, t12, t22] (or a preset)");
    }
    return *from_preset;
  }
  const Sym2 tensor = given->tensor();
  for (const double entry : tensor) {
    if (bound == Bound::positive && !(entry > 0.0)) {
      given->fail(fmt::format("every entry must be > 0, got {}", entry));
    }
    if (bound == Bound::non_negative && !(entry >= 0.0)) {
      given->fail(fmt::format("every entry must be >= 0, got {}", entry));
    }
  }
  return tensor;
}

// A key beside `preset` replaces the preset's value. Said out loud, because it may leave little
// of the preset: `--set material.preset=silk` on a scene that gives every material key changes
// nothing.
void warn_of_overridden_preset(const Table& material, const Entry& preset, Scene& scene) {
  std::vector<std::string> overriding;
  bool mass = false;
  int tensors = 0;
  for (const std::string_view name : {"mass", "density", "zeta", "xi", "phi"})
    if (const auto given = material.find(name)) {
      overriding.push_back(fmt::format("{} ({})", given->key(), given->where()));
      if (name == "mass" || name == "density")
        mass = true;
      else
        ++tensors;
    }
  if (overriding.empty()) return;
  const std::string name = preset.string();
  const std::string effect = mass && tensors == 3
                                 ? "so the preset changes nothing"
                                 : "which keep their own values; the preset gives the rest";
  scene.warnings.push_back(fmt::format(
      "{}: key '{}': preset \"{}\" is overridden by {}, {} (to take the preset whole, remove "
      "them, or --set material={{preset=\"{}\"}})",
      preset.where(), preset.key(), name, joined(overriding), effect, name));
}

// A positive number times `factor` as a mass (kg), `product` naming the two ("density x
// area"), `unit` the factor's. Compared before multiplying: an overflow would trap in a build
// with FPE traps on.
double mass_product(const Entry& entry, double factor, std::string_view product,
                    std::string_view unit) {
  const double value = positive(entry);
  if (!(value <= std::numeric_limits<double>::max() / factor))
    entry.fail(fmt::format("{} = {} x {}{} is not a finite mass", product, value, factor, unit));
  return value * factor;
}

// The mass-spring model's material is its particles' mass alone: the total, the areal
// density or each particle's; its stiffness is in [model] (docs/scene-format.md, "Keys").
void read_particle_mass(const Table& material, Scene& scene) {
  for (const std::string_view name : {"preset", "zeta", "xi", "phi"})
    if (const auto given = material.find(name))
      given->fail(
          "the mass-spring model takes no Cosserat material; give mass, density or "
          "particle_mass here and the springs' ke and kd in [model]");
  material.allow({"mass", "density", "particle_mass", "thickness"});
  if (const auto thickness = material.find("thickness"))
    scene.material.thickness = positive(*thickness);
  const double nodes = static_cast<double>(scene.m) * scene.n;
  const auto mass = material.find("mass");
  const auto density = material.find("density");
  const auto particle = material.find("particle_mass");
  if ((mass ? 1 : 0) + (density ? 1 : 0) + (particle ? 1 : 0) > 1)
    material.fail("give one of mass (total kg), density (kg/m^2) or particle_mass (kg)");
  if (mass) {
    scene.material.mass = positive(*mass);
  } else if (density) {
    scene.material.mass =
        mass_product(*density, scene.size1 * scene.size2, "density x area", " m^2");
  } else if (particle) {
    scene.material.mass = mass_product(*particle, nodes, "particle_mass x nodes", "");
  } else {
    material.missing("mass", "mass (total kg), density (kg/m^2) or particle_mass (kg)");
  }
}

void read_cosserat_material(const Table& material, Scene& scene) {
  material.allow({"preset", "mass", "density", "zeta", "xi", "phi", "thickness"});
  const double area = scene.size1 * scene.size2;

  std::optional<Preset> preset;
  const auto preset_entry = material.find("preset");
  if (preset_entry) preset = preset_named(*preset_entry);
  auto preset_value = [&](Sym2 Preset::*member) {
    return preset ? std::optional<Sym2>((*preset).*member) : std::nullopt;
  };
  scene.material.zeta =
      material_tensor(material, "zeta", preset_value(&Preset::zeta), Bound::positive);
  scene.material.xi =
      material_tensor(material, "xi", preset_value(&Preset::xi), Bound::non_negative);
  scene.material.phi = material_tensor(material, "phi", preset_value(&Preset::phi), Bound::any);

  const auto mass = material.find("mass");
  const auto density = material.find("density");
  if (mass && density) density->fail("give mass (total kg) or density (kg/m^2), not both");
  if (mass) {
    scene.material.mass = positive(*mass);
  } else if (density) {
    scene.material.mass = mass_product(*density, area, "density x area", " m^2");
  } else if (preset) {
    // A preset is a fabric, the same at any size: its areal density is kept.
    scene.material.mass = preset->mass * area / preset->area;
  } else {
    material.missing("mass", "mass (total kg) or density (kg/m^2), exactly one (or a preset)");
  }
  if (const auto thickness = material.find("thickness"))
    scene.material.thickness = positive(*thickness);
  else if (preset)
    scene.material.thickness = preset->thickness;
  if (preset) warn_of_overridden_preset(material, *preset_entry, scene);
}

// model.match = "material" (docs/models.md, "Matched springs"): the [material] is a Cosserat
// one, whose mass the particles take and whose ζ and ξ the springs are matched to; the
// material then is the mass alone, as for any mass-spring scene.
void match_springs(const Table& material, Scene& scene) {
  read_cosserat_material(material, scene);
  const double h1 = scene.h1(), h2 = scene.h2();
  if (std::abs(h1 - h2) > 1e-9 * std::max(h1, h2))
    material.fail(fmt::format(
        "model.match = \"material\" needs square cells, got h1 = {:.6g} m and h2 = {:.6g} m: "
        "one spring stiffness per family cannot match both axes",
        h1, h2));
  const Material cosserat = scene.material;
  const auto matched = matched_springs(cosserat, scene.areal_density(), h1);
  if (!matched)
    material.fail(fmt::format(
        "model.match = \"material\": the shear resistance zeta12 = {} is at least 6 x the "
        "mean tension resistance {}, which leaves the structural springs no stiffness",
        cosserat.zeta[1], 0.5 * (cosserat.zeta[0] + cosserat.zeta[2])));
  scene.springs.structural = matched->springs.structural;
  scene.springs.shear = matched->springs.shear;
  scene.springs.bend = matched->springs.bend;
  if (matched->bending_share < 1.0)
    scene.warnings.push_back(fmt::format(
        "[material]: the matched bend springs store {:.3g} of its bending energy at its "
        "bending length c = {:.3g} m: the grid holds {:.3g} spacings per c, and bend springs "
        "stiff enough for all of it would carry more than half the sheet's stiffness in its "
        "plane (docs/models.md, \"Matched springs\")",
        matched->bending_share, matched->bending_length,
        matched->bending_length / h1));
  scene.material = Material{};
  scene.material.mass = cosserat.mass;
}

void read_material(const Table& material, Scene& scene, bool springs_matched) {
  if (scene.model_kind != ModelKind::mass_spring)
    read_cosserat_material(material, scene);
  else if (springs_matched)
    match_springs(material, scene);
  else
    read_particle_mass(material, scene);
}

SpringFamily read_spring_family(const Table& family) {
  family.allow({"ke", "kd"});
  SpringFamily springs;
  springs.ke = non_negative(family.require("ke", "the springs' stiffness in N/m, >= 0"));
  if (const auto kd = family.find("kd")) springs.kd = non_negative(*kd);
  return springs;
}

// [model] of kind "mass-spring" (docs/scene-format.md, "Keys"): the three families and the
// options of docs/model.md, "The mass-spring model", lengths in rest lengths.
// Returns whether the springs are to be matched to the material (model.match).
bool read_springs(const Table& model, Scene& scene) {
  for (const std::string_view name : {"discretisation", "borders"})
    if (const auto given = model.find(name))
      given->fail("belongs to the Cosserat model; the mass-spring model has none");
  model.allow({"kind", "preset", "match", "structural", "shear", "bend", "dead_zone",
               "min_length", "max_length", "rupture_length"});
  SpringSpec& springs = scene.springs;
  // The families from the [material] (match_springs); the options as below.
  const auto match = model.find("match");
  if (match) {
    if (match->string() != "material")
      match->fail(fmt::format("unknown match \"{}\"; allowed: material", match->string()));
    for (const std::string_view name : {"preset", "structural", "shear", "bend"})
      if (const auto given = model.find(name))
        given->fail(
            "match = \"material\" gives the three families; give either it or the springs");
  }
  // A preset gives every key but rupture_length; a key beside it replaces the preset's.
  const auto preset = model.find("preset");
  if (preset) {
    const std::string name = preset->string();
    const auto found = find_spring_preset(name);
    if (!found) {
      std::vector<std::string> names;
      for (const SpringPreset& p : spring_presets()) names.emplace_back(p.name);
      preset->fail(fmt::format("unknown spring preset \"{}\"; allowed: {}", name, joined(names)));
    }
    springs = found->springs;
  }
  const char* what = "a table { ke = N/m, kd = N s/m } (or a preset)";
  if (const auto structural = model.find_table("structural"))
    springs.structural = read_spring_family(*structural);
  else if (!preset && !match)
    model.missing("structural", what);
  if (const auto shear = model.find_table("shear")) springs.shear = read_spring_family(*shear);
  if (const auto bend = model.find_table("bend")) springs.bend = read_spring_family(*bend);
  if (!match && !(springs.structural.ke > 0.0))
    model.fail("model.structural.ke must be > 0: without it the sheet holds no shape");
  if (const auto zone = model.find("dead_zone")) {
    springs.dead_zone = non_negative(*zone);
    if (springs.dead_zone >= 1.0)
      zone->fail(fmt::format("must be < 1 (a fraction of the rest length), got {}",
                             springs.dead_zone));
  }
  if (const auto least = model.find("min_length")) {
    springs.min_length = non_negative(*least);
    if (springs.min_length >= 1.0)
      least->fail(fmt::format("must be < 1 (in rest lengths), got {}", springs.min_length));
  }
  if (const auto most = model.find("max_length")) {
    springs.max_length = positive(*most);
    if (springs.max_length <= 1.0)
      most->fail(fmt::format("must be > 1 (in rest lengths), got {}", springs.max_length));
  }
  if (const auto rupture = model.find("rupture_length")) {
    springs.rupture_length = positive(*rupture);
    if (springs.rupture_length <= 1.0)
      rupture->fail(
          fmt::format("must be > 1 (in rest lengths), got {}", springs.rupture_length));
  }
  return match.has_value();
}

// Returns whether the springs are to be matched to the material (model.match).
bool read_model(const Table& model, Scene& scene) {
  if (const auto kind = model.find("kind")) {
    const std::string name = kind->string();
    if (name == "mass-spring") {
      scene.model_kind = ModelKind::mass_spring;
      return read_springs(model, scene);
    }
    if (name != "cosserat") {
      kind->fail(fmt::format("unknown model \"{}\"; allowed: cosserat, mass-spring", name));
    }
  }
  model.allow({"kind", "discretisation", "borders"});
  if (const auto borders = model.find("borders")) {
    const std::string name = borders->string();
    if (name == "symmetric") {
      scene.borders = Borders::symmetric;
    } else if (name == "published") {
      // The published rules exist in the flux form alone, so asking for them asks for it.
      scene.borders = Borders::published;
      scene.discretisation = Discretisation::flux;
    } else {
      borders->fail(fmt::format("unknown borders \"{}\"; allowed: symmetric, published", name));
    }
  }
  if (const auto discretisation = model.find("discretisation")) {
    const std::string name = discretisation->string();
    bool known = false;
    for (const Discretisation d :
         {Discretisation::flux, Discretisation::energy, Discretisation::energy_nodal})
      if (name == discretisation_name(d)) {
        scene.discretisation = d;
        known = true;
      }
    if (!known)
      discretisation->fail(fmt::format(
          "unknown discretisation \"{}\"; allowed: energy, energy-nodal, flux", name));
    // The energy forms' border terms are docs/equations.md §2.5's; the published rules are the
    // flux form's alone.
    if (is_energy_form(scene.discretisation) && scene.borders == Borders::published)
      discretisation->fail(fmt::format(
          "\"{}\" has no published border rules; use borders = \"symmetric\" (the "
          "default) or discretisation = \"flux\"",
          name));
  }
  return false;
}

Gusts read_gusts(const Table& gust) {
  gust.allow({"amplitude", "correlation_time", "correlation_length", "seed"});
  Gusts gusts;
  gusts.amplitude = non_negative(
      gust.require("amplitude", "the rms gust speed in m/s, >= 0 (0: no gusts)"));
  gusts.correlation_time =
      positive(gust.require("correlation_time", "the gusts' correlation time in seconds, > 0"));
  gusts.correlation_length = positive(
      gust.require("correlation_length", "the gusts' correlation length in metres, > 0"));
  if (const auto seed = gust.find("seed"))
    gusts.seed = static_cast<std::uint64_t>(integer_at_least(*seed, 0));
  return gusts;
}

// [environment.wind], or the same table under its older name [environment.fluid]; `drag` is
// likewise the newer name of `viscosity`. Users say wind; docs/equations.md §1 says fluid.
Fluid read_wind(const Table& wind) {
  wind.allow({"drag", "velocity", "gust", "viscosity"});
  const auto drag = wind.find("drag");
  const auto viscosity = wind.find("viscosity");
  if (drag && viscosity)
    viscosity->fail(fmt::format("is the older name of {}; give one of the two, not both",
                                wind.key_of("drag")));
  if (!drag && !viscosity)
    wind.missing("drag", "the drag coefficient rho_R >= 0 in N s/m^3 (older name: viscosity)");
  Fluid fluid;
  fluid.viscosity = non_negative(drag ? *drag : *viscosity);
  fluid.velocity =
      wind.require("velocity", "the mean wind, an array of 3 numbers [x, y, z] in m/s").vector3();
  if (const auto gust = wind.find_table("gust")) fluid.gusts = read_gusts(*gust);
  return fluid;
}

void read_environment(const Table& environment, Scene& scene) {
  environment.allow({"gravity", "damping", "initial_velocity", "wind", "fluid"});
  if (const auto gravity = environment.find("gravity")) scene.gravity = gravity->vector3();
  if (const auto damping = environment.find("damping")) scene.damping = non_negative(*damping);
  if (const auto velocity = environment.find("initial_velocity")) {
    scene.initial_velocity = velocity->vector3();
  }
  const auto wind = environment.find_table("wind");
  const auto fluid = environment.find_table("fluid");
  if (wind && fluid)
    fluid->fail(fmt::format("is the older name of {}; give one of the two, not both",
                            environment.key_of("wind")));
  if (wind || fluid) scene.fluid = read_wind(wind ? *wind : *fluid);
}

LinearSolver read_solver(const Table& solver) {
  solver.allow({"ksp", "pc", "rtol", "atol", "max_iterations", "jacobian_every"});
  LinearSolver linear;
  // The names are PETSc's (gmres, cg, bcgs, ...; bjacobi, jacobi, gamg, none, ...); PETSc checks
  // them when the solver is set up, before the first step.
  if (const auto ksp = solver.find("ksp")) linear.ksp = ksp->string();
  if (const auto pc = solver.find("pc")) linear.pc = pc->string();
  if (const auto rtol = solver.find("rtol")) linear.rtol = positive(*rtol);
  if (const auto atol = solver.find("atol")) linear.atol = positive(*atol);
  if (const auto iterations = solver.find("max_iterations")) {
    linear.max_iterations = integer_at_least(*iterations, 1);
  }
  if (const auto every = solver.find("jacobian_every")) {
    linear.jacobian_every = integer_at_least(*every, 1);
  }
  return linear;
}

// time.dt a number: steps (or a duration) of that step, a frame every output_every steps (or
// the nearest whole number of steps to output_dt), so that a scene written for adaptive steps
// also runs with `--set time.dt=...`.
void read_fixed_step(const Table& time, const Entry& dt, Scene& scene) {
  scene.dt = positive(dt);
  const auto steps = time.find("steps");
  const auto duration = time.find("duration");
  if (steps && duration) duration->fail("give time.steps or time.duration, not both");
  if (duration) {
    const double seconds = positive(*duration);
    // Steps are counted in a long: a duration of more steps than that is not a run.
    const double count = std::ceil(seconds / scene.dt - 1e-9);
    if (!(count < 1e15)) {
      duration->fail(fmt::format("{} s in steps of {} s is {:.3g} steps: too many", seconds,
                                 scene.dt, count));
    }
    scene.steps = static_cast<long>(count);
  } else {
    scene.steps = integer_at_least(
        time.require("steps", "an integer >= 0 (or time.duration in seconds)"), 0);
  }
  scene.duration = static_cast<double>(scene.steps) * scene.dt;
  // About a hundred frames unless the scene says otherwise.
  scene.output_every = std::max(1L, scene.steps / 100);
  const auto every = time.find("output_every");
  const auto output_dt = time.find("output_dt");
  if (every && output_dt) output_dt->fail("give time.output_every or time.output_dt, not both");
  if (every) scene.output_every = integer_at_least(*every, 1);
  if (output_dt) {
    const double frames = positive(*output_dt) / scene.dt;
    scene.output_every = frames < 1e15 ? std::max(1L, std::lround(frames)) : std::max(1L, scene.steps);
  }
}

// No time.dt, or time.dt = { adaptive = true, min, max, safety }: a duration and frames at fixed
// simulated times (docs/stability.md, "Adaptive steps").
void read_adaptive_step(const Table& time, const std::optional<Table>& dt, Scene& scene) {
  for (const char* fixed_only : {"steps", "output_every"}) {
    if (const auto entry = time.find(fixed_only)) {
      entry->fail(fmt::format(
          "counts fixed steps, and this scene's steps vary ({}); give time.duration and "
          "time.output_dt in seconds, or a fixed step time.dt = <seconds>",
          dt ? "time.dt is a table" : "it gives no time.dt: adaptive steps"));
    }
  }
  switch (scene.integrator) {
    case Integrator::leapfrog:
    case Integrator::verlet_lagged:
    case Integrator::semi_implicit:
    case Integrator::semi_implicit_2: {
      const std::string why = fmt::format(
          "the {} integrator assumes a constant step; variable steps (adaptive or random) work "
          "with verlet, tc-verlet, symplectic-euler, euler, midpoint, rk4 and velocity-verlet",
          integrator_name(scene.integrator));
      if (dt) dt->fail(why);
      time.missing("dt", "a fixed step in seconds: " + why);
    }
    default:
      break;
  }
  scene.duration = positive(time.require("duration", "the simulated time in seconds"));
  scene.output_dt = scene.duration / 100.0;
  if (const auto output_dt = time.find("output_dt")) scene.output_dt = positive(*output_dt);
  AdaptiveStep adaptive;
  adaptive.max = scene.output_dt;
  if (dt) {
    dt->allow({"adaptive", "sequence", "min", "max", "safety", "seed"});
    if (const auto sequence = dt->find("sequence")) {
      const std::string name = sequence->string();
      if (name != "random") {
        sequence->fail(fmt::format("unknown step sequence \"{}\"; allowed: random (steps that "
                                   "follow the state are adaptive = true)",
                                   name));
      }
      for (const char* adaptive_only : {"adaptive", "safety"})
        if (const auto entry = dt->find(adaptive_only))
          entry->fail("belongs to adaptive steps; random steps take min, max and seed");
      adaptive.random = true;
      adaptive.max = positive(dt->require("max", "the longest step in seconds"));
      dt->require("min", "the shortest step in seconds");
      if (const auto seed = dt->find("seed"))
        adaptive.seed = static_cast<std::uint64_t>(integer_at_least(*seed, 0));
    } else {
      const Entry flag =
          dt->require("adaptive", "true (a fixed step is a number: time.dt = 0.001)");
      if (!flag.boolean()) {
        flag.fail("a fixed step is a number (time.dt = 0.001); a table means adaptive = true or "
                  "sequence = \"random\"");
      }
      if (const auto max = dt->find("max")) adaptive.max = positive(*max);
      if (const auto safety = dt->find("safety")) {
        adaptive.safety = positive(*safety);
        if (adaptive.safety > 1.0) {
          safety->fail(fmt::format("must be in (0, 1], a fraction of the stability estimate; "
                                   "got {}", adaptive.safety));
        }
      }
    }
  }
  // The rest sheet's CFL step sets the scale of the smallest step worth taking.
  const CflEstimate cfl = rest_step_estimate(scene.model_spec());
  adaptive.min = 1e-6 * std::min(adaptive.max, adaptive.safety * cfl.dt);
  if (dt)
    if (const auto min = dt->find("min")) {
      adaptive.min = positive(*min);
      if (adaptive.min > adaptive.max) {
        min->fail(fmt::format("must be <= time.dt.max ({} s), got {}", adaptive.max,
                              adaptive.min));
      }
    }
  scene.dt = adaptive.max;
  // Enough for the duration at the smallest step; a bound, not a schedule.
  const double most = std::ceil(scene.duration / adaptive.min);
  scene.steps = most < 9e18 ? static_cast<long>(most) : std::numeric_limits<long>::max();
  scene.adaptive = adaptive;
}

void read_time(const Table& time, Scene& scene) {
  time.allow({"integrator", "dt", "steps", "duration", "output_every", "output_dt", "solver"});
  if (const auto entry = time.find("integrator")) {
    const std::string name = entry->string();
    const auto integrator = integrator_from_name(name);
    if (!integrator) {
      entry->fail(
          fmt::format("unknown integrator \"{}\"; allowed: {}", name, joined(integrator_names())));
    }
#ifndef COSSERAT_HAVE_PETSC
    if (is_semi_implicit(*integrator)) {
      entry->fail(
          "the semi-implicit integrators are the PETSc baseline, and this build has no PETSc "
          "(install libpetsc-real-dev and configure with -DCOSSERAT_WITH_PETSC=ON)");
    }
#endif
    const SpringSpec& springs = scene.springs;
    if (is_semi_implicit(*integrator) && scene.model_kind == ModelKind::mass_spring &&
        springs.damped()) {
      entry->fail(
          "the semi-implicit baseline does not treat the springs' damping kd; use verlet, "
          "which solves for it at the step's centre (docs/model.md, \"Damping along the "
          "springs\"), or kd = 0");
    }
    scene.integrator = *integrator;
  }
  if (const auto solver = time.find_table("solver")) {
    scene.solver = read_solver(*solver);
    // A sweep over integrators keeps the table; only the semi-implicit ones read it.
    if (!is_semi_implicit(scene.integrator)) {
      scene.warnings.push_back(
          "[time.solver] is read by the semi-implicit integrators only; ignored for " +
          integrator_name(scene.integrator));
    }
  }
  const auto dt = time.find("dt");
  if (dt && !dt->is_table()) {
    read_fixed_step(time, *dt, scene);
  } else {
    read_adaptive_step(time, dt ? std::optional(dt->table()) : std::nullopt, scene);
  }
}

// [output] fields = [...]: each name once, any order; without it every field on a grid of at
// most kOutputFieldsDefaultMaxNodes nodes and none on a larger one. Read after the grid.
void read_output(const std::optional<Table>& output, Scene& scene) {
  const std::vector<OutputField> every = all_output_fields();
  std::vector<std::string> names;
  for (const OutputField field : every) names.emplace_back(output_field_name(field));
  std::optional<Entry> fields;
  if (output) {
    output->allow({"fields"});
    fields = output->find("fields");
  }
  if (!fields) {
    if (static_cast<long>(scene.m) * scene.n <= kOutputFieldsDefaultMaxNodes)
      scene.output_fields = every;
    return;
  }
  std::vector<bool> chosen(every.size(), false);
  for (const Entry& entry : fields->elements(0, "an array of field names")) {
    const std::string name = entry.string();
    const auto at = std::ranges::find(names, name);
    if (at == names.end())
      entry.fail(fmt::format("unknown field \"{}\"; allowed: {}", name, joined(names)));
    const auto index = static_cast<std::size_t>(at - names.begin());
    if (chosen[index]) entry.fail(fmt::format("\"{}\" is named twice", name));
    chosen[index] = true;
  }
  for (std::size_t i = 0; i < every.size(); ++i)
    if (chosen[i]) scene.output_fields.push_back(every[i]);
}

// ---------------------------------------------------------------------------------------------
// Node sets: a list of [k, l] pairs or a region in grid index space

// An index into 0 .. count-1 along one grid direction.
int grid_index(const Entry& entry, int count, std::string_view direction) {
  const long value = entry.integer();
  if (value < 0 || value >= count) {
    entry.fail(fmt::format("{} = {} is outside the grid: must be in 0 .. {}", direction, value,
                           count - 1));
  }
  return static_cast<int>(value);
}

NodeIndex node_index(const Entry& entry, const Scene& scene) {
  const auto kl = entry.elements(2, "a node [k, l]");
  const long k = kl[0].integer();
  const long l = kl[1].integer();
  if (k < 0 || k >= scene.m || l < 0 || l >= scene.n) {
    entry.fail(
        fmt::format("node [{}, {}] is outside the {}x{} grid: k must be in 0 .. {}, l in 0 .. {}",
                    k, l, scene.m, scene.n, scene.m - 1, scene.n - 1));
  }
  return {static_cast<int>(k), static_cast<int>(l)};
}

NodeSet node_list(const Entry& list, const Scene& scene) {
  NodeSet set;
  for (const auto& entry : list.elements(0, "an array of nodes [[k, l], ...]")) {
    const NodeIndex node = node_index(entry, scene);
    // A repeated node would double a load on it.
    if (std::find(set.nodes.begin(), set.nodes.end(), node) != set.nodes.end()) {
      entry.fail(fmt::format("node [{}, {}] is listed twice; list each node once", node.k, node.l));
    }
    set.nodes.push_back(node);
  }
  if (set.nodes.empty()) list.fail("must list at least one node [k, l]");
  return set;
}

// Inclusive corners [k0, l0, k1, l1]; nodes in x1-fastest order like the fields.
NodeSet rect_nodes(const Entry& entry, const Scene& scene) {
  const auto corners = entry.elements(4, "an array of 4 integers [k0, l0, k1, l1]");
  const int k0 = grid_index(corners[0], scene.m, "k0");
  const int l0 = grid_index(corners[1], scene.n, "l0");
  const int k1 = grid_index(corners[2], scene.m, "k1");
  const int l1 = grid_index(corners[3], scene.n, "l1");
  if (k0 > k1 || l0 > l1) {
    entry.fail(fmt::format("needs k0 <= k1 and l0 <= l1, got [{}, {}, {}, {}]", k0, l0, k1, l1));
  }
  NodeSet set;
  for (int l = l0; l <= l1; ++l) {
    for (int k = k0; k <= k1; ++k) set.nodes.push_back({k, l});
  }
  return set;
}

// Nodes with (k - ck)^2 + (l - cl)^2 <= r^2. The centre may fall between nodes so that a disk
// can sit in the middle of a grid with an even node count.
NodeSet disk_nodes(const Entry& entry, const Scene& scene) {
  const Table disk = entry.table();
  disk.allow({"center", "radius"});
  const Entry center = disk.require("center", "an array of 2 numbers [k, l] inside the grid");
  const auto kl = center.elements(2, "an array of 2 numbers [k, l] inside the grid");
  const double ck = kl[0].number();
  const double cl = kl[1].number();
  if (ck < 0 || ck > scene.m - 1 || cl < 0 || cl > scene.n - 1) {
    center.fail(fmt::format("center [{}, {}] is outside the {}x{} grid", ck, cl, scene.m, scene.n));
  }
  const double radius = non_negative(disk.require("radius", "a number >= 0 (in node spacings)"));
  // Only the disk's bounding box, clipped to the grid and one node wider than it so rounding in
  // centre ± radius cannot drop a node the test below takes: testing every node of the grid made
  // a small disk on a 10^5 x 10^5 grid cost 10^10 tests (found by tests/fuzz).
  const auto first = [](double centre, double r) {
    return static_cast<int>(std::max(0.0, std::floor(centre - r) - 1.0));
  };
  const auto last = [](double centre, double r, int count) {
    return static_cast<int>(std::min(count - 1.0, std::ceil(centre + r) + 1.0));
  };
  NodeSet set;
  for (int l = first(cl, radius); l <= last(cl, radius, scene.n); ++l) {
    for (int k = first(ck, radius); k <= last(ck, radius, scene.m); ++k) {
      if ((k - ck) * (k - ck) + (l - cl) * (l - cl) <= radius * radius) set.nodes.push_back({k, l});
    }
  }
  if (set.nodes.empty()) {
    entry.fail(fmt::format("selects no node (center [{}, {}], radius {}); make the radius larger",
                           ck, cl, radius));
  }
  return set;
}

NodeSet region_nodes(const Entry& entry, const Scene& scene) {
  const Table region = entry.table();
  region.allow({"rect", "disk", "row", "column"});
  const auto rect = region.find("rect");
  const auto disk = region.find("disk");
  const auto row = region.find("row");
  const auto column = region.find("column");
  const int shapes = rect.has_value() + disk.has_value() + row.has_value() + column.has_value();
  if (shapes != 1) {
    region.fail(
        "give exactly one of rect = [k0, l0, k1, l1], disk = { center = [k, l], radius = r }, "
        "row = l, column = k");
  }
  if (rect) return rect_nodes(*rect, scene);
  if (disk) return disk_nodes(*disk, scene);
  NodeSet set;
  if (row) {
    const int l = grid_index(*row, scene.n, "row l");
    for (int k = 0; k < scene.m; ++k) set.nodes.push_back({k, l});
  } else {
    const int k = grid_index(*column, scene.m, "column k");
    for (int l = 0; l < scene.n; ++l) set.nodes.push_back({k, l});
  }
  return set;
}

NodeSet read_node_set(const Table& block, const Scene& scene) {
  const auto nodes = block.find("nodes");
  const auto region = block.find("region");
  if (nodes && region) region->fail("give nodes or region, not both");
  if (nodes) return node_list(*nodes, scene);
  if (region) return region_nodes(*region, scene);
  block.missing("nodes", "an array of nodes [[k, l], ...], or a region instead");
}

// ---------------------------------------------------------------------------------------------
// Constraints (docs/equations.md §4.1)

// Inclusive windows in steps and in seconds; the ends default to the end of the run.
Window read_window(const Table& block, const Scene& scene) {
  Window window;
  // A random sequence takes no step back, so its step indices are the seed's alone and a
  // window may count them; adaptive steps' indices depend on the rollbacks.
  if (scene.adaptive && !scene.adaptive->random) {
    for (const char* in_steps : {"start", "end"})
      if (const auto entry = block.find(in_steps)) {
        entry->fail(fmt::format("counts steps, and this scene's steps are adaptive; give "
                                "{}_time in seconds",
                                in_steps));
      }
  }
  if (const auto start = block.find("start")) window.start = integer_at_least(*start, 0);
  if (const auto end = block.find("end")) {
    window.end = integer_at_least(*end, 0);
    if (window.start > window.end) {
      end->fail(fmt::format("must be >= start ({}), got {}", window.start, window.end));
    }
  }
  if (const auto start = block.find("start_time")) window.start_time = non_negative(*start);
  if (const auto end = block.find("end_time")) {
    window.end_time = non_negative(*end);
    if (window.start_time > window.end_time) {
      end->fail(fmt::format("must be >= start_time ({} s), got {}", window.start_time,
                            window.end_time));
    }
  }
  return window;
}

std::array<bool, 3> held_axes(const Entry& entry) {
  const std::string letters = entry.string();
  if (letters.empty()) {
    entry.fail("a fix with no axes holds nothing; give any of x, y, z (default \"xyz\")");
  }
  std::array<bool, 3> axes{false, false, false};
  for (const char letter : letters) {
    if (letter < 'x' || letter > 'z') {
      entry.fail(
          fmt::format("unknown axis '{}' in \"{}\"; allowed letters: x, y, z", letter, letters));
    }
    axes[letter - 'x'] = true;
  }
  return axes;
}

Fix read_fix(const Table& block, const Scene& scene) {
  block.allow({"nodes", "region", "axes", "start", "end", "start_time", "end_time", "velocity",
               "angular_velocity", "center"});
  Fix fix;
  fix.nodes = read_node_set(block, scene);
  if (const auto axes = block.find("axes")) fix.axes = held_axes(*axes);
  fix.window = read_window(block, scene);
  if (const auto velocity = block.find("velocity")) {
    fix.velocity = velocity->vector3();
    // A velocity along a free axis would be silently ignored: most likely a mistyped axes.
    for (std::size_t c = 0; c < 3; ++c)
      if (!fix.axes[c] && fix.velocity[static_cast<int>(c)] != 0.0) {
        velocity->fail(fmt::format("moves along {}, which this fix does not hold (axes); give 0 "
                                   "there or hold {} too",
                                   static_cast<char>('x' + c), static_cast<char>('x' + c)));
      }
  }
  const auto spin = block.find("angular_velocity");
  const auto center = block.find("center");
  if (spin) {
    fix.angular_velocity = spin->vector3();
    // A turn moves every component of a node: holding fewer would let the free ones drift off
    // the circle.
    if (!(fix.axes[0] && fix.axes[1] && fix.axes[2]))
      spin->fail("turns the nodes it holds, which needs all three axes held; give axes = \"xyz\"");
    if (block.find("velocity"))
      spin->fail("give either velocity (a translation) or angular_velocity (a turn about a fixed "
                 "axis), not both");
    fix.center = block
                     .require("center", "a point [x, y, z] in metres on the axis the nodes turn "
                                        "about")
                     .vector3();
  } else if (center) {
    center->fail("is the point the nodes turn about, which needs angular_velocity");
  }
  return fix;
}

Load read_load(const Table& block, const Scene& scene) {
  block.allow(
      {"nodes", "region", "force", "pressure", "start", "end", "start_time", "end_time"});
  Load load;
  load.nodes = read_node_set(block, scene);
  const auto pressure = block.find("pressure");
  if (pressure && block.find("force"))
    pressure->fail("give either force (newtons per node) or pressure (newtons per m²), not both");
  if (pressure) {
    load.force = pressure->vector3();
    load.per_area = true;
  } else {
    load.force = block
                     .require("force", "an array of 3 numbers [x, y, z] in newtons per node, or "
                                       "pressure in newtons per m² of rest area")
                     .vector3();
  }
  load.window = read_window(block, scene);
  return load;
}

// docs/equations.md §1: the energy is positive definite iff Theta^2 < 4 Phi Psi for every
// component. Phi, Psi and Theta are zeta, xi and phi times the same rest-metric factor
// A^aa A^bb + 2 (A^ab)^2 > 0, so the factor cancels and the test is phi^2 < 4 zeta xi.
void warn_if_not_positive_definite(const Origin& origin, Scene& scene) {
  constexpr std::array<std::string_view, 3> components{"11", "12", "22"};
  const Material& material = scene.material;
  for (std::size_t i = 0; i < components.size(); ++i) {
    const double coupling = material.phi[i] * material.phi[i];
    const double bound = 4.0 * material.zeta[i] * material.xi[i];
    if (coupling >= bound) {
      scene.energy_indefinite = true;
      scene.warnings.push_back(fmt::format(
          "{}: material component {}: phi^2 = {} >= 4 zeta xi = {}, so the stored energy is not "
          "positive definite (docs/materials.md); raise xi or lower phi",
          origin.path(), components[i], coupling, bound));
    }
  }
}

// docs/contact.md, "Crinkles": a drape whose grid holds fewer than about two spacings per
// bending length c = (6 xi / (mu0 g))^(1/3) (docs/materials.md) folds in creases one node wide,
// a zig-zag at the grid's scale that no response removes; about 2.4 keeps folds smooth. Said
// for scenes with solids, which are the drapes, in one warning naming each axis that falls
// short.
void warn_if_folds_unresolved(const Origin& origin, Scene& scene) {
  const double g = norm(scene.gravity);
  if (scene.solids.empty() || g == 0.0) return;
  constexpr double kCrease = 2.0;
  constexpr double kSmooth = 2.4;
  const double weight = scene.areal_density() * g;
  const std::array<std::pair<double, double>, 2> axes{
      {{scene.material.xi[0], scene.h1()}, {scene.material.xi[2], scene.h2()}}};
  std::vector<std::string> short_axes;
  for (std::size_t a = 0; a < axes.size(); ++a) {
    const auto [xi, h] = axes[a];
    const double c = std::cbrt(6.0 * xi / weight);
    if (c < kCrease * h)
      short_axes.push_back(fmt::format("{:.2f}{} along x{} (c = {:.3g} m, h = {:.3g} m)", c / h,
                                       short_axes.empty() ? " spacings h per bending length c" : "",
                                       a + 1, c, h));
  }
  if (short_axes.empty()) return;
  scene.warnings.push_back(fmt::format(
      "{}: the grid holds {}, so folds over the solids will crease at single nodes, a zig-zag "
      "at the grid's scale (docs/contact.md, \"Crinkles\"); {} or more keep them smooth",
      origin.path(), fmt::join(short_axes, " and "), kSmooth));
}

// docs/contact.md, "Self-contact": the layers are kept the material's thickness apart, which
// must be less than a grid spacing: a node is exempt only from the cells within two grid steps
// of it, and the nearest others lie about two spacings away in a flat sheet.
SelfContactSpec read_self_contact(const Table& table, const Scene& scene) {
  table.allow({"friction", "edges"});
  SelfContactSpec spec;
  if (const auto friction = table.find("friction")) spec.friction = non_negative(*friction);
  if (const auto edges = table.find("edges")) {
    const std::string name = edges->string();
    if (name != "all" && name != "border")
      edges->fail(fmt::format("unknown edges \"{}\"; allowed: all, border", name));
    spec.every_edge = name == "all";
  }
  spec.thickness = scene.material.thickness;
  if (spec.thickness == 0.0)
    table.fail(
        "self-contact keeps the cloth's layers its thickness apart: give material.thickness "
        "(m), or a material preset, which has one (docs/materials.md)");
  const double spacing = std::min(scene.h1(), scene.h2());
  if (!(spec.thickness < spacing))
    table.fail(fmt::format(
        "material.thickness = {} m is not less than the grid spacing {} m: self-contact needs a "
        "cloth thinner than its grid (docs/contact.md, \"Self-contact\"); refine the grid or "
        "give a smaller material.thickness",
        spec.thickness, spacing));
  return spec;
}

void read_scene(const Table& root, const Origin& origin, Scene& scene) {
  root.allow(
      {"title", "grid", "material", "model", "environment", "time", "output", "fix", "load",
       "solid", "self_contact"});
  if (const auto title = root.find("title")) scene.title = title->string();
  // Grid first: the material's mass and every node set depend on it.
  read_grid(root.require_table("grid", "a [grid] table with nodes and size"), scene);
  // The model before the material: the mass-spring model's material is its mass alone.
  bool springs_matched = false;
  if (const auto model = root.find_table("model")) springs_matched = read_model(*model, scene);
  read_material(root.require_table("material",
                                   "a [material] table with a preset, or zeta, xi, "
                                   "phi and mass or density"),
                scene, springs_matched);
  if (const auto environment = root.find_table("environment")) {
    read_environment(*environment, scene);
  }
  read_time(root.require_table("time", "a [time] table with dt and steps, or a duration"), scene);
  read_output(root.find_table("output"), scene);
  if (scene.model_kind == ModelKind::mass_spring && std::isfinite(scene.springs.rupture_length))
    scene.output_fields.push_back(OutputField::broken_springs);
  if (const auto fixes = root.find("fix")) {
    for (const auto& block : fixes->tables("fix")) scene.fixes.push_back(read_fix(block, scene));
  }
  if (const auto loads = root.find("load")) {
    for (const auto& block : loads->tables("load")) scene.loads.push_back(read_load(block, scene));
  }
  // Every integrator takes solids, the semi-implicit one too: contact acts on each accepted
  // step, after the scheme, whatever the scheme.
  if (const auto solids = root.find("solid")) scene.solids = read_solids(*solids, scene);
  if (const auto self = root.find_table("self_contact"))
    scene.self_contact = read_self_contact(*self, scene);
  if (scene.model_kind == ModelKind::cosserat) {
    warn_if_not_positive_definite(origin, scene);
    warn_if_folds_unresolved(origin, scene);
  }
}

}  // namespace

const char* output_field_name(OutputField field) {
  switch (field) {
    case OutputField::velocity: return "velocity";
    case OutputField::area_ratio: return "area_ratio";
    case OutputField::curvature: return "curvature";
    case OutputField::energy_density: return "energy_density";
    case OutputField::broken_springs: return "broken_springs";
  }
  return "";
}

std::vector<OutputField> all_output_fields() {
  return {OutputField::velocity, OutputField::area_ratio, OutputField::curvature,
          OutputField::energy_density};
}

Scene parse_scene(const std::string& text, const std::string& path,
                  const std::vector<std::string>& overrides) {
  // Values are told from --set ones by their source name, so it must not be empty.
  const Origin origin(path.empty() ? "<scene>" : path);
  toml::table document = parse_toml(text, origin);
  for (const auto& assignment : overrides) apply_override(document, assignment, origin);

  Scene scene;
  scene.path = path;
  scene.text = text;
  scene.name = std::filesystem::path(path).stem().string();
  scene.overrides = overrides;
  read_scene(Table(origin, document, "", /*top_level=*/true), origin, scene);
  return scene;
}

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  std::error_code ignored;
  if (std::filesystem::is_directory(path, ignored)) {
    throw SceneError(fmt::format("{}: cannot read the scene file: it is a directory", path));
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw SceneError(fmt::format("{}: cannot read the scene file: {}", path, std::strerror(errno)));
  }
  std::ostringstream text;
  text << file.rdbuf();
  if (file.bad()) throw SceneError(fmt::format("{}: cannot read the scene file", path));
  return parse_scene(text.str(), path, overrides);
}

}  // namespace cosserat
