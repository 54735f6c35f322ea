#include "cosserat/model/force_model.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "cosserat/model/cosserat_energy.hpp"
#include "cosserat/model/cosserat_model.hpp"

namespace cosserat {

void ForceModel::free_acceleration_rows(const Field<Vec3>&, const Vec3&, const RowConsumer&) {
  throw std::logic_error("ForceModel::free_acceleration_rows: this model has no row walk");
}

namespace {

// Both forms reach two nodes (docs/model.md, "Reach of the stencil and the ghost width").
constexpr int kCosseratReach = 2;

// The energy forms (docs/equations.md §2.5): the force is the exact gradient of the stored
// energy, on constant lumped masses, so the areal density is the rest one.
class EnergyForm final : public ForceModel {
 public:
  EnergyForm(const ModelSpec& spec, const Block& block, double rest_area)
      : energy_(block, spec.h1, spec.h2, flat_rest_state(spec.material, spec.u, spec.v),
                spec.discretisation == Discretisation::energy_nodal ? Quadrature::nodal
                                                                    : Quadrature::trapezoidal),
        // μ0 h1 h2 = (M/S0) h1 h2 at a node inside, times its share of the dual area in the
        // trapezoidal quadrature (docs/model.md, "Energy quadrature").
        node_mass_(energy_.node_mass(spec.material.mass / rest_area * (spec.h1 * spec.h2))) {}

  void free_acceleration(const Field<Vec3>& r, const Vec3& gravity, Field<Vec3>& a,
                         Field<Vec3>* normals) override {
    // Newtons on the constant lumped masses, with gravity, written by the kernel.
    energy_.acceleration(r, a, normals, 1.0 / node_mass_.interior, gravity);
  }
  void internal_acceleration(const Field<Vec3>& r, Field<Vec3>& a) override {
    energy_.acceleration(r, a, nullptr, 1.0 / node_mass_.interior, Vec3{});
  }
  bool fuses_rows() const override { return true; }
  void free_acceleration_rows(const Field<Vec3>& r, const Vec3& gravity,
                              const RowConsumer& consume) override {
    energy_.internal_force_rows(r, 1.0 / node_mass_.interior, gravity, consume);
  }
  double block_energy(const Field<Vec3>& r) const override { return energy_.block_energy(r); }
  void energy_density(const Field<Vec3>& r, Field<double>& density) const override {
    energy_.energy_density(r, density);
  }
  const NodeMass& node_mass() const override { return node_mass_; }
  int reach() const override { return kCosseratReach; }

 private:
  CosseratEnergy energy_;
  NodeMass node_mass_;
};

// The flux form (docs/equations.md §2.1–§2.3): the force per unit current area, so its
// acceleration is S0/M times the kernel's whatever the area, and μ = M/S follows the area
// (docs/equations.md §3). Its stored energy, for the output, is the trapezoidal energy form's.
class FluxForm final : public ForceModel {
 public:
  FluxForm(const ModelSpec& spec, const Block& block, double rest_area)
      : block_(&block),
        flux_(block, spec.h1, spec.h2, flat_rest_state(spec.material, spec.u, spec.v),
              spec.borders),
        energy_(block, spec.h1, spec.h2, flat_rest_state(spec.material, spec.u, spec.v),
                Quadrature::trapezoidal),
        internal_scale_(rest_area / spec.material.mass),
        node_mass_{spec.material.mass / (static_cast<double>(block.m) * block.n), block.m,
                   block.n, false} {}

  void free_acceleration(const Field<Vec3>& r, const Vec3& gravity, Field<Vec3>& a,
                         Field<Vec3>* normals) override {
    const Block& b = *block_;
    flux_.internal_force(r, a, normals);
    const double scale = internal_scale_;
#pragma omp parallel for schedule(static)
    for (int l = b.l0; l < b.l1; ++l)
#pragma omp simd
      for (int k = b.k0; k < b.k1; ++k) a(k, l) = scale * a(k, l) + gravity;
  }
  void internal_acceleration(const Field<Vec3>& r, Field<Vec3>& a) override {
    const Block& b = *block_;
    flux_.internal_force(r, a);
    const double scale = internal_scale_;
#pragma omp parallel for schedule(static)
    for (int l = b.l0; l < b.l1; ++l)
      for (int k = b.k0; k < b.k1; ++k) a(k, l) = scale * a(k, l);
  }
  bool density_follows_area() const override { return true; }
  double block_energy(const Field<Vec3>& r) const override { return energy_.block_energy(r); }
  void energy_density(const Field<Vec3>& r, Field<double>& density) const override {
    energy_.energy_density(r, density);
  }
  const NodeMass& node_mass() const override { return node_mass_; }
  int reach() const override { return kCosseratReach; }

 private:
  const Block* block_;
  CosseratModel flux_;
  CosseratEnergy energy_;
  double internal_scale_;  // S0/M
  NodeMass node_mass_;     // M/(m n) at every node, for the diagnostics
};

}  // namespace

std::unique_ptr<ForceModel> make_force_model(const ModelSpec& spec, const Block& block,
                                             double rest_area) {
  std::unique_ptr<ForceModel> model;
  if (is_energy_form(spec.discretisation))
    model = std::make_unique<EnergyForm>(spec, block, rest_area);
  else
    model = std::make_unique<FluxForm>(spec, block, rest_area);
  if (model->reach() > kGhostWidth)
    throw std::invalid_argument("the force model reads " + std::to_string(model->reach()) +
                                " nodes out, beyond the block's " + std::to_string(kGhostWidth) +
                                " ghost rings");
  return model;
}

CflEstimate rest_step_estimate(const ModelSpec& spec) {
  return cfl_estimate(spec.material, spec.density, spec.h1, spec.h2);
}

// A membrane strain ε = (λ² − 1)/2 along an edge stretched by λ stiffens the edge: the second
// derivative of Φ ε² with respect to λ is Φ (3λ² − 1) (docs/equations.md §2.5 with ε_αα as in
// §2.1), so the membrane wave speed grows by √((3λ² − 1)/2) over the rest sheet's. Bending's
// rate is that of the rest sheet (it does not stiffen with stretch to first order).
double stretched_step_estimate(const ModelSpec& spec, double stretch2) {
  const CflEstimate cfl = rest_step_estimate(spec);
  const double stiffening = std::max(1.0, 0.5 * (3.0 * stretch2 - 1.0));
  return std::min(cfl.membrane_dt / std::sqrt(stiffening), cfl.bending_dt);
}

double kernel_bytes_per_node(const ModelSpec& spec) {
  // The flux form keeps its resultants and two tractions per node; the energy form only row
  // buffers (docs/kernel.md, "Memory"), counted with the threads.
  return is_energy_form(spec.discretisation)
             ? 0.0
             : static_cast<double>(sizeof(NodeResultants) + 2 * sizeof(Vec3));
}

}  // namespace cosserat
