#include "cosserat/contact/contact.hpp"

#include <mpi.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

namespace cosserat {

namespace {

// Detection and response passes over the nodes and cells before a node still inside a solid
// is left for the next step (docs/contact.md, "Detection": a bounded number of repeats).
constexpr int kMaxPasses = 4;

// Jacobi sweeps of the cell pass's shares (cell_pass; docs/contact.md, "Cells"). The round
// tablecloth of scenes/contact/tablecloth_round_table.toml over 40 s, frames 0.1 s apart: with
// 1, its total energy rose in 90 of 400 frames, by at most 4.6e-7 J; with 3, in 86, by at
// most 9.3e-7 J; averaged at each node as before, in 133, by at most 4.9e-5 J.
constexpr int kCellSweeps = 1;

constexpr double kHuge = std::numeric_limits<double>::infinity();

// Whether any solid is bounded (not a plane): only those have a cell pass.
bool any_bounded(const std::vector<SolidSpec>& solids) {
  return std::any_of(solids.begin(), solids.end(),
                     [](const SolidSpec& spec) { return spec.shape.kind != ShapeKind::plane; });
}

// What touched_ holds for a node: the response moved it; a free body was among the solids.
constexpr unsigned char kTouched = 1;
constexpr unsigned char kByFreeBody = 2;
// The walk's planes moved it (prepare): alone, its velocity is the one the walk found.
constexpr unsigned char kWalked = 4;

// The spherical-linear interpolation from a to b at s in [0, 1], along the shorter arc.
Quaternion slerp(Quaternion a, const Quaternion& b, double s) {
  double c = a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
  if (c < 0.0) {
    a = {-a.w, -a.x, -a.y, -a.z};
    c = -c;
  }
  double wa = 1.0 - s, wb = s;
  if (c < 1.0 - 1e-12) {
    const double angle = std::acos(c);
    const double sin_angle = std::sin(angle);
    wa = std::sin((1.0 - s) * angle) / sin_angle;
    wb = std::sin(s * angle) / sin_angle;
  }
  return normalized({wa * a.w + wb * b.w, wa * a.x + wb * b.x, wa * a.y + wb * b.y,
                     wa * a.z + wb * b.z});
}

// The rotation vector of unit quaternion q (angle × axis, angle in [0, π]).
Vec3 rotation_vector(Quaternion q) {
  if (q.w < 0.0) q = {-q.w, -q.x, -q.y, -q.z};
  const Vec3 axis{q.x, q.y, q.z};
  const double s = norm(axis);
  if (s == 0.0) return {};
  return (2.0 * std::atan2(s, q.w) / s) * axis;
}

// A kinematic solid's state at time t: closed forms of the time, so that the path is the same
// on every rank and after any restart, however the steps fell.
SolidState kinematic_state(const SolidSpec& spec, double t) {
  const KinematicPath& path = spec.path;
  SolidState s;
  if (!path.keyframes.empty()) {
    const std::vector<Keyframe>& keys = path.keyframes;
    if (t <= keys.front().time) {
      s.pose = {keys.front().position, keys.front().orientation};
      return s;
    }
    if (t >= keys.back().time) {
      s.pose = {keys.back().position, keys.back().orientation};
      return s;
    }
    std::size_t i = 0;
    while (keys[i + 1].time <= t) ++i;
    const Keyframe& a = keys[i];
    const Keyframe& b = keys[i + 1];
    const double span = b.time - a.time;
    const double frac = (t - a.time) / span;
    s.pose = {a.position + frac * (b.position - a.position),
              slerp(a.orientation, b.orientation, frac)};
    s.velocity = (b.position - a.position) / span;
    s.angular_velocity = rotation_vector(b.orientation * conjugate(a.orientation)) / span;
    return s;
  }
  const double moved = std::clamp(t - path.start_time, 0.0, path.end_time - path.start_time);
  s.pose = {spec.pose.position + moved * path.velocity,
            from_rotation_vector(moved * path.angular_velocity) * spec.pose.orientation};
  if (path.start_time <= t && t < path.end_time) {
    s.velocity = path.velocity;
    s.angular_velocity = path.angular_velocity;
  }
  return s;
}

// R diag(I) Rᵀ x and its inverse: a free body's inertia in the world frame.
Vec3 inertia_times(const Quaternion& q, const Vec3& moments, const Vec3& x) {
  Vec3 local = rotate(conjugate(q), x);
  local = {moments.x * local.x, moments.y * local.y, moments.z * local.z};
  return rotate(q, local);
}
Vec3 inertia_solve(const Quaternion& q, const Vec3& moments, const Vec3& x) {
  Vec3 local = rotate(conjugate(q), x);
  local = {local.x / moments.x, local.y / moments.y, local.z / moments.z};
  return rotate(q, local);
}

// docs/contact.md, "Response": the velocity a node leaves with, from its velocity v relative to a
// surface moving at `surface`, with outward normal n: v_n' = −e v_n when approaching, Coulomb
// friction |Δv_t| ≤ μ |Δv_n|, sticking when that suffices.
[[gnu::always_inline]] inline Vec3 respond_velocity(const Vec3& v, const Vec3& surface,
                                                    const Vec3& n, double e, double mu) {
  const Vec3 relative = v - surface;
  const double vn = dot(relative, n);
  if (vn >= 0.0) return v;
  const Vec3 vt = relative - vn * n;
  const double dvn = -(1.0 + e) * vn;
  const double speed_t = norm(vt);
  const double slip = mu * dvn;
  const Vec3 vt_after = speed_t <= slip ? Vec3{} : (1.0 - slip / speed_t) * vt;
  return surface + (-e * vn) * n + vt_after;
}


// The velocity of a solid's surface at world point x.
[[gnu::always_inline]] inline Vec3 surface_velocity(const SolidState& body, const Vec3& x) {
  return body.velocity + cross(body.angular_velocity, x - body.pose.position);
}

// The smallest radius of curvature of a shape's curved faces (infinite for flat ones).
double curved_radius(const Shape& shape) {
  switch (shape.kind) {
    case ShapeKind::sphere:
    case ShapeKind::cylinder:
    case ShapeKind::capsule:
      return shape.radius;
    default:
      return std::numeric_limits<double>::infinity();
  }
}

// The angle a frame turns through from orientation a to b.
double turn_angle(const Quaternion& a, const Quaternion& b) {
  const double c = std::min(1.0, std::abs(a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z));
  return 2.0 * std::acos(c);
}

// How far along unit direction n point p (in the shape's frame) must move to be `offset` clear
// of the shape: bisection on the signed distance, from a bound where the ball holding the shape
// is left behind.
double clearance(const SolidGeometry& g, const Vec3& p, const Vec3& n, double offset) {
  double inside = 0.0, outside = norm(p) + g.bounding_radius() + offset;
  for (int i = 0; i < 60; ++i) {
    const double t = 0.5 * (inside + outside);
    (g.closest(p + t * n).distance >= offset ? outside : inside) = t;
  }
  return outside;
}

// Box helpers of the broad phase: the distance between two boxes (a point is a box), the
// farthest distance from p to a box, the lowest value of n·x over it.
double box_gap(const Vec3& alo, const Vec3& ahi, const Vec3& blo, const Vec3& bhi) {
  const Vec3 d{std::max({alo.x - bhi.x, 0.0, blo.x - ahi.x}),
               std::max({alo.y - bhi.y, 0.0, blo.y - ahi.y}),
               std::max({alo.z - bhi.z, 0.0, blo.z - ahi.z})};
  return norm(d);
}
double farthest_in(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  const Vec3 d{std::max(std::abs(p.x - lo.x), std::abs(p.x - hi.x)),
               std::max(std::abs(p.y - lo.y), std::abs(p.y - hi.y)),
               std::max(std::abs(p.z - lo.z), std::abs(p.z - hi.z))};
  return norm(d);
}
double lowest_along(const Vec3& n, const Vec3& lo, const Vec3& hi) {
  return (n.x > 0.0 ? n.x * lo.x : n.x * hi.x) + (n.y > 0.0 ? n.y * lo.y : n.y * hi.y) +
         (n.z > 0.0 ? n.z * lo.z : n.z * hi.z);
}
void widen(Vec3& lo, Vec3& hi, const Vec3& p) {
  lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
  hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
}
// The box [lo, hi] grown to hold the box [other_lo, other_hi], which may be empty (lows +∞,
// highs −∞): widened by its corners as points, an empty one would make a box of everything.
void enclose(Vec3& lo, Vec3& hi, const Vec3& other_lo, const Vec3& other_hi) {
  lo = {std::min(lo.x, other_lo.x), std::min(lo.y, other_lo.y), std::min(lo.z, other_lo.z)};
  hi = {std::max(hi.x, other_hi.x), std::max(hi.y, other_hi.y), std::max(hi.z, other_hi.z)};
}
constexpr Vec3 kEmptyLow{kHuge, kHuge, kHuge};
constexpr Vec3 kEmptyHigh{-kHuge, -kHuge, -kHuge};

// A node's path from `start` to `end` into a box and the largest squared move.
void widen_path(Vec3& lo, Vec3& hi, double& moved2, const Vec3& start, const Vec3& end) {
  widen(lo, hi, start);
  widen(lo, hi, end);
  const Vec3 d = end - start;
  moved2 = std::max(moved2, dot(d, d));
}

// The broad phase's tests allow for the round-off of the per-node tests they stand in for
// (the frame's rotation), relative to the distances involved.
constexpr double kBroadSlack = 1e-9;

// The box holding a bounded shape in its own frame (the shapes of docs/contact.md,
// "Solids and their motion").
std::pair<Vec3, Vec3> local_bounds(const Shape& shape) {
  const double r = shape.radius;
  switch (shape.kind) {
    case ShapeKind::sphere:
      return {{-r, -r, -r}, {r, r, r}};
    case ShapeKind::box:
      return {-shape.half_extents, shape.half_extents};
    case ShapeKind::cylinder:
      return {{-r, -r, -shape.half_length}, {r, r, shape.half_length}};
    case ShapeKind::capsule:
      return {{-r, -r, -shape.half_length - r}, {r, r, shape.half_length + r}};
    case ShapeKind::mesh: {
      Vec3 lo = kEmptyLow, hi = kEmptyHigh;
      for (const Vec3& v : shape.mesh->vertices) widen(lo, hi, v);
      return {lo, hi};
    }
    case ShapeKind::plane:
      break;
  }
  return {kEmptyHigh, kEmptyLow};
}

// A solid's bit in a tile's mask: the 64th stands for every solid from the 64th on.
std::uint64_t solid_bit(std::size_t i) { return std::uint64_t{1} << std::min<std::size_t>(i, 63); }

}  // namespace

// One node's change of velocity by a free body in one phase of one pass (docs/contact.md,
// "Free bodies"): the impulse J = m (v' − v), its moment r' × J about the origin, the moment
// m (r' − r) × v of the node's move onto the surface, and the velocity v before. `key` orders
// the sums by (solid, node, pass, phase), the same on every decomposition, with a node's
// changes next to each other.
struct Contact::Exchange {
  std::int64_t key;
  Vec3 impulse, moment, move_moment, velocity;
};

// A cell triangle pressed into a solid: its barycentric weights at the deepest point, the move
// δ n of that point and the change of its velocity (docs/contact.md, "Detection", "Cells").
struct Contact::CellPush {
  std::size_t triangle = 0;  // its index among the block's: 4 (cell index) + 0 … 3
  std::array<double, 3> weights{};
  Vec3 slip;  // friction's move of the point (slip_correction)
  Vec3 velocity_change;
  Vec3 normal;   // world
  Vec3 surface;  // the solid's surface velocity at the point
  std::array<double, 3> barycentric{};  // the point's
  double depth = 0.0;                   // δ
  // The Jacobi sweeps of cell_pass: its relaxation, 1 / the most pressed triangles any of its
  // nodes lies in, and the share of its push it takes.
  double relaxation = 1.0;
  double share = 1.0;
};

Contact::Contact(const std::vector<SolidSpec>& solids, const Block& block, Halo& halo,
                 const NodeMass& node_mass, const Vec3& gravity, double spacing)
    : block_(&block),
      halo_(&halo),
      node_mass_(node_mass),
      gravity_(gravity),
      spacing_(spacing),
      velocity_(block),
      touched_(block),
      contact_normal_(block),
      surface_velocity_(block),
      normal_speed_(block),
      distance_(block),
      normal_(block),
      local_(block) {
  if (!solids.empty()) {
    tiles_k_ = (block.owned_k() + kTile - 1) / kTile;
    tiles_l_ = (block.owned_l() + kTile - 1) / kTile;
    const auto tiles = static_cast<std::size_t>(tiles_k_) * static_cast<std::size_t>(tiles_l_);
    boxes_.resize(tiles);
    row_boxes_.resize(static_cast<std::size_t>(tiles_k_) *
                      static_cast<std::size_t>(block.owned_l()));
    row_boxed_.resize(static_cast<std::size_t>(block.owned_l()));
    band_far_.assign(static_cast<std::size_t>(tiles_l_), 0);
    band_travel_.assign(static_cast<std::size_t>(tiles_l_), 0.0);
    far_boxes_.resize(tiles);
    row_move_.assign(static_cast<std::size_t>(block.owned_l()), 0.0);
    near_.resize(tiles);
    spare_.resize(tiles);
    tile_touched_.resize(tiles);
    cells_near_.resize(tiles);
    cells_live_.resize(tiles);
    reach_.resize(tiles);
    live_cells_.assign(static_cast<std::size_t>(block.owned_k() + 3) * (block.owned_l() + 3), 0);
    travel_.resize(tiles);
    clear_.resize(solids.size());
    node_clear_.resize(solids.size());
    for (std::size_t i = 0; i < solids.size(); ++i) {
      const SolidSpec& spec = solids[i];
      if (spec.motion != SolidMotion::fixed || spec.shape.kind == ShapeKind::plane) continue;
      clear_[i].assign(live_cells_.size(), -kHuge);
      if (spec.shape.kind != ShapeKind::mesh)
        node_clear_[i].assign(static_cast<std::size_t>(block.owned_k()) * block.owned_l(),
                              -kHuge);
    }
    if (any_bounded(solids)) node_sums_ = Field<Vec3>(block);
    ready_.resize(tiles);
    exchange_rows_.resize(static_cast<std::size_t>(tiles_l_));
    push_rows_.resize(static_cast<std::size_t>(tiles_l_));
    const auto rows = static_cast<std::size_t>(block.owned_l());
    walk_count_.resize(rows);
    walk_inside_.resize(rows);
    walk_deepest_.resize(rows);
  }
  for (const bool plane : {true, false})
    for (std::size_t i = 0; i < solids.size(); ++i)
      if ((solids[i].shape.kind == ShapeKind::plane) == plane) {
        order_.push_back(i);
        if (plane) {
          ++planes_;
          plane_bits_ |= solid_bit(i);
        }
      }
  walk_boxes_ = planes_ < solids.size();
  walk_after_ = planes_ != 1 || walk_boxes_;
  if (planes_ > 0) {
    const std::size_t owned = static_cast<std::size_t>(block.owned_k()) * block.owned_l();
    walk_met_.assign(owned, 0);
    if (walk_after_) walk_velocity_.resize(owned);
  }
  for (const SolidSpec& spec : solids) {
    Solid s{spec, SolidGeometry(spec.shape), {}, {}, {}, false, false, {}, {}, {}, {}, {}};
    if (spec.motion == SolidMotion::free) {
      s.inertia_per_mass = s.geometry.inertia_per_mass();
      s.state = {spec.pose, spec.body.initial_velocity, spec.body.initial_angular_velocity};
      s.pushing = dot(spec.body.force, spec.body.force) > 0.0;
      any_free_ = true;
    } else if (spec.motion == SolidMotion::kinematic) {
      s.state = kinematic_state(spec, 0.0);
    } else {
      s.state.pose = spec.pose;
    }
    s.proposed = s.state;
    s.proposed_pushing = s.pushing;
    std::tie(s.local_lo, s.local_hi) = local_bounds(spec.shape);
    solids_.push_back(std::move(s));
  }
}

Contact::~Contact() = default;

// A free body's state at time + dt before the cloth's impulses: velocity Verlet under gravity,
// the push and linear drag; the rotation to second order through the angular velocity at the
// half step, from the angular momentum, which nothing changes between contacts.
void Contact::propose_free(Solid& s, double dt) const {
  const FreeBody& body = s.spec.body;
  const double mass = body.mass;
  const auto acceleration = [&](const Vec3& v) {
    Vec3 a = gravity_ - (body.drag / mass) * v;
    if (s.pushing) a += body.force / mass;
    return a;
  };
  const SolidState& now = s.state;
  const Vec3 v_half = now.velocity + (0.5 * dt) * acceleration(now.velocity);
  SolidState next;
  next.pose.position = now.pose.position + dt * v_half;
  next.velocity = v_half + (0.5 * dt) * acceleration(v_half);
  const Vec3 moments = mass * s.inertia_per_mass;
  const Vec3 spin = inertia_times(now.pose.orientation, moments, now.angular_velocity);
  const Quaternion q_half = normalized(
      from_rotation_vector((0.5 * dt) * now.angular_velocity) * now.pose.orientation);
  const Vec3 omega_half = inertia_solve(q_half, moments, spin);
  next.pose.orientation =
      normalized(from_rotation_vector(dt * omega_half) * now.pose.orientation);
  next.angular_velocity = inertia_solve(next.pose.orientation, moments, spin);
  s.proposed = next;
  s.proposed_pushing = s.pushing;
}

// The response (docs/contact.md, "Response") at a point of solid s whose surface moves at
// `surface`, with world normal n, for cloth moving at `velocity` there: the change against the
// solid's surface as if it could not be moved. A free body's share is settled once all its
// contacts are known (apply_impulses).
Vec3 Contact::velocity_change(const Solid& s, const Vec3& surface, const Vec3& normal,
                              const Vec3& velocity) const {
  return respond_velocity(velocity, surface, normal, s.spec.restitution, s.spec.friction) -
         velocity;
}

double Contact::leaving_speed(const Solid& s, const Vec3& n, const Vec3& surface,
                              const Vec3& velocity) {
  const double approach = dot(velocity - surface, n);
  return approach < 0.0 ? -s.spec.restitution * approach : approach;
}

void Contact::remember(const Solid& s, int k, int l, const Vec3& n, const Vec3& surface,
                       const Vec3& velocity) {
  touched_(k, l) |= s.spec.motion == SolidMotion::free ? kTouched | kByFreeBody : kTouched;
  contact_normal_(k, l) = n;
  surface_velocity_(k, l) = surface;
  normal_speed_(k, l) = leaving_speed(s, n, surface, velocity);
}

// docs/contact.md, "Velocities": the positions are what the next step starts from, so a
// velocity that says more than the node moved is energy no position holds (nodes pushed back
// by a box's side face every step kept the push as speed, 142 m/s while standing still). The
// tangential part is what the node moved over the step (friction's change is in the move:
// slip_correction); the normal part relative to the surface is the response's: e times the
// approach, 0 for cloth that does not bounce, a leaving node's own, never the push that put
// it back on the surface. A free body's nodes keep the response's velocity: their impulses
// are what the body took (apply_impulses).
Vec3 Contact::settled_velocity(int k, int l, const Field<Vec3>& current,
                               const Field<Vec3>& next) const {
  if ((touched_(k, l) & ~kWalked) != kTouched) return velocity_(k, l);
  return settled((next(k, l) - current(k, l)) / dt_, contact_normal_(k, l),
                 surface_velocity_(k, l), normal_speed_(k, l));
}

Vec3 Contact::settled(const Vec3& moved, const Vec3& n, const Vec3& surface, double speed) {
  const double normal = dot(moved - surface, n);
  return moved + (speed - normal) * n;
}

// The step moved the node with its velocity before the response: friction's change of the
// tangential velocity moves it too, Δt Δv_t, or a node that sticks would still creep by the
// tangential a Δt² of every step. That holds as it is for the Verlet family, whose move over a
// step is Δt times the velocity it ends with. A scheme that carries velocities moves a node by
// its own rule (velocity-verlet by Δt (v + ½aΔt), ending at v + aΔt): the tangential part of
// the difference, `scheme_offset` (scheme_offset_), comes off too, or a node that stuck on an
// incline crept (1.52 m in 10 s in velocity-verlet) and one sliding slid at the wrong rate
// (tests/unit/test_contact.cpp, the Coulomb tests).
Vec3 Contact::slip_correction(const Vec3& change, const Vec3& normal,
                              const Vec3& scheme_offset) const {
  const Vec3 slip = dt_ * (change - dot(change, normal) * normal);
  if (next_velocities_ == nullptr) return slip;
  return slip - (scheme_offset - dot(scheme_offset, normal) * normal);
}

bool Contact::meet_plane(const Solid& s, Vec3& r, Vec3& v, Vec3& surface,
                         const Vec3& scheme_offset) const {
  const Vec3& n = s.plane_normal;
  const double thickness = s.spec.thickness;
  const double d = plane_height(s, r);
  if (d >= thickness) return false;
  const Vec3 point = r + (thickness - d) * n;
  surface = surface_velocity(s.proposed, point);
  const Vec3 change = velocity_change(s, surface, n, v);
  r = point + slip_correction(change, n, scheme_offset);
  v = v + change;
  return true;
}

// A node's scheme offset, taken off by the first response that corrects its move: that one
// uses it up (take_offset).
Vec3 Contact::scheme_offset_at(int k, int l) const {
  return next_velocities_ ? scheme_offset_(k, l) : Vec3{};
}

Vec3 Contact::take_offset(int k, int l) {
  const Vec3 offset = scheme_offset_at(k, l);
  if (next_velocities_) scheme_offset_(k, l) = {};
  return offset;
}

// Planes against kLanes nodes at once, written as meet_plane() is, operation for operation, as
// lanes of doubles that the compiler vectorises: the node's proposed end r and velocity v in and
// out, and of the last plane met its normal, its surface's velocity and the normal speed the
// node leaves it with (leaving_speed()). A lane a plane does not meet computes the same and
// keeps what it had; what meet_plane() takes only on approach (the division by the tangential
// speed) is guarded so that such a lane raises no floating-point exception. The walk met the
// planes node by node before: 20 ns a node-step with a plane under every node at 1024²
// (benchmarks/results/contact-lanes-*). Sixteen lanes rather than eight: one plane's response
// is a long chain of dependent operations, and eight lanes left the core waiting on it
// (benchmarks/results/contact-starts-*). OneStill: one plane that does not turn, whose normal
// and velocity every lane it meets shares, so the lanes do not carry them (the benchmark's
// plane 7.5–8.5 → 5.0–6.1 ns a node-step, benchmarks/results/contact-one-plane-*).
namespace {
constexpr int kLanes = 16;
// |t|² < (1 − 1e-12) s² with s > 0 gives √|t|², rounded, below s.
constexpr double kSureStick = 1.0 - 1e-12;
// Whether a solid with angular velocity w turns.
bool turns(const Vec3& w) { return w.x != 0.0 || w.y != 0.0 || w.z != 0.0; }
}  // namespace

struct Contact::PlaneLanes {
  double rx[kLanes], ry[kLanes], rz[kLanes];
  double vx[kLanes], vy[kLanes], vz[kLanes];
  double nx[kLanes], ny[kLanes], nz[kLanes];
  double ux[kLanes], uy[kLanes], uz[kLanes];
  double speed[kLanes];
  long met[kLanes];
};

template <bool OneStill>
inline void Contact::meet_planes(PlaneLanes& a) const {
  for (int i = 0; i < kLanes; ++i) {
    if constexpr (!OneStill) a.nx[i] = a.ny[i] = a.nz[i] = a.ux[i] = a.uy[i] = a.uz[i] = 0.0;
    a.speed[i] = 0.0;
    a.met[i] = 0;
  }
  const double dt = dt_;
  for (std::size_t o = 0; o < planes_; ++o) {
    const Solid& s = solids_[order_[o]];
    const Vec3 n = s.plane_normal;
    const Vec3 p = s.proposed.pose.position;
    const Vec3 u0 = s.proposed.velocity;
    const Vec3 w = s.proposed.angular_velocity;
    const double offset = s.spec.thickness;
    const double e = s.spec.restitution;
    const double mu = s.spec.friction;
    const double bounce = -(1.0 + e);
    const double keep = -e;
    // Most nodes of most scenes are clear of the floor: a plane no lane meets costs its heights.
    double d[kLanes];
    long any = 0;
#pragma omp simd reduction(| : any)
    for (int i = 0; i < kLanes; ++i) {
      d[i] = (a.rx[i] - p.x) * n.x + (a.ry[i] - p.y) * n.y + (a.rz[i] - p.z) * n.z;
      any |= d[i] >= offset ? 0 : 1;
    }
    if (!any) continue;
    double qx[kLanes], qy[kLanes], qz[kLanes], ux[kLanes], uy[kLanes], uz[kLanes];
    double tx[kLanes], ty[kLanes], tz[kLanes], vn[kLanes], slip[kLanes], speed2[kLanes];
    // A plane that does not turn has its velocity everywhere: u0 + 0 × c is u0, bit for bit.
    const auto approach = [&]<bool Turning>() {
      long sliding = 0;
#pragma omp simd reduction(| : sliding)
      for (int i = 0; i < kLanes; ++i) {
        const double lift = offset - d[i];
        qx[i] = a.rx[i] + lift * n.x;
        qy[i] = a.ry[i] + lift * n.y;
        qz[i] = a.rz[i] + lift * n.z;
        if constexpr (Turning) {
          const double cx = qx[i] - p.x, cy = qy[i] - p.y, cz = qz[i] - p.z;
          ux[i] = u0.x + (w.y * cz - w.z * cy), uy[i] = u0.y + (w.z * cx - w.x * cz),
          uz[i] = u0.z + (w.x * cy - w.y * cx);
        } else {
          ux[i] = u0.x, uy[i] = u0.y, uz[i] = u0.z;
        }
        // respond_velocity(v, surface, n, e, μ)
        const double relx = a.vx[i] - ux[i], rely = a.vy[i] - uy[i], relz = a.vz[i] - uz[i];
        vn[i] = relx * n.x + rely * n.y + relz * n.z;
        tx[i] = relx - vn[i] * n.x, ty[i] = rely - vn[i] * n.y, tz[i] = relz - vn[i] * n.z;
        slip[i] = mu * (bounce * vn[i]);
        speed2[i] = tx[i] * tx[i] + ty[i] * ty[i] + tz[i] * tz[i];
        // Coulomb's test |v_t| ≤ μ Δv_n without the square root, with a margin that covers
        // its rounding: a lane that passes this sticks for certain.
        const long hit = d[i] >= offset ? 0 : 1;
        const long approaching = vn[i] >= 0.0 ? 0 : 1;
        const long unsure = slip[i] > 0.0 ? 0 : 1;
        const long close = speed2[i] < kSureStick * (slip[i] * slip[i]) ? 0 : 1;
        sliding |= hit & approaching & (unsure | close);
      }
      return sliding;
    };
    const bool turning = !OneStill && turns(w);
    const long sliding =
        turning ? approach.template operator()<true>() : approach.template operator()<false>();
    // Nodes lying still on a plane all stick: their lanes need no square root nor division.
    const auto respond = [&]<bool Slide>() {
#pragma omp simd
      for (int i = 0; i < kLanes; ++i) {
        const bool approaching = !(vn[i] >= 0.0);
        double ax = 0.0, ay = 0.0, az = 0.0;
        if constexpr (Slide) {
          const double speed_t = std::sqrt(speed2[i]);
          const bool stick = speed_t <= slip[i];
          const double f = 1.0 - slip[i] / (stick || !approaching ? 1.0 : speed_t);
          ax = stick ? 0.0 : f * tx[i], ay = stick ? 0.0 : f * ty[i],
          az = stick ? 0.0 : f * tz[i];
        }
        const double kn = keep * vn[i];
        const double outx = approaching ? (ux[i] + kn * n.x) + ax : a.vx[i];
        const double outy = approaching ? (uy[i] + kn * n.y) + ay : a.vy[i];
        const double outz = approaching ? (uz[i] + kn * n.z) + az : a.vz[i];
        const double chx = outx - a.vx[i], chy = outy - a.vy[i], chz = outz - a.vz[i];
        // slip_correction(change, n)
        const double cn = chx * n.x + chy * n.y + chz * n.z;
        const double rx = qx[i] + dt * (chx - cn * n.x), ry = qy[i] + dt * (chy - cn * n.y),
                     rz = qz[i] + dt * (chz - cn * n.z);
        const double vx = a.vx[i] + chx, vy = a.vy[i] + chy, vz = a.vz[i] + chz;
        const double leaving = approaching ? keep * vn[i] : vn[i];
        const bool hit = !(d[i] >= offset);
        a.rx[i] = hit ? rx : a.rx[i];
        a.ry[i] = hit ? ry : a.ry[i];
        a.rz[i] = hit ? rz : a.rz[i];
        a.vx[i] = hit ? vx : a.vx[i];
        a.vy[i] = hit ? vy : a.vy[i];
        a.vz[i] = hit ? vz : a.vz[i];
        if constexpr (!OneStill) {
          a.nx[i] = hit ? n.x : a.nx[i];
          a.ny[i] = hit ? n.y : a.ny[i];
          a.nz[i] = hit ? n.z : a.nz[i];
          a.ux[i] = hit ? ux[i] : a.ux[i];
          a.uy[i] = hit ? uy[i] : a.uy[i];
          a.uz[i] = hit ? uz[i] : a.uz[i];
        }
        a.speed[i] = hit ? leaving : a.speed[i];
        a.met[i] = hit ? 1 : a.met[i];
      }
    };
    if (sliding)
      respond.template operator()<true>();
    else
      respond.template operator()<false>();
  }
}

void Contact::record(std::size_t solid, int pass, int phase, int k, int l, const Vec3& r_before,
                     const Vec3& v_before, const Vec3& r_after,
                     std::vector<Exchange>& out) const {
  if (solids_[solid].spec.motion != SolidMotion::free) return;
  const double mass = node_mass_(k, l);
  const Vec3 j = mass * (velocity_(k, l) - v_before);
  const Block& b = *block_;
  const std::int64_t node = static_cast<std::int64_t>(l) * b.m + k;
  const std::int64_t nodes = static_cast<std::int64_t>(b.m) * b.n;
  const std::int64_t key =
      ((static_cast<std::int64_t>(solid) * nodes + node) * kMaxPasses + pass) * 2 + phase;
  out.push_back({key, j, cross(r_after, j), mass * cross(r_after - r_before, v_before),
                 v_before});
}

// The broad phase (docs/contact.md, "Cost"). Each tile of owned nodes keeps the box holding
// them at both ends of the step and their largest move; from it, the solids each test below
// could pass for one of its nodes. A tile no solid can reach is not visited at all. Every
// test here is implied by the per-node or per-triangle test it spares, so the response is the
// same as if every node were tested, on any tiling, decomposition or thread count.
Contact::TileRange Contact::tile_nodes(int i, int j) const {
  const Block& b = *block_;
  const int k0 = b.k0 + i * kTile, l0 = b.l0 + j * kTile;
  return {k0, std::min(k0 + kTile, b.k1), l0, std::min(l0 + kTile, b.l1)};
}

// The cells (kc, lc) of a tile's nodes, the block's first tile column and row taking the ghost
// cells kc = k0 − 1 and lc = l0 − 1 too, given by the nodes [kc, kc + 1] x [lc, lc + 1] they
// span: a cell's far nodes belong to the next tiles or are ghosts.
Contact::TileRange Contact::tile_cell_nodes(int i, int j) const {
  const Block& b = *block_;
  const TileRange t = tile_nodes(i, j);
  return {i == 0 ? std::max(b.k0 - 1, 0) : t.k0,
          i == tiles_k_ - 1 ? std::min(b.k1, b.m - 1) : t.k1,
          j == 0 ? std::max(b.l0 - 1, 0) : t.l0,
          j == tiles_l_ - 1 ? std::min(b.l1, b.n - 1) : t.l1};
}

// near_[t]: the solids a node of tile t can meet; spare_[t]: how far any of its nodes can
// still be moved before it might meet one of the others (a move δ brings a node's end δ
// closer to a solid and lengthens its path by δ: 2δ of each margin below).
void Contact::classify(std::size_t t) {
  const Box& box = boxes_[t];
  std::uint64_t near = 0;
  double spare = kHuge;
  for (std::size_t i = 0; i < solids_.size(); ++i) {
    const Solid& s = solids_[i];
    const double offset = s.spec.thickness;
    double margin = 0.0;
    if (s.spec.shape.kind == ShapeKind::plane) {
      // node_pass meets a plane only at an end closer to it than the offset.
      const Vec3& n = s.plane_normal;
      const Vec3& p = s.proposed.pose.position;
      const double lowest = lowest_along(n, box.lo, box.hi) - dot(n, p);
      margin = 2.0 * (lowest - offset - kBroadSlack * (offset + farthest_in(p, box.lo, box.hi)));
    } else {
      // node_pass's first test, with the box's nearest end and farthest start; and the same
      // against the box holding the solid: every point of a node's path in the solid's frame
      // lies within that bound of its end, so a path that stays farther than the offset from
      // the box meets nothing.
      const double far = farthest_in(s.state.pose.position, box.lo, box.hi);
      const double path = box.moved + shift_[i] + turn_[i] * far;
      const Vec3& centre = s.proposed.pose.position;
      const double gap = box_gap(centre, centre, box.lo, box.hi) - path;
      const double radius = s.geometry.bounding_radius() + offset;
      const double slack = kBroadSlack * (radius + far + shift_[i]);
      margin = std::max(gap - radius - slack,
                        box_gap(box.lo, box.hi, s.reach_lo, s.reach_hi) - path - offset - slack);
    }
    if (margin > 0.0)
      spare = std::min(spare, margin);
    else
      near |= solid_bit(i);
  }
  near_[t] = near;
  spare_[t] = 0.5 * spare;
}

// A tile's box from its nodes' positions at both ends of the proposed step.
void Contact::make_box(int i, int j, const Field<Vec3>& current, const Field<Vec3>& next) {
  const TileRange r = tile_nodes(i, j);
  Box box{kEmptyLow, kEmptyHigh, 0.0};
  double moved2 = 0.0;
  for (int l = r.l0; l < r.l1; ++l)
    for (int k = r.k0; k < r.k1; ++k) widen_path(box.lo, box.hi, moved2, current(k, l), next(k, l));
  box.moved = std::sqrt(moved2);
  const std::size_t t = tile(i, j);
  boxes_[t] = box;
  classify(t);
}

double Contact::memory_bytes(const Block& block, const std::vector<SolidSpec>& solids) {
  if (solids.empty()) return 0.0;
  const double ghosted = static_cast<double>(block.local_size());
  const double owned = static_cast<double>(block.owned_k()) * block.owned_l();
  const double cells = static_cast<double>(block.owned_k() + 3) * (block.owned_l() + 3);
  // velocity_, contact_normal_, surface_velocity_, normal_, local_; normal_speed_, distance_;
  // touched_. live_cells_; the tiles' boxes, flags and margins, about 150 bytes a tile of 64
  // nodes.
  double bytes = ghosted * (5.0 * sizeof(Vec3) + 2.0 * sizeof(double) + 1.0) +
                 owned * 150.0 / (kTile * kTile) + cells;
  // The schemes that carry velocities: scheme_offset_ (a bound: the Verlet family has none).
  bytes += ghosted * sizeof(Vec3);
  // With a plane, the walk's flag and velocity per owned node, and the Verlet family's next r⁻
  // that it writes into (RowReader).
  if (std::any_of(solids.begin(), solids.end(),
                  [](const SolidSpec& spec) { return spec.shape.kind == ShapeKind::plane; }))
    bytes += owned * (1.0 + sizeof(Vec3)) + ghosted * sizeof(Vec3);
  // With a bounded solid, the cell pass's node_sums_.
  if (any_bounded(solids)) bytes += ghosted * sizeof(Vec3);
  for (const SolidSpec& spec : solids) {
    if (spec.motion != SolidMotion::fixed || spec.shape.kind == ShapeKind::plane) continue;
    bytes += cells * sizeof(double);
    if (spec.shape.kind != ShapeKind::mesh) bytes += owned * sizeof(double);
  }
  return bytes;
}

void Contact::begin_walk(double time, double dt, Field<Vec3>* starts) {
  if (planes_ > 0 && starts == nullptr)
    throw std::logic_error("Contact::begin_walk: a walk that meets planes needs their starts");
  propose(time, dt);
  walked_ = true;
  walk_starts_ = starts;
  dt_ = dt;
  if (walk_boxes_) {
    box_runs_.resize(static_cast<std::size_t>(omp_get_max_threads()));
    for (BoxRun& run : box_runs_) run.open = false;
    std::fill(row_boxed_.begin(), row_boxed_.end(), 0);
  }
}

void Contact::walk_row(int l, const Field<Vec3>& current, Field<Vec3>& next) {
  if (planes_ > 0) {
#if COSSERAT_WIDE_COPIES
    if (wide_walk_)
      walk_planes_wide(l, current, next);
    else
#endif
      walk_planes(l, current, next);
  }
  if (walk_boxes_) walk_boxes(l, current, next);
}

// The planes first (order_), each node's as node_pass meets them, while the row is in cache.
// A node they move leaves with the velocity settled_velocity() gives it, unless something
// after them moves it again: the walk writes the r⁻ of that velocity into `starts`, and r for
// the nodes it does not move, so the row of starts is whole. Which nodes it moved, and their
// velocities after the planes, stay for prepare().
void Contact::walk_planes(int l, const Field<Vec3>& current, Field<Vec3>& next) {
  if (planes_ == 1 && !turns(solids_[order_[0]].proposed.angular_velocity))
    walk_planes_of<true>(l, current, next);
  else
    walk_planes_of<false>(l, current, next);
}

// OneStill: one plane, which does not turn, so every lane it meets has its normal and its
// velocity, and the lanes need not carry them.
template <bool OneStill>
void Contact::walk_planes_of(int l, const Field<Vec3>& current, Field<Vec3>& next) {
  const Block& b = *block_;
  const auto row = static_cast<std::size_t>(l - b.l0);
  const std::size_t first = row * static_cast<std::size_t>(b.owned_k());
  unsigned char* met_row = &walk_met_[first];
  Vec3* after = walk_after_ ? &walk_velocity_[first] : nullptr;
  int count = 0;
  double inside_lanes[kLanes] = {}, deepest_lanes[kLanes] = {};
  // (r⁺ − r)/Δt as Vec3's division finds it: times the reciprocal.
  const double rate = 1.0 / dt_;
  const double dt = dt_;
  PlaneLanes a;
  double sx[kLanes], sy[kLanes], sz[kLanes];
  double wx[kLanes], wy[kLanes], wz[kLanes];
  const Vec3* origins = &current(b.k0, l);
  Vec3* ends = &next(b.k0, l);
  Vec3* starts = &(*walk_starts_)(b.k0, l);
  // A row's last block, when shorter than the lanes, goes through these.
  Vec3 tail_origins[kLanes], tail_ends[kLanes], tail_starts[kLanes];
  const Solid& still = solids_[order_[0]];  // OneStill's plane
  for (int k0 = 0; k0 < b.owned_k(); k0 += kLanes) {
    // A row's last lanes repeat its last node, and are not read.
    const int lanes = std::min(kLanes, b.owned_k() - k0);
    const Vec3* from = origins + k0;
    const Vec3* to = ends + k0;
    if (lanes < kLanes) {
      for (int i = 0; i < kLanes; ++i) {
        const int k = k0 + std::min(i, lanes - 1);
        tail_origins[i] = origins[k];
        tail_ends[i] = ends[k];
      }
      from = tail_origins;
      to = tail_ends;
    }
    // As three packed doubles, so that the loop de-interleaves them with shuffles (node by
    // node, the compiler moved each double alone).
    const double* o = &from->x;
    const double* e = &to->x;
#pragma omp simd
    for (int i = 0; i < kLanes; ++i) {
      sx[i] = o[3 * i], sy[i] = o[3 * i + 1], sz[i] = o[3 * i + 2];
      a.rx[i] = e[3 * i], a.ry[i] = e[3 * i + 1], a.rz[i] = e[3 * i + 2];
    }
#pragma omp simd
    for (int i = 0; i < kLanes; ++i) {
      a.vx[i] = (a.rx[i] - sx[i]) * rate;
      a.vy[i] = (a.ry[i] - sy[i]) * rate;
      a.vz[i] = (a.rz[i] - sz[i]) * rate;
    }
    meet_planes<OneStill>(a);
    long any = 0;
    for (int i = 0; i < kLanes; ++i) any |= a.met[i];
    if (!any) {
      std::copy_n(origins + k0, lanes, starts + k0);
      std::fill_n(met_row + k0, lanes, 0);
      continue;
    }
    // settled() of the velocity the node leaves with, operation for operation, as
    // settled_velocity() finds it on a prepared tile; then VerletFamily::set_velocities' r⁻
    // of it, the same way.
#pragma omp simd
    for (int i = 0; i < kLanes; ++i) {
      const double mx = (a.rx[i] - sx[i]) * rate, my = (a.ry[i] - sy[i]) * rate,
                   mz = (a.rz[i] - sz[i]) * rate;
      const double nx = OneStill ? still.plane_normal.x : a.nx[i];
      const double ny = OneStill ? still.plane_normal.y : a.ny[i];
      const double nz = OneStill ? still.plane_normal.z : a.nz[i];
      const double ux = OneStill ? still.proposed.velocity.x : a.ux[i];
      const double uy = OneStill ? still.proposed.velocity.y : a.uy[i];
      const double uz = OneStill ? still.proposed.velocity.z : a.uz[i];
      const double normal = (mx - ux) * nx + (my - uy) * ny + (mz - uz) * nz;
      const double lift = a.speed[i] - normal;
      const bool met = a.met[i] != 0;
      wx[i] = met ? a.rx[i] - dt * (mx + lift * nx) : sx[i];
      wy[i] = met ? a.ry[i] - dt * (my + lift * ny) : sy[i];
      wz[i] = met ? a.rz[i] - dt * (mz + lift * nz) : sz[i];
    }
    // any_inside()'s test of the planes, for the nodes they moved: the others are clear.
    for (std::size_t o = 0; o < planes_; ++o) {
      const Solid& s = solids_[order_[o]];
      const Vec3 n = s.plane_normal;
      const Vec3 p = s.proposed.pose.position;
      const double level = inside_level(s.spec.thickness);
#pragma omp simd
      for (int i = 0; i < kLanes; ++i) {
        const double d =
            (a.rx[i] - p.x) * n.x + (a.ry[i] - p.y) * n.y + (a.rz[i] - p.z) * n.z;
        const bool met = a.met[i] != 0;
        deepest_lanes[i] = met & (deepest_lanes[i] < -d) ? -d : deepest_lanes[i];
        inside_lanes[i] = met & (d < level) ? 1.0 : inside_lanes[i];
      }
    }
    // A lane the planes did not meet keeps its end as it was.
    Vec3* end_out = lanes < kLanes ? tail_ends : ends + k0;
    Vec3* start_out = lanes < kLanes ? tail_starts : starts + k0;
    double* e_out = &end_out->x;
    double* w_out = &start_out->x;
#pragma omp simd
    for (int i = 0; i < kLanes; ++i) {
      e_out[3 * i] = a.rx[i], e_out[3 * i + 1] = a.ry[i], e_out[3 * i + 2] = a.rz[i];
      w_out[3 * i] = wx[i], w_out[3 * i + 1] = wy[i], w_out[3 * i + 2] = wz[i];
    }
    if (lanes < kLanes) {
      std::copy_n(tail_ends, lanes, ends + k0);
      std::copy_n(tail_starts, lanes, starts + k0);
    }
    for (int i = 0; i < lanes; ++i) {
      met_row[k0 + i] = static_cast<unsigned char>(a.met[i]);
      count += static_cast<int>(a.met[i]);
    }
    if (after != nullptr)
      for (int i = 0; i < lanes; ++i) after[k0 + i] = {a.vx[i], a.vy[i], a.vz[i]};
  }
  double inside = 0.0, deepest = 0.0;
  for (int i = 0; i < kLanes; ++i) {
    inside = std::max(inside, inside_lanes[i]);
    deepest = std::max(deepest, deepest_lanes[i]);
  }
  walk_count_[row] = count;
  walk_inside_[row] = inside > 0.0 ? 1 : 0;
  walk_deepest_[row] = deepest;
}

#if COSSERAT_WIDE_COPIES
// flatten inlines walk_planes and all it calls, so all of it is compiled for AVX2.
[[gnu::target("avx2"), gnu::flatten]] void Contact::walk_planes_wide(int l,
                                                                    const Field<Vec3>& current,
                                                                    Field<Vec3>& next) {
  walk_planes(l, current, next);
}
#endif

// The tiles' boxes from the walk's rows, as the planes left them: each thread's run of rows of
// a tile band is kept node slot by node slot, and folded onto x, y and z into row_boxes_ once,
// on the run's last row (a tile band's last, or the thread's last of this step, closed before
// the response). Vec3 is three packed doubles, so a full tile's nodes are 24 interleaved
// doubles, whose elementwise extremes and squared moves vectorise; the fold is scalar (folded
// on every row it cost 1.9 ns a node at 1024², node by node 2.5 ns). The largest move, summed
// over the axes of each slot's largest moves along them, bounds the one make_box finds.
void Contact::walk_boxes(int l, const Field<Vec3>& current, const Field<Vec3>& next) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double));
  constexpr int kValues = 3 * kTile;
  const Block& b = *block_;
  const auto row = static_cast<std::size_t>(l - b.l0);
  if (band_far_[row / kTile]) {
    const double* a = &current(b.k0, l).x;
    const double* e = &next(b.k0, l).x;
    const int count = 3 * b.owned_k();
    // Independent lanes, or each maximum waits for the one before it.
    constexpr int kMaxLanes = 32;
    double lanes[kMaxLanes] = {};
    int v = 0;
    for (; v + kMaxLanes <= count; v += kMaxLanes)
#pragma omp simd
      for (int i = 0; i < kMaxLanes; ++i) {
        const double d = e[v + i] - a[v + i], d2 = d * d;
        lanes[i] = d2 > lanes[i] ? d2 : lanes[i];
      }
    for (; v < count; ++v) {
      const double d = e[v] - a[v], d2 = d * d;
      lanes[0] = d2 > lanes[0] ? d2 : lanes[0];
    }
    double largest = 0.0;
    for (const double lane : lanes) largest = lane > largest ? lane : largest;
    row_move_[row] = largest;
    return;
  }
  BoxRun& run = box_runs_[static_cast<std::size_t>(omp_get_thread_num())];
  const auto values = static_cast<std::size_t>(kValues) * static_cast<std::size_t>(tiles_k_);
  if (run.low.size() != values) {
    run.low.resize(values);
    run.high.resize(values);
    run.square.resize(values);
  }
  const bool band_start = (l - b.l0) % kTile == 0;
  if (run.open && (run.last != l - 1 || band_start)) close_box_run(run);
  if (!run.open) {
    std::fill(run.low.begin(), run.low.end(), kEmptyLow.x);
    std::fill(run.high.begin(), run.high.end(), kEmptyHigh.x);
    std::fill(run.square.begin(), run.square.end(), 0.0);
    run.open = true;
  }
  run.last = l;
  // Slot v of tile i is value 24 i + v of the run's arrays and of the row, so the row is one
  // loop; a short last tile's slots past the row's end stay empty. Selects of values:
  // std::min and std::max return a reference to one of their arguments, which GCC vectorised
  // as gathers from memory. Tile by tile, the loop's remainder tests cost a third of it.
  const double* a = &current(b.k0, l).x;
  const double* e = &next(b.k0, l).x;
  double* low = run.low.data();
  double* high = run.high.data();
  double* square = run.square.data();
  const int count = 3 * b.owned_k();
#pragma omp simd
  for (int v = 0; v < count; ++v) {
    const double from = a[v], to = e[v], d = to - from, d2 = d * d;
    const double lo = low[v], hi = high[v], sq = square[v];
    const double smaller = to < from ? to : from, larger = to < from ? from : to;
    low[v] = smaller < lo ? smaller : lo;
    high[v] = larger > hi ? larger : hi;
    square[v] = d2 > sq ? d2 : sq;
  }
  if ((l - b.l0) % kTile == kTile - 1 || l == b.l1 - 1) close_box_run(run);
}

void Contact::close_box_run(BoxRun& run) {
  constexpr int kValues = 3 * kTile;
  const Block& b = *block_;
  Box* boxes =
      &row_boxes_[static_cast<std::size_t>(run.last - b.l0) * static_cast<std::size_t>(tiles_k_)];
  for (int i = 0; i < tiles_k_; ++i) {
    const double* low = run.low.data() + static_cast<std::ptrdiff_t>(kValues) * i;
    const double* high = run.high.data() + static_cast<std::ptrdiff_t>(kValues) * i;
    const double* square = run.square.data() + static_cast<std::ptrdiff_t>(kValues) * i;
    // Each slot is a box of its own, empty in a short tile's last slots.
    Box box{kEmptyLow, kEmptyHigh, 0.0};
    for (int v = 0; v < kValues; v += 3) {
      enclose(box.lo, box.hi, {low[v], low[v + 1], low[v + 2]},
              {high[v], high[v + 1], high[v + 2]});
      box.moved = std::max(box.moved, square[v] + square[v + 1] + square[v + 2]);
    }
    boxes[i] = box;
  }
  row_boxed_[static_cast<std::size_t>(run.last - b.l0)] = 1;
  run.open = false;
}

void Contact::merge_rows(int i, int j) {
  const Block& b = *block_;
  const TileRange r = tile_nodes(i, j);
  Box box{kEmptyLow, kEmptyHigh, 0.0};
  double moved2 = 0.0;
  for (int l = r.l0; l < r.l1; ++l) {
    if (!row_boxed_[static_cast<std::size_t>(l - b.l0)]) continue;
    const Box& row = row_boxes_[static_cast<std::size_t>(l - b.l0) *
                                    static_cast<std::size_t>(tiles_k_) +
                                static_cast<std::size_t>(i)];
    enclose(box.lo, box.hi, row.lo, row.hi);
    moved2 = std::max(moved2, row.moved);
  }
  box.moved = std::sqrt(moved2);
  const std::size_t t = tile(i, j);
  boxes_[t] = box;
  classify(t);
}

// A node moved at most √(3 m²) in a step whose largest squared move along an axis is m² (its
// rows' row_move_), so the box kept when the band was found far, grown by the sum of those
// bounds since (band_travel_), holds the band's nodes at both ends of this step: classify()
// answers for it as for the tight box, if more cautiously.
void Contact::far_box(int i, int j, double moved) {
  const std::size_t t = tile(i, j);
  const Box& kept = far_boxes_[t];
  const double grown = band_travel_[static_cast<std::size_t>(j)] + moved;
  const Vec3 grow{grown, grown, grown};
  boxes_[t] = {kept.lo - grow, kept.hi + grow, moved};
  classify(t);
}

double Contact::far_band_move(int j) const {
  const TileRange r = tile_nodes(0, j);
  double largest = 0.0;
  for (int l = r.l0; l < r.l1; ++l)
    largest = std::max(largest, row_move_[static_cast<std::size_t>(l - block_->l0)]);
  return std::sqrt(3.0 * largest);
}

// A band stays far while every tile of it is found far from its grown boxes; one found far
// from the walk's own boxes keeps them, with no travel yet. The next walk reads band_far_.
void Contact::mark_far_bands() {
  for (int j = 0; j < tiles_l_; ++j) {
    const auto band = static_cast<std::size_t>(j);
    bool far = true;
    for (int i = 0; i < tiles_k_ && far; ++i) {
      const std::size_t t = tile(i, j);
      far = near_[t] == 0 && !tile_touched_[t];
    }
    if (!far) {
      band_far_[band] = 0;
      continue;
    }
    if (band_far_[band]) {
      band_travel_[band] += boxes_[tile(0, j)].moved;
      continue;
    }
    band_far_[band] = 1;
    band_travel_[band] = 0.0;
    for (int i = 0; i < tiles_k_; ++i) far_boxes_[tile(i, j)] = boxes_[tile(i, j)];
  }
}

// The response moved node (k, l) of tile t: its box grows to hold where it is now, so that it
// still holds the node's every position over the step.
void Contact::grow_box(std::size_t t, int k, int l, const Field<Vec3>& current,
                       const Field<Vec3>& next) {
  Box& box = boxes_[t];
  widen(box.lo, box.hi, next(k, l));
  box.moved = std::max(box.moved, norm(next(k, l) - current(k, l)));
  tile_touched_[t] = 1;
}

// A node of tile t tested now, at most boxes_[t].moved from where the step began, began it at
// most travel_[t] − travel_then from where it began a step that ended with travel_then, and
// a bound D of its distance found then, less that step's move to then, bounds it from there.
// So D − until + since bounds it now, with since and until these, for any solid that stays
// put (node_clear_). travel_ sums the largest move of the tile and the tiles after it, which
// hold the nodes of its cells, so a cell's nodes are bound the same way with that move for
// boxes_[t].moved (reach_, clear_).
Contact::Travel Contact::travelled_tile(std::size_t t) const {
  return {travel_[t] - boxes_[t].moved, travel_[t] + boxes_[t].moved};
}

double Contact::cell_reach_move(int i, int j) const {
  double moved = 0.0;
  for (int dj = 0; dj < 2 && j + dj < tiles_l_; ++dj)
    for (int di = 0; di < 2 && i + di < tiles_k_; ++di)
      moved = std::max(moved, boxes_[tile(i + di, j + dj)].moved);
  return moved;
}

// A tile's velocities before the response moves any of its nodes. After a walk, the nodes it
// moved onto planes take the velocities they left the planes with, marked kWalked: until a
// later solid moves one (remember()), it leaves with the velocity the walk found, as on the
// tiles never prepared.
void Contact::prepare(int i, int j, const Field<Vec3>& current, Field<Vec3>& next) {
  const std::size_t t = tile(i, j);
  if (ready_[t]) return;
  const TileRange r = tile_nodes(i, j);
  for (int l = r.l0; l < r.l1; ++l)
    for (int k = r.k0; k < r.k1; ++k) {
      velocity_(k, l) = next_velocities_ ? (*next_velocities_)(k, l)
                                         : (next(k, l) - current(k, l)) / dt_;
      touched_(k, l) = 0;
      if (next_velocities_)
        scheme_offset_(k, l) = (next(k, l) - current(k, l)) - dt_ * (*next_velocities_)(k, l);
    }
  if (walked_ && planes_ > 0)
    for (int l = r.l0; l < r.l1; ++l)
      for (int k = r.k0; k < r.k1; ++k) {
        const std::size_t at = walk_index(k, l);
        if (!walk_met_[at]) continue;
        velocity_(k, l) = walk_after_ ? walk_velocity_[at]
                                      : (next(k, l) - (*walk_starts_)(k, l)) / dt_;
        touched_(k, l) = kWalked;
      }
  ready_[t] = 1;
}

// docs/contact.md, "Detection", nodes: the segment from the node at the start of the step to its
// proposed end, each end in the solid's frame at its own time, against the solid inflated by
// `thickness`. An end inside goes to the nearest point of the inflated surface; an end beyond a
// thin solid the segment passed through goes back onto the tangent plane where the segment
// entered.
// The planes and then the other solids, each in scene order (order_), each seeing the node
// where the ones before it put it. After a walk, the first pass's planes are done.
void Contact::node_pass(int pass, const Field<Vec3>& current, Field<Vec3>& next,
                        std::vector<Exchange>& out) {
  const std::size_t first = walked_ && pass == 0 ? planes_ : 0;
  const Block& b = *block_;
#pragma omp parallel for schedule(static)
  for (int j = 0; j < tiles_l_; ++j) {
    std::vector<Exchange>& row = exchange_rows_[static_cast<std::size_t>(j)];
    row.clear();
    for (int ti = 0; ti < tiles_k_; ++ti) {
      const std::size_t here = tile(ti, j);
      const std::uint64_t near = near_[here] & (first > 0 ? ~plane_bits_ : ~std::uint64_t{0});
      if (near == 0) continue;
      prepare(ti, j, current, next);
      const TileRange range = tile_nodes(ti, j);
      const double spare = spare_[here];
      bool grew = false;
      for (int l = range.l0; l < range.l1; ++l)
        for (int k = range.k0; k < range.k1; ++k) {
          // The tile's box says which solids its nodes can meet; a node one of them moved
          // farther than the tile's spare can meet any of the later ones.
          const Vec3 proposed = next(k, l);
          bool moved = false;
          for (std::size_t o = first; o < order_.size(); ++o) {
            const std::size_t i = order_[o];
            if (!(near & solid_bit(i)) && !(moved && !(norm(next(k, l) - proposed) < spare)))
              continue;
            const Solid& s = solids_[i];
            const SolidGeometry& g = s.geometry;
            const double offset = s.spec.thickness;
            if (s.spec.shape.kind == ShapeKind::plane) {
              // A plane, in the world frame: only an end closer than the offset meets it.
              Vec3& r = next(k, l);
              const Vec3 v_before = velocity_(k, l);
              Vec3 v = v_before, surface;
              if (!meet_plane(s, r, v, surface, scheme_offset_at(k, l))) continue;
              take_offset(k, l);
              velocity_(k, l) = v;
              remember(s, k, l, s.plane_normal, surface, v_before);
              moved = grew = true;
              grow_box(here, k, l, current, next);
              continue;
            }
            // A node found clear of a fixed solid (node_clear_) stays so while it moves less
            // than its margin (travelled_tile): a path no longer than its tile's move, ending
            // that much farther than the offset, meets nothing (the test on both ends outside,
            // below).
            const bool remembered = pass == 0 && !node_clear_[i].empty();
            const std::size_t at = static_cast<std::size_t>(k - b.k0) +
                                   static_cast<std::size_t>(l - b.l0) * b.owned_k();
            if (remembered) {
              const double move = boxes_[here].moved;
              if (node_clear_[i][at] - travelled_tile(here).until - move >
                  offset + SolidGeometry::kContactTolerance * std::max(move, offset) +
                      kBroadSlack * (g.bounding_radius() + offset))
                continue;
            }
            const Vec3 world_end = next(k, l);
            const Vec3 world_start = current(k, l);
            // A segment that stays outside the ball holding the solid cannot touch it: first
            // in world coordinates, then in the solid's frame. The path in the frame is at
            // most the node's own, plus the frame's shift, plus its turn times the node's
            // distance from the frame's origin (a chord is shorter than its arc).
            const double path_bound = norm(world_end - world_start) + shift_[i] +
                                      turn_[i] * norm(world_start - s.state.pose.position);
            if (norm(world_end - s.proposed.pose.position) - path_bound >
                g.bounding_radius() + offset)
              continue;
            const Vec3 end = s.proposed.pose.to_local(world_end);
            const Vec3 start = s.state.pose.to_local(world_start);
            const Vec3 path = end - start;
            if (norm(end) - norm(path) > g.bounding_radius() + offset) continue;
            const Closest at_end = g.closest(end);
            if (remembered) node_clear_[i][at] = at_end.distance + travelled_tile(here).since;
            Vec3 target, normal;
            if (at_end.distance < offset) {
              normal = at_end.normal;
              target = end + (offset - at_end.distance) * normal;
            } else {
              // Both ends outside: only a segment crossing the solid can touch it. The distance
              // is 1-Lipschitz, so a path shorter than the end's clearance stays out, with
              // first_contact's tolerance to spare (a mesh's search can end on its iteration
              // limit instead, so it is always asked).
              const double length = norm(path);
              if (s.spec.shape.kind != ShapeKind::mesh &&
                  at_end.distance - length >
                      offset + SolidGeometry::kContactTolerance * std::max(length, offset))
                continue;
              if (g.closest(start).distance < offset) continue;  // leaving, not entering
              const std::optional<double> t = g.first_contact(start, end, offset);
              if (!t) continue;
              const Vec3 entry = start + *t * path;
              normal = g.closest(entry).normal;
              // A node leaving the offset surface it rested on meets it at t = 0 when
              // round-off puts its start a hair outside: it is not entering. Put back on the
              // tangent plane, it stayed glued to a box's side face while its velocity grew
              // without bound.
              if (dot(path, normal) >= 0.0) continue;
              target = end - dot(end - entry, normal) * normal;
            }
            const Vec3 point = s.proposed.pose.to_world(target);
            const Vec3 n = s.proposed.pose.direction_to_world(normal);
            Vec3& r = next(k, l);
            const Vec3 r_before = r;
            const Vec3 v_before = velocity_(k, l);
            const Vec3 surface = surface_velocity(s.proposed, point);
            const Vec3 change = velocity_change(s, surface, n, v_before);
            r = point + slip_correction(change, n, take_offset(k, l));
            velocity_(k, l) = v_before + change;
            remember(s, k, l, n, surface, v_before);
            record(i, pass, 0, k, l, r_before, v_before, r, row);
            moved = grew = true;
            grow_box(here, k, l, current, next);
          }
        }
      // Grown, the box may reach more solids.
      if (grew) classify(here);
    }
  }
  for (const auto& row : exchange_rows_) out.insert(out.end(), row.begin(), row.end());
}

// The four triangles of cell (kc, lc), the two of each diagonal, so that the cells have every
// mirror of the grid, k → m−1−k, l → n−1−l and (k, l) → (l, k), as the energy does
// (docs/contact.md, "Symmetry"); one diagonal for every cell kept only the last, and a
// diagonal that points to the grid's centre in each quadrant made nodes on a box's edge jitter
// where the diagonals turn (tests/regression/test_contact_rest.cpp, measured).
namespace {
using TriangleCorners = std::array<std::array<int, 2>, 3>;
constexpr int kCellTriangles = 4;
constexpr TriangleCorners triangle_corners(int kc, int lc, int tri) {
  switch (tri) {
    case 0: return {{{kc, lc}, {kc + 1, lc}, {kc + 1, lc + 1}}};
    case 1: return {{{kc, lc}, {kc, lc + 1}, {kc + 1, lc + 1}}};
    case 2: return {{{kc + 1, lc}, {kc, lc}, {kc, lc + 1}}};
    default: return {{{kc + 1, lc}, {kc + 1, lc + 1}, {kc, lc + 1}}};
  }
}

// The twelve triangles around a node, (cell offset, triangle, the node's corner in it), in the
// order a node sums their pushes: cells (dk, dl) with dl, then dk, from −1 to 0, triangles in
// order. Derived from triangle_corners once, at compile time.
struct Around {
  int dk, dl, tri, corner;
};
constexpr std::array<Around, 12> triangles_around() {
  std::array<Around, 12> around{};
  std::size_t i = 0;
  for (int dl = -1; dl <= 0; ++dl)
    for (int dk = -1; dk <= 0; ++dk)
      for (int tri = 0; tri < kCellTriangles; ++tri) {
        const TriangleCorners corners = triangle_corners(dk, dl, tri);
        for (int corner = 0; corner < 3; ++corner)
          if (corners[corner][0] == 0 && corners[corner][1] == 0)
            around[i++] = {dk, dl, tri, corner};
      }
  // Reached at compile time only if the triangles did not cover each corner three times.
  if (i != around.size()) throw "a node must lie in three triangles of each of its cells";
  return around;
}
constexpr std::array<Around, 12> kAround = triangles_around();

// The six edges of a cell, by their corners as offsets from (kc, lc): the four sides and the
// two diagonals; and each triangle's three edges among them, derived from triangle_corners.
constexpr std::array<std::array<std::array<int, 2>, 2>, 6> kCellEdges{{
    {{{0, 0}, {1, 0}}}, {{{1, 0}, {1, 1}}}, {{{0, 0}, {1, 1}}},
    {{{0, 0}, {0, 1}}}, {{{0, 1}, {1, 1}}}, {{{1, 0}, {0, 1}}}}};
constexpr std::array<std::array<int, 3>, kCellTriangles> triangle_edges() {
  std::array<std::array<int, 3>, kCellTriangles> edges{};
  for (int tri = 0; tri < kCellTriangles; ++tri) {
    const TriangleCorners c = triangle_corners(0, 0, tri);
    for (int v = 0; v < 3; ++v) {
      const auto& a = c[static_cast<std::size_t>(v)];
      const auto& b = c[static_cast<std::size_t>((v + 1) % 3)];
      int found = -1;
      for (int e = 0; e < 6; ++e) {
        const auto& edge = kCellEdges[static_cast<std::size_t>(e)];
        if ((edge[0] == a && edge[1] == b) || (edge[0] == b && edge[1] == a)) found = e;
      }
      // Reached at compile time only if a triangle had an edge that is not the cell's.
      if (found < 0) throw "a triangle's edge must be one of its cell's six";
      edges[static_cast<std::size_t>(tri)][static_cast<std::size_t>(v)] = found;
    }
  }
  return edges;
}
constexpr std::array<std::array<int, 3>, kCellTriangles> kTriangleEdges = triangle_edges();
}  // namespace

// Between nodes (docs/contact.md, "Cells"): each triangle of a cell (triangle_corners) at its
// point deepest in the solid, moved out through its three nodes with weights w_i = b_i / Σ b_j²,
// so the point itself moves by δ n and its velocity by the response's change. Triangles are
// found on the cells touching owned nodes, ghosts included, so each node sums the pushes of the
// triangles of its four cells in one fixed order, whatever the decomposition.
void Contact::cell_pass(int pass, std::size_t solid, const Field<Vec3>& current,
                        Field<Vec3>& next, std::vector<Exchange>& out) {
  const Block& b = *block_;
  const Solid& s = solids_[solid];
  const SolidGeometry& g = s.geometry;
  // Nodes rest on the offset surface; a triangle is pressed in only when its deepest point
  // reaches half way to the solid, or, nearest a curved face of radius R at least its longest
  // edge L, deeper than the sag L²/8R of a chord whose ends rest on that face; it goes back
  // out to there (docs/contact.md, "Cells"). Tested against the offset surface itself, every
  // triangle resting on a curved solid was pushed out by its sag every step, which lifted its
  // nodes off: they jittered, and without a normal force friction let them slide off a sphere.
  const double thickness = s.spec.thickness;
  const double curvature_radius = curved_radius(s.spec.shape);
  const double flat_offset = 0.5 * thickness;
  // The sag, exactly: a triangle whose corners rest on the offset sphere of radius
  // ρ = R + thickness lies in a plane that cuts it in a circle through them, and its deepest
  // point is where the triangle comes nearest that circle's centre: ρ − √(ρ² − r²), r the
  // radius of the smallest circle around the triangle (half the longest edge when the
  // triangle is right or obtuse, its circumradius when acute). The approximation L²/8ρ
  // fell short by L⁴/128ρ³ and the circumradius of a sheared, acute triangle was not in it:
  // a triangle resting on a sphere was pressed by that much (1.6 µm on the 15 × 15 drape of
  // tests/regression/test_contact_rest.cpp) and pushed its nodes off the surface every step,
  // where friction could not hold them, and the drape gained energy while it crept.
  const double offset_radius = curvature_radius + thickness;
  const auto curved_offset = [&](const std::array<double, 3>& sides) {
    std::array<double, 3> e = sides;
    std::sort(e.begin(), e.end());
    const auto [a, b2, c] = e;
    double r = 0.5 * c;
    if (a * a + b2 * b2 > c * c) {
      // Heron's product in the order that keeps it accurate for a thin triangle (Kahan).
      const double product = (c + (b2 + a)) * (a - (c - b2)) * (a + (c - b2)) * (c + (b2 - a));
      if (product > 0.0) r = std::max(r, a * b2 * c / std::sqrt(product));
    }
    if (r >= offset_radius) return flat_offset;
    const double sag =
        r * r / (offset_radius + std::sqrt((offset_radius - r) * (offset_radius + r)));
    return std::min(flat_offset, thickness - sag);
  };
  const double radius = g.bounding_radius();
  const bool convex = s.spec.shape.kind != ShapeKind::mesh;
  const double bound_slack = kBroadSlack * (radius + thickness);
  const bool remembers = pass == 0 && !clear_[solid].empty();
  std::vector<double>& clear = clear_[solid];
  halo_->exchange(next);
  halo_->exchange(velocity_);
  if (next_velocities_) halo_->exchange(scheme_offset_);
  // The broad phase: a tile's cells are visited only when the box of their nodes (the tile's
  // box and its next neighbours', ghosts added) comes closer than half the thickness to the
  // ball and to the box holding the solid. Every point of those cells lies in that box, and a
  // triangle is pressed in only when its deepest point is closer than that (below): a tile
  // farther away has no triangle to press in, whatever the per-triangle tests would find.
  const Vec3& centre = s.proposed.pose.position;
#pragma omp parallel for schedule(static)
  for (int j = 0; j < tiles_l_; ++j)
    for (int i = 0; i < tiles_k_; ++i) {
      const TileRange c = tile_cell_nodes(i, j);
      Vec3 lo = kEmptyLow, hi = kEmptyHigh;
      for (int dj = 0; dj < 2 && j + dj < tiles_l_; ++dj)
        for (int di = 0; di < 2 && i + di < tiles_k_; ++di) {
          const Box& box = boxes_[tile(i + di, j + dj)];
          enclose(lo, hi, box.lo, box.hi);
        }
      const auto ghost = [&](int k, int l) {
        if (!b.owns(k, l)) widen(lo, hi, next(k, l));
      };
      if (c.k0 < b.k0 || c.k1 >= b.k1)
        for (int l = c.l0; l <= c.l1; ++l) {
          ghost(c.k0, l);
          ghost(c.k1, l);
        }
      if (c.l0 < b.l0 || c.l1 >= b.l1)
        for (int k = c.k0; k <= c.k1; ++k) {
          ghost(k, c.l0);
          ghost(k, c.l1);
        }
      const double slack = kBroadSlack * (radius + farthest_in(centre, lo, hi));
      cells_near_[tile(i, j)] =
          c.k1 > c.k0 && c.l1 > c.l0 &&
          box_gap(centre, centre, lo, hi) - radius < flat_offset + slack &&
          box_gap(lo, hi, s.reach_lo, s.reach_hi) < flat_offset + slack;
      // The nodes of a tile's own cells are in it and the tiles after it (travelled_tile).
      if (remembers) {
        const std::size_t t = tile(i, j);
        const double moved = cell_reach_move(i, j);
        reach_[t] = {travel_[t] - moved, travel_[t] + moved};
      }
    }
  // A cell of owned nodes found clear by a distance D (any lower bound of its triangles'
  // signed distances: the tests below) stays clear while its nodes have moved less than
  // D − flat_offset since, since the distance is 1-Lipschitz and each point of a triangle
  // moves at most as far as its corners; its nodes' tiles bound that move (reach_).
  const auto owned_cell = [&](int kc, int lc) {
    return kc >= b.k0 && lc >= b.l0 && kc + 1 < b.k1 && lc + 1 < b.l1;
  };
  // Cells from kc = k0 − 2 on (a ghost node's cells, and one beyond), in rows of `width`:
  // clear_, live_cells_ and slot_ (per triangle) by the same index.
  const int width = b.owned_k() + 3;
  const auto cell_index = [&](int kc, int lc) {
    return static_cast<std::size_t>(kc - b.k0 + 2 + (lc - b.l0 + 2) * width);
  };
  const auto known_clear = [&](int kc, int lc, std::size_t t) {
    return remembers && owned_cell(kc, lc) &&
           clear[cell_index(kc, lc)] - reach_[t].until >= flat_offset + bound_slack;
  };
  // The cells to visit: those of the tiles near the solid not known to be clear, flagged in
  // live_cells_, whose cells of a tile not live are all 0, and those of no tile always.
#pragma omp parallel for schedule(static)
  for (int j = 0; j < tiles_l_; ++j)
    for (int i = 0; i < tiles_k_; ++i) {
      const std::size_t t = tile(i, j);
      if (!cells_near_[t] && !cells_live_[t]) continue;
      bool live = false;
      const TileRange cells = tile_cell_nodes(i, j);
      for (int lc = cells.l0; lc < cells.l1; ++lc)
        for (int kc = cells.k0; kc < cells.k1; ++kc) {
          const bool needed = cells_near_[t] && !known_clear(kc, lc, t);
          live_cells_[cell_index(kc, lc)] = needed ? 1 : 0;
          live = live || needed;
        }
      cells_live_[t] = live ? 1 : 0;
    }
  // Whether a tile's nodes belong to a visited cell: its own cells, or those of the tiles
  // before it; and a node's.
  const auto near_node_tile = [&](int i, int j) {
    for (int dj = -1; dj <= 0; ++dj)
      for (int di = -1; di <= 0; ++di)
        if (i + di >= 0 && j + dj >= 0 && cells_live_[tile(i + di, j + dj)]) return true;
    return false;
  };
  const auto live_node = [&](int k, int l) {
    const unsigned char* around = &live_cells_[cell_index(k - 1, l - 1)];
    return (around[0] | around[1] | around[width] | around[width + 1]) != 0;
  };
  // A lower bound of each node's signed distance: the distance itself near the solid, the
  // distance to its bounding ball farther out. The distance is 1-Lipschitz, so a triangle
  // whose nodes are all farther than its longest edge plus the offset cannot be pressed in.
  // Each node of a visited cell is found by one tile: its own, a ghost by a border tile.
#pragma omp parallel for schedule(static)
  for (int j = 0; j < tiles_l_; ++j)
    for (int i = 0; i < tiles_k_; ++i) {
      if (!near_node_tile(i, j)) continue;
      prepare(i, j, current, next);
      const TileRange t = tile_nodes(i, j), c = tile_cell_nodes(i, j);
      const int ka = i == 0 ? c.k0 : t.k0, kb = i == tiles_k_ - 1 ? c.k1 : t.k1 - 1;
      const int la = j == 0 ? c.l0 : t.l0, lb = j == tiles_l_ - 1 ? c.l1 : t.l1 - 1;
      for (int l = la; l <= lb; ++l)
        for (int k = ka; k <= kb; ++k) {
          if (!live_node(k, l)) continue;
          const double outside_ball = norm(next(k, l) - centre) - radius;
          local_(k, l) = s.proposed.pose.to_local(next(k, l));
          if (outside_ball > thickness) {
            distance_(k, l) = outside_ball;
            normal_(k, l) = {};
          } else {
            const Closest near = g.closest(local_(k, l));
            distance_(k, l) = near.distance;
            normal_(k, l) = near.normal;
          }
        }
    }
  // The signed distance to a convex solid lies above its tangent plane at each node, so over
  // any triangle of `points` holding node (k, l) it is at least d + min_j n·(p_j − p), or −∞
  // for a node without a normal (outside the solid's ball): a cell resting on a face, all its
  // nodes on the offset surface, is not tested further.
  const auto tangent_bound = [&](int k, int l, const auto& points) {
    const Vec3 n = normal_(k, l);
    if (dot(n, n) == 0.0) return -1e300;
    const Vec3& here = local_(k, l);
    double reach = 0.0;
    for (const Vec3& q : points) reach = std::min(reach, dot(n, q - here));
    return distance_(k, l) + reach;
  };
  const auto triangle = [&](int kc, int lc, int tri) {
    return cell_index(kc, lc) * kCellTriangles + static_cast<std::size_t>(tri);
  };
  const std::size_t triangles =
      static_cast<std::size_t>(width) * (b.owned_l() + 3) * kCellTriangles;
  if (slot_.size() != triangles) slot_.assign(triangles, -1);
  // Visits a cell: its pushes, and the bound of its distance its tests found (−∞ when a
  // triangle needed the search).
  const auto visit = [&](int kc, int lc, std::vector<CellPush>& pushes) {
    // The test below for every triangle of the cell at once: its nodes' nearest and its
    // six edges' longest bound each triangle's, and the difference is monotone in both,
    // rounded too. An edge's length is the same whichever way it is walked.
    std::array<double, 6> edge{};
    for (std::size_t e = 0; e < edge.size(); ++e) {
      const auto& [a, b2] = kCellEdges[e];
      edge[e] = norm(next(kc + b2[0], lc + b2[1]) - next(kc + a[0], lc + a[1]));
    }
    const double cell_nearest =
        std::min(std::min(distance_(kc, lc), distance_(kc + 1, lc)),
                 std::min(distance_(kc, lc + 1), distance_(kc + 1, lc + 1)));
    const double cell_longest = *std::max_element(edge.begin(), edge.end());
    if (cell_nearest - cell_longest >= flat_offset) return cell_nearest - cell_longest;
    // The tangent-plane bound below, for the whole cell first: each node's over all
    // four nodes is at most its own over any triangle of them, and every triangle holds
    // one of the two nodes with the largest, so the second largest bounds them all. A
    // cell resting on a face is done here, not four times.
    if (convex) {
      const std::array<Vec3, 4> corners{local_(kc, lc), local_(kc + 1, lc),
                                        local_(kc, lc + 1), local_(kc + 1, lc + 1)};
      std::array<double, 4> bound{};
      for (int v = 0; v < 4; ++v) {
        const auto at = static_cast<std::size_t>(v);
        bound[at] = tangent_bound(kc + (v & 1), lc + (v >> 1), corners);
      }
      std::sort(bound.begin(), bound.end());
      if (bound[2] >= flat_offset) return bound[2];
    }
    double found = kHuge;
    for (int tri = 0; tri < kCellTriangles; ++tri) {
      const TriangleCorners nodes = triangle_corners(kc, lc, tri);
      double nearest = 1e300, longest = 0.0;
      std::array<double, 3> sides{};
      for (int v = 0; v < 3; ++v) {
        nearest = std::min(nearest, distance_(nodes[v][0], nodes[v][1]));
        sides[static_cast<std::size_t>(v)] = edge[static_cast<std::size_t>(
            kTriangleEdges[static_cast<std::size_t>(tri)][static_cast<std::size_t>(v)])];
        longest = std::max(longest, sides[static_cast<std::size_t>(v)]);
      }
      if (nearest - longest >= flat_offset) {
        found = std::min(found, nearest - longest);
        continue;
      }
      std::array<Vec3, 3> p;
      for (int v = 0; v < 3; ++v)
        p[v] = local_(nodes[v][0], nodes[v][1]);
      if (convex) {
        double lower = -1e300;
        for (int v = 0; v < 3; ++v)
          lower = std::max(lower, tangent_bound(nodes[v][0], nodes[v][1], p));
        if (lower >= flat_offset) {
          found = std::min(found, lower);
          continue;
        }
      }
      // The deepest point's distance is at least the bound, and the offset below at
      // most flat_offset (rounded: the slack); so the search may stop once it proves the
      // triangle that far.
      const double least = g.lower_bound(p[0], p[1], p[2]);
      if (least >= flat_offset + bound_slack) {
        found = std::min(found, least);
        continue;
      }
      found = -kHuge;
      const std::array<double, 3> w =
          g.deepest_point(p[0], p[1], p[2], flat_offset + bound_slack);
      if (std::max({w[0], w[1], w[2]}) >= 1.0 - 1e-12) continue;  // a node: node_pass's
      const Vec3 point = w[0] * p[0] + w[1] * p[1] + w[2] * p[2];
      const Closest c = g.closest(point);
      // A cylinder's side is curved (its normal radial); its caps and rims are not. A
      // free body keeps the flat rule: with the allowance, a free sphere's exchange with a
      // coarse sheet (9 x 9 on 1 m, sag 2 cm) lost angular momentum at 5e-10 of 2.7
      // (tests/unit/test_contact.cpp, AFreeBodyAndTheSheetExchangeMomentumExactly), cause
      // not found.
      const bool curved = s.spec.motion != SolidMotion::free &&
                          (s.spec.shape.kind != ShapeKind::cylinder || c.normal.z == 0.0);
      // A cylinder's side curves around its axis only: a triangle resting on it sags by the
      // circle through its corners seen along the axis, the sides' lengths across it. A
      // capsule keeps its sides as they are: a corner on a cap lies inside that circle.
      if (curved && s.spec.shape.kind == ShapeKind::cylinder)
        for (int v = 0; v < 3; ++v) {
          const Vec3 d = p[static_cast<std::size_t>((v + 1) % 3)] - p[static_cast<std::size_t>(v)];
          sides[static_cast<std::size_t>(v)] = std::sqrt(d.x * d.x + d.y * d.y);
        }
      const double offset = curved ? curved_offset(sides) : flat_offset;
      if (c.distance >= offset) continue;
      double depth = offset - c.distance;
      Vec3 side = c.normal;
      // The point's own path over the step, in the solid's frame at each end's time, says
      // where it entered: a thin solid can pass through a cell in one step, or leave it
      // across the solid's core, where the nearest surface can be any way. When the
      // surface it entered through faces more than 60° away from the nearest one, it goes
      // back out through the one it entered, as far as it takes to clear the solid.
      Vec3 from;
      for (int v = 0; v < 3; ++v)
        from += w[v] * s.state.pose.to_local(current(nodes[v][0], nodes[v][1]));
      if (const std::optional<double> t = g.first_contact(from, point, offset)) {
        const Vec3 entered = g.closest(from + *t * (point - from)).normal;
        if (dot(entered, c.normal) < 0.5) {
          side = entered;
          depth = clearance(g, point, side, offset);
        }
      }
      // The push is one force at the point, shared among the nodes as its weights say:
      // node i moves by (w_i/m_i) / Σ_j (w_j²/m_j) times the point's move (docs/contact.md,
      // "Cells"), so a light border node is moved as far as its share of that force takes it.
      std::array<double, 3> inverse_mass{};
      for (std::size_t v = 0; v < 3; ++v)
        inverse_mass[v] = 1.0 / node_mass_(nodes[v][0], nodes[v][1]);
      const double squares = w[0] * w[0] * inverse_mass[0] + w[1] * w[1] * inverse_mass[1] +
                             w[2] * w[2] * inverse_mass[2];
      const Vec3 normal = s.proposed.pose.direction_to_world(side);
      Vec3 velocity, point_offset;
      for (int v = 0; v < 3; ++v) {
        velocity += w[v] * velocity_(nodes[v][0], nodes[v][1]);
        point_offset += w[v] * scheme_offset_at(nodes[v][0], nodes[v][1]);
      }
      CellPush push;
      push.triangle = triangle(kc, lc, tri);
      push.weights = {w[0] * inverse_mass[0] / squares, w[1] * inverse_mass[1] / squares,
                      w[2] * inverse_mass[2] / squares};
      push.barycentric = w;
      push.depth = depth;
      push.normal = normal;
      push.surface = surface_velocity(s.proposed, s.proposed.pose.to_world(point));
      push.velocity_change = velocity_change(s, push.surface, normal, velocity);
      push.slip = slip_correction(push.velocity_change, normal, point_offset);
      pushes.push_back(push);
    }
    return found;
  };
#pragma omp parallel for schedule(static)
  for (int j = 0; j < tiles_l_; ++j) {
    std::vector<CellPush>& pushes = push_rows_[static_cast<std::size_t>(j)];
    pushes.clear();
    for (int i = 0; i < tiles_k_; ++i) {
      if (!cells_live_[tile(i, j)]) continue;
      const TileRange cells = tile_cell_nodes(i, j);
      for (int lc = cells.l0; lc < cells.l1; ++lc)
        for (int kc = cells.k0; kc < cells.k1; ++kc) {
          if (!live_cells_[cell_index(kc, lc)]) continue;
          const double found = visit(kc, lc, pushes);
          if (remembers && owned_cell(kc, lc))
            clear[cell_index(kc, lc)] = found + reach_[tile(i, j)].since;
        }
    }
  }
  cells_.clear();
  for (const auto& row : push_rows_) cells_.insert(cells_.end(), row.begin(), row.end());
  // The pressed triangles' pushes are forces at their points: a node adds its triangles'
  // pushes, each the same share of its triangle's at all its nodes (docs/contact.md, "Cells").
  // Added whole, the up to six triangles of a node resting on a box's edge moved it up to six
  // times too far, and the next step it fell back. Averaged at each node instead, as before
  // 2026-12-05, the nodes of one triangle took different shares of its push: no longer one
  // force at the triangle's point, the pushes did work around a cycle, and pumped the swing
  // of a drape's flaps over a cylinder's rim (+2.7e-6 J a frame). A triangle's relaxation,
  // 1 / (the most pressed triangles any of its nodes lies in), is a share no node overshoots
  // with; Jacobi sweeps from it take the depths' shares towards those that clear the
  // triangles together, to first order in the moves. Friction's move and the velocity change
  // keep the relaxation: a sweep's share is the ratio of what is left of a depth to the
  // depth, round-off itself for a triangle barely pressed, and on friction's move, which the
  // depth does not bound, it broke the mirror of the cube thrown into the 11 x 11 net
  // (tests/unit/test_contact.cpp) by 2.5e-8 m at the impact. node_sums_ holds a node's sum
  // over its pressed triangles, first how many they are, then how far their shares lift it;
  // the owners sum theirs, and the exchange gives the ghosts theirs. Every rank exchanges as
  // often, pressed triangles or none.
  // A pushed triangle's cell (kc, lc), and its corners.
  const auto cell_of = [&](const CellPush& push) {
    const auto cell = static_cast<int>(push.triangle / kCellTriangles);
    return std::array<int, 2>{cell % width + b.k0 - 2, cell / width + b.l0 - 2};
  };
  const auto corners_of = [&](const CellPush& push) {
    const auto [kc, lc] = cell_of(push);
    return triangle_corners(kc, lc, static_cast<int>(push.triangle % kCellTriangles));
  };
  for (const CellPush& push : cells_)
    for (const auto& [k, l] : corners_of(push))
      if (b.owns(k, l)) node_sums_(k, l).x += 1.0;
  halo_->exchange(node_sums_);
  if (cells_.empty()) {
    // The sweeps' exchanges, with nothing pressed here to send: the other ranks' sweeps need
    // this rank's part of them.
    for (int sweep = 0; sweep < kCellSweeps; ++sweep) halo_->exchange(node_sums_);
    return;
  }
  for (CellPush& push : cells_) {
    double most = 1.0;
    for (const auto& [k, l] : corners_of(push)) most = std::max(most, node_sums_(k, l).x);
    push.relaxation = 1.0 / most;
    push.share = push.relaxation;
  }
  for (std::size_t i = 0; i < cells_.size(); ++i) slot_[cells_[i].triangle] = static_cast<int>(i);
  // The tiles holding a pushed triangle's owned nodes: only their nodes can have a push to sum.
  pushed_.assign(cells_near_.size(), 0);
  for (const CellPush& push : cells_) {
    const auto [kc, lc] = cell_of(push);
    for (int v = 0; v < 4; ++v) {
      const int k = kc + (v & 1), l = lc + (v >> 1);
      if (b.owns(k, l)) pushed_[tile((k - b.k0) / kTile, (l - b.l0) / kTile)] = 1;
    }
  }
  // Calls f(push, corner) for each pressed triangle around node (k, l), in kAround's order,
  // the same on every split.
  const auto for_pushes_at = [&](int k, int l, const auto& f) {
    for (const Around& a : kAround) {
      const int kc = k + a.dk, lc = l + a.dl;
      if (kc < 0 || lc < 0 || kc >= b.m - 1 || lc >= b.n - 1) continue;
      const int slot = slot_[triangle(kc, lc, a.tri)];
      if (slot >= 0)
        f(cells_[static_cast<std::size_t>(slot)], static_cast<std::size_t>(a.corner));
    }
  };
  for (int sweep = 0; sweep < kCellSweeps; ++sweep) {
#pragma omp parallel for schedule(static)
    for (int j = 0; j < tiles_l_; ++j)
      for (int i = 0; i < tiles_k_; ++i) {
        if (!pushed_[tile(i, j)]) continue;
        const TileRange range = tile_nodes(i, j);
        for (int l = range.l0; l < range.l1; ++l)
          for (int k = range.k0; k < range.k1; ++k) {
            Vec3 lift;
            for_pushes_at(k, l, [&](const CellPush& push, std::size_t corner) {
              lift += (push.share * push.weights[corner] * push.depth) * push.normal;
            });
            node_sums_(k, l) = lift;
          }
      }
    halo_->exchange(node_sums_);
#pragma omp parallel for schedule(static)
    for (std::size_t t = 0; t < cells_.size(); ++t) {
      CellPush& push = cells_[t];
      const auto corners = corners_of(push);
      double lifted = 0.0;
      for (std::size_t v = 0; v < 3; ++v)
        lifted +=
            push.barycentric[v] * dot(push.normal, node_sums_(corners[v][0], corners[v][1]));
      if (push.depth > 0.0)
        push.share =
            std::max(0.0, push.share + push.relaxation * (push.depth - lifted) / push.depth);
    }
  }
#pragma omp parallel for schedule(static)
  for (int j = 0; j < tiles_l_; ++j) {
    std::vector<Exchange>& exchanges = exchange_rows_[static_cast<std::size_t>(j)];
    exchanges.clear();
    for (int i = 0; i < tiles_k_; ++i) {
      if (!pushed_[tile(i, j)]) continue;
      const TileRange range = tile_nodes(i, j);
      bool grew = false;
      for (int l = range.l0; l < range.l1; ++l)
        for (int k = range.k0; k < range.k1; ++k) {
          Vec3 move, dv, normal, surface;
          int pushes = 0;
          for_pushes_at(k, l, [&](const CellPush& push, std::size_t corner) {
            const double weight = push.weights[corner];
            move += (push.share * weight * push.depth) * push.normal +
                    (push.relaxation * weight) * push.slip;
            dv += (push.relaxation * weight) * push.velocity_change;
            normal += weight * push.normal;
            surface += push.surface;
            ++pushes;
          });
          if (pushes == 0 || dot(normal, normal) == 0.0) continue;
          const double mean = 1.0 / pushes;
          Vec3& r = next(k, l);
          const Vec3 r_before = r;
          const Vec3 v_before = velocity_(k, l);
          r += move;
          velocity_(k, l) += dv;
          take_offset(k, l);
          remember(s, k, l, normal / norm(normal), mean * surface, v_before);
          record(solid, pass, 1, k, l, r_before, v_before, r, exchanges);
          grow_box(tile(i, j), k, l, current, next);
          grew = true;
        }
      if (grew) classify(tile(i, j));
    }
  }
  for (const CellPush& push : cells_) {
    slot_[push.triangle] = -1;
    for (const auto& [k, l] : corners_of(push)) node_sums_(k, l) = {};
  }
  for (const auto& row : exchange_rows_) out.insert(out.end(), row.begin(), row.end());
}

bool Contact::any_inside(int pass, const Field<Vec3>& next, double& penetration) const {
  int inside = 0;
  double deepest = 0.0;
  // After a walk, the first pass's planes were tested there, on the nodes they moved; here only
  // where a bounded solid moved a node since.
  const bool walk_tested = walked_ && pass == 0;
  if (walk_tested)
    for (std::size_t row = 0; row < walk_inside_.size(); ++row) {
      inside = std::max(inside, static_cast<int>(walk_inside_[row]));
      deepest = std::max(deepest, walk_deepest_[row]);
    }
#pragma omp parallel for schedule(static) reduction(max : inside, deepest)
  for (int j = 0; j < tiles_l_; ++j)
    for (int ti = 0; ti < tiles_k_; ++ti) {
      const std::size_t t = tile(ti, j);
      const std::uint64_t near =
          near_[t] & (walk_tested && !tile_touched_[t] ? ~plane_bits_ : ~std::uint64_t{0});
      if (near == 0) continue;
      const TileRange range = tile_nodes(ti, j);
      for (int l = range.l0; l < range.l1; ++l)
        for (int k = range.k0; k < range.k1; ++k)
          for (std::size_t i = 0; i < solids_.size(); ++i) {
            if (!(near & solid_bit(i))) continue;
            const Solid& s = solids_[i];
            const double offset = s.spec.thickness;
            double d = 0.0;
            if (s.spec.shape.kind == ShapeKind::plane) {
              d = plane_height(s, next(k, l));
            } else {
              if (norm(next(k, l) - s.proposed.pose.position) >
                  s.geometry.bounding_radius() + offset)
                continue;
              d = s.geometry.closest(s.proposed.pose.to_local(next(k, l))).distance;
            }
            deepest = std::max(deepest, -d);
            if (inside_offset(d, offset)) inside = 1;
          }
    }
  penetration = std::max(penetration, deepest);
  int any = inside;
  MPI_Allreduce(&inside, &any, 1, MPI_INT, MPI_MAX, block_->comm);
  return any != 0;
}

bool Contact::any_moving() const {
  return std::any_of(solids_.begin(), solids_.end(),
                     [](const Solid& s) { return s.spec.motion != SolidMotion::fixed; });
}

// A bounded solid's surface lies within its ball about its frame's origin, grown by the offset,
// and moves at most |v| + |ω| R there; a plane pushes only along its normal, and turning it moves
// the points over the box by at most |ω| times their farthest from its point.
double Contact::approach_step(const Vec3& lo, const Vec3& hi, double reach) const {
  double step = kHuge;
  for (const Solid& s : solids_) {
    if (s.spec.motion == SolidMotion::fixed) continue;
    const SolidState& now = s.state;
    const Vec3& p = now.pose.position;
    double gap = 0.0, speed = 0.0;
    if (s.spec.shape.kind == ShapeKind::plane) {
      const Vec3 n = now.pose.direction_to_world({0.0, 0.0, 1.0});
      gap = lowest_along(n, lo, hi) - dot(n, p) - s.spec.thickness;
      speed = std::abs(dot(now.velocity, n)) + norm(now.angular_velocity) * farthest_in(p, lo, hi);
    } else {
      const double radius = s.geometry.bounding_radius() + s.spec.thickness;
      gap = box_gap(p, p, lo, hi) - radius;
      speed = norm(now.velocity) + norm(now.angular_velocity) * radius;
    }
    if (speed > 0.0) step = std::min(step, (std::max(gap, 0.0) + reach) / speed);
  }
  return step;
}

void Contact::propose(double time, double dt) {
  shift_.assign(solids_.size(), 0.0);
  turn_.assign(solids_.size(), 0.0);
  for (std::size_t i = 0; i < solids_.size(); ++i) {
    Solid& s = solids_[i];
    if (s.spec.motion == SolidMotion::free)
      propose_free(s, dt);
    else if (s.spec.motion == SolidMotion::kinematic)
      s.proposed = kinematic_state(s.spec, time + dt);
    shift_[i] = norm(s.proposed.pose.position - s.state.pose.position);
    turn_[i] = turn_angle(s.state.pose.orientation, s.proposed.pose.orientation);
    if (s.spec.shape.kind == ShapeKind::plane) {
      s.plane_normal = s.proposed.pose.direction_to_world({0.0, 0.0, 1.0});
    } else {
      // The world box of the rotated local box: centre R c + p, half-widths |R| h.
      const Pose& pose = s.proposed.pose;
      const Vec3 centre = pose.to_world(0.5 * (s.local_lo + s.local_hi));
      const Vec3 half = 0.5 * (s.local_hi - s.local_lo);
      const Vec3 ex = pose.direction_to_world({1.0, 0.0, 0.0});
      const Vec3 ey = pose.direction_to_world({0.0, 1.0, 0.0});
      const Vec3 ez = pose.direction_to_world({0.0, 0.0, 1.0});
      const auto reach = [&](double x, double y, double z) {
        return std::abs(x) * half.x + std::abs(y) * half.y + std::abs(z) * half.z;
      };
      const Vec3 extent{reach(ex.x, ey.x, ez.x), reach(ex.y, ey.y, ez.y), reach(ex.z, ey.z, ez.z)};
      s.reach_lo = centre - extent;
      s.reach_hi = centre + extent;
    }
  }
}

ContactStats Contact::respond(double time, double dt, const Field<Vec3>& current,
                              Field<Vec3>& next, const Field<Vec3>* next_velocities,
                              NodeVelocities& corrected,
                              std::vector<char>* moved_rows) {
  const Block& b = *block_;
  if (!walked_) propose(time, dt);
  dt_ = dt;
  if (unaccepted_) forget_clear();
  unaccepted_ = true;
  // Each tile's box, from the scheme's row walk or a sweep of its own; the velocities only
  // where the response can need them (prepare): on tiles a solid can reach, and on the tiles
  // along a border with another block, which the cell pass's exchange sends to its ghosts.
  // After a walk, the planes of the first pass are met, and need nothing here.
  // With planes alone, the walk met them all and a first pass has nothing to do: the boxes
  // are found only if a node was left inside one (two planes that disagree), for the next.
  next_velocities_ = next_velocities;
  if (next_velocities_ != nullptr && scheme_offset_.data() == nullptr)
    scheme_offset_ = Field<Vec3>(b);
  const std::uint64_t first_pass = walked_ ? ~plane_bits_ : ~std::uint64_t{0};
  bool boxed = !walked_ || walk_boxes_;
  if (walked_ && walk_boxes_)
    for (BoxRun& run : box_runs_)
      if (run.open) close_box_run(run);
#pragma omp parallel for schedule(static)
  for (int j = 0; j < tiles_l_; ++j) {
    const bool far = walked_ && walk_boxes_ && band_far_[static_cast<std::size_t>(j)];
    const double far_move = far ? far_band_move(j) : 0.0;
    for (int i = 0; i < tiles_k_; ++i) {
      const std::size_t t = tile(i, j);
      tile_touched_[t] = 0;
      ready_[t] = 0;
      if (!walked_)
        make_box(i, j, current, next);
      else if (far)
        far_box(i, j, far_move);
      else if (walk_boxes_)
        merge_rows(i, j);
      else
        near_[t] = 0;
      if ((near_[t] & first_pass) || (i == 0 && b.k0 > 0) || (j == 0 && b.l0 > 0) ||
          (i == tiles_k_ - 1 && b.k1 < b.m) || (j == tiles_l_ - 1 && b.l1 < b.n))
        prepare(i, j, current, next);
    }
  }

  std::vector<Exchange> exchanges;
  ContactStats stats;
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    if (pass > 0 && !boxed) {
#pragma omp parallel for schedule(static)
      for (int j = 0; j < tiles_l_; ++j)
        for (int i = 0; i < tiles_k_; ++i) make_box(i, j, current, next);
      boxed = true;
    }
    node_pass(pass, current, next, exchanges);
    for (std::size_t i = 0; i < solids_.size(); ++i)
      if (std::isfinite(solids_[i].geometry.bounding_radius()))
        cell_pass(pass, i, current, next, exchanges);
    double penetration = 0.0;
    const bool inside = any_inside(pass, next, penetration);
    stats.max_penetration = penetration;
    if (!inside) break;
  }
  double deepest = stats.max_penetration;
  MPI_Allreduce(&deepest, &stats.max_penetration, 1, MPI_DOUBLE, MPI_MAX, b.comm);

  if (any_free_) apply_impulses(exchanges);
  // The velocities of the nodes the response moved after the walk, from the fields on the
  // tiles it prepared; the walk wrote those of the others into the scheme's r⁻ (begin_walk),
  // and counts them. Only the moves after the walk need the stability check's edge test
  // again.
  long local = 0;
  for (int j = 0; j < tiles_l_; ++j) {
    bool any_ready = false;
    for (int i = 0; i < tiles_k_; ++i) {
      const std::size_t t = tile(i, j);
      if (!ready_[t]) continue;
      any_ready = true;
      const TileRange r = tile_nodes(i, j);
      if (moved_rows != nullptr && tile_touched_[t])
        for (int l = r.l0; l < r.l1; ++l) (*moved_rows)[static_cast<std::size_t>(l - b.l0)] = 1;
    }
    const TileRange rows = tile_nodes(0, j);
    for (int l = rows.l0; l < rows.l1; ++l) {
      long moved_again = 0;
      if (any_ready)
        for (int i = 0; i < tiles_k_; ++i) {
          if (!ready_[tile(i, j)]) continue;
          const TileRange r = tile_nodes(i, j);
          for (int k = r.k0; k < r.k1; ++k) {
            const unsigned char touched = touched_(k, l);
            if (touched == 0 || touched == kWalked) continue;
            corrected.push_back({k, l, settled_velocity(k, l, current, next)});
            ++local;
            if (touched & kWalked) ++moved_again;
          }
        }
      // The walk gave the scheme the velocities of the others itself (begin_walk).
      if (walked_ && planes_ > 0)
        local += walk_count_[static_cast<std::size_t>(l - b.l0)] - moved_again;
    }
  }
  if (!walked_)
    std::fill(band_far_.begin(), band_far_.end(), 0);
  else if (walk_boxes_)
    mark_far_bands();
  walked_ = false;
  walk_starts_ = nullptr;
  MPI_Allreduce(&local, &stats.contacts, 1, MPI_LONG, MPI_SUM, b.comm);
  return stats;
}

// docs/contact.md, "Free bodies" and "Parallel runs, restarts and output". Each node met a free
// body as if it could not move, with impulse J_i; the body and its nodes then share the impact
// as two bodies do: the nodes keep s J_i and the body takes −s ΣJ_i, with one factor s for all
// its contacts. The kinetic energy changes by
// ΔK(s) = s a + s² b, a = Σ J_i·(v_i − v_surface,i) < 0 for approaching nodes,
// b = Σ|J_node|²/2m + |ΣJ|²/2M + T·I⁻¹T/2 with T = Σ (r_i − x) × J_i; s = (1 + e)/2 · (−a/b)
// is the two-body impact with restitution e for a single contact, ΔK = s a (1 − e)/2 ≤ 0 for
// any number of contacts, and s ≤ 1 keeps each node's response no stronger than against an
// immovable surface. The body's angular momentum takes −Σ m (r' × v' − r × v) + x × ΣJ: with
// the linear part, cloth and body together keep their momentum and angular momentum about the
// origin to round-off, the nodes' moves onto the surface included. The sums run in the
// exchanges' key order after gathering every rank's, the same on every rank and decomposition.
void Contact::apply_impulses(std::vector<Exchange>& exchanges) {
  const MPI_Comm comm = block_->comm;
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  const int bytes = static_cast<int>(exchanges.size() * sizeof(Exchange));
  std::vector<int> counts(static_cast<std::size_t>(ranks)), displacements(counts.size());
  MPI_Allgather(&bytes, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  int total = 0;
  for (std::size_t r = 0; r < counts.size(); ++r) {
    displacements[r] = total;
    total += counts[r];
  }
  std::vector<Exchange> all(static_cast<std::size_t>(total) / sizeof(Exchange));
  MPI_Allgatherv(exchanges.data(), bytes, MPI_BYTE, all.data(), counts.data(),
                 displacements.data(), MPI_BYTE, comm);
  std::sort(all.begin(), all.end(),
            [](const Exchange& a, const Exchange& b) { return a.key < b.key; });
  const auto nodes = static_cast<std::int64_t>(block_->m) * block_->n;
  const std::int64_t per_solid = nodes * kMaxPasses * 2;
  std::vector<double> scale(solids_.size(), 1.0);
  for (std::size_t first = 0; first < all.size();) {
    const std::int64_t solid_key = all[first].key / per_solid;
    Solid& s = solids_[static_cast<std::size_t>(solid_key)];
    SolidState& body = s.proposed;
    Vec3 impulse, moment, move_moment;
    double approach = 0.0, node_energy = 0.0;
    std::size_t i = first;
    while (i < all.size() && all[i].key / per_solid == solid_key) {
      // One node's exchanges, pass after pass.
      const std::int64_t node_key = all[i].key / (kMaxPasses * 2);
      const Vec3 v0 = all[i].velocity;
      Vec3 node_impulse;
      for (; i < all.size() && all[i].key / (kMaxPasses * 2) == node_key; ++i) {
        node_impulse += all[i].impulse;
        moment += all[i].moment;
        move_moment += all[i].move_moment;
      }
      impulse += node_impulse;
      approach += dot(node_impulse, v0);
      const std::int64_t node = node_key % nodes;
      const double node_mass =
          node_mass_(static_cast<int>(node % block_->m), static_cast<int>(node / block_->m));
      node_energy += dot(node_impulse, node_impulse) / (2.0 * node_mass);
    }
    const double mass = s.spec.body.mass;
    const Vec3 moments = mass * s.inertia_per_mass;
    const Vec3 torque = moment - cross(body.pose.position, impulse);
    const double a = approach - dot(body.velocity, impulse) - dot(body.angular_velocity, torque);
    const double b = node_energy + dot(impulse, impulse) / (2.0 * mass) +
                     0.5 * dot(torque, inertia_solve(body.pose.orientation, moments, torque));
    double share = 1.0;
    if (a < 0.0 && b > 0.0) share = std::min(1.0, 0.5 * (1.0 + s.spec.restitution) * (-a / b));
    scale[static_cast<std::size_t>(solid_key)] = share;
    Vec3 spin = inertia_times(body.pose.orientation, moments, body.angular_velocity);
    spin -= move_moment + share * torque;
    body.velocity -= (share / mass) * impulse;
    body.angular_velocity = inertia_solve(body.pose.orientation, moments, spin);
    if (s.spec.body.force_until_contact) s.proposed_pushing = false;
    first = i;
  }
  // This rank's nodes keep their share of what they exchanged.
  const Block& b = *block_;
  for (const Exchange& e : exchanges) {
    const auto solid = static_cast<std::size_t>(e.key / per_solid);
    if (scale[solid] == 1.0) continue;
    const std::int64_t node = (e.key / (kMaxPasses * 2)) % nodes;
    const int k = static_cast<int>(node % b.m), l = static_cast<int>(node / b.m);
    velocity_(k, l) -= ((1.0 - scale[solid]) / node_mass_(k, l)) * e.impulse;
  }
}

void Contact::accept() {
  for (Solid& s : solids_) {
    s.state = s.proposed;
    s.pushing = s.proposed_pushing;
  }
  for (int j = 0; j < tiles_l_; ++j)
    for (int i = 0; i < tiles_k_; ++i) travel_[tile(i, j)] += cell_reach_move(i, j);
  unaccepted_ = false;
}

void Contact::forget_clear() {
  for (std::vector<double>& cells : clear_) std::fill(cells.begin(), cells.end(), -kHuge);
  for (std::vector<double>& nodes : node_clear_) std::fill(nodes.begin(), nodes.end(), -kHuge);
}

namespace {
constexpr std::size_t kStateSize = 14;  // position 3, orientation 4, velocity 3, ω 3, pushing
}

std::vector<double> Contact::state_vector() const {
  std::vector<double> v;
  for (const Solid& s : solids_) {
    const SolidState& st = s.state;
    const Quaternion& q = st.pose.orientation;
    v.insert(v.end(), {st.pose.position.x, st.pose.position.y, st.pose.position.z, q.w, q.x, q.y,
                       q.z, st.velocity.x, st.velocity.y, st.velocity.z, st.angular_velocity.x,
                       st.angular_velocity.y, st.angular_velocity.z, s.pushing ? 1.0 : 0.0});
  }
  return v;
}

void Contact::restore(const std::vector<double>& v) {
  if (v.size() != solids_.size() * kStateSize)
    throw std::invalid_argument("contact state: " + std::to_string(v.size()) + " numbers for " +
                                std::to_string(solids_.size()) + " solids");
  for (std::size_t i = 0; i < solids_.size(); ++i) {
    const double* x = v.data() + i * kStateSize;
    Solid& s = solids_[i];
    s.state.pose = {{x[0], x[1], x[2]}, {x[3], x[4], x[5], x[6]}};
    s.state.velocity = {x[7], x[8], x[9]};
    s.state.angular_velocity = {x[10], x[11], x[12]};
    s.pushing = x[13] != 0.0;
    s.proposed = s.state;
    s.proposed_pushing = s.pushing;
  }
  forget_clear();
  std::fill(band_far_.begin(), band_far_.end(), 0);
}

}  // namespace cosserat
