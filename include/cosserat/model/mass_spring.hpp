#pragma once
// The mass-spring model (docs/model.md, "The mass-spring model"): the grid's nodes are
// particles of equal mass joined by structural, shear and bend springs, each family with its
// stiffness ke and its damping kd along the spring. A second force model beside the Cosserat
// surface, on the same grid, behind the same interface.

#include <array>
#include <cstdint>
#include <vector>

#include "cosserat/grid/block.hpp"
#include "cosserat/model/force_model.hpp"

namespace cosserat {

class MassSpring final : public ForceModel {
 public:
  MassSpring(const ModelSpec& spec, const Block& block);

  void free_acceleration(const Field<Vec3>& r, const Vec3& gravity, Field<Vec3>& a,
                         Field<Vec3>* normals) override;
  void internal_acceleration(const Field<Vec3>& r, Field<Vec3>& a) override;
  double block_energy(const Field<Vec3>& r) const override;
  void energy_density(const Field<Vec3>& r, Field<double>& density) const override;
  const NodeMass& node_mass() const override { return node_mass_; }
  int reach() const override { return 2; }
  double load_inverse_mass(int, int, double, double) const override {
    return 1.0 / node_mass_.interior;
  }

  bool has_velocity_force() const override { return spec_.damped(); }
  void velocity_acceleration(const Field<Vec3>& r, const Field<Vec3>& v,
                             Field<Vec3>& a) const override;
  double velocity_force_bound() const override { return damping_bound_; }

  bool acts_on_steps() const override { return breakable_ || limited_; }
  bool act_on_step(const Field<Vec3>& next, const Field<Vec3>& held, Field<Vec3>& moves,
                   bool first_pass) override;
  // The broken springs' global numbers, slot + 6 (k + m l) of their owner, ascending.
  std::vector<double> step_state() const override;
  void restore_step_state(const std::vector<double>& state) override;

  // A spring of the grid, named by the node it starts from (its owner) and its slot there:
  // 0 (k+1, l), 1 (k, l+1), 2 (k+1, l+1), 3 (k+1, l−1), 4 (k+2, l), 5 (k, l+2).
  static constexpr int kSlots = 6;
  bool broken(int k, int l, int slot) const { return (broken_(k, l) >> slot) & 1u; }
  void broken_springs(Field<double>& bits) const override;
  // Grid neighbours part when their structural spring breaks.
  bool parted(int k, int l, int k2, int l2) const override {
    if (k2 < k || l2 < l) return parted(k2, l2, k, l);
    return broken(k, l, k2 > k ? 0 : 1);
  }

 private:
  // One of the twelve springs that meet at a node, seen from it: towards (k+dk, l+dl).
  struct Incident {
    int dk, dl;
    int slot;
    bool owned_here;  // the spring starts at this node (else at the other end)
    double rest;      // ℓ0, m
    SpringFamily family;
  };

  // Whether the spring `s` of node (k, l) joins two grid nodes.
  bool exists(int k, int l, const Incident& s) const {
    const int k2 = k + s.dk, l2 = l + s.dl;
    return k2 >= 0 && k2 < block_->m && l2 >= 0 && l2 < block_->n;
  }
  bool is_broken(int k, int l, const Incident& s) const {
    return s.owned_here ? broken(k, l, s.slot) : broken(k + s.dk, l + s.dl, s.slot);
  }
  // Breaks, for good, every spring that starts at an owned node and is longer than its rupture
  // length at r, and learns which the other blocks broke (collective).
  void break_overlong(const Field<Vec3>& r);
  // Marks the spring numbered `id` broken where this block sees it (owned nodes and ghosts).
  void mark_broken(std::int64_t id);
  // The displacement of owned node (k, l) that brings its springs back within their lengths.
  Vec3 length_correction(const Field<Vec3>& r, const Field<Vec3>& held, int k, int l) const;
  // The elastic force on (k, l) from its springs (N).
  Vec3 elastic_force(const Field<Vec3>& r, int k, int l) const;
  // The stored energy of one spring of length ℓ (J).
  double spring_energy(const Incident& s, double length) const;
  void accelerations(const Field<Vec3>& r, const Vec3& gravity, Field<Vec3>& a);

  const Block* block_;
  std::array<Incident, 12> incident_;
  SpringSpec spec_;
  NodeMass node_mass_;
  double h1h2_;
  bool breakable_;
  bool limited_;
  std::vector<std::int64_t> broken_ids_;  // every block's, ascending
  double damping_bound_;  // 1/s
  Field<std::uint8_t> broken_;
};

}  // namespace cosserat
