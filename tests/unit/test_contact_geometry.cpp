// Geometry of rigid solids (docs/contact.md, "Solids and their motion" and "Detection"): every
// query checked against an independent construction (brute force over a sampled surface or segment,
// inside tests by inequalities, Monte Carlo integrals), not against numbers the implementation
// produced.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "cosserat/contact/geometry.hpp"

namespace cosserat {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

constexpr double kPi = std::numbers::pi;

Vec3 random_vector(std::mt19937_64& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  const double x = u(rng);
  const double y = u(rng);
  return {x, y, u(rng)};
}

Vec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  const double x = g(rng);
  const double y = g(rng);
  const Vec3 v{x, y, g(rng)};
  return v / norm(v);
}

Quaternion random_rotation(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  return from_axis_angle(random_unit(rng), angle(rng));
}

void expect_near(const Vec3& a, const Vec3& b, double tolerance) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

// ---- Quaternions and poses --------------------------------------------------------------

TEST(QuaternionTest, RotationsKeepLengthsComposeAndInvert) {
  std::mt19937_64 rng(1);
  for (int i = 0; i < 200; ++i) {
    const Quaternion p = random_rotation(rng);
    const Quaternion q = random_rotation(rng);
    const Vec3 v = random_vector(rng, 3.0);
    EXPECT_NEAR(norm(rotate(q, v)), norm(v), 1e-12);
    expect_near(rotate(conjugate(q), rotate(q, v)), v, 1e-12);
    expect_near(rotate(p * q, v), rotate(p, rotate(q, v)), 1e-12);
  }
}

TEST(QuaternionTest, AxisAngleTurnsRightHanded) {
  const Quaternion quarter = from_axis_angle({0.0, 0.0, 5.0}, 0.5 * kPi);
  expect_near(rotate(quarter, {1.0, 0.0, 0.0}), {0.0, 1.0, 0.0}, 1e-15);
  expect_near(rotate(quarter, {0.0, 1.0, 0.0}), {-1.0, 0.0, 0.0}, 1e-15);
  const Quaternion identity = from_rotation_vector({0.0, 0.0, 0.0});
  EXPECT_EQ(identity.w, 1.0);
  const Vec3 r{0.3, -0.4, 1.2};
  const Quaternion a = from_rotation_vector(r);
  const Quaternion b = from_axis_angle(r, norm(r));
  EXPECT_NEAR(a.w, b.w, 1e-15);
  expect_near({a.x, a.y, a.z}, {b.x, b.y, b.z}, 1e-15);
  // A rotation vector is left fixed by its own rotation.
  expect_near(rotate(a, r), r, 1e-14);
  const Quaternion n = normalized({2.0, 0.0, 0.0, 0.0});
  EXPECT_EQ(n.w, 1.0);
  EXPECT_THROW(from_axis_angle({0.0, 0.0, 0.0}, 1.0), std::invalid_argument);
}

TEST(QuaternionTest, RotationBetweenIsTheShortestIncludingOpposite) {
  std::mt19937_64 rng(2);
  std::vector<std::pair<Vec3, Vec3>> pairs{{{1, 0, 0}, {1, 0, 0}},
                                           {{1, 0, 0}, {-1, 0, 0}},
                                           {{0, 0, 1}, {0, 0, -1}},
                                           {{0.6, 0.8, 0}, {-0.6, -0.8, 0}}};
  for (int i = 0; i < 100; ++i) pairs.emplace_back(random_unit(rng), random_unit(rng));
  for (const auto& [a, b] : pairs) {
    const Quaternion q = rotation_between(a, b);
    EXPECT_NEAR(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z, 1.0, 1e-14);
    expect_near(rotate(q, a), b, 1e-12);
    // Shortest: turned by the angle between them, about an axis normal to both.
    const double angle = 2.0 * std::acos(std::clamp(std::abs(q.w), 0.0, 1.0));
    EXPECT_NEAR(angle, std::acos(std::clamp(dot(a, b), -1.0, 1.0)), 1e-7);
    EXPECT_NEAR(dot(Vec3{q.x, q.y, q.z}, a), 0.0, 1e-12);
  }
}

TEST(QuaternionTest, PoseToLocalInvertsToWorld) {
  std::mt19937_64 rng(3);
  for (int i = 0; i < 100; ++i) {
    const Pose pose{random_vector(rng, 10.0), random_rotation(rng)};
    const Vec3 p = random_vector(rng, 5.0);
    expect_near(pose.to_local(pose.to_world(p)), p, 1e-12);
    expect_near(pose.to_world(pose.to_local(p)), p, 1e-12);
    expect_near(pose.direction_to_world(p), pose.to_world(p) - pose.to_world({}), 1e-12);
  }
}

// ---- Shapes and their independent descriptions --------------------------------------------

Shape sphere(double r) { return {ShapeKind::sphere, r, 0.0, {}, nullptr}; }
Shape box(const Vec3& half) { return {ShapeKind::box, 0.0, 0.0, half, nullptr}; }
Shape cylinder(double r, double h) { return {ShapeKind::cylinder, r, h, {}, nullptr}; }
Shape capsule(double r, double h) { return {ShapeKind::capsule, r, h, {}, nullptr}; }
Shape plane() { return {}; }

// A shape with its inside written as inequalities and its surface sampled densely, so distances
// can be found by brute force.
struct Reference {
  std::string name;
  Shape shape;
  std::function<bool(const Vec3&)> inside;
  std::vector<Vec3> surface;  // samples
  double spacing;             // largest gap between neighbouring samples
  double volume;
  double scale;  // a length of the shape
};

void sample_disk(std::vector<Vec3>& out, double r, double z, double step) {
  for (double x = -r; x <= r + 1e-12; x += step) {
    for (double y = -r; y <= r + 1e-12; y += step) {
      if (x * x + y * y <= r * r) out.push_back({x, y, z});
    }
  }
  const int rim = static_cast<int>(std::ceil(2 * kPi * r / step));
  for (int j = 0; j < rim; ++j) {
    out.push_back({r * std::cos(2 * kPi * j / rim), r * std::sin(2 * kPi * j / rim), z});
  }
}

void sample_side(std::vector<Vec3>& out, double r, double h, double step) {
  const int around = static_cast<int>(std::ceil(2 * kPi * r / step));
  const int along = static_cast<int>(std::ceil(2 * h / step));
  for (int j = 0; j < around; ++j) {
    for (int k = 0; k <= along; ++k) {
      out.push_back({r * std::cos(2 * kPi * j / around), r * std::sin(2 * kPi * j / around),
                     -h + 2 * h * k / along});
    }
  }
}

void sample_sphere(std::vector<Vec3>& out, double r, const Vec3& centre, int count) {
  // Fibonacci points: near-uniform, spacing about sqrt(4π / count) r.
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / count;
    const double rho = std::sqrt(1.0 - z * z);
    const double phi = i * kPi * (3.0 - std::sqrt(5.0));
    out.push_back(centre + r * Vec3{rho * std::cos(phi), rho * std::sin(phi), z});
  }
}

std::vector<Reference> references() {
  std::vector<Reference> out;
  {
    Reference s{"sphere", sphere(0.7), [](const Vec3& p) { return norm(p) < 0.7; }, {}, 0, 0, 0.7};
    sample_sphere(s.surface, 0.7, {}, 40000);
    s.spacing = 0.7 * std::sqrt(4 * kPi / 40000) * 1.5;
    s.volume = 4.0 / 3.0 * kPi * std::pow(0.7, 3);
    out.push_back(std::move(s));
  }
  {
    const Vec3 h{1.0, 0.5, 0.3};
    Reference b{"box", box(h),
                [h](const Vec3& p) {
                  return std::abs(p.x) < h.x && std::abs(p.y) < h.y && std::abs(p.z) < h.z;
                },
                {}, 0.0, 8 * h.x * h.y * h.z, 0.3};
    const double step = 0.01;
    for (double u = -1.0; u <= 1.0 + 1e-12; u += step / 1.0) {
      for (double v = -1.0; v <= 1.0 + 1e-12; v += step / 1.0) {
        for (const double s : {-1.0, 1.0}) {
          b.surface.push_back({s * h.x, u * h.y, v * h.z});
          b.surface.push_back({u * h.x, s * h.y, v * h.z});
          b.surface.push_back({u * h.x, v * h.y, s * h.z});
        }
      }
    }
    b.spacing = step * 1.5;
    out.push_back(std::move(b));
  }
  {
    const double r = 0.4;
    const double h = 0.6;
    Reference c{"cylinder", cylinder(r, h),
                [=](const Vec3& p) { return std::hypot(p.x, p.y) < r && std::abs(p.z) < h; },
                {}, 0.0, kPi * r * r * 2 * h, r};
    const double step = 0.008;
    sample_side(c.surface, r, h, step);
    sample_disk(c.surface, r, h, step);
    sample_disk(c.surface, r, -h, step);
    c.spacing = step * 1.5;
    out.push_back(std::move(c));
  }
  {
    const double r = 0.3;
    const double h = 0.5;
    Reference c{"capsule", capsule(r, h),
                [=](const Vec3& p) {
                  const double z = std::clamp(p.z, -h, h);
                  return std::hypot(p.x, p.y, p.z - z) < r;
                },
                {}, 0.0, kPi * r * r * 2 * h + 4.0 / 3.0 * kPi * r * r * r, r};
    const double step = 0.006;
    sample_side(c.surface, r, h, step);
    std::vector<Vec3> caps;
    sample_sphere(caps, r, {0, 0, h}, 20000);
    sample_sphere(caps, r, {0, 0, -h}, 20000);
    for (const Vec3& p : caps) {
      if (std::abs(p.z) >= h) c.surface.push_back(p);
    }
    c.spacing = std::max(step, r * std::sqrt(4 * kPi / 20000)) * 1.5;
    out.push_back(std::move(c));
  }
  return out;
}

double brute_distance(const Reference& reference, const Vec3& p) {
  double d2 = std::numeric_limits<double>::infinity();
  for (const Vec3& s : reference.surface) d2 = std::min(d2, dot(p - s, p - s));
  return reference.inside(p) ? -std::sqrt(d2) : std::sqrt(d2);
}

TEST(GeometryTest, SignedDistanceMatchesBruteForceOverTheSurface) {
  std::mt19937_64 rng(4);
  for (const Reference& reference : references()) {
    SCOPED_TRACE(reference.name);
    const SolidGeometry geometry(reference.shape);
    for (int i = 0; i < 150; ++i) {
      const Vec3 p = random_vector(rng, 1.5);
      EXPECT_NEAR(geometry.closest(p).distance, brute_distance(reference, p), reference.spacing);
    }
  }
  const SolidGeometry floor(plane());
  EXPECT_EQ(floor.closest({3.0, -2.0, 0.25}).distance, 0.25);
  EXPECT_EQ(floor.closest({3.0, -2.0, -0.5}).distance, -0.5);
}

// The closest surface point is p − d n with n a unit outward normal: the distance vanishes
// there, and moving along n raises the distance at unit rate.
void expect_consistent_normals(const SolidGeometry& geometry, const Vec3& p, double scale) {
  const Closest c = geometry.closest(p);
  EXPECT_NEAR(norm(c.normal), 1.0, 1e-12);
  EXPECT_NEAR(geometry.closest(p - c.distance * c.normal).distance, 0.0, 1e-9 * scale);
  const double step = 1e-4 * scale;
  EXPECT_NEAR(geometry.closest(p + step * c.normal).distance, c.distance + step, 1e-9 * scale);
}

TEST(GeometryTest, NormalsAreUnitOutwardAndLeadToTheSurface) {
  std::mt19937_64 rng(5);
  std::vector<Shape> shapes{plane(), sphere(0.7), box({1.0, 0.5, 0.3}), cylinder(0.4, 0.6),
                            capsule(0.3, 0.5)};
  for (const Shape& shape : shapes) {
    const SolidGeometry geometry(shape);
    for (int i = 0; i < 500; ++i) expect_consistent_normals(geometry, random_vector(rng, 1.5), 1.0);
  }
  // Degenerate points still give a unit normal, the same every time.
  for (const Shape& shape : shapes) {
    const SolidGeometry geometry(shape);
    const Closest centre = geometry.closest({});
    EXPECT_NEAR(norm(centre.normal), 1.0, 1e-15);
    EXPECT_EQ(geometry.closest({}).normal.z, centre.normal.z);
  }
}

TEST(GeometryTest, BoundingRadiusHoldsTheShape) {
  std::mt19937_64 rng(6);
  for (const Reference& reference : references()) {
    SCOPED_TRACE(reference.name);
    const SolidGeometry geometry(reference.shape);
    const double radius = geometry.bounding_radius();
    double farthest = 0.0;
    for (const Vec3& s : reference.surface) farthest = std::max(farthest, norm(s));
    EXPECT_LE(farthest, radius + 1e-12);
    EXPECT_GE(farthest, radius - reference.spacing);  // and is not much larger
  }
  EXPECT_TRUE(std::isinf(SolidGeometry(plane()).bounding_radius()));
}

// ---- Meshes ---------------------------------------------------------------------------------

class ObjTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    directory_ = fs::temp_directory_path() / ("cosserat_test_obj_" + std::to_string(getpid()) +
                                              "_" + test->test_suite_name() + "_" + test->name());
    fs::remove_all(directory_);
    fs::create_directories(directory_);
  }
  void TearDown() override { fs::remove_all(directory_); }

  std::string write(const std::string& name, const std::string& text) const {
    const fs::path path = directory_ / name;
    std::ofstream(path) << text;
    return path.string();
  }

  std::string write_mesh(const std::string& name, const TriangleMesh& mesh) const {
    std::string text = "# written by the test\n";
    for (const Vec3& v : mesh.vertices) {
      char line[128];
      std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", v.x, v.y, v.z);
      text += line;
    }
    for (const auto& [a, b, c] : mesh.triangles) {
      text += "f " + std::to_string(a + 1) + " " + std::to_string(b + 1) + " " +
              std::to_string(c + 1) + "\n";
    }
    return write(name, text);
  }

  // The message read_obj throws for `text`, or "" if it reads.
  std::string error_of(const std::string& text) const {
    const std::string path = write("bad.obj", text);
    try {
      read_obj(path);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  }

  fs::path directory_;
};

using GeometryMeshTest = ObjTest;

// The eight corners of [-1, 1]³ scaled by `half`, and its twelve faces counter-clockwise seen
// from outside, as OBJ lines.
std::string cube_vertices(const Vec3& half) {
  std::string text;
  for (int i = 0; i < 8; ++i) {
    text += "v " + std::to_string((i & 1) ? half.x : -half.x) + " " +
            std::to_string((i & 2) ? half.y : -half.y) + " " +
            std::to_string((i & 4) ? half.z : -half.z) + "\n";
  }
  return text;
}
const std::vector<std::array<int, 3>> kCubeFaces{
    {1, 5, 7}, {1, 7, 3}, {2, 4, 8}, {2, 8, 6}, {1, 2, 6}, {1, 6, 5},
    {3, 7, 8}, {3, 8, 4}, {1, 3, 4}, {1, 4, 2}, {5, 6, 8}, {5, 8, 7}};
std::string cube_faces() {
  std::string text;
  for (const auto& [a, b, c] : kCubeFaces) {
    text += "f " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "\n";
  }
  return text;
}

double signed_volume(const TriangleMesh& mesh) {
  double volume = 0.0;
  for (const auto& [a, b, c] : mesh.triangles) {
    volume += dot(mesh.vertices[a], cross(mesh.vertices[b], mesh.vertices[c])) / 6.0;
  }
  return volume;
}

TEST_F(ObjTest, ReadsACubeWithSlashesAndNegativeIndices) {
  std::string text = "o cube\n" + cube_vertices({1.0, 1.0, 1.0}) + "vt 0 0\nvn 0 0 1\n";
  // Two faces written with v/vt/vn, v//vn and negative indices (−8 is the first vertex).
  for (std::size_t i = 0; i < kCubeFaces.size(); ++i) {
    const auto& [a, b, c] = kCubeFaces[i];
    if (i == 0) {
      text += "f " + std::to_string(a) + "/1/1 " + std::to_string(b) + "//1 " + std::to_string(c) + "/1\n";
    } else if (i == 1) {
      text += "f " + std::to_string(a - 9) + " " + std::to_string(b - 9) + "/1 " +
              std::to_string(c - 9) + "  # negative\n";
    } else {
      text += "f " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "\n";
    }
  }
  const TriangleMesh mesh = read_obj(write("cube.obj", text));
  ASSERT_EQ(mesh.vertices.size(), 8u);
  ASSERT_EQ(mesh.triangles.size(), 12u);
  EXPECT_EQ(mesh.triangles[0], (std::array<int, 3>{0, 4, 6}));
  EXPECT_EQ(mesh.triangles[1], (std::array<int, 3>{0, 6, 2}));
  EXPECT_NEAR(signed_volume(mesh), 8.0, 1e-12);
}

TEST_F(ObjTest, TurnsAConsistentlyInwardMeshOutward) {
  std::string text = cube_vertices({1.0, 1.0, 1.0});
  for (const auto& [a, b, c] : kCubeFaces) {
    text += "f " + std::to_string(a) + " " + std::to_string(c) + " " + std::to_string(b) + "\n";
  }
  EXPECT_NEAR(signed_volume(read_obj(write("inward.obj", text))), 8.0, 1e-12);
}

TEST_F(ObjTest, EachFaultIsNamedWithTheFile) {
  const std::string missing = (directory_ / "nowhere.obj").string();
  try {
    read_obj(missing);
    ADD_FAILURE() << "a missing file was read";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr(missing), HasSubstr("cannot open")));
  }
  EXPECT_THAT(error_of(""), HasSubstr("no faces"));
  EXPECT_THAT(error_of(cube_vertices({1, 1, 1})), HasSubstr("no faces"));
  EXPECT_THAT(error_of(cube_vertices({1, 1, 1}) + "f 1 2 4 3\n"),
              AllOf(HasSubstr("bad.obj:9:"), HasSubstr("4 vertices"), HasSubstr("only triangles")));
  EXPECT_THAT(error_of(cube_vertices({1, 1, 1}) + cube_faces() + "f 1 2 9\n"),
              AllOf(HasSubstr("bad.obj:21:"), HasSubstr("9"), HasSubstr("out of range")));
  EXPECT_THAT(error_of(cube_vertices({1, 1, 1}) + "f 1 2 -9\n"),
              AllOf(HasSubstr("bad.obj:9:"), HasSubstr("out of range")));
  EXPECT_THAT(error_of(cube_vertices({1, 1, 1}) + "f 1 0 2\n"),
              AllOf(HasSubstr("bad.obj:9:"), HasSubstr("'0'")));
  EXPECT_THAT(error_of("v 1 2\nf 1 1 1\n"), AllOf(HasSubstr("bad.obj:1:"), HasSubstr("three coordinates")));
  EXPECT_THAT(error_of("v 1 2 nan\n"), HasSubstr("not a finite number"));
  // One face missing leaves the three edges around the hole with one face each.
  std::string open = cube_vertices({1, 1, 1});
  for (std::size_t i = 1; i < kCubeFaces.size(); ++i) {
    const auto& [a, b, c] = kCubeFaces[i];
    open += "f " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "\n";
  }
  EXPECT_THAT(error_of(open), AllOf(HasSubstr("bad.obj"), HasSubstr("not closed"), HasSubstr("1 face,")));
  // A face flipped: closed, but two faces run an edge the same way.
  std::string flipped = cube_vertices({1, 1, 1}) + "f 1 7 5\n";
  for (std::size_t i = 1; i < kCubeFaces.size(); ++i) {
    const auto& [a, b, c] = kCubeFaces[i];
    flipped += "f " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "\n";
  }
  EXPECT_THAT(error_of(flipped), AllOf(HasSubstr("bad.obj"), HasSubstr("inconsistent orientation")));
  // Three faces on one edge.
  EXPECT_THAT(error_of(cube_vertices({1, 1, 1}) + cube_faces() + "f 1 5 2\n"),
              HasSubstr("not closed"));
}

TEST_F(GeometryMeshTest, ACubeMeshHasTheBoxDistance) {
  const Vec3 half{1.0, 0.5, 0.25};
  auto mesh = std::make_shared<const TriangleMesh>(
      read_obj(write("box.obj", cube_vertices(half) + cube_faces())));
  const SolidGeometry from_mesh(Shape{ShapeKind::mesh, 0.0, 0.0, {}, mesh});
  const SolidGeometry analytic(box(half));
  EXPECT_NEAR(from_mesh.bounding_radius(), norm(half), 1e-12);
  std::mt19937_64 rng(7);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 p = random_vector(rng, 1.5);
    const Closest m = from_mesh.closest(p);
    const Closest a = analytic.closest(p);
    EXPECT_NEAR(m.distance, a.distance, 1e-12);
    EXPECT_NEAR(norm(m.normal), 1.0, 1e-12);
    // Inside, the normal is the nearest face's unless two faces tie.
    std::array<double, 3> q{std::abs(p.x) - half.x, std::abs(p.y) - half.y, std::abs(p.z) - half.z};
    std::sort(q.begin(), q.end());
    if (a.distance > 0.0 || q[2] - q[1] > 1e-9) expect_near(m.normal, a.normal, 1e-9);
  }
  // On a face: distance 0, the face's normal.
  const Closest on = from_mesh.closest({0.3, 0.1, 0.25});
  EXPECT_EQ(on.distance, 0.0);
  expect_near(on.normal, {0.0, 0.0, 1.0}, 1e-15);
  EXPECT_THROW(from_mesh.inertia_per_mass(), std::logic_error);
  EXPECT_EQ(from_mesh.surface(1.0).triangles.size(), 12u);
}

TEST_F(GeometryMeshTest, AnIcosphereMeshIsNearlyTheSphere) {
  const double r = 0.8;
  const TriangleMesh surface = SolidGeometry(sphere(r)).surface(0.0);
  const SolidGeometry from_mesh(
      Shape{ShapeKind::mesh, 0.0, 0.0, {}, std::make_shared<const TriangleMesh>(read_obj(write_mesh("ball.obj", surface)))});
  // The flat faces sit at most this far inside the sphere.
  double sag = 0.0;
  for (const auto& [i, j, k] : surface.triangles) {
    const Vec3& a = surface.vertices[i];
    const Vec3 n = cross(surface.vertices[j] - a, surface.vertices[k] - a);
    sag = std::max(sag, r - dot(a, n) / norm(n));
  }
  std::mt19937_64 rng(8);
  for (int i = 0; i < 300; ++i) {
    const Vec3 p = random_vector(rng, 1.5);
    const Closest c = from_mesh.closest(p);
    EXPECT_NEAR(c.distance, norm(p) - r, sag);
    expect_consistent_normals(from_mesh, p, 1.0);
  }
}

TEST_F(GeometryMeshTest, FirstContactAndDeepestPointOnAMesh) {
  const Vec3 half{1.0, 0.5, 0.25};
  const SolidGeometry from_mesh(Shape{ShapeKind::mesh, 0.0, 0.0, {}, std::make_shared<const TriangleMesh>(
      read_obj(write("box.obj", cube_vertices(half) + cube_faces())))});
  const SolidGeometry analytic(box(half));
  std::mt19937_64 rng(9);
  for (int i = 0; i < 100; ++i) {
    const Vec3 a = random_vector(rng, 2.0);
    const Vec3 b = random_vector(rng, 2.0);
    const auto m = from_mesh.first_contact(a, b, 0.05);
    const auto x = analytic.first_contact(a, b, 0.05);
    ASSERT_EQ(m.has_value(), x.has_value());
    if (m) {
      EXPECT_NEAR(*m, *x, 1e-6);
    }
  }
  // A triangle through the box's middle: some sample lies at the deepest depth, −0.25.
  const std::array<double, 3> w =
      from_mesh.deepest_point({-3.0, -3.0, 0.0}, {3.0, -3.0, 0.0}, {0.0, 3.0, 0.0});
  const Vec3 p = w[0] * Vec3{-3.0, -3.0, 0.0} + w[1] * Vec3{3.0, -3.0, 0.0} + w[2] * Vec3{0.0, 3.0, 0.0};
  EXPECT_NEAR(w[0] + w[1] + w[2], 1.0, 1e-15);
  EXPECT_LT(from_mesh.closest(p).distance, 0.0);
}

// ---- Continuous detection ----------------------------------------------------------------

TEST(GeometryTest, FirstContactCatchesAThinSphere) {
  const SolidGeometry ball(sphere(0.01));
  const auto through = ball.first_contact({-0.5, 0.0, 0.0}, {0.5, 0.0, 0.0}, 0.0);
  ASSERT_TRUE(through.has_value());
  EXPECT_NEAR(*through, 0.49, 1e-7);
  const auto inflated = ball.first_contact({-0.5, 0.0, 0.0}, {0.5, 0.0, 0.0}, 0.002);
  ASSERT_TRUE(inflated.has_value());
  EXPECT_NEAR(*inflated, 0.488, 1e-7);
  // Off centre: the entry is where the line meets the sphere.
  const double y = 0.006;
  const auto slanted = ball.first_contact({-0.5, y, 0.0}, {0.5, y, 0.0}, 0.0);
  ASSERT_TRUE(slanted.has_value());
  EXPECT_NEAR(*slanted, 0.5 - std::sqrt(0.01 * 0.01 - y * y), 1e-7);
  EXPECT_FALSE(ball.first_contact({-0.5, 0.02, 0.0}, {0.5, 0.02, 0.0}, 0.0).has_value());
  EXPECT_FALSE(ball.first_contact({-0.5, 0.0, 0.0}, {-0.02, 0.0, 0.0}, 0.0).has_value());
  EXPECT_EQ(ball.first_contact({0.005, 0.0, 0.0}, {0.5, 0.0, 0.0}, 0.0), 0.0);
  EXPECT_FALSE(ball.first_contact({0.5, 0.0, 0.0}, {0.5, 0.0, 0.0}, 0.0).has_value());
  const SolidGeometry floor(plane());
  EXPECT_NEAR(*floor.first_contact({0, 0, 1.0}, {1, 0, -1.0}, 0.1), 0.45, 1e-12);
}

// Brute force along the segment: the reported t must have reached the inflated surface, and
// no sample before it may be inside; a segment reported clear must have no sample inside.
TEST(GeometryTest, FirstContactNeverTunnelsAndFindsTheEntry) {
  std::mt19937_64 rng(10);
  std::uniform_real_distribution<double> offsets(0.0, 0.1);
  for (const Reference& reference : references()) {
    SCOPED_TRACE(reference.name);
    const SolidGeometry geometry(reference.shape);
    int contacts = 0;
    for (int i = 0; i < 300; ++i) {
      const Vec3 a = random_vector(rng, 1.6);
      const Vec3 b = random_vector(rng, 1.6);
      const double offset = offsets(rng);
      const auto t = geometry.first_contact(a, b, offset);
      const double tolerance = 1e-6 * std::max(norm(b - a), offset);
      constexpr int kSamples = 4000;
      const double until = t ? *t : 1.0;
      for (int k = 0; k <= kSamples; ++k) {
        const double s = until * k / kSamples;
        if (t && s >= *t) break;
        ASSERT_GT(geometry.closest(a + s * (b - a)).distance - offset, -1e-9) << "t " << s;
      }
      if (t) {
        ++contacts;
        EXPECT_LE(geometry.closest(a + *t * (b - a)).distance - offset, tolerance);
      }
    }
    EXPECT_GT(contacts, 30);
  }
}

// ---- Deepest point on a triangle -----------------------------------------------------------

Vec3 at(const std::array<double, 3>& w, const Vec3& a, const Vec3& b, const Vec3& c) {
  return w[0] * a + w[1] * b + w[2] * c;
}

TEST(GeometryTest, DeepestPointOfASmallSphereUnderABigTriangleIsTheFoot) {
  const SolidGeometry ball(sphere(0.05));
  const Vec3 a{-2.0, -1.0, 0.03};
  const Vec3 b{2.0, -1.0, 0.03};
  const Vec3 c{0.0, 2.0, 0.03};
  const auto w = ball.deepest_point(a, b, c);
  expect_near(at(w, a, b, c), {0.0, 0.0, 0.03}, 1e-12);
  // No node of the triangle is anywhere near the sphere.
  EXPECT_GT(ball.closest(a).distance, 1.0);
}

TEST(GeometryTest, DeepestPointOfABoxCornerIsTheCornersProjection) {
  // A cube's corner (1, 1, 1) pressed 0.05 through a triangle normal to the diagonal.
  const SolidGeometry cube(box({1.0, 1.0, 1.0}));
  const Vec3 n = Vec3{1.0, 1.0, 1.0} / std::sqrt(3.0);
  const Vec3 foot = Vec3{1.0, 1.0, 1.0} - 0.05 * n;
  const Vec3 u = cross(n, {0.0, 0.0, 1.0}) / norm(cross(n, {0.0, 0.0, 1.0}));
  const Vec3 v = cross(n, u);
  const Vec3 a = foot + 2.0 * u - 0.7 * v;
  const Vec3 b = foot - 1.5 * u - 1.1 * v;
  const Vec3 c = foot + 0.2 * u + 2.4 * v;
  const auto w = cube.deepest_point(a, b, c);
  expect_near(at(w, a, b, c), foot, 1e-12);
  EXPECT_NEAR(cube.closest(at(w, a, b, c)).distance, -0.05 / std::sqrt(3.0), 1e-12);
}

// The smallest signed distance to the shape over a lattice of triangle (a, b, c), `divisions`
// steps along each side, its corners and edges included.
double lattice_distance(const SolidGeometry& geometry, const Vec3& a, const Vec3& b, const Vec3& c,
                        int divisions) {
  double lattice = std::numeric_limits<double>::infinity();
  for (int j = 0; j <= divisions; ++j)
    for (int k = 0; j + k <= divisions; ++k) {
      const std::array<double, 3> s{1.0 - double(j + k) / divisions, double(j) / divisions,
                                    double(k) / divisions};
      lattice = std::min(lattice, geometry.closest(at(s, a, b, c)).distance);
    }
  return lattice;
}

// Against the best of a fine lattice of the triangle: exact methods never lose to it, nor does
// the cylinder's where the triangle presses into it; apart from it the cylinder's search may
// stop a little short.
TEST(GeometryTest, DeepestPointBeatsAFineLattice) {
  std::mt19937_64 rng(11);
  std::vector<Shape> shapes{plane(), sphere(0.7), box({1.0, 0.5, 0.3}), cylinder(0.4, 0.6),
                            capsule(0.3, 0.5)};
  for (const Shape& shape : shapes) {
    const SolidGeometry geometry(shape);
    SCOPED_TRACE(static_cast<int>(shape.kind));
    for (int i = 0; i < 200; ++i) {
      const Vec3 centre = random_vector(rng, 0.8);
      const double size = i % 2 == 0 ? 0.3 : 1.5;
      const Vec3 a = centre + random_vector(rng, size);
      const Vec3 b = centre + random_vector(rng, size);
      const Vec3 c = centre + random_vector(rng, size);
      const auto w = geometry.deepest_point(a, b, c);
      EXPECT_NEAR(w[0] + w[1] + w[2], 1.0, 1e-14);
      EXPECT_GE(std::min({w[0], w[1], w[2]}), 0.0);
      const double found = geometry.closest(at(w, a, b, c)).distance;
      const double lattice = lattice_distance(geometry, a, b, c, 80);
      const double slack = shape.kind == ShapeKind::cylinder && lattice > 0.0 ? 1e-4 : 1e-12;
      EXPECT_LE(found, lattice + slack);
    }
  }
}

// The smallest signed distance over triangle (a, b, c) by a lattice zoomed in on its best
// point: each level takes the cells around the best point so far, 20 times smaller, eight
// times. A distance at a point of the triangle, so never below the smallest; on a smooth
// minimum within far less than 1e-12 of it.
double zoomed_distance(const SolidGeometry& geometry, const Vec3& a, const Vec3& b, const Vec3& c) {
  double u0 = 0.0, v0 = 0.0, width = 1.0, best = std::numeric_limits<double>::infinity();
  constexpr int kDivisions = 40;
  for (int level = 0; level < 9; ++level) {
    double bu = u0, bv = v0;
    const double cell = width / kDivisions;
    for (int i = -kDivisions; i <= kDivisions; ++i)
      for (int j = -kDivisions; j <= kDivisions; ++j) {
        const double u = u0 + i * cell, v = v0 + j * cell;
        if (u < 0.0 || v < 0.0 || u + v > 1.0) continue;
        const double d = geometry.closest(at({1.0 - u - v, u, v}, a, b, c)).distance;
        if (d < best) {
          best = d;
          bu = u;
          bv = v;
        }
      }
    u0 = bu;
    v0 = bv;
    width = 2.0 * cell;
  }
  return best;
}

// Nearest a cylinder's rim from outside, the deepest point is the triangle's point nearest the
// rim's circle (Newton's method on the rim's angle, certified by the convexity bound): its
// distance is the triangle's smallest to 1e-12, where a compass search on the weights stops
// about 1e-10 short (15 of these triangles fail with the compass alone). Small triangles, as
// a cloth's cells, tilted every way just above and beyond the top rim: the first 100 that
// stay outside the cylinder.
TEST(GeometryTest, DeepestPointNearACylindersRimIsTheNearestToItsCircle) {
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  std::uniform_real_distribution<double> gap(0.002, 0.01);
  const SolidGeometry geometry(cylinder(0.55, 0.375));
  int tested = 0;
  for (int i = 0; tested < 100 && i < 1000; ++i) {
    const double phi = angle(rng);
    const Vec3 out{std::cos(phi), std::sin(phi), 0.0};
    const Vec3 centre = Vec3{0.55 * out.x, 0.55 * out.y, 0.375} + gap(rng) * out +
                        Vec3{0.0, 0.0, gap(rng)} + random_vector(rng, 0.004);
    const Vec3 a = centre + random_vector(rng, 0.03);
    const Vec3 b = centre + random_vector(rng, 0.03);
    const Vec3 c = centre + random_vector(rng, 0.03);
    const double zoomed = zoomed_distance(geometry, a, b, c);
    if (zoomed <= 0.0) continue;
    ++tested;
    const auto w = geometry.deepest_point(a, b, c);
    EXPECT_LE(geometry.closest(at(w, a, b, c)).distance, zoomed + 1e-12) << "triangle " << i;
  }
  EXPECT_EQ(tested, 100);
}

// With a floor, the search may stop once it has proven the triangle no closer than the floor:
// it then returns a point at least that far, and the lattice agrees that none is closer.
// Where some point is closer than the floor, the answer is the one without a floor, to the
// bit. Small triangles over a cylinder's rim, where the cell pass searches (docs/contact.md,
// "Cost"), with floors just below and above the distance found.
TEST(GeometryTest, DeepestPointWithAFloorStopsOnlyWhenNoPointIsCloser) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  const SolidGeometry geometry(cylinder(0.4, 0.6));
  int stopped = 0, searched = 0;
  for (int i = 0; i < 300; ++i) {
    const double phi = angle(rng);
    const Vec3 rim{0.4 * std::cos(phi), 0.4 * std::sin(phi), 0.6};
    const Vec3 centre = rim + random_vector(rng, 0.01);
    const Vec3 a = centre + random_vector(rng, 0.03);
    const Vec3 b = centre + random_vector(rng, 0.03);
    const Vec3 c = centre + random_vector(rng, 0.03);
    const auto deepest = geometry.deepest_point(a, b, c);
    const double found = geometry.closest(at(deepest, a, b, c)).distance;
    const double lattice = lattice_distance(geometry, a, b, c, 60);
    for (const double shift : {-1e-3, -1e-6, 1e-6, 1e-3}) {
      const double floor = found + shift;
      const auto w = geometry.deepest_point(a, b, c, floor);
      if (w == deepest) {
        ++searched;
        continue;
      }
      ++stopped;
      EXPECT_GE(geometry.closest(at(w, a, b, c)).distance, floor) << "triangle " << i;
      EXPECT_GE(lattice, floor - 1e-12) << "triangle " << i;
    }
  }
  // Both ways taken (the stops can only be for the floors below the distance found).
  EXPECT_GT(stopped, 40);
  EXPECT_GT(searched, 600);
}

// The triangle's lower bound of the distance never exceeds the distance anywhere on it (a fine
// lattice, its corners included), for triangles small and large, inside, across and outside
// the box and the cylinder; and it is the distance itself for a triangle above a face, where
// it lets the cell pass skip the deepest-point search: the lowest corner's height over the
// face.
TEST(GeometryTest, TheTrianglesLowerBoundHoldsEverywhereOnIt) {
  std::mt19937_64 rng(12);
  for (const Shape& shape : {box({1.0, 0.5, 0.3}), cylinder(0.4, 0.6)}) {
    const SolidGeometry geometry(shape);
    SCOPED_TRACE(static_cast<int>(shape.kind));
    for (int i = 0; i < 400; ++i) {
      const Vec3 centre = random_vector(rng, 1.0);
      const double size = i % 2 == 0 ? 0.05 : 1.0;
      const Vec3 a = centre + random_vector(rng, size);
      const Vec3 b = centre + random_vector(rng, size);
      const Vec3 c = centre + random_vector(rng, size);
      const double bound = geometry.lower_bound(a, b, c);
      EXPECT_LE(bound, lattice_distance(geometry, a, b, c, 60) + 1e-12) << "triangle " << i;
    }
    // A small triangle over the top face, its corners 2, 3 and 5 mm above it.
    const double top = shape.kind == ShapeKind::box ? 0.3 : 0.6;
    EXPECT_NEAR(geometry.lower_bound({0.0, 0.0, top + 0.003}, {0.03, 0.0, top + 0.002},
                                     {0.0, 0.03, top + 0.005}),
                0.002, 1e-15);
  }
}

// ---- Mass properties --------------------------------------------------------------------

TEST(GeometryTest, InertiaMatchesClosedFormsAndMonteCarlo) {
  const Vec3 sphere_inertia = SolidGeometry(sphere(2.0)).inertia_per_mass();
  expect_near(sphere_inertia, {1.6, 1.6, 1.6}, 1e-15);
  const Vec3 box_inertia = SolidGeometry(box({1.0, 2.0, 3.0})).inertia_per_mass();
  // A box of sides 2, 4, 6: (b² + c²) / 12 with full sides.
  expect_near(box_inertia, {(16.0 + 36.0) / 12.0, (4.0 + 36.0) / 12.0, (4.0 + 16.0) / 12.0}, 1e-14);
  const Vec3 rod = SolidGeometry(cylinder(0.5, 1.0)).inertia_per_mass();
  expect_near(rod, {0.25 * 0.25 + 4.0 / 12.0, 0.25 * 0.25 + 4.0 / 12.0, 0.125}, 1e-15);

  std::mt19937_64 rng(12);
  for (const Reference& reference : references()) {
    SCOPED_TRACE(reference.name);
    const SolidGeometry geometry(reference.shape);
    const double extent = geometry.bounding_radius();
    std::uniform_real_distribution<double> u(-extent, extent);
    Vec3 sum;
    int inside = 0;
    for (int i = 0; i < 400000; ++i) {
      const double x = u(rng);
      const double y = u(rng);
      const Vec3 p{x, y, u(rng)};
      if (!reference.inside(p)) continue;
      ++inside;
      sum += Vec3{p.y * p.y + p.z * p.z, p.x * p.x + p.z * p.z, p.x * p.x + p.y * p.y};
    }
    const Vec3 expected = sum / inside;
    const Vec3 inertia = geometry.inertia_per_mass();
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(inertia[k], expected[k], 0.01 * expected[k]);
  }
  EXPECT_THROW(SolidGeometry(plane()).inertia_per_mass(), std::logic_error);
}

// ---- Surfaces for output -------------------------------------------------------------------

// Closed and consistently oriented: every directed edge once, and its reverse once.
void expect_closed(const TriangleMesh& mesh) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& [a, b, c] : mesh.triangles) {
    ++directed[{a, b}];
    ++directed[{b, c}];
    ++directed[{c, a}];
  }
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1) << edge.first << "-" << edge.second;
    EXPECT_EQ(directed.count({edge.second, edge.first}), 1u) << edge.first << "-" << edge.second;
  }
}

TEST(GeometryTest, SurfacesAreClosedOutwardAndOnTheShape) {
  for (const Reference& reference : references()) {
    SCOPED_TRACE(reference.name);
    const SolidGeometry geometry(reference.shape);
    const TriangleMesh mesh = geometry.surface(1.0);
    EXPECT_GE(mesh.triangles.size(), 12u);
    EXPECT_LE(mesh.triangles.size(), 1100u);
    expect_closed(mesh);
    for (const Vec3& v : mesh.vertices) EXPECT_NEAR(geometry.closest(v).distance, 0.0, 1e-12);
    // Inscribed: a little less volume than the shape, never more.
    const double volume = signed_volume(mesh);
    EXPECT_LE(volume, reference.volume * (1.0 + 1e-12));
    EXPECT_GT(volume, reference.volume * 0.95);
  }
  const TriangleMesh square = SolidGeometry(plane()).surface(4.0);
  ASSERT_EQ(square.triangles.size(), 2u);
  for (const auto& [a, b, c] : square.triangles) {
    const Vec3 n = cross(square.vertices[b] - square.vertices[a], square.vertices[c] - square.vertices[a]);
    EXPECT_NEAR(n.z, 16.0, 1e-12);  // twice the triangle's area, facing +z
  }
  expect_closed(SolidGeometry(capsule(0.3, 0.0)).surface(0.0));
}

}  // namespace
}  // namespace cosserat
