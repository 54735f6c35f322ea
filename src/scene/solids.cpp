// [[solid]] blocks: a solid's shape and where it starts, how it moves, and how cloth meets it.
// Which keys a block may hold depends on its shape and motion, so a key that belongs to another
// shape or motion is refused with that reason rather than as unknown: "a sphere has no
// half_extents" tells a user more than a list of allowed keys.

#include "solids.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string_view>

namespace cosserat::scene_detail {
namespace {

struct KeysOf {
  std::string_view name;
  std::vector<std::string_view> keys;
};

const std::vector<std::string_view> kCommonKeys{"name",     "shape",       "motion",
                                                "friction", "restitution", "thickness"};

// In ShapeKind order.
const std::array<KeysOf, 6> kShapes{{
    {"plane", {"point", "normal"}},
    {"sphere", {"center", "radius"}},
    {"box", {"center", "half_extents", "orientation"}},
    {"cylinder", {"center", "axis", "radius", "half_length"}},
    {"capsule", {"ends", "radius"}},
    {"mesh", {"file", "position", "orientation", "scale"}},
}};

// In SolidMotion order.
const std::array<KeysOf, 3> kMotions{{
    {solid_motion_name(SolidMotion::fixed), {}},
    {solid_motion_name(SolidMotion::kinematic),
     {"velocity", "angular_velocity", "start_time", "end_time", "keyframes"}},
    {solid_motion_name(SolidMotion::free),
     {"mass", "initial_velocity", "initial_angular_velocity", "drag", "force",
      "force_until_contact"}},
}};

bool holds(const std::vector<std::string_view>& keys, std::string_view key) {
  return std::find(keys.begin(), keys.end(), key) != keys.end();
}

template <std::size_t N>
std::string names_of(const std::array<KeysOf, N>& table) {
  std::vector<std::string_view> names;
  for (const auto& entry : table) names.push_back(entry.name);
  return fmt::format("{}", fmt::join(names, ", "));
}

// The index into `table` of the name `entry` holds.
template <std::size_t N>
std::size_t one_of(const Entry& entry, const std::array<KeysOf, N>& table, std::string_view what) {
  const std::string name = entry.string();
  for (std::size_t i = 0; i < N; ++i)
    if (table[i].name == name) return i;
  entry.fail(fmt::format("unknown {} \"{}\"; allowed: {}", what, name, names_of(table)));
}

// Every key given must be common or belong to this shape or this motion.
void check_keys(const Table& block, const KeysOf& shape, const KeysOf& motion) {
  for (const auto& key : block.keys()) {
    if (holds(kCommonKeys, key) || holds(shape.keys, key) || holds(motion.keys, key)) continue;
    const Entry entry = *block.find(key);
    for (const auto& other : kShapes)
      if (holds(other.keys, key)) {
        entry.fail(fmt::format("a {} has no {} (it is a key of other shapes); a {} takes: {}",
                               shape.name, key, shape.name, fmt::join(shape.keys, ", ")));
      }
    for (const auto& other : kMotions)
      if (holds(other.keys, key)) {
        entry.fail(fmt::format("is for motion = \"{}\", and this solid's motion is \"{}\"",
                               other.name, motion.name));
      }
    std::vector<std::string_view> allowed = kCommonKeys;
    allowed.insert(allowed.end(), shape.keys.begin(), shape.keys.end());
    allowed.insert(allowed.end(), motion.keys.begin(), motion.keys.end());
    entry.fail(fmt::format("unknown key; allowed here: {}", fmt::join(allowed, ", ")));
  }
}

// A direction, normalised. Scaled by its largest entry first so that huge or tiny entries
// neither overflow nor underflow the norm.
Vec3 unit_direction(const Entry& entry, std::string_view what) {
  const Vec3 given = entry.vector3();
  const double largest = std::max({std::abs(given.x), std::abs(given.y), std::abs(given.z)});
  if (largest == 0.0) entry.fail(fmt::format("must not be zero-length: it is {}", what));
  const Vec3 scaled = given / largest;
  return scaled / norm(scaled);
}

Vec3 required_point(const Table& block, std::string_view name, std::string_view what) {
  return block.require(name, fmt::format("an array of 3 numbers [x, y, z]: {} (m)", what))
      .vector3();
}

double required_positive(const Table& block, std::string_view name, std::string_view what) {
  return positive(block.require(name, fmt::format("a number > 0: {}", what)));
}

// { axis = [x, y, z], angle = radians }: a rotation of the solid from its shape's own frame.
Quaternion rotation(const Entry& entry) {
  const Table table = entry.table();
  table.allow({"axis", "angle"});
  const Vec3 axis = unit_direction(
      table.require("axis", "an array of 3 numbers [x, y, z], not zero-length: the axis of the "
                            "rotation"),
      "the axis of the rotation");
  const double angle = table.require("angle", "a number: the angle of the rotation in radians")
                           .number();
  return from_axis_angle(axis, angle);
}

Quaternion optional_rotation(const Table& block) {
  if (const auto orientation = block.find("orientation")) return rotation(*orientation);
  return {};
}

// The shape's local +z is given in the world as `direction`.
constexpr Vec3 kLocalZ{0.0, 0.0, 1.0};

void read_capsule(const Table& block, SolidSpec& solid) {
  const char* form =
      "an array of 2 points [[x, y, z], [x, y, z]]: the ends of the capsule's axis (m)";
  const Entry ends = block.require("ends", form);
  const auto points = ends.elements(2, form);
  const Vec3 a = points[0].vector3();
  const Vec3 b = points[1].vector3();
  const Vec3 along = b - a;
  const double largest = std::max({std::abs(along.x), std::abs(along.y), std::abs(along.z)});
  if (largest == 0.0) ends.fail("the two ends must differ: the capsule's axis runs between them");
  const Vec3 scaled = along / largest;
  const double length = largest * norm(scaled);
  if (!std::isfinite(length)) ends.fail("the ends are too far apart for a double to hold");
  solid.shape.half_length = 0.5 * length;
  solid.pose.position = a + 0.5 * along;
  solid.pose.orientation = rotation_between(kLocalZ, scaled / norm(scaled));
}

void read_mesh(const Table& block, const Scene& scene, SolidSpec& solid) {
  const Entry file =
      block.require("file", "a string: the closed triangle mesh's OBJ file, relative to the "
                            "scene file's directory");
  const std::string name = file.string();
  if (name.empty()) file.fail("must name an OBJ file, got an empty string");
  const std::filesystem::path path = std::filesystem::path(scene.path).parent_path() / name;
  TriangleMesh mesh;
  try {
    mesh = read_obj(path.string());
  } catch (const std::runtime_error& error) {
    file.fail(fmt::format("cannot use the mesh: {}", error.what()));
  }
  double scale = 1.0;
  const auto scale_entry = block.find("scale");
  if (scale_entry) scale = positive(*scale_entry);
  for (auto& vertex : mesh.vertices) {
    vertex = scale * vertex;
    if (!std::isfinite(vertex.x) || !std::isfinite(vertex.y) || !std::isfinite(vertex.z)) {
      if (scale_entry) scale_entry->fail("takes a vertex beyond a double's range");
      file.fail(fmt::format("cannot use the mesh {}: a vertex is not a finite number",
                            path.string()));
    }
  }
  solid.shape.mesh = std::make_shared<const TriangleMesh>(std::move(mesh));
  if (const auto position = block.find("position")) solid.pose.position = position->vector3();
  solid.pose.orientation = optional_rotation(block);
}

void read_shape(const Table& block, const Scene& scene, SolidSpec& solid) {
  Shape& shape = solid.shape;
  Pose& pose = solid.pose;
  switch (shape.kind) {
    case ShapeKind::plane: {
      pose.position = required_point(block, "point", "a point on the plane");
      const Vec3 normal = unit_direction(
          block.require("normal", "an array of 3 numbers [x, y, z], not zero-length: the "
                                  "plane's outward normal (the half-space behind it is solid)"),
          "the plane's normal");
      pose.orientation = rotation_between(kLocalZ, normal);
      break;
    }
    case ShapeKind::sphere:
      pose.position = required_point(block, "center", "the sphere's centre");
      shape.radius = required_positive(block, "radius", "the sphere's radius in metres");
      break;
    case ShapeKind::box: {
      pose.position = required_point(block, "center", "the box's centre");
      const char* form = "an array of 3 numbers [a, b, c], each > 0: half the box's edges (m)";
      const auto half = block.require("half_extents", form).elements(3, form);
      shape.half_extents = {positive(half[0]), positive(half[1]), positive(half[2])};
      pose.orientation = optional_rotation(block);
      break;
    }
    case ShapeKind::cylinder: {
      pose.position = required_point(block, "center", "the cylinder's centre");
      const Vec3 axis = unit_direction(
          block.require("axis", "an array of 3 numbers [x, y, z], not zero-length: the "
                                "direction of the cylinder's axis"),
          "the direction of the cylinder's axis");
      pose.orientation = rotation_between(kLocalZ, axis);
      shape.radius = required_positive(block, "radius", "the cylinder's radius in metres");
      shape.half_length = required_positive(
          block, "half_length", "half the cylinder's length along its axis in metres");
      break;
    }
    case ShapeKind::capsule:
      read_capsule(block, solid);
      shape.radius = required_positive(block, "radius", "the capsule's radius in metres");
      break;
    case ShapeKind::mesh:
      read_mesh(block, scene, solid);
      break;
  }
}

void read_kinematic(const Table& block, SolidSpec& solid) {
  KinematicPath& path = solid.path;
  if (const auto keyframes = block.find("keyframes")) {
    for (const char* name : {"velocity", "angular_velocity", "start_time", "end_time"})
      if (const auto entry = block.find(name)) {
        entry->fail("is not taken with keyframes: a keyframed path is its keyframes alone");
      }
    const auto frames = keyframes->elements(
        0, "an array of at least 2 tables [{ time = s, position = [x, y, z], orientation = "
           "{ axis = [x, y, z], angle = radians } }, ...]");
    if (frames.size() < 2) {
      keyframes->fail(fmt::format("needs at least 2 keyframes, got {}", frames.size()));
    }
    for (const auto& element : frames) {
      const Table frame = element.table();
      frame.allow({"time", "position", "orientation"});
      const Entry time = frame.require("time", "a number >= 0: the keyframe's time in seconds");
      Keyframe keyframe;
      keyframe.time = non_negative(time);
      if (!path.keyframes.empty() && !(keyframe.time > path.keyframes.back().time)) {
        time.fail(fmt::format("keyframe times must increase strictly: got {} after {}",
                              keyframe.time, path.keyframes.back().time));
      }
      keyframe.position = required_point(frame, "position", "where the solid is at this time");
      // Relative to the orientation the shape keys give (a cylinder's axis, a plane's normal).
      keyframe.orientation = optional_rotation(frame) * solid.pose.orientation;
      path.keyframes.push_back(keyframe);
    }
    // Held before the first keyframe, whose time is >= 0: it is the pose at time 0.
    solid.pose = {path.keyframes.front().position, path.keyframes.front().orientation};
    return;
  }
  const auto velocity = block.find("velocity");
  const auto angular_velocity = block.find("angular_velocity");
  if (!velocity && !angular_velocity) {
    block.missing("velocity", "a kinematic solid moves by velocity and angular_velocity, or "
                              "by keyframes");
  }
  if (velocity) path.velocity = velocity->vector3();
  if (angular_velocity) path.angular_velocity = angular_velocity->vector3();
  if (const auto start = block.find("start_time")) path.start_time = non_negative(*start);
  if (const auto end = block.find("end_time")) {
    path.end_time = non_negative(*end);
    if (path.start_time > path.end_time) {
      end->fail(
          fmt::format("must be >= start_time ({} s), got {}", path.start_time, path.end_time));
    }
  }
}

void read_free(const Table& block, SolidSpec& solid) {
  FreeBody& body = solid.body;
  body.mass = required_positive(block, "mass", "the body's mass in kg");
  if (const auto v = block.find("initial_velocity")) body.initial_velocity = v->vector3();
  if (const auto w = block.find("initial_angular_velocity")) {
    body.initial_angular_velocity = w->vector3();
  }
  if (const auto drag = block.find("drag")) body.drag = non_negative(*drag);
  if (const auto force = block.find("force")) body.force = force->vector3();
  if (const auto until = block.find("force_until_contact")) {
    body.force_until_contact = until->boolean();
  }
}

SolidSpec read_solid(const Table& block, std::size_t index, const Scene& scene) {
  SolidSpec solid;
  const Entry shape_entry = block.require(
      "shape", fmt::format("the solid's shape, one of {}", names_of(kShapes)));
  const std::size_t shape = one_of(shape_entry, kShapes, "shape");
  std::size_t motion = 0;
  const auto motion_entry = block.find("motion");
  if (motion_entry) motion = one_of(*motion_entry, kMotions, "motion");
  check_keys(block, kShapes[shape], kMotions[motion]);
  const auto kind = static_cast<ShapeKind>(shape);
  if (motion_entry && static_cast<SolidMotion>(motion) == SolidMotion::free &&
      (kind == ShapeKind::plane || kind == ShapeKind::mesh)) {
    // Only these four have closed-form mass properties (SolidGeometry::inertia_per_mass).
    motion_entry->fail(fmt::format(
        "a free solid must be a sphere, box, cylinder or capsule, got a {}", kShapes[shape].name));
  }

  solid.name = fmt::format("solid[{}]", index);
  if (const auto name = block.find("name")) solid.name = name->string();
  solid.shape.kind = kind;
  read_shape(block, scene, solid);

  solid.motion = static_cast<SolidMotion>(motion);
  if (solid.motion == SolidMotion::kinematic) read_kinematic(block, solid);
  if (solid.motion == SolidMotion::free) read_free(block, solid);

  if (const auto friction = block.find("friction")) solid.friction = non_negative(*friction);
  if (const auto restitution = block.find("restitution")) {
    solid.restitution = restitution->number();
    if (!(solid.restitution >= 0.0 && solid.restitution <= 1.0)) {
      restitution->fail(fmt::format("must be in [0, 1] (0: no bounce, 1: elastic), got {}",
                                    solid.restitution));
    }
  }
  // Small beside a cell, so cloth resting on a solid sits visibly on it, yet not zero, so
  // round-off in the response cannot leave a node on the wrong side.
  solid.thickness = 0.05 * std::min(scene.h1(), scene.h2());
  if (const auto thickness = block.find("thickness")) solid.thickness = non_negative(*thickness);
  return solid;
}

}  // namespace

std::vector<SolidSpec> read_solids(const Entry& blocks, const Scene& scene) {
  std::vector<SolidSpec> solids;
  const auto tables = blocks.tables("solid");
  for (std::size_t i = 0; i < tables.size(); ++i) solids.push_back(read_solid(tables[i], i, scene));
  return solids;
}

}  // namespace cosserat::scene_detail
