#pragma once
// A rigid solid as a scene describes it (docs/contact.md, "Solids and their motion";
// docs/scene-format.md, "Solids"): its shape and where it starts, how it moves, and how cloth
// meets it.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cosserat/contact/geometry.hpp"

namespace cosserat {

enum class SolidMotion { fixed, kinematic, free };

// The motion's name in scene files and run summaries.
constexpr std::string_view solid_motion_name(SolidMotion motion) {
  constexpr std::string_view names[] = {"fixed", "kinematic", "free"};
  return names[static_cast<int>(motion)];
}

// A kinematic solid's prescribed path: either a constant velocity and angular velocity between
// start_time and end_time (at rest before and after, where it got to), or keyframes of pose,
// linear in position and spherical-linear in orientation between them, held outside them.
struct Keyframe {
  double time = 0.0;
  Vec3 position;
  Quaternion orientation;
};
struct KinematicPath {
  Vec3 velocity;          // m/s
  Vec3 angular_velocity;  // rad/s, world frame
  double start_time = 0.0;
  double end_time = 1e300;
  std::vector<Keyframe> keyframes;  // when not empty, replaces the velocities
};

// A free solid: a rigid body of uniform density under gravity, linear drag and an optional
// constant push, exchanging momentum with the cloth.
struct FreeBody {
  double mass = 0.0;  // kg
  Vec3 initial_velocity;
  Vec3 initial_angular_velocity;  // rad/s, world frame
  double drag = 0.0;              // N·s/m: force −drag × v
  Vec3 force;                     // N, constant, at the centre of mass
  bool force_until_contact = false;  // the push stops at the body's first contact
};

struct SolidSpec {
  std::string name;  // "solid[i]" unless the scene names it
  Shape shape;
  Pose pose;  // at time 0; the frame of `shape`
  SolidMotion motion = SolidMotion::fixed;
  KinematicPath path;  // kinematic only
  FreeBody body;       // free only
  double friction = 0.3;     // Coulomb μ >= 0
  double restitution = 0.0;  // e in [0, 1]
  double thickness = 0.0;    // m, contact offset: the cloth rests this far from the surface
};

}  // namespace cosserat
