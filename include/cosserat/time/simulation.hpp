#pragma once
// A scene set up on this rank's block: rest state, dynamics, constraints and integrator
// (docs/design.md, principle 4: scene -> Simulation -> step loop -> writers).

#include <mpi.h>

#include <limits>
#include <memory>
#include <optional>

#include "cosserat/contact/contact.hpp"
#include "cosserat/contact/self_contact.hpp"
#include "cosserat/grid/block.hpp"
#include "cosserat/grid/decomposition.hpp"
#include "cosserat/grid/halo.hpp"
#include "cosserat/scene/scene.hpp"
#include "cosserat/time/adaptive_step.hpp"
#include "cosserat/time/dynamics.hpp"
#include "cosserat/time/stepper.hpp"

namespace cosserat {

// Whole-sheet quantities reported in the run summary; all global reductions.
// What contact did over the accepted steps so far (docs/output.md, "Run summary"), the same on
// every rank.
struct ContactSummary {
  double max_penetration = 0.0;  // m, deepest any node sat inside a solid after a step
  long max_contacts = 0;         // most nodes moved by contact in one step
};

// What self-contact did over the accepted steps so far, the same on every rank.
struct SelfContactSummary {
  double thickness = 0.0;  // m, the cloth's, which the pairs are held apart by
  long max_pairs = 0;  // most node-triangle pairs closer than the thickness in one step
  // m: the smallest distance of a held pair after a step (infinite: none met)
  double closest = std::numeric_limits<double>::infinity();
};

struct Diagnostics {
  double area_ratio = 0.0;      // S / S0
  double kinetic_energy = 0.0;        // ½ Σ m |v|², m of each node from Dynamics::node_mass()
  double gravitational_energy = 0.0;  // −Σ m g·r
  double max_speed = 0.0;
  Vec3 center_of_mass;                // Σ m r / Σ m
};

class Simulation {
 public:
  // The scene on the ranks of comm, split by Decomposition::choose (throws
  // DecompositionError when the grid is too small for that many ranks) or as given, its
  // scheme built by `make`: this module's explicit schemes, or the baseline module's
  // any_scheme, which adds the semi-implicit one.
  Simulation(const Scene& scene, MPI_Comm comm, const SchemeFactory& make = explicit_scheme);
  Simulation(const Scene& scene, MPI_Comm comm, const Decomposition& decomposition,
             const SchemeFactory& make = explicit_scheme);
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  // Upper bound of the memory one rank's block takes: every field of the most demanding
  // explicit scheme, the force kernel's intermediates, the output buffer and the
  // `scalar_output_fields` fields of node_field() the output keeps, the contact with `solids`,
  // self-contact where `self_contact`, and for the semi-implicit one its PETSc matrix and
  // colouring.
  static double memory_bytes(const Block& block, Integrator integrator, const ModelSpec& model,
                             std::size_t scalar_output_fields = 0,
                             const std::vector<SolidSpec>& solids = {},
                             bool self_contact = false);

  std::optional<Instability> step() { return stepper_.step(); }
  long step_index() const { return stepper_.step_index(); }
  double time() const { return stepper_.time(); }
  const Block& block() const { return block_; }
  // The lumped mass of every node (kg).
  const NodeMass& node_mass() const { return dynamics_.node_mass(); }
  const Field<Vec3>& positions() const { return stepper_.positions(); }
  const Field<Vec3>& velocities() { return stepper_.velocities(); }
  // Wall time this rank spent in halo exchanges so far.
  double halo_seconds() const { return halo_.seconds(); }

  // The scheme's state for checkpoints (see Stepper::state_fields).
  Stepper& stepper() { return stepper_; }

  Diagnostics diagnostics();
  // What adaptive steps estimate the next step from; global maxima, reads the ghosts of r.
  StateMeasures state_measures();
  // The scene's solids, or null when it has none.
  const Contact* contact() const { return contact_.get(); }
  ContactSummary contact_summary() const;
  // Nothing when the scene has no [self_contact].
  std::optional<SelfContactSummary> self_contact_summary() const;
  // The scene's self-contact, or null when it has none.
  const SelfContact* self_contact() const { return self_contact_.get(); }

  // The stored energy of docs/equations.md §2.5 at the current positions (J); a global sum that
  // costs about one force evaluation, so not part of diagnostics().
  double elastic_energy() { return dynamics_.elastic_energy(stepper_.positions()); }

  // A scalar field of the output at the current state into the owned nodes of `values`
  // (docs/output.md, "Fields"): OutputField::area_ratio, curvature or energy_density; the
  // velocity field is velocities(). Each node's value is a function of its 3 × 3 box of
  // positions alone, so every decomposition and thread count gives the same bits.
  void node_field(OutputField field, Field<double>& values) const;

 private:
  static Field<Vec3> rest_positions(const Scene& scene, const Block& block);
  static Field<Vec3> initial_velocities(const Scene& scene, const Block& block);

  const Scene* scene_;
  Decomposition decomposition_;
  Block block_;
  Halo halo_;
  Dynamics dynamics_;
  std::unique_ptr<Contact> contact_;
  std::unique_ptr<SelfContact> self_contact_;
  Stepper stepper_;
  class ModelAction;
  class ContactAction;
  class SelfContactAction;
  ContactAction* contact_action_ = nullptr;  // owned by stepper_
  SelfContactAction* self_contact_action_ = nullptr;  // owned by stepper_
};

}  // namespace cosserat
