#pragma once
// What a force model is built from, and the explicit step it allows, known before any model is
// built (docs/model.md, "Force models"). Free of MPI and the grid, as the scene loader is.

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "cosserat/grid/vec3.hpp"
#include "cosserat/model/borders.hpp"
#include "cosserat/model/material.hpp"
#include "cosserat/model/wave_speed.hpp"

namespace cosserat {

enum class ModelKind { cosserat, mass_spring };

// As written in scene files and the run summary.
inline const char* model_kind_name(ModelKind kind) {
  return kind == ModelKind::mass_spring ? "mass-spring" : "cosserat";
}

// One family of the mass-spring model's springs (docs/model.md, "The mass-spring model").
struct SpringFamily {
  double ke = 0.0;  // stiffness, N/m
  double kd = 0.0;  // damping along the spring, N s/m
};

// The mass-spring model's keys. Lengths are in units of each spring's rest length.
struct SpringSpec {
  SpringFamily structural, shear, bend;
  double dead_zone = 0.0;  // no elastic force while |ℓ − ℓ0| < dead_zone ℓ0
  double min_length = 0.0;
  double max_length = std::numeric_limits<double>::infinity();
  double rupture_length = std::numeric_limits<double>::infinity();
  // Whether any family damps along its springs (the damping solve, docs/model.md).
  bool damped() const { return structural.kd > 0.0 || shear.kd > 0.0 || bend.kd > 0.0; }
};

// A named set of springs (docs/model.md, "Spring presets"): the source's experiments, each for
// the particle mass and grid it was meant for, which `approximates` says.
struct SpringPreset {
  const char* name;
  SpringSpec springs;
  const char* approximates;
};

const std::vector<SpringPreset>& spring_presets();
std::optional<SpringPreset> find_spring_preset(const std::string& name);

// Springs matched to a Cosserat material on square cells of side h (docs/models.md, "Matched
// springs"): per unit area the spring sheet stores the Cosserat sheet's energy in a small stretch
// along either axis with the other held, in a small shear, and in a bend of radius c, the
// bending length under standard gravity, as far as the bend springs may take it without carrying
// more than half the sheet's stiffness in its plane. The two axes' ζ and ξ are averaged; φ has
// no counterpart. No damping along the springs: the medium's damping is the models' common one.
struct MatchedSprings {
  SpringSpec springs;
  double bending_length = 0.0;  // c, m; 0 where ξ = 0
  // The bend springs' stiffness over the one that matches the bend of radius c: 1 unless capped.
  double bending_share = 1.0;
};
// Empty where the in-plane shear resistance ζ₁₂ leaves the structural springs no stiffness
// (ζ₁₂ ≥ 3 (ζ₁₁ + ζ₂₂)).
std::optional<MatchedSprings> matched_springs(const Material& material, double density, double h);

// The scene's model keys, its material and its grid's spacings and directions
// (Scene::model_spec gives it).
struct ModelSpec {
  Discretisation discretisation = Discretisation::energy;
  Borders borders = Borders::symmetric;
  Material material;
  double h1 = 0.0, h2 = 0.0;  // m
  Vec3 u{1.0, 0.0, 0.0}, v{0.0, 0.0, 1.0};
  double density = 0.0;  // μ0, kg/m²
  ModelKind kind = ModelKind::cosserat;
  SpringSpec springs;          // mass-spring only
  double particle_mass = 0.0;  // kg, the mass of every node; mass-spring only
};

// The explicit step the model allows on the flat rest sheet (s), with the wave speeds behind
// it (scene validation, `cosserat stable-dt`). For the mass-spring model the speeds are those
// of the structural springs and the step is the bound of docs/model.md, "Its step".
CflEstimate rest_step_estimate(const ModelSpec& spec);
// The same for a sheet whose edges are stretched by up to √stretch2 (adaptive steps).
double stretched_step_estimate(const ModelSpec& spec, double stretch2);

}  // namespace cosserat
