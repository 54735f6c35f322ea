#pragma once
// What a force model is built from, and the explicit step it allows, known before any model is
// built (docs/model.md, "Force models"). Free of MPI and the grid, as the scene loader is.

#include "cosserat/grid/vec3.hpp"
#include "cosserat/model/borders.hpp"
#include "cosserat/model/material.hpp"
#include "cosserat/model/wave_speed.hpp"

namespace cosserat {

// The scene's model keys, its material and its grid's spacings and directions
// (Scene::model_spec gives it).
struct ModelSpec {
  Discretisation discretisation = Discretisation::energy;
  Borders borders = Borders::symmetric;
  Material material;
  double h1 = 0.0, h2 = 0.0;  // m
  Vec3 u{1.0, 0.0, 0.0}, v{0.0, 0.0, 1.0};
  double density = 0.0;  // μ0, kg/m²
};

// The explicit step the model allows on the flat rest sheet (s), with the wave speeds behind
// it (scene validation, `cosserat stable-dt`).
CflEstimate rest_step_estimate(const ModelSpec& spec);
// The same for a sheet whose edges are stretched by up to √stretch2 (adaptive steps).
double stretched_step_estimate(const ModelSpec& spec, double stretch2);

}  // namespace cosserat
