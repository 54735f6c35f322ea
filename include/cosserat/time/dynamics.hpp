#pragma once
// The right-hand side of the equation of motion (docs/equations.md §1, §4): internal force plus
// exactly the external terms the scene declares (docs/design.md, principle 3).

#include <memory>
#include <optional>
#include <vector>

#include "cosserat/grid/block.hpp"
#include "cosserat/grid/halo.hpp"
#include "cosserat/model/force_model.hpp"
#include "cosserat/scene/scene.hpp"
#include "cosserat/time/constraints.hpp"
#include "cosserat/time/gust_field.hpp"

namespace cosserat {

// Coefficients of the terms linear in velocity, per unit mass: the acceleration is
// a_free − damping v − fluid (n·v) n (docs/equations.md §4).
struct VelocityTerms {
  double damping = 0.0;  // ϱ_D / μ
  double fluid = 0.0;    // ϱ_R / μ
};

class Dynamics {
 public:
  // `halo` exchanges the velocities' ghosts for a model whose force reads its neighbours'
  // velocities (has_velocity_force); it may be null for a block that is the whole grid.
  Dynamics(const Scene& scene, const Block& block, const Field<Vec3>& rest_positions,
           Halo* halo = nullptr);

  // The velocity-free part of the acceleration at `step` into `a`, and the coefficients of
  // the velocity terms, for schemes that treat those at the step's centre. `normals` receives
  // the unit normals at r that the fluid terms use: required when has_fluid(), else null.
  VelocityTerms free_acceleration(const Field<Vec3>& r, long step, Field<Vec3>& a,
                                  Field<Vec3>* normals);

  // Whether free_acceleration_rows can stand for free_acceleration: the energy form without a
  // fluid, whose terms need every row's normals before any row's acceleration is complete.
  bool fuses_rows() const { return model_->fuses_rows() && !fluid_.has_value(); }
  // The velocity terms free_acceleration would return; with fuses_rows() only.
  VelocityTerms row_velocity_terms() const {
    return VelocityTerms{damping_ * rest_inverse_density(), 0.0};
  }
  // free_acceleration's `a`, without the field: each finished row goes to `consume` (see
  // ForceModel::free_acceleration_rows) while it is in cache, so that a scheme's update reads
  // it there. The same bits as free_acceleration's; with fuses_rows() only.
  void free_acceleration_rows(const Field<Vec3>& r, long step,
                              const ForceModel::RowConsumer& consume);

  // Whether the model's own force depends on the velocities (the mass-spring model's damping
  // along its springs): then the schemes that treat the velocity terms at the step's centre
  // solve for them with solve_velocity_terms.
  bool has_velocity_force() const { return model_->has_velocity_force(); }

  // Solves (1 + c) w + d (n·w) n − s K(w) = g for the velocities w at every owned node, where
  // K(w) = −M⁻¹D(r) w is the model's velocity force over the masses (docs/model.md,
  // "Damping along the springs"): the centred step of a scheme whose model has a velocity force.
  // `w` holds a first guess on entry; its components held by `held` (their velocities) are
  // kept. n are the fluid's normals (null without a fluid, where d is 0). A Chebyshev
  // iteration over the spectrum [1, 1 + s bound] that the model's bound gives: no global
  // reduction, so any decomposition takes the same iterates bitwise.
  void solve_velocity_terms(const Field<Vec3>& r, const Field<Vec3>* normals, double c, double d,
                            double s, const Field<Vec3>& g,
                            const std::vector<Constraints::NodeState>& held, Field<Vec3>& w);
  // The model's velocity force over the masses, −M⁻¹D(r) v, into `a` (exchanges v's ghosts:
  // collective); with has_velocity_force() only.
  void velocity_acceleration(const Field<Vec3>& r, const Field<Vec3>& v, Field<Vec3>& a);

  // The internal force's share of the acceleration, f_int/μ, into `a`: independent of S
  // (docs/equations.md §3), so a function of the positions alone. The semi-implicit baseline
  // differentiates it.
  void internal_acceleration(const Field<Vec3>& r, Field<Vec3>& a);

  // The whole acceleration A(r, v) at `step`; `normals` as for free_acceleration.
  void acceleration(const Field<Vec3>& r, const Field<Vec3>& v, long step, Field<Vec3>& a,
                    Field<Vec3>* normals);

  // The time at which the step the next evaluations belong to starts: load windows in seconds
  // are told by it, as those in steps are by `step`. The wind's gusts are evaluated at it too,
  // until set_stage_time says otherwise.
  void set_time(double time) {
    time_ = time;
    stage_time_ = time;
  }
  // The time of a stage inside the step (midpoint, rk4), where the next evaluations take the
  // gusts; load windows still go by the step.
  void set_stage_time(double time) { stage_time_ = time; }

  // The force model, for what it does besides forces (ForceModel::act_on_step).
  ForceModel& model() { return *model_; }
  const ForceModel& model() const { return *model_; }

  bool has_fluid() const { return fluid_.has_value(); }
  // The stored energy E of docs/equations.md §2.5 (J), a global sum; reads the ghosts of r. For the
  // flux form too, whose force is not its gradient: there it shows what the discretisation
  // does to the energy.
  double elastic_energy(const Field<Vec3>& r);
  // Its density per unit rest area at every owned node (J/m²), for either form alike; reads the
  // ghosts of r one node beyond the owned range.
  void energy_density(const Field<Vec3>& r, Field<double>& density) const {
    model_->energy_density(r, density);
  }
  // The masses the nodes carry (kg): μ0 h1 h2 times the node's share of the dual area in the
  // energy forms (docs/model.md, "Energy quadrature"; the share is 1 at every node of the nodal
  // quadrature), M/(m n) at every node in the flux form's diagnostics.
  const NodeMass& node_mass() const { return model_->node_mass(); }

  bool has_velocity_terms() const {
    return damping_ > 0.0 || fluid_.has_value() || model_->has_velocity_force();
  }
  double rest_area() const { return rest_area_; }
  // S, a global reduction, the same bitwise for any decomposition; reads the ghosts of r.
  double total_area(const Field<Vec3>& r) const;

 private:
  struct PointLoad {
    int k, l;
    Vec3 force;
    Window window;
  };

  // Fills the ghosts of `field` (velocities for the velocity force).
  void exchange(Field<Vec3>& field);
  // velocity_acceleration for a field whose ghosts may be filled in place: no copy.
  void velocity_acceleration_in_place(const Field<Vec3>& r, Field<Vec3>& v, Field<Vec3>& a);

  // 1/μ0 = S0/M, the energy form's constant inverse areal density (docs/equations.md §2.5).
  double rest_inverse_density() const { return rest_area_ / mass_; }

  const Block* block_;
  double h1h2_;
  double area_quantum_;
  double mass_;
  double rest_area_;
  std::unique_ptr<ForceModel> model_;
  Vec3 gravity_;
  double damping_;
  std::optional<Fluid> fluid_;
  std::optional<GustField> gusts_;  // with a gust amplitude > 0 only
  std::vector<PointLoad> loads_;
  bool needs_area_;
  Halo* halo_;
  // The velocity force's work fields, allocated at their first use: a copy of a velocity
  // field handed in as const, with its ghosts; K(v); the Chebyshev iteration's direction and
  // residual.
  Field<Vec3> ghosted_velocity_, velocity_force_, direction_, residual_;
  double time_ = 0.0;
  double stage_time_ = 0.0;
};

}  // namespace cosserat
