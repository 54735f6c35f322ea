#pragma once
// Rigid shapes in their own frame and the rigid motions that place them (docs/contact.md,
// "Solids and their motion" and "Detection"): the geometric queries contact detection needs,
// nothing about time or response.

#include <array>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cosserat/grid/vec3.hpp"

namespace cosserat {

// A unit quaternion w + (x, y, z): the orientation of a solid.
struct Quaternion {
  double w = 1.0;
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
};
Quaternion operator*(const Quaternion& a, const Quaternion& b);
inline Quaternion conjugate(const Quaternion& q) { return {q.w, -q.x, -q.y, -q.z}; }
Quaternion normalized(const Quaternion& q);
// The rotation by `angle` radians about `axis` (normalised here; any length > 0).
Quaternion from_axis_angle(const Vec3& axis, double angle);
// The rotation by |rotation| radians about rotation/|rotation| (the identity for zero).
Quaternion from_rotation_vector(const Vec3& rotation);
// The shortest rotation taking unit vector a to unit vector b.
Quaternion rotation_between(const Vec3& a, const Vec3& b);
// Inline: contact rotates every node it tests into each solid's frame.
inline Vec3 rotate(const Quaternion& q, const Vec3& v) {
  const Vec3 u{q.x, q.y, q.z};
  const Vec3 t = 2.0 * cross(u, v);
  return v + q.w * t + cross(u, t);
}

// Where a solid's frame sits: world = position + R(orientation) local.
struct Pose {
  Vec3 position;
  Quaternion orientation;
  Vec3 to_world(const Vec3& local) const { return position + rotate(orientation, local); }
  Vec3 to_local(const Vec3& world) const {
    return rotate(conjugate(orientation), world - position);
  }
  Vec3 direction_to_world(const Vec3& local) const { return rotate(orientation, local); }
  Vec3 to_local_direction(const Vec3& world) const {
    return rotate(conjugate(orientation), world);
  }
};

struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise seen from outside
};

// Reads a closed triangle mesh from a Wavefront OBJ file (v and f lines; f may carry /vt/vn
// indices, negative indices count back). Throws std::runtime_error naming the file and what is
// wrong: missing or unreadable, a face that is not a triangle, an index out of range, no faces,
// an edge not shared by exactly two faces (not closed), inconsistent orientation.
TriangleMesh read_obj(const std::string& path);

enum class ShapeKind { plane, sphere, box, cylinder, capsule, mesh };

// A shape in its own frame:
//   plane     the half-space z <= 0 (outward normal +z)
//   sphere    radius about the origin
//   box       |x| <= half_extents.x, |y| <= ..., |z| <= ...
//   cylinder  axis z, radius, |z| <= half_length, capped
//   capsule   the points within radius of the segment (0, 0, ±half_length)
//   mesh      the closed mesh's inside, vertices in this frame
struct Shape {
  ShapeKind kind = ShapeKind::plane;
  double radius = 0.0;
  double half_length = 0.0;
  Vec3 half_extents;
  std::shared_ptr<const TriangleMesh> mesh;
};

// The nearest surface point to p: signed distance (negative inside) and the unit outward
// normal there, so the surface point is p − distance × normal.
struct Closest {
  double distance;
  Vec3 normal;
};

// A shape with what its queries need (a bounding-volume tree for a mesh); immutable, so one
// instance serves every thread.
class SolidGeometry {
 public:
  explicit SolidGeometry(Shape shape);
  ~SolidGeometry();
  SolidGeometry(SolidGeometry&&) noexcept;
  SolidGeometry& operator=(SolidGeometry&&) noexcept;

  const Shape& shape() const { return shape_; }

  // Inline for the plane and the sphere: contact asks it of every node it tests.
  Closest closest(const Vec3& p) const {
    if (shape_.kind == ShapeKind::plane) return {p.z, {0.0, 0.0, 1.0}};
    if (shape_.kind == ShapeKind::sphere) {
      const double r = norm(p);
      if (r == 0.0) return {-shape_.radius, {0.0, 0.0, 1.0}};
      return {r - shape_.radius, p / r};
    }
    return closest_other(p);
  }

  // Continuous detection (docs/contact.md, "Detection"): the smallest t in [0, 1] at which
  // a + t (b − a) is within `offset` of the shape (t = 0 when a already is), or nothing.
  // "Within" to kContactTolerance times the larger of |b − a| and the offset: far below any
  // response's own error, and reached in a few Newton steps.
  static constexpr double kContactTolerance = 1e-7;
  std::optional<double> first_contact(const Vec3& a, const Vec3& b, double offset) const;

  // The point of triangle (a, b, c) with the smallest signed distance to the shape, as
  // barycentric weights (summing to 1, each >= 0): where a solid smaller than a cell, or a
  // box's edge or corner, presses deepest into it. A search (the cylinder's) may stop early
  // once it has proven that no point of the triangle is closer than `floor`, and then returns
  // a point no closer than that instead of the deepest.
  std::array<double, 3> deepest_point(
      const Vec3& a, const Vec3& b, const Vec3& c,
      double floor = std::numeric_limits<double>::infinity()) const;

  // A lower bound of the signed distance over triangle (a, b, c), cheap next to
  // deepest_point: for a box and a cylinder the largest of the distances to the slabs (and the
  // infinite cylinder) whose intersection the solid is, each exact over the triangle; −∞ for
  // the other shapes.
  double lower_bound(const Vec3& a, const Vec3& b, const Vec3& c) const;

  // The radius of a ball about the frame's origin that holds the shape (infinite for a plane):
  // lets detection skip nodes far away cheaply.
  double bounding_radius() const { return bounding_radius_; }

  // Principal moments of inertia per unit mass, about the origin along the frame's axes, of a
  // solid of uniform density. Not for plane or mesh (throws std::logic_error).
  Vec3 inertia_per_mass() const;

  // The surface as triangles in this frame, for output; a plane is drawn as a square of side
  // `plane_extent` centred on the origin.
  TriangleMesh surface(double plane_extent) const;

 private:
  struct MeshTree;
  Closest closest_other(const Vec3& p) const;  // the box, cylinder, capsule and mesh
  Shape shape_;
  double bounding_radius_ = 0.0;
  std::unique_ptr<MeshTree> tree_;  // mesh only
};

}  // namespace cosserat
