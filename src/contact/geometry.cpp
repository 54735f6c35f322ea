// The solids of docs/contact.md, "Solids and their motion", in their own frames: closed forms for
// every shape but the mesh, whose queries go through the CGAL tree of mesh_tree.cpp.

#include "cosserat/contact/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>
#include <utility>

#include "mesh_tree.hpp"

namespace cosserat {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// A list of at most N values held in place: the searches below run for every cell near a
// solid on every step, and allocate nothing.
template <class T, std::size_t N>
class FixedList {
 public:
  FixedList() = default;
  FixedList(std::initializer_list<T> values) {
    for (const T& v : values) push_back(v);
  }
  void push_back(const T& v) {
    if (size_ == N) throw std::logic_error("FixedList: more than its capacity");
    items_[size_++] = v;
  }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const T& front() const { return items_[0]; }
  const T& operator[](std::size_t i) const { return items_[i]; }
  const T* begin() const { return items_.data(); }
  const T* end() const { return items_.data() + size_; }

 private:
  std::array<T, N> items_{};
  std::size_t size_ = 0;
};

// ---- Signed distances in the shape's frame ------------------------------------------------
// Where the nearest surface point is not unique (a centre, an axis) the normal is a fixed
// axis: any choice is a valid subgradient of the distance, and a fixed one keeps runs
// repeatable.

Closest box_closest(const Vec3& p, const Vec3& half) {
  const Vec3 q{std::abs(p.x) - half.x, std::abs(p.y) - half.y, std::abs(p.z) - half.z};
  const Vec3 outside{std::max(q.x, 0.0), std::max(q.y, 0.0), std::max(q.z, 0.0)};
  const double gap = norm(outside);
  if (gap > 0.0) {
    return {gap, Vec3{std::copysign(outside.x, p.x), std::copysign(outside.y, p.y),
                      std::copysign(outside.z, p.z)} / gap};
  }
  // Inside or on the surface: the nearest face, the first axis on a tie.
  int axis = 0;
  for (int i = 1; i < 3; ++i) {
    if (q[i] > q[axis]) axis = i;
  }
  Vec3 normal;
  normal[axis] = p[axis] < 0.0 ? -1.0 : 1.0;
  return {q[axis], normal};
}

// sqrt of the sums rather than std::hypot, which guards against overflow no contact coordinate
// comes near and cost a third of the tablecloth's contact time (27.6 million calls).
Closest cylinder_closest(const Vec3& p, double radius, double half_length) {
  const double r = std::sqrt(p.x * p.x + p.y * p.y);
  const Vec3 radial = r > 0.0 ? Vec3{p.x / r, p.y / r, 0.0} : Vec3{1.0, 0.0, 0.0};
  const Vec3 axial{0.0, 0.0, p.z < 0.0 ? -1.0 : 1.0};
  const double side = r - radius;
  const double cap = std::abs(p.z) - half_length;
  if (side > 0.0 || cap > 0.0) {
    const double s = std::max(side, 0.0);
    const double c = std::max(cap, 0.0);
    const double gap = std::sqrt(s * s + c * c);
    return {gap, (s / gap) * radial + (c / gap) * axial};
  }
  if (cap >= side) return {cap, axial};
  return {side, radial};
}

// cylinder_closest's distance alone, by the same operations, for the searches of
// cylinder_deepest, which ask for nothing else: its normal's four divisions were about half of
// a round table's run.
[[gnu::always_inline]] inline double cylinder_distance(const Vec3& p, double radius,
                                                       double half_length) {
  const double side = std::sqrt(p.x * p.x + p.y * p.y) - radius;
  const double cap = std::abs(p.z) - half_length;
  if (side > 0.0 || cap > 0.0) {
    const double s = std::max(side, 0.0);
    const double c = std::max(cap, 0.0);
    return std::sqrt(s * s + c * c);
  }
  return cap >= side ? cap : side;
}

Closest capsule_closest(const Vec3& p, double radius, double half_length) {
  const Vec3 spine{0.0, 0.0, std::clamp(p.z, -half_length, half_length)};
  const Vec3 d = p - spine;
  const double r = norm(d);
  if (r == 0.0) return {-radius, {1.0, 0.0, 0.0}};
  return {r - radius, d / r};
}

// ---- Closest points between a triangle and simple features --------------------------------

using Weights = std::array<double, 3>;

Vec3 at(const Weights& w, const Vec3& a, const Vec3& b, const Vec3& c) {
  return w[0] * a + w[1] * b + w[2] * c;
}

// The parameter in [0, 1] of the point of segment (a, b) nearest to p.
double closest_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double length2 = dot(ab, ab);
  if (!(length2 > 0.0)) return 0.0;
  return std::clamp(dot(p - a, ab) / length2, 0.0, 1.0);
}

// Parameters (s, t) of the nearest points of segments p0 + s (p1 - p0) and q0 + t (q1 - q0)
// (Ericson, Real-Time Collision Detection, §5.1.9), degenerate segments included.
std::pair<double, double> closest_segment_segment(const Vec3& p0, const Vec3& p1, const Vec3& q0,
                                                  const Vec3& q1) {
  const Vec3 d1 = p1 - p0;
  const Vec3 d2 = q1 - q0;
  const Vec3 r = p0 - q0;
  const double a = dot(d1, d1);
  const double e = dot(d2, d2);
  const double f = dot(d2, r);
  if (a <= 0.0 && e <= 0.0) return {0.0, 0.0};
  if (a <= 0.0) return {0.0, std::clamp(f / e, 0.0, 1.0)};
  const double c = dot(d1, r);
  if (e <= 0.0) return {std::clamp(-c / a, 0.0, 1.0), 0.0};
  const double b = dot(d1, d2);
  const double denominator = a * e - b * b;
  double s = denominator > 0.0 ? std::clamp((b * f - c * e) / denominator, 0.0, 1.0) : 0.0;
  double t = (b * s + f) / e;
  if (t < 0.0) {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (t > 1.0) {
    t = 1.0;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
  return {s, t};
}

// Barycentric weights of the point of triangle (a, b, c) nearest to p, by Voronoi region
// (Ericson §5.1.5), so exact on vertices and edges; a degenerate triangle falls back to its
// edges.
Weights closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a;
  const Vec3 ac = c - a;
  const Vec3 ap = p - a;
  const double d1 = dot(ab, ap);
  const double d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {1.0, 0.0, 0.0};
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp);
  const double d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return {0.0, 1.0, 0.0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 && d1 - d3 > 0.0) {
    const double v = d1 / (d1 - d3);
    return {1.0 - v, v, 0.0};
  }
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp);
  const double d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return {0.0, 0.0, 1.0};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 && d2 - d6 > 0.0) {
    const double w = d2 / (d2 - d6);
    return {1.0 - w, 0.0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 && (d4 - d3) + (d5 - d6) > 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0.0, 1.0 - w, w};
  }
  const double area = va + vb + vc;
  if (area > 0.0) {
    const double v = vb / area;
    const double w = vc / area;
    return {1.0 - v - w, v, w};
  }
  const std::array<Weights, 3> on_edges{
      Weights{1.0 - closest_on_segment(p, a, b), closest_on_segment(p, a, b), 0.0},
      Weights{0.0, 1.0 - closest_on_segment(p, b, c), closest_on_segment(p, b, c)},
      Weights{closest_on_segment(p, c, a), 0.0, 1.0 - closest_on_segment(p, c, a)}};
  Weights best = on_edges[0];
  double best_distance2 = kInfinity;
  for (const Weights& w : on_edges) {
    const Vec3 d = at(w, a, b, c) - p;
    if (dot(d, d) < best_distance2) {
      best_distance2 = dot(d, d);
      best = w;
    }
  }
  return best;
}

// The point of triangle (a, b, c) nearest to segment (p0, p1), as weights on the triangle: the
// crossing if the segment pierces it, else the best of the segment's ends against the triangle
// and the segment against the triangle's edges.
Weights closest_segment_triangle(const Vec3& p0, const Vec3& p1, const Vec3& a, const Vec3& b,
                                 const Vec3& c) {
  Weights best{1.0, 0.0, 0.0};
  double best_distance2 = kInfinity;
  const auto consider = [&](const Weights& w, const Vec3& on_segment) {
    const Vec3 d = at(w, a, b, c) - on_segment;
    if (dot(d, d) < best_distance2) {
      best_distance2 = dot(d, d);
      best = w;
    }
  };
  const Vec3 n = cross(b - a, c - a);
  const double h0 = dot(n, p0 - a);
  const double h1 = dot(n, p1 - a);
  if (((h0 <= 0.0 && h1 >= 0.0) || (h0 >= 0.0 && h1 <= 0.0)) && h0 != h1) {
    const Vec3 crossing = p0 + (h0 / (h0 - h1)) * (p1 - p0);
    consider(closest_on_triangle(crossing, a, b, c), crossing);
  }
  consider(closest_on_triangle(p0, a, b, c), p0);
  consider(closest_on_triangle(p1, a, b, c), p1);
  const std::array<std::pair<int, int>, 3> edges{{{0, 1}, {1, 2}, {2, 0}}};
  const std::array<Vec3, 3> corner{a, b, c};
  for (const auto& [i, j] : edges) {
    const auto [s, t] = closest_segment_segment(p0, p1, corner[i], corner[j]);
    Weights w{0.0, 0.0, 0.0};
    w[i] = 1.0 - t;
    w[j] = t;
    consider(w, p0 + s * (p1 - p0));
  }
  return best;
}

// Weights made exactly non-negative and summing to one (round-off of the constructions).
Weights clean(Weights w) {
  for (double& x : w) x = std::max(x, 0.0);
  const double sum = w[0] + w[1] + w[2];
  if (!(sum > 0.0)) return {1.0, 0.0, 0.0};
  return {w[0] / sum, w[1] / sum, w[2] / sum};
}

// ---- Surfaces for output -----------------------------------------------------------------

// A closed surface of revolution about z from a profile of (radius, z) running from the top
// pole to the bottom pole (radius 0 at both, > 0 between): fans at the poles, quads between
// rings, counter-clockwise seen from outside.
TriangleMesh revolution_surface(const std::vector<std::pair<double, double>>& profile,
                                int segments) {
  TriangleMesh mesh;
  const int rings = static_cast<int>(profile.size()) - 2;
  mesh.vertices.push_back({0.0, 0.0, profile.front().second});
  for (int k = 1; k <= rings; ++k) {
    const auto [r, z] = profile[k];
    for (int j = 0; j < segments; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / segments;
      mesh.vertices.push_back({r * std::cos(phi), r * std::sin(phi), z});
    }
  }
  const int bottom = static_cast<int>(mesh.vertices.size());
  mesh.vertices.push_back({0.0, 0.0, profile.back().second});
  const auto ring = [segments](int k, int j) { return 1 + (k - 1) * segments + j % segments; };
  for (int j = 0; j < segments; ++j) {
    mesh.triangles.push_back({0, ring(1, j), ring(1, j + 1)});
    for (int k = 1; k < rings; ++k) {
      mesh.triangles.push_back({ring(k, j), ring(k + 1, j), ring(k + 1, j + 1)});
      mesh.triangles.push_back({ring(k, j), ring(k + 1, j + 1), ring(k, j + 1)});
    }
    mesh.triangles.push_back({bottom, ring(rings, j + 1), ring(rings, j)});
  }
  return mesh;
}

// The icosahedron subdivided twice (320 triangles): even triangles, unlike a UV sphere's
// slivers at the poles.
TriangleMesh icosphere(double radius) {
  const double g = std::numbers::phi;
  TriangleMesh mesh;
  mesh.vertices = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                   {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  mesh.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (Vec3& v : mesh.vertices) v = v / norm(v);
  for (int level = 0; level < 2; ++level) {
    std::map<std::pair<int, int>, int> midpoints;
    const auto midpoint = [&](int i, int j) {
      const auto key = std::minmax(i, j);
      const auto [it, inserted] = midpoints.try_emplace(key, static_cast<int>(mesh.vertices.size()));
      if (inserted) {
        const Vec3 m = mesh.vertices[i] + mesh.vertices[j];
        mesh.vertices.push_back(m / norm(m));
      }
      return it->second;
    };
    std::vector<std::array<int, 3>> finer;
    for (const auto& [a, b, c] : mesh.triangles) {
      const int ab = midpoint(a, b);
      const int bc = midpoint(b, c);
      const int ca = midpoint(c, a);
      finer.insert(finer.end(), {{a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca}});
    }
    mesh.triangles = std::move(finer);
  }
  for (Vec3& v : mesh.vertices) v *= radius;
  return mesh;
}

TriangleMesh box_surface(const Vec3& half) {
  TriangleMesh mesh;
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.push_back({(i & 1) ? half.x : -half.x, (i & 2) ? half.y : -half.y,
                             (i & 4) ? half.z : -half.z});
  }
  for (int axis = 0; axis < 3; ++axis) {
    const int j = (axis + 1) % 3;
    const int k = (axis + 2) % 3;
    for (const int side : {0, 1}) {
      // The cycle (−,−), (+,−), (+,+), (−,+) in (e_j, e_k) turns about e_j × e_k = e_axis.
      std::array<int, 4> cycle{};
      const std::array<std::pair<int, int>, 4> signs{{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
      for (int n = 0; n < 4; ++n) {
        cycle[n] = (side << axis) | (signs[n].first << j) | (signs[n].second << k);
      }
      if (side == 0) std::swap(cycle[1], cycle[3]);
      mesh.triangles.push_back({cycle[0], cycle[1], cycle[2]});
      mesh.triangles.push_back({cycle[0], cycle[2], cycle[3]});
    }
  }
  return mesh;
}

constexpr int kRoundSegments = 32;
// circle_nearest: Newton's method converges quadratically, and an angle settled to 1e-13 puts
// the circle's point within 1e-13 R of its place; the answer is then certified (below) to
// within 1e-12 of the cylinder's size.
constexpr int kCircleIterations = 40;
constexpr double kCircleAngleTolerance = 1e-13;
constexpr double kCircleCertified = 1e-12;

// ---- deepest_point for each shape --------------------------------------------------------

// Compass search on the weights from `start`: moves weight between two corners by a step
// halved whenever no move lowers the distance. It uses values only (the distance inside a
// box or a cylinder has kinks where gradients jump) and never raises the distance; on a kink
// not aligned with any of its six directions it can stop short of the minimum.
// `far_enough(w, value)` is asked before each step size: when it says yes the search stops
// where it is.
template <typename Distance, typename FarEnough>
Weights compass_refine(Weights w, double value, const Distance& distance,
                       const FarEnough& far_enough) {
  constexpr double kSmallestStep = 1.0 / (1 << 16);
  double step = 0.25;
  if (far_enough(w, value)) return w;
  while (step >= kSmallestStep) {
    bool moved = false;
    for (int from = 0; from < 3 && !moved; ++from) {
      for (int to = 0; to < 3 && !moved; ++to) {
        if (from == to || w[from] <= 0.0) continue;
        Weights trial = w;
        const double amount = std::min(step, w[from]);
        trial[from] -= amount;
        trial[to] += amount;
        const double trial_value = distance(trial);
        if (trial_value < value) {
          w = trial;
          value = trial_value;
          moved = true;
        }
      }
    }
    if (!moved) {
      step *= 0.5;
      if (step >= kSmallestStep && far_enough(w, value)) break;
    }
  }
  return w;
}

// Candidates whose distance is within this fraction of the larger of the box and the
// triangle of the deepest tie with it: round-off, and the drift round-off leaves in a free
// box (the two ends of a cell's diagonal under the cube of scenes/contact/cube_net_500.toml
// differed by 1.5e-12 m, 5e-12 of it). Weights this close are one point. A tie so taken is
// at most 0.3 nm shallower than the deepest under a 0.3 m box.
constexpr double kTieTolerance = 1e-9;

// The box's distance is exact from two candidate sets. Apart from the box, the nearest pair of
// features of two convex polytopes is a vertex of one against the other or an edge against an
// edge: the triangle's vertices, the box's corners against the triangle, the box's edges
// against the triangle. Pressed into the box, the distance there is the largest of the six
// face functions ±x_i − h_i, linear on the triangle, so its minimum is a vertex of that
// piecewise-linear program: where two faces tie on a triangle edge, or three inside it.
Weights box_deepest(const Vec3& half, const Vec3& a, const Vec3& b, const Vec3& c) {
  // 3 corners, 8 box corners, 12 box edges, 15 face pairs on 3 edges, 20 face triples.
  FixedList<Weights, 88> candidates{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  std::array<Vec3, 8> corners;
  for (int i = 0; i < 8; ++i) {
    corners[i] = {(i & 1) ? half.x : -half.x, (i & 2) ? half.y : -half.y,
                  (i & 4) ? half.z : -half.z};
    candidates.push_back(closest_on_triangle(corners[i], a, b, c));
  }
  for (int i = 0; i < 8; ++i) {
    for (int bit = 1; bit < 8; bit <<= 1) {
      if (!(i & bit)) candidates.push_back(closest_segment_triangle(corners[i], corners[i | bit], a, b, c));
    }
  }
  // Face k: s x_axis − h_axis = alpha + beta u + gamma v at a + u (b − a) + v (c − a).
  std::array<std::array<double, 3>, 6> face{};
  for (int k = 0; k < 6; ++k) {
    const int axis = k / 2;
    const double s = (k % 2 == 0) ? 1.0 : -1.0;
    face[k] = {s * a[axis] - half[axis], s * (b[axis] - a[axis]), s * (c[axis] - a[axis])};
  }
  const std::array<std::array<double, 2>, 3> ends{{{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}}};
  for (int k = 0; k < 6; ++k) {
    for (int l = k + 1; l < 6; ++l) {
      const std::array<double, 3> g{face[k][0] - face[l][0], face[k][1] - face[l][1],
                                    face[k][2] - face[l][2]};
      for (int e = 0; e < 3; ++e) {
        const auto& p = ends[e];
        const auto& q = ends[(e + 1) % 3];
        const double g0 = g[0] + g[1] * p[0] + g[2] * p[1];
        const double g1 = g[1] * (q[0] - p[0]) + g[2] * (q[1] - p[1]);
        if (g1 == 0.0) continue;
        const double sigma = -g0 / g1;
        if (sigma < 0.0 || sigma > 1.0) continue;
        const double u = p[0] + sigma * (q[0] - p[0]);
        const double v = p[1] + sigma * (q[1] - p[1]);
        candidates.push_back(clean({1.0 - u - v, u, v}));
      }
      for (int m = l + 1; m < 6; ++m) {
        const double a11 = face[k][1] - face[l][1];
        const double a12 = face[k][2] - face[l][2];
        const double a21 = face[k][1] - face[m][1];
        const double a22 = face[k][2] - face[m][2];
        const double det = a11 * a22 - a12 * a21;
        if (det == 0.0) continue;
        const double r1 = face[l][0] - face[k][0];
        const double r2 = face[m][0] - face[k][0];
        const double u = (r1 * a22 - a12 * r2) / det;
        const double v = (a11 * r2 - r1 * a21) / det;
        if (u < 0.0 || v < 0.0 || u + v > 1.0) continue;
        candidates.push_back(clean({1.0 - u - v, u, v}));
      }
    }
  }
  // The signed distance is convex, so the candidates that tie for the deepest bound a set of
  // deepest points, and their mean is one of them. The mean of the distinct ones does not
  // depend on the order they were found in, which a mirror of the triangle and the box
  // changes: taking the first found, the cube thrown into the net of
  // scenes/contact/cube_net_500.toml left 5.6 cm to the side when two ends of a cell's
  // diagonal tied under it (measured in a build without the cell pass's sweep; docs/contact.md,
  // "Cells").
  std::array<double, 88> values{};
  double best_value = kInfinity;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    values[i] = box_closest(at(candidates[i], a, b, c), half).distance;
    best_value = std::min(best_value, values[i]);
  }
  const double scale = std::max({half.x, half.y, half.z, norm(b - a), norm(c - a), norm(c - b)});
  const double tie = best_value + kTieTolerance * scale;
  FixedList<Weights, 88> tied;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (values[i] > tie) continue;
    const Weights w = clean(candidates[i]);
    const bool seen = std::any_of(tied.begin(), tied.end(), [&](const Weights& v) {
      return std::abs(v[0] - w[0]) + std::abs(v[1] - w[1]) + std::abs(v[2] - w[2]) <=
             kTieTolerance;
    });
    if (!seen) tied.push_back(w);
  }
  Weights mean{0.0, 0.0, 0.0};
  for (const Weights& w : tied)
    for (std::size_t j = 0; j < 3; ++j) mean[j] += w[j];
  return clean(mean);
}

// The smallest F = max(ρ − R, |z| − H) on the triangle (ρ the distance from the axis), which
// is the signed distance wherever it is negative: F <= s holds somewhere on the triangle when
// the part of it with |z| <= H + s comes within R + s of the axis, a test in the xy-plane
// after clipping, and that is monotone in s, so bisection finds the minimum to round-off.
// Returns the weights of a point with F <= hi, hi an F known to be reached.
Weights cylinder_pressed(double radius, double half_length, const Vec3& a, const Vec3& b,
                         const Vec3& c, double hi) {
  struct Corner {
    Vec3 x;
    Weights w;
  };
  // The point of the clipped triangle nearest the axis, or nothing if the clip is empty.
  const auto nearest_axis = [&](double s, double& rho) -> std::optional<Weights> {
    // A triangle clipped by two parallel planes keeps at most five corners.
    using Polygon = FixedList<Corner, 5>;
    Polygon polygon{{a, {1, 0, 0}}, {b, {0, 1, 0}}, {c, {0, 0, 1}}};
    for (const double side : {1.0, -1.0}) {
      Polygon kept;
      for (std::size_t i = 0; i < polygon.size(); ++i) {
        const Corner& p = polygon[i];
        const Corner& q = polygon[(i + 1) % polygon.size()];
        const double hp = side * p.x.z - (half_length + s);
        const double hq = side * q.x.z - (half_length + s);
        if (hp <= 0.0) kept.push_back(p);
        if ((hp < 0.0 && hq > 0.0) || (hp > 0.0 && hq < 0.0)) {
          const double t = hp / (hp - hq);
          kept.push_back({p.x + t * (q.x - p.x),
                          {p.w[0] + t * (q.w[0] - p.w[0]), p.w[1] + t * (q.w[1] - p.w[1]),
                           p.w[2] + t * (q.w[2] - p.w[2])}});
        }
      }
      polygon = kept;
      if (polygon.empty()) return std::nullopt;
    }
    // The axis pierces the polygon's projection: some fan triangle holds the origin.
    for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
      const Vec3& p0 = polygon[0].x;
      const Vec3& p1 = polygon[i].x;
      const Vec3& p2 = polygon[i + 1].x;
      const double area = (p1.x - p0.x) * (p2.y - p0.y) - (p1.y - p0.y) * (p2.x - p0.x);
      if (area == 0.0) continue;
      const double l1 = ((0.0 - p0.x) * (p2.y - p0.y) - (0.0 - p0.y) * (p2.x - p0.x)) / area;
      const double l2 = ((p1.x - p0.x) * (0.0 - p0.y) - (p1.y - p0.y) * (0.0 - p0.x)) / area;
      if (l1 >= 0.0 && l2 >= 0.0 && l1 + l2 <= 1.0) {
        rho = 0.0;
        Weights w{};
        for (int k = 0; k < 3; ++k) {
          w[k] = (1.0 - l1 - l2) * polygon[0].w[k] + l1 * polygon[i].w[k] + l2 * polygon[i + 1].w[k];
        }
        return w;
      }
    }
    rho = kInfinity;
    Weights best{};
    for (std::size_t i = 0; i < polygon.size(); ++i) {
      const Corner& p = polygon[i];
      const Corner& q = polygon[(i + 1) % polygon.size()];
      const Vec3 pf{p.x.x, p.x.y, 0.0};
      const Vec3 qf{q.x.x, q.x.y, 0.0};
      const double t = closest_on_segment({0.0, 0.0, 0.0}, pf, qf);
      const double r = norm(pf + t * (qf - pf));
      if (r < rho) {
        rho = r;
        for (int k = 0; k < 3; ++k) best[k] = p.w[k] + t * (q.w[k] - p.w[k]);
      }
    }
    return best;
  };
  double lo = -std::min(radius, half_length);
  double rho = 0.0;
  std::optional<Weights> found = nearest_axis(hi, rho);
  Weights best = found ? *found : Weights{1.0, 0.0, 0.0};
  for (int iteration = 0; iteration < 100 && hi - lo > 1e-13 * (radius + half_length); ++iteration) {
    const double mid = 0.5 * (lo + hi);
    found = nearest_axis(mid, rho);
    if (found && rho <= radius + mid) {
      hi = mid;
      best = *found;
    } else {
      lo = mid;
    }
  }
  return clean(best);
}

// The triangle's point nearest the circle ρ = R at height z, from the circle's direction u (a
// unit vector in the xy-plane): with q(θ) the circle's point at angle θ and p(θ) the
// triangle's point nearest it, the pair is nearest where q − p is normal to the circle,
// s(θ) = (q − p)·t̂ = 0 (t̂ the circle's tangent, r̂ its outward normal). Newton's method on θ,
// with s′ = R (1 − t̂·J t̂) − (q − p)·r̂, J the derivative of the nearest point: the projection
// on the triangle's plane inside it, on an edge's line on an edge, zero at a corner. A step δ
// turns u to the direction of u − δ t̂ (by atan δ, which is δ to third order, so the
// convergence stays quadratic), with no sine or cosine: they were 4 % of a round table's run.
// Nothing when s′ is not positive (p then lies within the circle's radius, nearer the cap than
// the rim) or when it has not settled.
std::optional<Weights> circle_nearest(double radius, double z, Vec3 u, const Vec3& a,
                                      const Vec3& b, const Vec3& c) {
  const std::array<const Vec3*, 3> corner{&a, &b, &c};
  const Vec3 normal = cross(b - a, c - a);
  const double area2 = dot(normal, normal);
  const auto turn = [](const Vec3& from, const Vec3& to) { return from.x * to.y - from.y * to.x; };
  // Directions where s < 0 and where s >= 0, once seen: the root lies between them.
  Vec3 below, above;
  bool has_below = false, has_above = false;
  for (int iteration = 0; iteration < kCircleIterations; ++iteration) {
    const Vec3 q{radius * u.x, radius * u.y, z};
    const Vec3 tangent{-u.y, u.x, 0.0};
    const Weights w = closest_on_triangle(q, a, b, c);
    const Vec3 d = q - at(w, a, b, c);
    double along = 0.0;
    const int zeros = (w[0] == 0.0) + (w[1] == 0.0) + (w[2] == 0.0);
    if (zeros == 0) {
      const double across = dot(normal, tangent);
      along = 1.0 - across * across / area2;
    } else if (zeros == 1) {
      const int skip = w[0] == 0.0 ? 0 : (w[1] == 0.0 ? 1 : 2);
      const Vec3 edge = *corner[(skip + 2) % 3] - *corner[(skip + 1) % 3];
      const double length2 = dot(edge, edge);
      const double component = dot(edge, tangent);
      if (length2 > 0.0) along = component * component / length2;
    }
    const double rate = radius * (1.0 - along) - dot(d, u);
    if (!(rate > 0.0)) return std::nullopt;
    const double slope = dot(d, tangent);
    if (slope < 0.0) {
      below = u;
      has_below = true;
    } else {
      above = u;
      has_above = true;
    }
    const double step = slope / rate;
    const bool bracketed = has_below && has_above;
    if (std::abs(step) <= kCircleAngleTolerance ||
        (bracketed && turn(below, above) <= kCircleAngleTolerance))
      return w;
    u = u - step * tangent;
    // s is smooth only between the points where p(θ) changes feature: where Newton's step
    // leaves the directions known to bracket the root, halve the angle between them instead.
    if (bracketed && !(turn(below, u) > 0.0 && turn(u, above) > 0.0)) u = below + above;
    u = u / norm(u);
  }
  return std::nullopt;
}

// The cylinder's distance has a curved kink where side and cap meet, so no finite candidate
// set is exact. Beside the side it is in closed form, and nearest a rim from outside
// circle_nearest finds it, certified by the convexity bound. Pressed into the cylinder the
// bisection above is exact; elsewhere candidates (the triangle's corners, its points nearest
// the centre, the axis and rim samples) and a compass search from the best cover it.
Weights cylinder_deepest(double radius, double half_length, const Vec3& a, const Vec3& b,
                         const Vec3& c, double floor) {
  // Beside the side, away from the caps, the distance is ρ − R, ρ the distance from the axis:
  // the deepest point is then the point of the triangle's shadow on the xy-plane nearest the
  // axis, in closed form. That holds when every corner is within |z| <= H (so is the whole
  // triangle: |z| is convex) and ρ − R there is at least the caps' largest |z| − H on the
  // triangle, its largest at a corner: then max(ρ − R, |z| − H), and the distance outside, is
  // ρ − R at that point and no less anywhere. A cloth hanging beside a round table's side takes
  // this path; the search below is for the rims.
  const double top = std::max({std::abs(a.z), std::abs(b.z), std::abs(c.z)});
  if (top <= half_length) {
    const Vec3 fa{a.x, a.y, 0.0}, fb{b.x, b.y, 0.0}, fc{c.x, c.y, 0.0};
    const Weights w = closest_on_triangle({0.0, 0.0, 0.0}, fa, fb, fc);
    if (norm(at(w, fa, fb, fc)) - radius >= top - half_length) return clean(w);
  }
  // The signed distance to a convex solid is convex, so over the triangle it is at least its
  // value at any point p plus the least reach of its normal n there towards the corners.
  const auto bound_at = [&](const Vec3& p, double value, const Vec3& n) {
    return value + std::min({dot(n, a - p), dot(n, b - p), dot(n, c - p)});
  };
  // Apart from the cylinder and nearest a rim, the deepest point is the triangle's point
  // nearest the rim's circle; the bound at it is its distance when its nearest point of the
  // cylinder is on that rim (the triangle then lies beyond the plane through it normal to
  // q − p), which certifies it. The rim of the triangle's middle's side, from the middle's
  // angle.
  const Vec3 centroid = (a + b + c) / 3.0;
  if (centroid.x != 0.0 || centroid.y != 0.0) {
    const Vec3 u{centroid.x, centroid.y, 0.0};
    const std::optional<Weights> w = circle_nearest(
        radius, centroid.z >= 0.0 ? half_length : -half_length, u / norm(u), a, b, c);
    if (w) {
      const Weights found = clean(*w);
      const Vec3 p = at(found, a, b, c);
      const Closest near = cylinder_closest(p, radius, half_length);
      if (near.distance > 0.0) {
        const double bound = bound_at(p, near.distance, near.normal);
        if (bound >= floor || near.distance - bound <= kCircleCertified * (radius + half_length))
          return found;
      }
    }
  }
  // 6 fixed candidates and the 2 x 16 rim samples.
  FixedList<Weights, 38> candidates{
      {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1.0 / 3, 1.0 / 3, 1.0 / 3}};
  candidates.push_back(closest_on_triangle({0.0, 0.0, 0.0}, a, b, c));
  candidates.push_back(
      closest_segment_triangle({0.0, 0.0, -half_length}, {0.0, 0.0, half_length}, a, b, c));
  // The rim samples' directions, computed once: their sines and cosines were 4 % of a round
  // table's run.
  constexpr int kRimSamples = 16;
  static const std::array<std::pair<double, double>, kRimSamples> rim = [] {
    std::array<std::pair<double, double>, kRimSamples> directions{};
    for (int j = 0; j < kRimSamples; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / kRimSamples;
      directions[static_cast<std::size_t>(j)] = {std::cos(phi), std::sin(phi)};
    }
    return directions;
  }();
  // Only the rim on the triangle's side of the middle, and only its samples within a sample's
  // spacing of the directions the triangle's corners lie in seen from the axis, can be where it
  // presses deepest: the others were 30 of 38 candidates on a round table's rim, the most
  // expensive cells of its run.
  const Vec3 middle{(a.x + b.x + c.x) / 3.0, (a.y + b.y + c.y) / 3.0, 0.0};
  const double middle_length = norm(middle);
  double widest = std::numbers::pi;
  if (middle_length > 0.0) {
    widest = 0.0;
    for (const Vec3* corner : {&a, &b, &c}) {
      const Vec3 flat{corner->x, corner->y, 0.0};
      const double length = norm(flat);
      const double cosine = length > 0.0 ? dot(flat, middle) / (length * middle_length) : -1.0;
      widest = std::max(widest, std::acos(std::clamp(cosine, -1.0, 1.0)));
    }
  }
  const double spacing = 2.0 * std::numbers::pi / kRimSamples;
  const double within = std::cos(std::min(std::numbers::pi, widest + spacing));
  const bool upper = std::max({a.z, b.z, c.z}) >= 0.0, lower = std::min({a.z, b.z, c.z}) <= 0.0;
  for (const auto& [cosine, sine] : rim) {
    if (middle_length > 0.0 &&
        (cosine * middle.x + sine * middle.y) / middle_length < within - 1e-12)
      continue;
    for (const double z : {-half_length, half_length})
      if (z > 0.0 ? upper : lower)
        candidates.push_back(closest_on_triangle({radius * cosine, radius * sine, z}, a, b, c));
  }
  const auto distance = [&](const Weights& w) {
    return cylinder_distance(at(w, a, b, c), radius, half_length);
  };
  Weights best = candidates.front();
  double best_value = kInfinity;
  for (const Weights& w : candidates) {
    const double value = distance(clean(w));
    if (value < best_value) {
      best_value = value;
      best = clean(w);
    }
  }
  if (best_value < 0.0) {
    const Weights pressed = cylinder_pressed(radius, half_length, a, b, c, best_value);
    const double value = distance(pressed);
    if (value < best_value) {
      best_value = value;
      best = pressed;
    }
  }
  // Else the compass search, which stops once the bound at its best point proves that no
  // point of the triangle comes closer than `floor`.
  const auto far_enough = [&](const Weights& w, double value) {
    if (value < floor) return false;
    const Vec3 p = at(w, a, b, c);
    return bound_at(p, value, cylinder_closest(p, radius, half_length).normal) >= floor;
  };
  return clean(compass_refine(best, best_value, distance, far_enough));
}

// The radius of the ball about the frame's origin that holds the shape.
double ball_radius(const Shape& shape) {
  switch (shape.kind) {
    case ShapeKind::plane:
      return kInfinity;
    case ShapeKind::sphere:
      return shape.radius;
    case ShapeKind::box:
      return norm(shape.half_extents);
    case ShapeKind::cylinder:
      return std::hypot(shape.radius, shape.half_length);
    case ShapeKind::capsule:
      return shape.half_length + shape.radius;
    case ShapeKind::mesh: {
      double radius = 0.0;
      for (const Vec3& v : shape.mesh->vertices) radius = std::max(radius, norm(v));
      return radius;
    }
  }
  throw std::logic_error("ball_radius: unknown shape kind");
}

}  // namespace

SolidGeometry::SolidGeometry(Shape shape) : shape_(std::move(shape)) {
  const auto positive = [](double x) { return x > 0.0 && std::isfinite(x); };
  const auto fail = [](const char* what) { throw std::invalid_argument(what); };
  switch (shape_.kind) {
    case ShapeKind::plane:
      break;
    case ShapeKind::sphere:
      if (!positive(shape_.radius)) fail("sphere: radius must be finite and > 0");
      break;
    case ShapeKind::box:
      if (!positive(shape_.half_extents.x) || !positive(shape_.half_extents.y) ||
          !positive(shape_.half_extents.z)) {
        fail("box: half extents must be finite and > 0");
      }
      break;
    case ShapeKind::cylinder:
    case ShapeKind::capsule:
      if (!positive(shape_.radius)) fail("cylinder or capsule: radius must be finite and > 0");
      if (!(shape_.half_length >= 0.0) || !std::isfinite(shape_.half_length)) {
        fail("cylinder or capsule: half_length must be finite and >= 0");
      }
      if (shape_.kind == ShapeKind::cylinder && shape_.half_length == 0.0) {
        fail("cylinder: half_length must be > 0");
      }
      break;
    case ShapeKind::mesh:
      if (!shape_.mesh || shape_.mesh->triangles.empty()) fail("mesh: no triangles");
      tree_ = std::make_unique<MeshTree>(*shape_.mesh);
      break;
  }
  bounding_radius_ = ball_radius(shape_);
}

SolidGeometry::~SolidGeometry() = default;
SolidGeometry::SolidGeometry(SolidGeometry&&) noexcept = default;
SolidGeometry& SolidGeometry::operator=(SolidGeometry&&) noexcept = default;

Closest SolidGeometry::closest_other(const Vec3& p) const {
  switch (shape_.kind) {
    case ShapeKind::plane:
    case ShapeKind::sphere:
      return closest(p);
    case ShapeKind::box:
      return box_closest(p, shape_.half_extents);
    case ShapeKind::cylinder:
      return cylinder_closest(p, shape_.radius, shape_.half_length);
    case ShapeKind::capsule:
      return capsule_closest(p, shape_.radius, shape_.half_length);
    case ShapeKind::mesh:
      return tree_->closest(p);
  }
  throw std::logic_error("SolidGeometry::closest: unknown shape kind");
}

// Advancement on the signed distance, which never steps past the surface: every point within
// the current gap of p lies outside the inflated solid. For the convex shapes the gap along a
// line is convex, so the Newton step gap / (−gap′) (gap′ from the normal, a subgradient) still
// never overshoots, converges quadratically instead of linearly on slanted approaches, and a
// gap that stops falling can never fall again. A mesh is not convex: it advances by
// gap / |b − a|, the step the 1-Lipschitz bound allows.
std::optional<double> SolidGeometry::first_contact(const Vec3& a, const Vec3& b,
                                                   double offset) const {
  constexpr int kMaxIterations = 200;
  const Vec3 d = b - a;
  const double length = norm(d);
  const double tolerance = kContactTolerance * std::max(length, offset);
  Closest nearest = closest(a);
  double gap = nearest.distance - offset;
  if (gap <= tolerance) return 0.0;
  if (length == 0.0) return std::nullopt;
  const bool convex = shape_.kind != ShapeKind::mesh;
  double t = 0.0;
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    double rate = length;
    if (convex) {
      rate = -dot(nearest.normal, d);
      if (rate <= 0.0) return std::nullopt;
    }
    t += gap / rate;
    if (t > 1.0) return std::nullopt;
    nearest = closest(a + t * d);
    gap = nearest.distance - offset;
    if (gap <= tolerance) return t;
  }
  // Only a mesh grazed at a shallow angle gets here: the segment is within its last gap of the
  // surface, and a contact reported slightly early is safer than a tunnel.
  return t;
}

std::array<double, 3> SolidGeometry::deepest_point(const Vec3& a, const Vec3& b, const Vec3& c,
                                                   double floor) const {
  switch (shape_.kind) {
    case ShapeKind::plane: {
      const std::array<double, 3> height{a.z, b.z, c.z};
      const auto lowest = std::min_element(height.begin(), height.end()) - height.begin();
      Weights w{0.0, 0.0, 0.0};
      w[lowest] = 1.0;
      return w;
    }
    case ShapeKind::sphere:
      // The distance grows with the distance to the centre.
      return clean(closest_on_triangle({0.0, 0.0, 0.0}, a, b, c));
    case ShapeKind::capsule:
      return clean(closest_segment_triangle({0.0, 0.0, -shape_.half_length},
                                            {0.0, 0.0, shape_.half_length}, a, b, c));
    case ShapeKind::box:
      return box_deepest(shape_.half_extents, a, b, c);
    case ShapeKind::cylinder:
      return cylinder_deepest(shape_.radius, shape_.half_length, a, b, c, floor);
    case ShapeKind::mesh: {
      // Sampled, not exact: a mesh's distance is not convex, so any local search could settle
      // in the wrong valley; a fixed lattice of quarters (the vertices and edge midpoints among
      // them) and the centroid find a mesh feature about a quarter of the triangle across.
      constexpr int kDivisions = 4;
      FixedList<Weights, 16> samples{{1.0 / 3, 1.0 / 3, 1.0 / 3}};
      for (int i = 0; i <= kDivisions; ++i) {
        for (int j = 0; i + j <= kDivisions; ++j) {
          samples.push_back({static_cast<double>(kDivisions - i - j) / kDivisions,
                             static_cast<double>(i) / kDivisions,
                             static_cast<double>(j) / kDivisions});
        }
      }
      Weights best = samples.front();
      double best_value = kInfinity;
      for (const Weights& w : samples) {
        const double value = tree_->closest(at(w, a, b, c)).distance;
        if (value < best_value) {
          best_value = value;
          best = w;
        }
      }
      return best;
    }
  }
  throw std::logic_error("SolidGeometry::deepest_point: unknown shape kind");
}

namespace {
// The smallest |x| over the values a linear function takes at a triangle's corners.
double smallest_magnitude(double a, double b, double c) {
  if ((a > 0.0 && b > 0.0 && c > 0.0) || (a < 0.0 && b < 0.0 && c < 0.0))
    return std::min({std::abs(a), std::abs(b), std::abs(c)});
  return 0.0;
}

// The distance from the z axis to triangle (a, b, c): from the origin to its projection on
// the xy plane, zero when that holds the origin, else along its nearest edge.
double axis_distance(const Vec3& a, const Vec3& b, const Vec3& c) {
  const std::array<std::array<double, 2>, 3> p{{{a.x, a.y}, {b.x, b.y}, {c.x, c.y}}};
  const auto side = [&](int i, int j) { return p[i][0] * p[j][1] - p[i][1] * p[j][0]; };
  const double s0 = side(0, 1), s1 = side(1, 2), s2 = side(2, 0);
  if ((s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0) || (s0 <= 0.0 && s1 <= 0.0 && s2 <= 0.0)) return 0.0;
  double nearest2 = kInfinity;
  for (int i = 0; i < 3; ++i) {
    const auto& u = p[static_cast<std::size_t>(i)];
    const auto& v = p[static_cast<std::size_t>((i + 1) % 3)];
    const double ex = v[0] - u[0], ey = v[1] - u[1];
    const double length2 = ex * ex + ey * ey;
    const double t =
        length2 > 0.0 ? std::clamp(-(u[0] * ex + u[1] * ey) / length2, 0.0, 1.0) : 0.0;
    const double x = u[0] + t * ex, y = u[1] + t * ey;
    nearest2 = std::min(nearest2, x * x + y * y);
  }
  return std::sqrt(nearest2);
}
}  // namespace

// The solid lies inside each slab |x_i| <= h_i (and a cylinder inside ρ <= R), so its signed
// distance is at least each of |x_i| − h_i (ρ − R), inside it as well as outside.
double SolidGeometry::lower_bound(const Vec3& a, const Vec3& b, const Vec3& c) const {
  switch (shape_.kind) {
    case ShapeKind::box: {
      const Vec3& h = shape_.half_extents;
      return std::max({smallest_magnitude(a.x, b.x, c.x) - h.x,
                       smallest_magnitude(a.y, b.y, c.y) - h.y,
                       smallest_magnitude(a.z, b.z, c.z) - h.z});
    }
    case ShapeKind::cylinder:
      return std::max(axis_distance(a, b, c) - shape_.radius,
                      smallest_magnitude(a.z, b.z, c.z) - shape_.half_length);
    default:
      return -kInfinity;
  }
}

Vec3 SolidGeometry::inertia_per_mass() const {
  const double r2 = shape_.radius * shape_.radius;
  const double h = shape_.half_length;
  switch (shape_.kind) {
    case ShapeKind::sphere:
      return {0.4 * r2, 0.4 * r2, 0.4 * r2};
    case ShapeKind::box: {
      const Vec3& e = shape_.half_extents;
      return {(e.y * e.y + e.z * e.z) / 3.0, (e.x * e.x + e.z * e.z) / 3.0,
              (e.x * e.x + e.y * e.y) / 3.0};
    }
    case ShapeKind::cylinder:
      // Length 2h: r²/4 + (2h)²/12 across the axis.
      return {0.25 * r2 + h * h / 3.0, 0.25 * r2 + h * h / 3.0, 0.5 * r2};
    case ShapeKind::capsule: {
      // Mass fractions of the cylinder (π r² 2h) and the two hemispheres (4/3 π r³). A
      // hemisphere about its flat face's centre has the full sphere's 2/5 r² per mass; its
      // centre of mass sits 3r/8 from that face, so shifting to its centre of mass and then to
      // the capsule's centre, h + 3r/8 away, gives 2/5 r² + h² + 3/4 h r across the axis.
      const double r = shape_.radius;
      const double cylinder = 2.0 * h;
      const double spheres = 4.0 / 3.0 * r;
      const double total = cylinder + spheres;
      const double across = (cylinder * (0.25 * r2 + h * h / 3.0) +
                             spheres * (0.4 * r2 + h * h + 0.75 * h * r)) / total;
      const double along = (cylinder * 0.5 * r2 + spheres * 0.4 * r2) / total;
      return {across, across, along};
    }
    case ShapeKind::plane:
    case ShapeKind::mesh:
      break;
  }
  throw std::logic_error("inertia_per_mass: a plane or mesh solid has no closed-form mass properties");
}

TriangleMesh SolidGeometry::surface(double plane_extent) const {
  switch (shape_.kind) {
    case ShapeKind::plane: {
      const double s = 0.5 * plane_extent;
      return {{{-s, -s, 0.0}, {s, -s, 0.0}, {s, s, 0.0}, {-s, s, 0.0}}, {{0, 1, 2}, {0, 2, 3}}};
    }
    case ShapeKind::sphere:
      return icosphere(shape_.radius);
    case ShapeKind::box:
      return box_surface(shape_.half_extents);
    case ShapeKind::cylinder: {
      const double r = shape_.radius;
      const double h = shape_.half_length;
      return revolution_surface({{0.0, h}, {r, h}, {r, -h}, {0.0, -h}}, kRoundSegments);
    }
    case ShapeKind::capsule: {
      const double r = shape_.radius;
      const double h = shape_.half_length;
      constexpr int kBandsPerCap = 4;
      std::vector<std::pair<double, double>> profile{{0.0, h + r}};
      for (int k = 1; k <= kBandsPerCap; ++k) {
        const double theta = 0.5 * std::numbers::pi * k / kBandsPerCap;
        profile.emplace_back(r * std::sin(theta), h + r * std::cos(theta));
      }
      // Without a cylinder between them the hemispheres share their equator.
      for (int k = h > 0.0 ? kBandsPerCap : kBandsPerCap - 1; k >= 1; --k) {
        const double theta = 0.5 * std::numbers::pi * k / kBandsPerCap;
        profile.emplace_back(r * std::sin(theta), -h - r * std::cos(theta));
      }
      profile.emplace_back(0.0, -h - r);
      return revolution_surface(profile, kRoundSegments);
    }
    case ShapeKind::mesh:
      return *shape_.mesh;
  }
  throw std::logic_error("SolidGeometry::surface: unknown shape kind");
}

}  // namespace cosserat
