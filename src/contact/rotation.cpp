// Quaternions and rotations (geometry.hpp): on their own, without the shapes' queries, since the
// scene loader needs them to place solids and its fuzz targets build without CGAL.

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "cosserat/contact/geometry.hpp"

namespace cosserat {

Quaternion operator*(const Quaternion& a, const Quaternion& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
          a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
          a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

Quaternion normalized(const Quaternion& q) {
  const double length = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (!(length > 0.0) || !std::isfinite(length)) {
    throw std::invalid_argument("normalized: a quaternion of zero or non-finite length has no orientation");
  }
  return {q.w / length, q.x / length, q.y / length, q.z / length};
}

Quaternion from_axis_angle(const Vec3& axis, double angle) {
  const double length = norm(axis);
  if (!(length > 0.0) || !std::isfinite(length)) {
    throw std::invalid_argument("from_axis_angle: the axis must have a finite length > 0");
  }
  const Vec3 v = (std::sin(0.5 * angle) / length) * axis;
  return {std::cos(0.5 * angle), v.x, v.y, v.z};
}

Quaternion from_rotation_vector(const Vec3& rotation) {
  const double angle = norm(rotation);
  if (angle == 0.0) return {};
  return from_axis_angle(rotation, angle);
}

Quaternion rotation_between(const Vec3& a, const Vec3& b) {
  const double c = dot(a, b);
  // (1 + a·b, a × b) halves the angle without trigonometry, but vanishes for opposite vectors,
  // where every axis normal to a is a shortest rotation: take the one normal to a and to the
  // coordinate axis a is least aligned with, so the choice is deterministic.
  if (1.0 + c > 1e-14) {
    const Vec3 v = cross(a, b);
    return normalized({1.0 + c, v.x, v.y, v.z});
  }
  const Vec3 e = std::abs(a.x) <= std::abs(a.y) && std::abs(a.x) <= std::abs(a.z)
                     ? Vec3{1.0, 0.0, 0.0}
                     : (std::abs(a.y) <= std::abs(a.z) ? Vec3{0.0, 1.0, 0.0} : Vec3{0.0, 0.0, 1.0});
  const Vec3 axis = cross(a, e);
  return from_axis_angle(axis, std::numbers::pi);
}

}  // namespace cosserat
