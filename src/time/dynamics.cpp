#include "cosserat/time/dynamics.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "cosserat/grid/reduce.hpp"
#include "cosserat/model/surface_measures.hpp"
#include "explicit_schemes.hpp"

namespace cosserat {

Dynamics::Dynamics(const Scene& scene, const Block& block, const Field<Vec3>& rest_positions,
                   Halo* halo)
    : block_(&block),
      h1h2_(scene.h1() * scene.h2()),
      // 2⁻⁴⁰ of a grid cell: far below the round-off of a double sum over the cells.
      area_quantum_(std::ldexp(h1h2_, -40)),
      mass_(scene.material.mass),
      rest_area_(total_area(rest_positions)),
      model_(make_force_model(scene.model_spec(), block, rest_area_)),
      gravity_(scene.gravity),
      damping_(scene.damping),
      fluid_(scene.fluid),
      halo_(halo) {
  if (fluid_ && fluid_->gusts && fluid_->gusts->amplitude > 0.0)
    gusts_.emplace(*fluid_->gusts, fluid_->velocity);
  for (const Load& load : scene.loads)
    for (const NodeIndex& node : load.nodes.nodes)
      if (block.owns(node.k, node.l)) {
        // A pressure acts on the node's dual area: h1 h2 times its share of it.
        const double area =
            load.per_area ? h1h2_ * model_->node_mass().weight(node.k, node.l) : 1.0;
        loads_.push_back(PointLoad{node.k, node.l, area * load.force, load.window});
      }
  // In row order, for free_acceleration_rows to find a row's loads; stable, so that a node's
  // own loads keep the scene's order and their sum its bits.
  std::stable_sort(loads_.begin(), loads_.end(),
                   [](const PointLoad& a, const PointLoad& b) { return a.l < b.l; });
  // μ = M/S enters only through loads, fluid and damping (docs/equations.md §3): without them the
  // current area is never needed during a step. The energy form's mass is constant (§2.5), so
  // it never is. The area is a collective reduction: decide from the scene, which every rank
  // shares.
  needs_area_ = model_->density_follows_area() &&
                (!scene.loads.empty() || fluid_.has_value() || damping_ > 0.0);
}

double Dynamics::total_area(const Field<Vec3>& r) const {
  return block_area(r, area_quantum_).global_total(block_->comm);
}

VelocityTerms Dynamics::free_acceleration(const Field<Vec3>& r, long step, Field<Vec3>& a,
                                          Field<Vec3>* normals) {
  const Block& b = *block_;
  assert((normals != nullptr) == has_fluid());
  const Vec3 g = gravity_;
  const bool fluid = fluid_.has_value();
  model_->free_acceleration(r, g, a, normals);
  // Damping, fluid and loads act on μ: M/S where the model's density follows the area (S/M
  // only when a term needs it, docs/equations.md §3), μ0 = M/S0 where it does not.
  double inverse_density = rest_inverse_density();
  if (model_->density_follows_area()) inverse_density = needs_area_ ? total_area(r) / mass_ : 0.0;
  const double fluid_coefficient = fluid ? fluid_->viscosity * inverse_density : 0.0;
  const Vec3 fluid_velocity = fluid ? fluid_->velocity : Vec3{};
  if (gusts_) {
    // The wind where each node is now (docs/model.md "Wind and gusts").
    const GustField::Phases phases = gusts_->phases(stage_time_);
#pragma omp parallel for schedule(static)
    for (int l = b.l0; l < b.l1; ++l)
      for (int k = b.k0; k < b.k1; ++k) {
        const Vec3 n = (*normals)(k, l);
        const Vec3 wind = fluid_velocity + gusts_->velocity(r(k, l), phases);
        a(k, l) += (fluid_coefficient * dot(n, wind)) * n;
      }
  } else if (fluid) {
#pragma omp parallel for schedule(static)
    for (int l = b.l0; l < b.l1; ++l)
#pragma omp simd
      for (int k = b.k0; k < b.k1; ++k) {
        const Vec3 n = (*normals)(k, l);
        a(k, l) += (fluid_coefficient * dot(n, fluid_velocity)) * n;
      }
  }
  // Point loads are newtons on the node's lumped mass: μ h1 h2 in the flux form
  // (docs/equations.md §1), times the node's share of the dual area in the trapezoidal one,
  // a particle's own mass in the mass-spring model.
  for (const PointLoad& load : loads_)
    if (load.window.contains(step, time_))
      a(load.k, load.l) +=
          model_->load_inverse_mass(load.k, load.l, inverse_density, h1h2_) * load.force;
  return VelocityTerms{damping_ * inverse_density, fluid_coefficient};
}

void Dynamics::free_acceleration_rows(const Field<Vec3>& r, long step,
                                      const ForceModel::RowConsumer& consume) {
  assert(fuses_rows());
  const Block& b = *block_;
  const double load_scale = rest_inverse_density() / h1h2_;
  const NodeMass& node_mass = model_->node_mass();
  model_->free_acceleration_rows(r, gravity_, [&](int l, double* x, double* y, double* z) {
    auto load = std::lower_bound(loads_.begin(), loads_.end(), l,
                                 [](const PointLoad& a, int row) { return a.l < row; });
    for (; load != loads_.end() && load->l == l; ++load)
      if (load->window.contains(step, time_)) {
        const auto i = static_cast<std::size_t>(load->k - b.k0);
        const Vec3 acceleration =
            (load_scale / node_mass.weight(load->k, load->l)) * load->force;
        x[i] += acceleration.x;
        y[i] += acceleration.y;
        z[i] += acceleration.z;
      }
    consume(l, x, y, z);
  });
}

double Dynamics::elastic_energy(const Field<Vec3>& r) {
  return global_sum(model_->block_energy(r), block_->comm);
}

void Dynamics::internal_acceleration(const Field<Vec3>& r, Field<Vec3>& a) {
  model_->internal_acceleration(r, a);
}

void Dynamics::acceleration(const Field<Vec3>& r, const Field<Vec3>& v, long step,
                            Field<Vec3>& a, Field<Vec3>* normals) {
  const VelocityTerms terms = free_acceleration(r, step, a, normals);
  if (!has_velocity_terms()) return;
  const Block& b = *block_;
  const bool fluid = fluid_.has_value();
  if (model_->has_velocity_force()) {
    if (velocity_force_.data() == nullptr) velocity_force_ = Field<Vec3>(b);
    velocity_acceleration(r, v, velocity_force_);
#pragma omp parallel for schedule(static)
    for (int l = b.l0; l < b.l1; ++l)
      for (int k = b.k0; k < b.k1; ++k) a(k, l) += velocity_force_(k, l);
  }
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) {
      const Vec3 vel = v(k, l);
      Vec3 acc = a(k, l) - terms.damping * vel;
      if (fluid) {
        const Vec3 n = (*normals)(k, l);
        acc -= (terms.fluid * dot(n, vel)) * n;
      }
      a(k, l) = acc;
    }
}

void Dynamics::velocity_acceleration(const Field<Vec3>& r, const Field<Vec3>& v, Field<Vec3>& a) {
  const Block& b = *block_;
  if (ghosted_velocity_.data() == nullptr) ghosted_velocity_ = Field<Vec3>(b);
  for_owned(b, [&](int k, int l) { ghosted_velocity_(k, l) = v(k, l); });
  velocity_acceleration_in_place(r, ghosted_velocity_, a);
}

void Dynamics::velocity_acceleration_in_place(const Field<Vec3>& r, Field<Vec3>& v,
                                              Field<Vec3>& a) {
  exchange(v);
  model_->velocity_acceleration(r, v, a);
}

void Dynamics::exchange(Field<Vec3>& field) {
  if (halo_ != nullptr) {
    halo_->exchange(field);
    return;
  }
  // Without a halo the block must be the whole grid, whose ghosts no force reads.
  assert(block_->k0 == 0 && block_->k1 == block_->m && block_->l0 == 0 && block_->l1 == block_->n);
}

// Chebyshev's iteration (Saad, Iterative Methods for Sparse Linear Systems, §12.1) on
// A w = P⁻¹ g, A = 1 − s P⁻¹K, P w = (1 + c) w + d (n·w) n per node. −K = M⁻¹D is symmetric
// positive semidefinite for equal masses and P⁻¹ shrinks it, so A's spectrum lies in
// [1, β], β = 1 + s bound; the held components are left out (a principal submatrix, whose
// spectrum lies there too). The error falls by 2 q^N after N iterations, q = (√κ − 1)/(√κ + 1)
// for κ = β: N is chosen for 1e-10 before the first, so every rank takes as many.
void Dynamics::solve_velocity_terms(const Field<Vec3>& r, const Field<Vec3>* normals, double c,
                                    double d, double s, const Field<Vec3>& g,
                                    const std::vector<Constraints::NodeState>& held,
                                    Field<Vec3>& w) {
  assert(model_->has_velocity_force());
  const Block& b = *block_;
  if (direction_.data() == nullptr) {
    direction_ = Field<Vec3>(b);
    residual_ = Field<Vec3>(b);
    if (velocity_force_.data() == nullptr) velocity_force_ = Field<Vec3>(b);
  }
  auto solve_p = [&](const Vec3& y, int k, int l) {
    return normals != nullptr ? solve_centred(y, (*normals)(k, l), c, d) : y / (1.0 + c);
  };
  // Held components take no correction.
  auto clear_held = [&](Field<Vec3>& field) {
    for (const Constraints::NodeState& node : held)
      if (b.owns(node.k, node.l))
        for (int axis = 0; axis < 3; ++axis)
          if ((node.held >> axis) & 1u) field(node.k, node.l)[axis] = 0.0;
  };
  const double alpha = 1.0;
  const double beta = 1.0 + s * model_->velocity_force_bound();
  const double theta = 0.5 * (beta + alpha), delta = 0.5 * (beta - alpha);
  const double kappa_root = std::sqrt(beta / alpha);
  const double q = (kappa_root - 1.0) / (kappa_root + 1.0);
  constexpr double kTolerance = 1e-10;
  const int iterations =
      q > 0.0 ? static_cast<int>(std::ceil(std::log(kTolerance / 2.0) / std::log(q))) : 0;
  // residual = P⁻¹ g − A w. The iteration's own fields, and w, take their ghosts in place.
  velocity_acceleration_in_place(r, w, velocity_force_);
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k)
      residual_(k, l) = solve_p(g(k, l) + s * velocity_force_(k, l), k, l) - w(k, l);
  clear_held(residual_);
  if (delta == 0.0) {
    // No velocity force at all (kd 0 in every family): A is the identity.
    for_owned(b, [&](int k, int l) { w(k, l) += residual_(k, l); });
    return;
  }
  const double sigma = theta / delta;
  double rho = 1.0 / sigma;
  for_owned(b, [&](int k, int l) { direction_(k, l) = residual_(k, l) / theta; });
  for (int it = 0; it < iterations; ++it) {
    // w += d; residual −= A d, A d = d − s P⁻¹ K(d).
    velocity_acceleration_in_place(r, direction_, velocity_force_);
    const double rho_next = 1.0 / (2.0 * sigma - rho);
    const double keep = rho_next * rho, gain = 2.0 * rho_next / delta;
#pragma omp parallel for schedule(static)
    for (int l = b.l0; l < b.l1; ++l)
      for (int k = b.k0; k < b.k1; ++k) {
        const Vec3 dk = direction_(k, l);
        w(k, l) += dk;
        residual_(k, l) -= dk - s * solve_p(velocity_force_(k, l), k, l);
      }
    clear_held(residual_);
    for_owned(b, [&](int k, int l) {
      direction_(k, l) = keep * direction_(k, l) + gain * residual_(k, l);
    });
    rho = rho_next;
  }
  for_owned(b, [&](int k, int l) { w(k, l) += direction_(k, l); });
}

}  // namespace cosserat
