#pragma once
// What the step needs of a force model (docs/model.md, "Force models"): the internal force,
// as a field or row by row into the step's walk, the stored energy and its density, the lumped
// node masses, the explicit step the model allows and how far its stencil reaches. time/ sees
// this type only; make_force_model builds one from the scene's model section (ModelSpec).

#include <functional>
#include <memory>
#include <vector>

#include "cosserat/grid/block.hpp"
#include "cosserat/grid/vec3.hpp"
#include "cosserat/model/model_spec.hpp"
#include "cosserat/model/node_hessian.hpp"
#include "cosserat/model/node_mass.hpp"

namespace cosserat {

class ForceModel {
 public:
  // A finished row l of accelerations, three component arrays over the owned columns (column
  // b.k0 first), handed over while it is still in cache; the consumer may change them.
  using RowConsumer = std::function<void(int l, double* x, double* y, double* z)>;

  virtual ~ForceModel() = default;

  // The internal force over the node masses, plus `gravity`, at every owned node; with
  // `normals`, also the unit normal of every owned node at r (the fluid term needs them).
  // Reads the ghosts of r up to reach() nodes out.
  virtual void free_acceleration(const Field<Vec3>& r, const Vec3& gravity, Field<Vec3>& a,
                                 Field<Vec3>* normals) = 0;
  // The internal force's share alone, a function of r only (the semi-implicit baseline
  // differentiates it).
  virtual void internal_acceleration(const Field<Vec3>& r, Field<Vec3>& a) = 0;

  // Whether free_acceleration_rows can stand for free_acceleration (normals not asked for).
  virtual bool fuses_rows() const { return false; }
  // free_acceleration's a, each row to `consume` in place of the field: the same bits.
  virtual void free_acceleration_rows(const Field<Vec3>& r, const Vec3& gravity,
                                      const RowConsumer& consume);

  // The part of the internal force linear in the velocities, −D(r) v with D symmetric and
  // positive semidefinite (the mass-spring model's damping along its springs): whether there is
  // one, its acceleration −M⁻¹D(r) v into `a` at every owned node (reads the ghosts of r and v
  // up to reach() nodes out), and a bound on the largest eigenvalue of M⁻¹D (1/s), whatever r.
  virtual bool has_velocity_force() const { return false; }
  virtual void velocity_acceleration(const Field<Vec3>& r, const Field<Vec3>& v,
                                     Field<Vec3>& a) const;
  virtual double velocity_force_bound() const { return 0.0; }

  // What a point load of one newton at node (k, l) accelerates it by (1/kg), for a sheet of
  // inverse areal density `inverse_density` (m²/kg) and grid cell h1 h2: over the node's share
  // of the sheet's mass, unless the model's particles carry masses of their own.
  virtual double load_inverse_mass(int k, int l, double inverse_density, double h1h2) const {
    return inverse_density / (h1h2 * node_mass().weight(k, l));
  }

  // What the model does to each proposed step (the mass-spring model's rupture and length
  // limits, docs/model.md "The mass-spring model"): whether it does anything; then, in passes
  // over the proposed positions r⁺ with their ghosts, it changes its state in the first
  // (collective over the block's communicator) and writes into `moves` the displacement it
  // gives each owned node, none to a node whose `held` x is nonzero (ghosts included). Returns
  // whether it moved a node of this block; the caller adds the moves and passes again while
  // any block's did.
  virtual bool acts_on_steps() const { return false; }
  virtual bool act_on_step(const Field<Vec3>& next, const Field<Vec3>& held, Field<Vec3>& moves,
                           bool first_pass);
  // That state, the same on every rank, as numbers (snapshots and checkpoints), and back.
  virtual std::vector<double> step_state() const { return {}; }
  virtual void restore_step_state(const std::vector<double>& state);

  // At every owned node, the bits of the springs that start there and are broken (the mass-spring
  // model's slots, docs/output.md "Fields"); 0 for a model without springs.
  virtual void broken_springs(Field<double>& bits) const;

  // Whether the grid neighbours (k, l) and (k2, l2) have parted (the spring between them broke):
  // the stability check lets them move apart.
  virtual bool parted(int /*k*/, int /*l*/, int /*k2*/, int /*l2*/) const { return false; }

  // Whether the areal density the velocity terms and loads act on follows the current area
  // (μ = M/S) rather than staying the rest one (μ0 = M/S0).
  virtual bool density_follows_area() const { return false; }

  // Where the force is the exact gradient of an energy that is a sum of node terms E_p over
  // each node's 3 × 3 box (the trapezoidal energy form): whether the model has E_p's exact
  // Hessian at (k, l) with the slots it reads (NodeHessian). Reads the
  // ghosts of r up to reach() nodes out. The semi-implicit step assembles its Jacobian from
  // them (docs/semi-implicit.md, "The Jacobian").
  virtual bool has_node_hessian() const { return false; }
  virtual void node_hessian(const Field<Vec3>& r, int k, int l, NodeHessian& hessian) const;

  // This block's share of the stored energy (J), the nodes it owns summed in a fixed order;
  // reads the ghosts one node out.
  virtual double block_energy(const Field<Vec3>& r) const = 0;
  // The stored energy per unit rest area at every owned node (J/m²), Σ density · dual area = E.
  virtual void energy_density(const Field<Vec3>& r, Field<double>& density) const = 0;
  // The mass each node carries (kg).
  virtual const NodeMass& node_mass() const = 0;
  // How many nodes beyond a node its force reads: the ghost rings a block must have.
  virtual int reach() const = 0;
};

// The model the spec names, on `block`, for a sheet of rest area `rest_area` (m²). Throws
// std::invalid_argument when the block's ghost layers are narrower than its reach.
std::unique_ptr<ForceModel> make_force_model(const ModelSpec& spec, const Block& block,
                                             double rest_area);

// The bytes a node of the model's force kernel keeps beside the positions (memory estimates).
double kernel_bytes_per_node(const ModelSpec& spec);

}  // namespace cosserat
