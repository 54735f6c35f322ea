#include "cosserat/time/simulation.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "cosserat/grid/reduce.hpp"
#include "cosserat/model/surface_measures.hpp"

namespace cosserat {

Field<Vec3> Simulation::rest_positions(const Scene& scene, const Block& block) {
  Field<Vec3> r(block);
  const double h1 = scene.h1(), h2 = scene.h2();
  // Ghost nodes inside the grid get their rest positions too, so a block's first force
  // evaluation reads real data whatever the decomposition.
  const int k_lo = std::max(block.k0 - block.ghost, 0), k_hi = std::min(block.k1 + block.ghost, block.m);
  const int l_lo = std::max(block.l0 - block.ghost, 0), l_hi = std::min(block.l1 + block.ghost, block.n);
  for (int l = l_lo; l < l_hi; ++l)
    for (int k = k_lo; k < k_hi; ++k)
      r(k, l) = scene.origin + (k * h1) * scene.u + (l * h2) * scene.v;
  return r;
}

Field<Vec3> Simulation::initial_velocities(const Scene& scene, const Block& block) {
  Field<Vec3> v(block);
  for (int l = block.l0; l < block.l1; ++l)
    for (int k = block.k0; k < block.k1; ++k) v(k, l) = scene.initial_velocity;
  return v;
}

// What the force model does to every proposed step (the mass-spring model's rupture and
// length limits, docs/model.md "The mass-spring model"), before the contact, which has the last
// word on where nodes go. A node it moves moves on with the velocity the move implies: the
// Verlet family's r⁻ stays, so (r⁺ − r⁻)/Δt takes it in; a scheme that carries velocities adds
// move/Δt.
class Simulation::ModelAction final : public StepAction {
 public:
  ModelAction(ForceModel& model, Halo& halo, const Constraints& constraints, const Block& block)
      : model_(&model),
        halo_(&halo),
        constraints_(&constraints),
        block_(&block),
        held_(block),
        moves_(block) {}

  void apply(ProposedStep& p) override {
    const Block& b = *block_;
    for (const Constraints::NodeState& node : constraints_->state())
      if (b.owns(node.k, node.l)) held_(node.k, node.l).x = node.held != 0 ? 1.0 : 0.0;
    halo_->exchange(held_);
    const double rate = 1.0 / p.dt;
    Field<Vec3>* velocities = p.next_velocities;
    for (int pass = 0; pass < kPasses; ++pass) {
      halo_->exchange(p.next_positions);
      int moved = model_->act_on_step(p.next_positions, held_, moves_, pass == 0) ? 1 : 0;
      MPI_Allreduce(MPI_IN_PLACE, &moved, 1, MPI_INT, MPI_MAX, b.comm);
      if (moved == 0) break;
      for_owned(b, [&](int k, int l) {
        p.next_positions(k, l) += moves_(k, l);
        if (velocities != nullptr) (*velocities)(k, l) += rate * moves_(k, l);
      });
    }
  }
  std::vector<double> state() const override { return model_->step_state(); }
  void restore(const std::vector<double>& values) override { model_->restore_step_state(values); }

 private:
  // Each pass of the length limits corrects a node by the mean of what its springs ask, which
  // never overshoots but leaves part of a correction shared with neighbours to the next pass
  // (docs/model.md, "The mass-spring model").
  static constexpr int kPasses = 8;

  ForceModel* model_;
  Halo* halo_;
  const Constraints* constraints_;
  const Block* block_;
  Field<Vec3> held_;   // x: 1 at a node held in some component, ghosts included
  Field<Vec3> moves_;  // the model's moves of the owned nodes
};

// docs/contact.md: the scene's solids against every proposed step, whatever the scheme; the run's
// maxima kept over accepted steps.
class Simulation::ContactAction final : public StepAction, public RowReader {
 public:
  explicit ContactAction(Contact& contact) : contact_(&contact) {}

  void apply(ProposedStep& p) override {
    last_ = contact_->respond(p.time, p.dt, p.positions, p.next_positions, p.next_velocities,
                              p.velocities, p.moved_rows);
  }
  RowReader* row_reader() override { return this; }
  bool marks_moved_rows() const override { return true; }
  bool sets_velocities() const override { return contact_->walk_sets_velocities(); }
  void begin_walk(double time, double dt, Field<Vec3>* starts) override {
    contact_->begin_walk(time, dt, starts);
  }
  void walk_row(int l, const Field<Vec3>& r, Field<Vec3>& next) override {
    contact_->walk_row(l, r, next);
  }
  void accepted() override {
    contact_->accept();
    summary_.max_penetration = std::max(summary_.max_penetration, last_.max_penetration);
    summary_.max_contacts = std::max(summary_.max_contacts, last_.contacts);
  }
  std::vector<double> state() const override {
    std::vector<double> values = contact_->state_vector();
    values.push_back(summary_.max_penetration);
    values.push_back(static_cast<double>(summary_.max_contacts));
    return values;
  }
  void restore(const std::vector<double>& values) override {
    if (values.size() < 2) throw std::invalid_argument("contact state: too few numbers");
    contact_->restore({values.begin(), values.end() - 2});
    summary_.max_penetration = values[values.size() - 2];
    summary_.max_contacts = static_cast<long>(values.back());
  }
  const ContactSummary& summary() const { return summary_; }

 private:
  Contact* contact_;
  ContactStats last_;
  ContactSummary summary_;
};

// docs/contact.md, "Self-contact": the cloth against its own cells on every proposed step,
// before the solids, which have the last word on where nodes go.
class Simulation::SelfContactAction final : public StepAction {
 public:
  SelfContactAction(SelfContact& self, const Constraints& constraints, const Block& block)
      : self_(&self), constraints_(&constraints), block_(&block) {}

  void apply(ProposedStep& p) override {
    const Block& b = *block_;
    held_.assign(static_cast<std::size_t>(b.owned_k()) * static_cast<std::size_t>(b.owned_l()), 0);
    for (const Constraints::NodeState& node : constraints_->state())
      if (b.owns(node.k, node.l) && node.held != 0)
        held_[static_cast<std::size_t>(node.l - b.l0) * static_cast<std::size_t>(b.owned_k()) +
              static_cast<std::size_t>(node.k - b.k0)] = 1;
    last_ = self_->respond(p.dt, p.positions, p.next_positions, p.next_velocities, p.starts,
                           held_, p.velocities, p.moved_rows);
  }
  bool marks_moved_rows() const override { return true; }
  void accepted() override {
    summary_.max_pairs = std::max(summary_.max_pairs, last_.contacts);
    summary_.closest = std::min(summary_.closest, last_.closest);
  }
  // No pair yet has no closest distance (infinite), which a checkpoint holds as the largest
  // double: its reader refuses any number that is not finite, and refused a run checkpointed
  // before its cloth first touched itself.
  std::vector<double> state() const override {
    return {static_cast<double>(summary_.max_pairs),
            std::min(summary_.closest, std::numeric_limits<double>::max())};
  }
  void restore(const std::vector<double>& values) override {
    if (values.size() != 2) throw std::invalid_argument("self-contact state: two numbers");
    summary_.max_pairs = static_cast<long>(values[0]);
    summary_.closest = values[1] == std::numeric_limits<double>::max()
                           ? std::numeric_limits<double>::infinity()
                           : values[1];
  }
  const SelfContactSummary& summary() const { return summary_; }

 private:
  SelfContact* self_;
  const Constraints* constraints_;
  const Block* block_;
  std::vector<char> held_;
  SelfContactStats last_;
  SelfContactSummary summary_;
};

Simulation::Simulation(const Scene& scene, MPI_Comm comm, const SchemeFactory& make)
    : Simulation(scene, comm, Decomposition::choose(scene.m, scene.n, size_of(comm)), make) {}

Simulation::Simulation(const Scene& scene, MPI_Comm comm, const Decomposition& decomposition,
                       const SchemeFactory& make)
    : scene_(&scene),
      decomposition_(decomposition),
      block_(decomposition_.block(rank_in(comm), comm)),
      halo_(decomposition_, block_, rank_in(comm)),
      dynamics_(scene, block_, rest_positions(scene, block_), &halo_),
      contact_(scene.solids.empty()
                   ? nullptr
                   : std::make_unique<Contact>(scene.solids, block_, halo_, dynamics_.node_mass(),
                                               scene.gravity, std::min(scene.h1(), scene.h2()))),
      self_contact_(scene.self_contact
                        ? std::make_unique<SelfContact>(
                              scene.self_contact->thickness, scene.self_contact->friction,
                              scene.self_contact->every_edge, std::min(scene.h1(), scene.h2()),
                              block_, dynamics_.node_mass(), scene.solids)
                        : nullptr),
      stepper_(scene, decomposition_, block_, halo_, dynamics_, rest_positions(scene, block_),
               initial_velocities(scene, block_), make) {
  if (dynamics_.model().acts_on_steps())
    stepper_.add_action(
        std::make_unique<ModelAction>(dynamics_.model(), halo_, stepper_.constraints(), block_));
  if (self_contact_) {
    auto action = std::make_unique<SelfContactAction>(*self_contact_, stepper_.constraints(), block_);
    self_contact_action_ = action.get();
    stepper_.add_action(std::move(action));
  }
  if (contact_) {
    auto action = std::make_unique<ContactAction>(*contact_);
    contact_action_ = action.get();
    stepper_.add_action(std::move(action));
  }
}

ContactSummary Simulation::contact_summary() const {
  return contact_action_ ? contact_action_->summary() : ContactSummary{};
}

std::optional<SelfContactSummary> Simulation::self_contact_summary() const {
  if (!self_contact_action_) return std::nullopt;
  SelfContactSummary summary = self_contact_action_->summary();
  summary.thickness = scene_->self_contact->thickness;
  return summary;
}

double Simulation::memory_bytes(const Block& block, Integrator integrator, const ModelSpec& model,
                                std::size_t scalar_output_fields,
                                const std::vector<SolidSpec>& solids, bool self_contact) {
  const double ghosted_nodes = static_cast<double>(block.local_size());
  const double owned_nodes = static_cast<double>(block.owned_k()) * block.owned_l();
  // rk4 keeps nine position-sized fields (state and new state of r and v, acceleration, two
  // stages, two weighted sums), and a fluid one more for the normals.
  // The force kernel's intermediates: the flux form's resultants and tractions per node; the
  // energy form keeps only row buffers, 36 rows of doubles a thread (docs/kernel.md).
  const double kernel = kernel_bytes_per_node(model);
  const double row_buffers = 36.0 * sizeof(double) * (block.stride() + 16) * omp_get_max_threads();
  const double per_node =
      kernel + 10 * sizeof(Vec3) + static_cast<double>(scalar_output_fields * sizeof(double));
  const double output_buffer = 3.0 * sizeof(double) * owned_nodes;
  // 3 rows of 75 entries per node, with the colouring's index of every entry for a differenced
  // Jacobian: 13 KB per node measured (peak RSS 578 MB against Verlet's 59 MB on 200 x 200);
  // the exact Jacobian's two matrices (J and the step's) with ILU's factor and the places of
  // its blocks took 10.2 KB.
  const double baseline = is_semi_implicit(integrator) ? 13.5e3 * owned_nodes : 0.0;
  return ghosted_nodes * per_node + row_buffers + output_buffer + baseline +
         Contact::memory_bytes(block, solids) +
         (self_contact ? SelfContact::memory_bytes(block.m, block.n) : 0.0);
}

void Simulation::node_field(OutputField field, Field<double>& values) const {
  const Scene& scene = *scene_;
  const Field<Vec3>& r = stepper_.positions();
  switch (field) {
    case OutputField::area_ratio:
      area_ratio(r, scene.h1(), scene.h2(), flat_metric(scene.u, scene.v), values);
      return;
    case OutputField::curvature:
      mean_curvature(r, scene.h1(), scene.h2(), values);
      return;
    case OutputField::energy_density:
      dynamics_.energy_density(r, values);
      return;
    case OutputField::broken_springs:
      dynamics_.model().broken_springs(values);
      return;
    case OutputField::velocity:
      break;
  }
  throw std::invalid_argument(
      fmt::format("{} is not a scalar field", output_field_name(field)));
}

Diagnostics Simulation::diagnostics() {
  const Block& b = block_;
  const Field<Vec3>& r = stepper_.positions();
  const Field<Vec3>& v = stepper_.velocities();
  // Per-row partials summed in row order: the same result for any thread count.
  const auto rows = static_cast<std::size_t>(b.owned_l());
  std::vector<double> energy2(rows), max_speed2(rows), mass_sum(rows);
  std::vector<Vec3> moment_sum(rows);
  const NodeMass& mass = dynamics_.node_mass();
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < b.l1; ++l) {
    const auto row = static_cast<std::size_t>(l - b.l0);
    double e2 = 0.0, max2 = 0.0, m = 0.0;
    Vec3 sum;
    for (int k = b.k0; k < b.k1; ++k) {
      const double w2 = dot(v(k, l), v(k, l)), node = mass(k, l);
      e2 += node * w2;
      max2 = std::max(max2, w2);
      sum += node * r(k, l);
      m += node;
    }
    energy2[row] = e2;
    max_speed2[row] = max2;
    moment_sum[row] = sum;
    mass_sum[row] = m;
  }
  double e2 = 0.0, max2 = 0.0, m = 0.0;
  Vec3 sum;
  for (std::size_t row = 0; row < rows; ++row) {
    e2 += energy2[row];
    max2 = std::max(max2, max_speed2[row]);
    sum += moment_sum[row];
    m += mass_sum[row];
  }
  Diagnostics d;
  d.area_ratio = dynamics_.total_area(r) / dynamics_.rest_area();
  d.kinetic_energy = 0.5 * global_sum(e2, b.comm);
  d.max_speed = std::sqrt(global_max(max2, b.comm));
  // Σ m r: the centre of mass and the potential of gravity, −Σ m g · r.
  const Vec3 moment_total{global_sum(sum.x, b.comm), global_sum(sum.y, b.comm),
                          global_sum(sum.z, b.comm)};
  d.center_of_mass = moment_total / global_sum(m, b.comm);
  d.gravitational_energy = -dot(scene_->gravity, moment_total);
  return d;
}

StateMeasures Simulation::state_measures() {
  const Block& b = block_;
  const Field<Vec3>& r = stepper_.positions();
  const double speed2 = stepper_.max_speed2();
  const double inverse_h1_2 = 1.0 / (scene_->h1() * scene_->h1());
  const double inverse_h2_2 = 1.0 / (scene_->h2() * scene_->h2());
  // The cloth's box only where a solid moves: approach_step reads it.
  const bool boxed = contact_ && contact_->any_moving();
  // Each edge is read by the rank and thread that own its first node, and maxima are exact, so
  // the result is the same for any decomposition. Row by row, each row's edges along k in one
  // loop and those to the next row in another, so that each vectorises.
  double stretch2 = 0.0;
  constexpr double kNone = -std::numeric_limits<double>::infinity();
  double lo_x = kNone, lo_y = kNone, lo_z = kNone;  // −(the box's low corner)
  double hi_x = kNone, hi_y = kNone, hi_z = kNone;
  const int along = std::min(b.k1, b.m - 1) - b.k0;  // edges to k + 1 inside the grid
#pragma omp parallel for schedule(static) \
    reduction(max                         \
              : stretch2, lo_x, lo_y, lo_z, hi_x, hi_y, hi_z)
  for (int l = b.l0; l < b.l1; ++l) {
    const Vec3* row = &r(b.k0, l);
    double most = 0.0;
#pragma omp simd reduction(max : most)
    for (int i = 0; i < along; ++i) {
      const Vec3 e = row[i + 1] - row[i];
      most = std::max(most, dot(e, e) * inverse_h1_2);
    }
    if (l + 1 < b.n) {
      const Vec3* next = &r(b.k0, l + 1);
#pragma omp simd reduction(max : most)
      for (int i = 0; i < b.owned_k(); ++i) {
        const Vec3 e = next[i] - row[i];
        most = std::max(most, dot(e, e) * inverse_h2_2);
      }
    }
    stretch2 = std::max(stretch2, most);
    if (boxed)
      for (int i = 0; i < b.owned_k(); ++i) {
        const Vec3& p = row[i];
        lo_x = std::max(lo_x, -p.x);
        lo_y = std::max(lo_y, -p.y);
        lo_z = std::max(lo_z, -p.z);
        hi_x = std::max(hi_x, p.x);
        hi_y = std::max(hi_y, p.y);
        hi_z = std::max(hi_z, p.z);
      }
  }
  // Every maximum in one reduction: it runs before every adaptive step.
  const double local[8] = {stretch2, speed2, lo_x, lo_y, lo_z, hi_x, hi_y, hi_z};
  double global[8];
  MPI_Allreduce(local, global, boxed ? 8 : 2, MPI_DOUBLE, MPI_MAX, b.comm);
  StateMeasures measures{global[0], std::sqrt(global[1])};
  if (boxed)
    measures.solid_step = contact_->approach_step({-global[2], -global[3], -global[4]},
                                                  {global[5], global[6], global[7]},
                                                  0.25 * std::min(scene_->h1(), scene_->h2()));
  return measures;
}

}  // namespace cosserat
