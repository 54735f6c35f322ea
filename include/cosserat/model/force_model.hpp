#pragma once
// What the step needs of a force model (docs/model.md, "Force models"): the internal force,
// as a field or row by row into the step's walk, the stored energy and its density, the lumped
// node masses, the explicit step the model allows and how far its stencil reaches. time/ sees
// this type only; make_force_model builds one from the scene's model section (ModelSpec).

#include <functional>
#include <memory>

#include "cosserat/grid/block.hpp"
#include "cosserat/grid/vec3.hpp"
#include "cosserat/model/model_spec.hpp"
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

  // Whether the areal density the velocity terms and loads act on follows the current area
  // (μ = M/S) rather than staying the rest one (μ0 = M/S0).
  virtual bool density_follows_area() const { return false; }

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
