#include "cosserat/model/mass_spring.hpp"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace cosserat {

namespace {

// The owner's offsets of the six slots (MassSpring::broken).
constexpr int kSlotOffset[MassSpring::kSlots][2] = {{1, 0},  {0, 1}, {1, 1},
                                                     {1, -1}, {2, 0}, {0, 2}};

}  // namespace

MassSpring::MassSpring(const ModelSpec& spec, const Block& block)
    : block_(&block),
      spec_(spec.springs),
      node_mass_{spec.particle_mass, block.m, block.n, false},
      h1h2_(spec.h1 * spec.h2),
      broken_(block) {
  const SpringFamily families[kSlots] = {spec_.structural, spec_.structural, spec_.shear,
                                         spec_.shear,      spec_.bend,       spec_.bend};
  // Rest lengths from the flat rest grid (docs/model.md, "The mass-spring model").
  const double diagonal = std::sqrt(spec.h1 * spec.h1 + spec.h2 * spec.h2);
  const double rests[kSlots] = {spec.h1, spec.h2, diagonal, diagonal, 2.0 * spec.h1,
                                2.0 * spec.h2};
  for (int s = 0; s < kSlots; ++s) {
    const int dk = kSlotOffset[s][0], dl = kSlotOffset[s][1];
    incident_[2 * s] = {dk, dl, s, true, rests[s], families[s]};
    incident_[2 * s + 1] = {-dk, -dl, s, false, rests[s], families[s]};
  }
  breakable_ = std::isfinite(spec_.rupture_length);
  limited_ = spec_.min_length > 0.0 || std::isfinite(spec_.max_length);
  // Gershgorin: a row of M⁻¹D holds Σ kd on its diagonal and as much off it, over the four
  // springs of each family at a node, whatever their directions.
  damping_bound_ =
      8.0 * (spec_.structural.kd + spec_.shear.kd + spec_.bend.kd) / spec.particle_mass;
}

void MassSpring::mark_broken(std::int64_t id) {
  const Block& b = *block_;
  const int slot = static_cast<int>(id % kSlots);
  const std::int64_t node = id / kSlots;
  const int k = static_cast<int>(node % b.m), l = static_cast<int>(node / b.m);
  if (k >= b.k0 - b.ghost && k < b.k1 + b.ghost && l >= b.l0 - b.ghost && l < b.l1 + b.ghost)
    broken_(k, l) = static_cast<std::uint8_t>(broken_(k, l) | (1u << slot));
}

void MassSpring::break_overlong(const Field<Vec3>& r) {
  const Block& b = *block_;
  // Each spring is judged once, by the block that owns the node it starts from; every block
  // then learns the whole list, so a spring across two blocks breaks on both.
  std::vector<std::int64_t> found;
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k)
      for (const Incident& s : incident_) {
        if (!s.owned_here || !exists(k, l, s) || is_broken(k, l, s)) continue;
        if (norm(r(k + s.dk, l + s.dl) - r(k, l)) > spec_.rupture_length * s.rest)
          found.push_back(s.slot + kSlots * (k + static_cast<std::int64_t>(b.m) * l));
      }
  const int ranks = [&] {
    int size = 1;
    MPI_Comm_size(b.comm, &size);
    return size;
  }();
  const int mine = static_cast<int>(found.size());
  std::vector<int> counts(static_cast<std::size_t>(ranks)), offsets(counts.size());
  MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, b.comm);
  int total = 0;
  for (std::size_t i = 0; i < counts.size(); ++i) {
    offsets[i] = total;
    total += counts[i];
  }
  if (total == 0) return;
  std::vector<std::int64_t> all(static_cast<std::size_t>(total));
  MPI_Allgatherv(found.data(), mine, MPI_INT64_T, all.data(), counts.data(), offsets.data(),
                 MPI_INT64_T, b.comm);
  for (const std::int64_t id : all) mark_broken(id);
  broken_ids_.insert(broken_ids_.end(), all.begin(), all.end());
  std::sort(broken_ids_.begin(), broken_ids_.end());
}

// A spring outside [min_length, max_length] ℓ0 is brought back to the nearer limit, each free
// end taking half of the correction, a free end whose other end is held all of it
// (docs/model.md, "The mass-spring model"). A node takes the mean of what its violated springs
// ask: their sum overshoots where several pull one way (a bend spring's excess is twice its
// structural neighbours'), and in a pulled net it went unstable.
Vec3 MassSpring::length_correction(const Field<Vec3>& r, const Field<Vec3>& held, int k,
                                   int l) const {
  Vec3 move{};
  if (held(k, l).x != 0.0) return move;
  int violated = 0;
  const Vec3 ri = r(k, l);
  for (const Incident& s : incident_) {
    if (!exists(k, l, s) || is_broken(k, l, s)) continue;
    const Vec3 d = r(k + s.dk, l + s.dl) - ri;
    const double length = norm(d);
    const double target =
        std::clamp(length, spec_.min_length * s.rest, spec_.max_length * s.rest);
    if (target == length || length == 0.0) continue;
    const double share = held(k + s.dk, l + s.dl).x != 0.0 ? 1.0 : 0.5;
    move += (share * (length - target) / length) * d;
    ++violated;
  }
  return violated > 1 ? move / static_cast<double>(violated) : move;
}

bool MassSpring::act_on_step(const Field<Vec3>& next, const Field<Vec3>& held,
                             Field<Vec3>& moves, bool first_pass) {
  if (breakable_ && first_pass) break_overlong(next);
  if (!limited_) return false;
  const Block& b = *block_;
  bool moved = false;
#pragma omp parallel for schedule(static) reduction(|| : moved)
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) {
      moves(k, l) = length_correction(next, held, k, l);
      moved = moved || moves(k, l).x != 0.0 || moves(k, l).y != 0.0 || moves(k, l).z != 0.0;
    }
  return moved;
}

std::vector<double> MassSpring::step_state() const {
  return {broken_ids_.begin(), broken_ids_.end()};
}

void MassSpring::restore_step_state(const std::vector<double>& state) {
  const double springs = static_cast<double>(kSlots) * block_->m * block_->n;
  for (const double id : state)
    if (!(id >= 0.0 && id < springs && id == std::floor(id)))
      throw std::invalid_argument(
          "its list of broken springs holds " + std::to_string(id) +
          ", not a spring of this grid");
  const Block& b = *block_;
  for (int l = b.l0 - b.ghost; l < b.l1 + b.ghost; ++l)
    for (int k = b.k0 - b.ghost; k < b.k1 + b.ghost; ++k) broken_(k, l) = 0;
  broken_ids_.assign(state.begin(), state.end());
  for (const std::int64_t id : broken_ids_) mark_broken(id);
}

// F_i = ke (ℓ − ℓ0) d̂ for d = r_j − r_i, none inside the dead zone (docs/model.md, "The
// mass-spring model"). The other end computes −d, so the pair's forces cancel bitwise.
Vec3 MassSpring::elastic_force(const Field<Vec3>& r, int k, int l) const {
  const Vec3 ri = r(k, l);
  Vec3 force{};
  for (const Incident& s : incident_) {
    if (!exists(k, l, s) || is_broken(k, l, s)) continue;
    const Vec3 d = r(k + s.dk, l + s.dl) - ri;
    const double length = norm(d);
    const double stretch = length - s.rest;
    if (std::abs(stretch) < spec_.dead_zone * s.rest || length == 0.0) continue;
    force += (s.family.ke * stretch / length) * d;
  }
  return force;
}

void MassSpring::accelerations(const Field<Vec3>& r, const Vec3& gravity, Field<Vec3>& a) {
  const Block& b = *block_;
  const double inverse_mass = 1.0 / node_mass_.interior;
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) a(k, l) = inverse_mass * elastic_force(r, k, l) + gravity;
}

void MassSpring::free_acceleration(const Field<Vec3>& r, const Vec3& gravity, Field<Vec3>& a,
                                   Field<Vec3>* normals) {
  accelerations(r, gravity, a);
  if (normals == nullptr) return;
  // The fluid's normal: the cross product of the central differences along the grid (one-sided
  // at a border); the fluid term is even in n, so its sign does not matter.
  const Block& b = *block_;
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) {
      const int km = k > 0 ? k - 1 : k, kp = k + 1 < b.m ? k + 1 : k;
      const int lm = l > 0 ? l - 1 : l, lp = l + 1 < b.n ? l + 1 : l;
      const Vec3 s = cross(r(kp, l) - r(km, l), r(k, lp) - r(k, lm));
      const double length = norm(s);
      (*normals)(k, l) = length > 0.0 ? s / length : Vec3{};
    }
}

void MassSpring::internal_acceleration(const Field<Vec3>& r, Field<Vec3>& a) {
  accelerations(r, Vec3{}, a);
}

// a_i = (1/m) Σ kd ((v_j − v_i)·d̂) d̂ over the unbroken springs: −M⁻¹D(r) v.
void MassSpring::velocity_acceleration(const Field<Vec3>& r, const Field<Vec3>& v,
                                       Field<Vec3>& a) const {
  const Block& b = *block_;
  const double inverse_mass = 1.0 / node_mass_.interior;
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) {
      const Vec3 ri = r(k, l), vi = v(k, l);
      Vec3 force{};
      for (const Incident& s : incident_) {
        if (s.family.kd == 0.0 || !exists(k, l, s) || is_broken(k, l, s)) continue;
        const Vec3 d = r(k + s.dk, l + s.dl) - ri;
        const double length2 = dot(d, d);
        if (length2 == 0.0) continue;
        force += (s.family.kd * dot(v(k + s.dk, l + s.dl) - vi, d) / length2) * d;
      }
      a(k, l) = inverse_mass * force;
    }
}

// ½ ke (ℓ − ℓ0)² less the dead zone's ½ ke (ε ℓ0)²: the potential whose force is ke (ℓ − ℓ0)
// outside the zone and none inside.
double MassSpring::spring_energy(const Incident& s, double length) const {
  const double stretch = length - s.rest;
  const double zone = spec_.dead_zone * s.rest;
  if (std::abs(stretch) < zone) return 0.0;
  return 0.5 * s.family.ke * (stretch * stretch - zone * zone);
}

double MassSpring::block_energy(const Field<Vec3>& r) const {
  const Block& b = *block_;
  double energy = 0.0;
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k)
      for (const Incident& s : incident_) {
        if (!s.owned_here || !exists(k, l, s) || is_broken(k, l, s)) continue;
        energy += spring_energy(s, norm(r(k + s.dk, l + s.dl) - r(k, l)));
      }
  return energy;
}

// Half of each spring's energy to each end, over the node's h1 h2 (its weight is 1).
void MassSpring::energy_density(const Field<Vec3>& r, Field<double>& density) const {
  const Block& b = *block_;
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) {
      double energy = 0.0;
      for (const Incident& s : incident_)
        if (exists(k, l, s) && !is_broken(k, l, s))
          energy += spring_energy(s, norm(r(k + s.dk, l + s.dl) - r(k, l)));
      density(k, l) = 0.5 * energy / h1h2_;
    }
}

void MassSpring::broken_springs(Field<double>& bits) const {
  const Block& b = *block_;
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) bits(k, l) = broken_(k, l);
}

}  // namespace cosserat
