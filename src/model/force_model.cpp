#include "cosserat/model/force_model.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "cosserat/model/cosserat_energy.hpp"
#include "cosserat/model/cosserat_model.hpp"
#include "cosserat/model/mass_spring.hpp"

namespace cosserat {

void ForceModel::free_acceleration_rows(const Field<Vec3>&, const Vec3&, const RowConsumer&) {
  throw std::logic_error("ForceModel::free_acceleration_rows: this model has no row walk");
}

void ForceModel::velocity_acceleration(const Field<Vec3>&, const Field<Vec3>&,
                                       Field<Vec3>&) const {
  throw std::logic_error("ForceModel::velocity_acceleration: this model has no velocity force");
}

bool ForceModel::act_on_step(const Field<Vec3>&, const Field<Vec3>&, Field<Vec3>&, bool) {
  throw std::logic_error("ForceModel::act_on_step: this model does not act on steps");
}

void ForceModel::restore_step_state(const std::vector<double>& state) {
  if (!state.empty())
    throw std::invalid_argument("the checkpoint holds a model state this model does not have");
}

void ForceModel::node_hessian(const Field<Vec3>&, int, int, NodeHessian&) const {
  throw std::logic_error("ForceModel::node_hessian: this model has no node Hessian");
}

void ForceModel::broken_springs(Field<double>& bits) const {
  const Block& b = bits.block();
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) bits(k, l) = 0.0;
}

namespace {

// Both forms reach two nodes (docs/model.md, "Reach of the stencil and the ghost width").
constexpr int kCosseratReach = 2;

// What both Cosserat forms answer alike: the stored energy of the energy form in `quadrature`
// (the flux form's output shows its energy too), its density, the masses, the reach.
class CosseratForm : public ForceModel {
 public:
  double block_energy(const Field<Vec3>& r) const override { return energy_.block_energy(r); }
  void energy_density(const Field<Vec3>& r, Field<double>& density) const override {
    energy_.energy_density(r, density);
  }
  const NodeMass& node_mass() const override { return node_mass_; }
  int reach() const override { return kCosseratReach; }

 protected:
  CosseratForm(const ModelSpec& spec, const Block& block, Quadrature quadrature)
      : energy_(block, spec.h1, spec.h2, flat_rest_state(spec.material, spec.u, spec.v),
                quadrature) {}

  CosseratEnergy energy_;
  NodeMass node_mass_;
};

// The energy forms (docs/equations.md §2.5): the force is the exact gradient of the stored
// energy, on constant lumped masses, so the areal density is the rest one.
class EnergyForm final : public CosseratForm {
 public:
  EnergyForm(const ModelSpec& spec, const Block& block, double rest_area)
      : CosseratForm(spec, block,
                     spec.discretisation == Discretisation::energy_nodal
                         ? Quadrature::nodal
                         : Quadrature::trapezoidal) {
    // μ0 h1 h2 = (M/S0) h1 h2 at a node inside, times its share of the dual area in the
    // trapezoidal quadrature (docs/model.md, "Energy quadrature").
    node_mass_ = energy_.node_mass(spec.material.mass / rest_area * (spec.h1 * spec.h2));
  }

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
  bool has_node_hessian() const override {
    return energy_.quadrature() == Quadrature::trapezoidal;
  }
  void node_hessian(const Field<Vec3>& r, int k, int l, NodeHessian& hessian) const override {
    energy_.node_hessian(r, k, l, hessian);
  }
};

// The flux form (docs/equations.md §2.1–§2.3): the force per unit current area, so its
// acceleration is S0/M times the kernel's whatever the area, and μ = M/S follows the area
// (docs/equations.md §3). Its stored energy, for the output, is the trapezoidal energy form's;
// its masses, for the diagnostics, M/(m n) at every node.
class FluxForm final : public CosseratForm {
 public:
  FluxForm(const ModelSpec& spec, const Block& block, double rest_area)
      : CosseratForm(spec, block, Quadrature::trapezoidal),
        block_(&block),
        flux_(block, spec.h1, spec.h2, flat_rest_state(spec.material, spec.u, spec.v),
              spec.borders),
        internal_scale_(rest_area / spec.material.mass) {
    node_mass_ = {spec.material.mass / (static_cast<double>(block.m) * block.n), block.m,
                  block.n, false};
  }

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

 private:
  const Block* block_;
  CosseratModel flux_;
  double internal_scale_;  // S0/M
};

}  // namespace

std::unique_ptr<ForceModel> make_force_model(const ModelSpec& spec, const Block& block,
                                             double rest_area) {
  std::unique_ptr<ForceModel> model;
  if (spec.kind == ModelKind::mass_spring)
    model = std::make_unique<MassSpring>(spec, block);
  else if (is_energy_form(spec.discretisation))
    model = std::make_unique<EnergyForm>(spec, block, rest_area);
  else
    model = std::make_unique<FluxForm>(spec, block, rest_area);
  if (model->reach() > kGhostWidth)
    throw std::invalid_argument("the force model reads " + std::to_string(model->reach()) +
                                " nodes out, beyond the block's " + std::to_string(kGhostWidth) +
                                " ghost rings");
  return model;
}

double kernel_bytes_per_node(const ModelSpec& spec) {
  // The mass-spring model keeps a byte of broken springs per node, and with damping along its
  // springs the damping solve's direction, residual and force and the scheme's velocity
  // (docs/model.md, "Damping along the springs"); the flux form its resultants and two
  // tractions; the energy form only row buffers (docs/kernel.md, "Memory"), counted with the
  // threads.
  if (spec.kind == ModelKind::mass_spring)
    return 1.0 + (spec.springs.damped() ? 4.0 * sizeof(Vec3) : 0.0);
  return is_energy_form(spec.discretisation)
             ? 0.0
             : static_cast<double>(sizeof(NodeResultants) + 2 * sizeof(Vec3));
}

}  // namespace cosserat
