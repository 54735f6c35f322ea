// [[solid]] blocks of the scene loader (docs/scene-format.md "Solids"): each shape gives the
// Shape and Pose that place it where the scene says, defaults are the documented ones, and every
// bad input is one SceneError naming the key and what is allowed.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "cosserat/scene/scene.hpp"

namespace cosserat {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr const char* kPath = "scenes/test.toml";
constexpr double kTight = 1e-12;

// A valid scene without solids; h1 = 10/9 m, h2 = 5/11 m.
std::string scene_with(const std::string& solids) {
  return "[grid]\nnodes = [10, 12]\nsize = [10.0, 5.0]\n"
         "[material]\nmass = 10.0\nzeta = 100.0\nxi = 0.3\nphi = 0.001\n"
         "[time]\ndt = 0.001\nsteps = 1000\n\n" +
         solids;
}

std::vector<SolidSpec> solids_of(const std::string& solids) {
  return parse_scene(scene_with(solids), kPath).solids;
}

SolidSpec solid_of(const std::string& block) {
  const auto solids = solids_of("[[solid]]\n" + block);
  EXPECT_EQ(solids.size(), 1u);
  return solids.at(0);
}

// The message of the SceneError that parsing must throw: one line, from the scene file.
std::string error_of(const std::string& block, const std::vector<std::string>& overrides = {}) {
  try {
    parse_scene(scene_with("[[solid]]\n" + block), kPath, overrides);
  } catch (const SceneError& error) {
    const std::string message = error.what();
    EXPECT_THAT(message, StartsWith(kPath));
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    return message;
  }
  ADD_FAILURE() << "expected a SceneError for\n" << block;
  return {};
}

void expect_near(const Vec3& got, const Vec3& want, double tolerance = kTight) {
  EXPECT_LT(norm(got - want), tolerance) << "got (" << got.x << ", " << got.y << ", " << got.z
                                         << "), want (" << want.x << ", " << want.y << ", "
                                         << want.z << ")";
}

// A unit quaternion rotates without scaling.
void expect_unit(const Quaternion& q) {
  EXPECT_NEAR(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z, 1.0, kTight);
}

constexpr const char* kSphere = "shape = \"sphere\"\ncenter = [0, 1, 0]\nradius = 0.5\n";

// ---------------------------------------------------------------------------------------------
// Shapes

TEST(SceneSolids, NoSolidBlockMeansNoSolids) {
  EXPECT_TRUE(parse_scene(scene_with(""), kPath).solids.empty());
}

TEST(SceneSolids, PlaneSitsOnItsPointWithLocalZAlongTheNormal) {
  const SolidSpec plane = solid_of("shape = \"plane\"\npoint = [1, 2, 3]\nnormal = [0, 5, 0]\n");
  EXPECT_EQ(plane.shape.kind, ShapeKind::plane);
  expect_near(plane.pose.position, {1, 2, 3});
  expect_unit(plane.pose.orientation);
  expect_near(plane.pose.direction_to_world({0, 0, 1}), {0, 1, 0});
  // The half-space behind the normal is solid: local z < 0 there.
  EXPECT_LT(plane.pose.to_local({1, 1.5, 3}).z, 0.0);
  EXPECT_GT(plane.pose.to_local({4, 2.5, -7}).z, 0.0);
}

TEST(SceneSolids, PlaneFacingDownIsNotTheIdentity) {
  const SolidSpec plane = solid_of("shape = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 0, -2]\n");
  expect_near(plane.pose.direction_to_world({0, 0, 1}), {0, 0, -1});
}

TEST(SceneSolids, SphereHasTheDocumentedDefaults) {
  const SolidSpec sphere = solid_of(kSphere);
  EXPECT_EQ(sphere.name, "solid[0]");
  EXPECT_EQ(sphere.shape.kind, ShapeKind::sphere);
  EXPECT_EQ(sphere.shape.radius, 0.5);
  expect_near(sphere.pose.position, {0, 1, 0});
  EXPECT_EQ(sphere.motion, SolidMotion::fixed);
  EXPECT_EQ(sphere.friction, 0.3);
  EXPECT_EQ(sphere.restitution, 0.0);
  // 0.05 of the smaller spacing, h2 = 5/11 m.
  EXPECT_DOUBLE_EQ(sphere.thickness, 0.05 * 5.0 / 11.0);
  EXPECT_TRUE(sphere.path.keyframes.empty());
  EXPECT_FALSE(sphere.shape.mesh);
}

TEST(SceneSolids, ContactKeysAndNamesAreRead) {
  const auto solids = solids_of(std::string("[[solid]]\nname = \"ball\"\n") + kSphere +
                                "friction = 0.8\nrestitution = 1\nthickness = 0.01\n"
                                "[[solid]]\n" + kSphere + "friction = 0\nthickness = 0\n");
  ASSERT_EQ(solids.size(), 2u);
  EXPECT_EQ(solids[0].name, "ball");
  EXPECT_EQ(solids[0].friction, 0.8);
  EXPECT_EQ(solids[0].restitution, 1.0);
  EXPECT_EQ(solids[0].thickness, 0.01);
  EXPECT_EQ(solids[1].name, "solid[1]");
  EXPECT_EQ(solids[1].friction, 0.0);
  EXPECT_EQ(solids[1].thickness, 0.0);
}

TEST(SceneSolids, BoxIsTurnedByItsOrientation) {
  const SolidSpec box = solid_of(
      "shape = \"box\"\ncenter = [1, 0, 0]\nhalf_extents = [0.5, 0.25, 2]\n"
      "orientation = { axis = [0, 0, 3], angle = " +
      std::to_string(std::numbers::pi / 2) + " }\n");
  EXPECT_EQ(box.shape.kind, ShapeKind::box);
  expect_near(box.shape.half_extents, {0.5, 0.25, 2});
  expect_unit(box.pose.orientation);
  // A quarter turn about z: the local corner (a, b, c) goes to (1 − b, a, c).
  expect_near(box.pose.to_world({0.5, 0.25, 2}), {0.75, 0.5, 2}, 1e-6);
}

TEST(SceneSolids, BoxWithoutOrientationIsAxisAligned) {
  const SolidSpec box = solid_of("shape = \"box\"\ncenter = [0, 0, 0]\nhalf_extents = [1, 2, 3]\n");
  expect_near(box.pose.to_world({1, 2, 3}), {1, 2, 3});
}

TEST(SceneSolids, CylinderAxisIsLocalZ) {
  const SolidSpec cylinder = solid_of(
      "shape = \"cylinder\"\ncenter = [0, 1, 0]\naxis = [2, 0, 0]\nradius = 0.2\n"
      "half_length = 1.5\n");
  EXPECT_EQ(cylinder.shape.kind, ShapeKind::cylinder);
  EXPECT_EQ(cylinder.shape.radius, 0.2);
  EXPECT_EQ(cylinder.shape.half_length, 1.5);
  expect_unit(cylinder.pose.orientation);
  expect_near(cylinder.pose.direction_to_world({0, 0, 1}), {1, 0, 0});
  expect_near(cylinder.pose.to_world({0, 0, -1.5}), {-1.5, 1, 0});
}

TEST(SceneSolids, CapsuleEndsAreLocalPlusMinusHalfLength) {
  const SolidSpec capsule =
      solid_of("shape = \"capsule\"\nends = [[1, 0, 0], [3, 2, -1]]\nradius = 0.1\n");
  EXPECT_EQ(capsule.shape.kind, ShapeKind::capsule);
  EXPECT_EQ(capsule.shape.radius, 0.1);
  EXPECT_DOUBLE_EQ(capsule.shape.half_length, 1.5);  // |(2, 2, −1)| = 3
  expect_near(capsule.pose.position, {2, 1, -0.5});
  expect_near(capsule.pose.to_world({0, 0, -1.5}), {1, 0, 0});
  expect_near(capsule.pose.to_world({0, 0, 1.5}), {3, 2, -1});
}

// ---------------------------------------------------------------------------------------------
// Meshes: OBJ files beside a scene file in a directory of the test's own.

// A tetrahedron, counter-clockwise seen from outside.
constexpr const char* kTetrahedron =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
    "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

class SceneSolidMesh : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("cosserat_solids_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "meshes");
  }
  void TearDown() override { fs::remove_all(dir_); }

  void write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
  }
  // The scene file sits in dir_, so `file` is relative to dir_.
  Scene load(const std::string& block) const {
    write("scene.toml", scene_with("[[solid]]\n" + block));
    return load_scene((dir_ / "scene.toml").string());
  }
  std::string error_of(const std::string& block) const {
    try {
      load(block);
    } catch (const SceneError& error) {
      const std::string message = error.what();
      EXPECT_THAT(message, StartsWith((dir_ / "scene.toml").string()));
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
      return message;
    }
    ADD_FAILURE() << "expected a SceneError for\n" << block;
    return {};
  }

  fs::path dir_;
};

TEST_F(SceneSolidMesh, FileIsRelativeToTheSceneAndScaled) {
  write("meshes/tetra.obj", kTetrahedron);
  const Scene scene = load(
      "shape = \"mesh\"\nfile = \"meshes/tetra.obj\"\nscale = 2\nposition = [0, 1, 0]\n"
      "orientation = { axis = [0, 1, 0], angle = " +
      std::to_string(std::numbers::pi) + " }\n");
  const SolidSpec& mesh = scene.solids.at(0);
  EXPECT_EQ(mesh.shape.kind, ShapeKind::mesh);
  ASSERT_TRUE(mesh.shape.mesh);
  ASSERT_EQ(mesh.shape.mesh->vertices.size(), 4u);
  EXPECT_EQ(mesh.shape.mesh->triangles.size(), 4u);
  expect_near(mesh.shape.mesh->vertices[1], {2, 0, 0});
  expect_near(mesh.shape.mesh->vertices[3], {0, 0, 2});
  // A half turn about y: local (2, 0, 0) goes to (−2, 0, 0), then up by 1.
  expect_near(mesh.pose.to_world(mesh.shape.mesh->vertices[1]), {-2, 1, 0}, 1e-6);
}

TEST_F(SceneSolidMesh, DefaultsToTheOriginUnscaled) {
  write("tetra.obj", kTetrahedron);
  const SolidSpec mesh = load("shape = \"mesh\"\nfile = \"tetra.obj\"\n").solids.at(0);
  expect_near(mesh.pose.to_world(mesh.shape.mesh->vertices[2]), {0, 1, 0});
}

TEST_F(SceneSolidMesh, MissingFileNamesTheKey) {
  EXPECT_THAT(error_of("shape = \"mesh\"\nfile = \"absent.obj\"\n"),
              AllOf(HasSubstr("key 'solid[0].file'"), HasSubstr("absent.obj")));
}

TEST_F(SceneSolidMesh, OpenMeshIsRefused) {
  write("open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n");
  EXPECT_THAT(error_of("shape = \"mesh\"\nfile = \"open.obj\"\n"),
              AllOf(HasSubstr("key 'solid[0].file'"), HasSubstr("open.obj"), HasSubstr("closed")));
}

TEST_F(SceneSolidMesh, QuadFaceIsRefused) {
  write("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  EXPECT_THAT(error_of("shape = \"mesh\"\nfile = \"quad.obj\"\n"),
              AllOf(HasSubstr("key 'solid[0].file'"), HasSubstr("quad.obj"),
                    HasSubstr("triangle")));
}

TEST_F(SceneSolidMesh, NonPositiveScaleIsRefused) {
  write("tetra.obj", kTetrahedron);
  EXPECT_THAT(error_of("shape = \"mesh\"\nfile = \"tetra.obj\"\nscale = 0\n"),
              AllOf(HasSubstr("key 'solid[0].scale'"), HasSubstr("must be > 0")));
}

TEST_F(SceneSolidMesh, FreeMeshIsRefused) {
  write("tetra.obj", kTetrahedron);
  EXPECT_THAT(error_of("shape = \"mesh\"\nfile = \"tetra.obj\"\nmotion = \"free\"\nmass = 1\n"),
              AllOf(HasSubstr("key 'solid[0].motion'"),
                    HasSubstr("a free solid must be a sphere, box, cylinder or capsule")));
}

// ---------------------------------------------------------------------------------------------
// Motion

TEST(SceneSolids, KinematicVelocitiesAndWindow) {
  const SolidSpec moving = solid_of(std::string(kSphere) +
                                    "motion = \"kinematic\"\nvelocity = [1, 0, 0]\n"
                                    "angular_velocity = [0, 0, 2]\nstart_time = 0.5\n"
                                    "end_time = 2\n");
  EXPECT_EQ(moving.motion, SolidMotion::kinematic);
  expect_near(moving.path.velocity, {1, 0, 0});
  expect_near(moving.path.angular_velocity, {0, 0, 2});
  EXPECT_EQ(moving.path.start_time, 0.5);
  EXPECT_EQ(moving.path.end_time, 2.0);
  EXPECT_TRUE(moving.path.keyframes.empty());
}

TEST(SceneSolids, KinematicWindowDefaultsToTheWholeRun) {
  const SolidSpec moving =
      solid_of(std::string(kSphere) + "motion = \"kinematic\"\nvelocity = [1, 0, 0]\n");
  EXPECT_EQ(moving.path.start_time, 0.0);
  EXPECT_GE(moving.path.end_time, 1e300);
  expect_near(moving.path.angular_velocity, {0, 0, 0});
}

TEST(SceneSolids, KeyframesTurnTheShapeFromItsOwnOrientation) {
  const SolidSpec rod = solid_of(
      "shape = \"cylinder\"\ncenter = [0, 0, 0]\naxis = [1, 0, 0]\nradius = 0.1\n"
      "half_length = 1\nmotion = \"kinematic\"\n"
      "keyframes = [ { time = 0.5, position = [0, 2, 0] },\n"
      "              { time = 1.5, position = [0, 3, 0], orientation = { axis = [0, 1, 0], "
      "angle = " + std::to_string(std::numbers::pi / 2) + " } } ]\n");
  ASSERT_EQ(rod.path.keyframes.size(), 2u);
  EXPECT_EQ(rod.path.keyframes[0].time, 0.5);
  EXPECT_EQ(rod.path.keyframes[1].time, 1.5);
  // Held before the first keyframe: the pose at time 0 is the first keyframe's.
  expect_near(rod.pose.position, {0, 2, 0});
  expect_near(rod.pose.direction_to_world({0, 0, 1}), {1, 0, 0});
  const Keyframe& last = rod.path.keyframes[1];
  expect_near(last.position, {0, 3, 0});
  expect_unit(last.orientation);
  // The axis, along x, turned a quarter about y: along −z.
  expect_near(rotate(last.orientation, {0, 0, 1}), {0, 0, -1}, 1e-6);
}

TEST(SceneSolids, FreeBodyKeys) {
  const SolidSpec cube = solid_of(
      "shape = \"box\"\ncenter = [-0.75, 0.625, -0.75]\nhalf_extents = [0.25, 0.25, 0.25]\n"
      "motion = \"free\"\nmass = 0.05\ninitial_velocity = [0, -1, 0]\n"
      "initial_angular_velocity = [0, 0, 1]\ndrag = 0.05\nforce = [0, -25, 0]\n"
      "force_until_contact = true\n");
  EXPECT_EQ(cube.motion, SolidMotion::free);
  EXPECT_EQ(cube.body.mass, 0.05);
  expect_near(cube.body.initial_velocity, {0, -1, 0});
  expect_near(cube.body.initial_angular_velocity, {0, 0, 1});
  EXPECT_EQ(cube.body.drag, 0.05);
  expect_near(cube.body.force, {0, -25, 0});
  EXPECT_TRUE(cube.body.force_until_contact);
}

TEST(SceneSolids, FreeBodyDefaults) {
  const SolidSpec ball = solid_of(std::string(kSphere) + "motion = \"free\"\nmass = 2\n");
  EXPECT_EQ(ball.body.drag, 0.0);
  expect_near(ball.body.force, {0, 0, 0});
  expect_near(ball.body.initial_velocity, {0, 0, 0});
  EXPECT_FALSE(ball.body.force_until_contact);
}

#ifdef COSSERAT_HAVE_PETSC
TEST(SceneSolids, SemiImplicitIntegratorTakesSolids) {
  const std::string text = scene_with(std::string("[[solid]]\n") + kSphere);
  const Scene scene = parse_scene(text, kPath, {"time.integrator=semi-implicit"});
  EXPECT_EQ(scene.solids.size(), 1u);
}
#endif

// ---------------------------------------------------------------------------------------------
// Bad input

TEST(SceneSolidsError, BlocksMustBeTables) {
  try {
    parse_scene(scene_with(""), kPath, {"solid=3"});
    ADD_FAILURE() << "expected a SceneError";
  } catch (const SceneError& error) {
    EXPECT_THAT(error.what(), AllOf(HasSubstr("key 'solid'"), HasSubstr("[[solid]]")));
  }
}

TEST(SceneSolidsError, ShapeIsRequiredAndKnown) {
  EXPECT_THAT(error_of("center = [0, 0, 0]\n"),
              AllOf(HasSubstr("key 'solid[0].shape'"), HasSubstr("required")));
  EXPECT_THAT(error_of("shape = \"cone\"\n"),
              AllOf(StartsWith(std::string(kPath) + ":14: key 'solid[0].shape'"),
                    HasSubstr("unknown shape \"cone\""),
                    HasSubstr("plane, sphere, box, cylinder, capsule, mesh")));
}

TEST(SceneSolidsError, MotionIsKnown) {
  EXPECT_THAT(error_of(std::string(kSphere) + "motion = \"moving\"\n"),
              AllOf(HasSubstr("key 'solid[0].motion'"), HasSubstr("unknown motion \"moving\""),
                    HasSubstr("fixed, kinematic, free")));
}

TEST(SceneSolidsError, KeyOfAnotherShapeNamesThisShapesKeys) {
  EXPECT_THAT(error_of(std::string(kSphere) + "half_extents = [1, 1, 1]\n"),
              AllOf(HasSubstr("key 'solid[0].half_extents'"), HasSubstr("a sphere has no"),
                    HasSubstr("center, radius")));
  EXPECT_THAT(error_of("shape = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\nradius = 1\n"),
              AllOf(HasSubstr("key 'solid[0].radius'"), HasSubstr("a plane has no")));
}

TEST(SceneSolidsError, UnknownKeyListsWhatIsAllowed) {
  EXPECT_THAT(error_of(std::string(kSphere) + "colour = \"red\"\n"),
              AllOf(HasSubstr("key 'solid[0].colour'"), HasSubstr("unknown key"),
                    HasSubstr("allowed here: name, shape, motion, friction, restitution, "
                              "thickness, center, radius")));
  EXPECT_THAT(error_of("shape = \"box\"\ncenter = [0, 0, 0]\nhalf_extents = [1, 1, 1]\n"
                       "orientation = { axis = [0, 0, 1], angle = 1, turns = 2 }\n"),
              AllOf(HasSubstr("key 'solid[0].orientation.turns'"), HasSubstr("axis, angle")));
}

TEST(SceneSolidsError, KeyOfAnotherMotionNamesItsMotion) {
  EXPECT_THAT(error_of(std::string(kSphere) + "velocity = [1, 0, 0]\n"),
              AllOf(HasSubstr("key 'solid[0].velocity'"),
                    HasSubstr("is for motion = \"kinematic\""), HasSubstr("\"fixed\"")));
  EXPECT_THAT(
      error_of(std::string(kSphere) + "motion = \"kinematic\"\nvelocity = [1, 0, 0]\nmass = 1\n"),
      AllOf(HasSubstr("key 'solid[0].mass'"), HasSubstr("is for motion = \"free\"")));
  EXPECT_THAT(error_of(std::string(kSphere) + "motion = \"free\"\nmass = 1\nkeyframes = []\n"),
              AllOf(HasSubstr("key 'solid[0].keyframes'"), HasSubstr("\"kinematic\"")));
}

TEST(SceneSolidsError, RequiredShapeKeys) {
  EXPECT_THAT(error_of("shape = \"sphere\"\ncenter = [0, 0, 0]\n"),
              AllOf(HasSubstr("key 'solid[0].radius'"), HasSubstr("required")));
  EXPECT_THAT(error_of("shape = \"plane\"\npoint = [0, 0, 0]\n"),
              AllOf(HasSubstr("key 'solid[0].normal'"), HasSubstr("required")));
  EXPECT_THAT(error_of("shape = \"box\"\ncenter = [0, 0, 0]\n"),
              AllOf(HasSubstr("key 'solid[0].half_extents'"), HasSubstr("required")));
  EXPECT_THAT(error_of("shape = \"cylinder\"\ncenter = [0, 0, 0]\naxis = [0, 0, 1]\nradius = 1\n"),
              AllOf(HasSubstr("key 'solid[0].half_length'"), HasSubstr("required")));
  EXPECT_THAT(error_of("shape = \"capsule\"\nradius = 1\n"),
              AllOf(HasSubstr("key 'solid[0].ends'"), HasSubstr("required")));
  EXPECT_THAT(error_of("shape = \"mesh\"\n"),
              AllOf(HasSubstr("key 'solid[0].file'"), HasSubstr("required")));
}

TEST(SceneSolidsError, SizesMustBePositive) {
  EXPECT_THAT(error_of("shape = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0\n"),
              AllOf(HasSubstr("key 'solid[0].radius'"), HasSubstr("must be > 0, got 0")));
  EXPECT_THAT(error_of("shape = \"box\"\ncenter = [0, 0, 0]\nhalf_extents = [1, -1, 1]\n"),
              AllOf(HasSubstr("key 'solid[0].half_extents[1]'"), HasSubstr("must be > 0")));
  EXPECT_THAT(error_of("shape = \"cylinder\"\ncenter = [0, 0, 0]\naxis = [0, 0, 1]\nradius = 1\n"
                       "half_length = -2\n"),
              AllOf(HasSubstr("key 'solid[0].half_length'"), HasSubstr("must be > 0")));
  EXPECT_THAT(error_of("shape = \"capsule\"\nends = [[0, 0, 0], [1, 0, 0]]\nradius = -0.1\n"),
              AllOf(HasSubstr("key 'solid[0].radius'"), HasSubstr("must be > 0")));
  EXPECT_THAT(error_of(std::string(kSphere) + "motion = \"free\"\nmass = 0\n"),
              AllOf(HasSubstr("key 'solid[0].mass'"), HasSubstr("must be > 0")));
  EXPECT_THAT(error_of(std::string(kSphere) + "motion = \"free\"\n"),
              AllOf(HasSubstr("key 'solid[0].mass'"), HasSubstr("required")));
}

TEST(SceneSolidsError, DirectionsMustNotBeZero) {
  EXPECT_THAT(error_of("shape = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 0, 0]\n"),
              AllOf(HasSubstr("key 'solid[0].normal'"), HasSubstr("zero-length")));
  EXPECT_THAT(error_of("shape = \"cylinder\"\ncenter = [0, 0, 0]\naxis = [0, 0, 0]\nradius = 1\n"
                       "half_length = 1\n"),
              AllOf(HasSubstr("key 'solid[0].axis'"), HasSubstr("zero-length")));
  EXPECT_THAT(error_of("shape = \"box\"\ncenter = [0, 0, 0]\nhalf_extents = [1, 1, 1]\n"
                       "orientation = { axis = [0, 0, 0], angle = 1 }\n"),
              AllOf(HasSubstr("key 'solid[0].orientation.axis'"), HasSubstr("zero-length")));
  EXPECT_THAT(error_of("shape = \"box\"\ncenter = [0, 0, 0]\nhalf_extents = [1, 1, 1]\n"
                       "orientation = { axis = [0, 0, 1] }\n"),
              AllOf(HasSubstr("key 'solid[0].orientation.angle'"), HasSubstr("required")));
}

TEST(SceneSolidsError, CapsuleEndsMustDiffer) {
  EXPECT_THAT(error_of("shape = \"capsule\"\nends = [[1, 2, 3], [1, 2, 3]]\nradius = 1\n"),
              AllOf(HasSubstr("key 'solid[0].ends'"), HasSubstr("must differ")));
  EXPECT_THAT(error_of("shape = \"capsule\"\nends = [1, 2, 3]\nradius = 1\n"),
              AllOf(HasSubstr("key 'solid[0].ends'"), HasSubstr("an array of 2 points")));
}

TEST(SceneSolidsError, FreePlaneIsRefused) {
  EXPECT_THAT(error_of("shape = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\n"
                       "motion = \"free\"\nmass = 1\n"),
              AllOf(HasSubstr("key 'solid[0].motion'"),
                    HasSubstr("a free solid must be a sphere, box, cylinder or capsule"),
                    HasSubstr("got a plane")));
}

TEST(SceneSolidsError, ContactCoefficientsInRange) {
  EXPECT_THAT(error_of(std::string(kSphere) + "friction = -0.1\n"),
              AllOf(HasSubstr("key 'solid[0].friction'"), HasSubstr("must be >= 0")));
  EXPECT_THAT(error_of(std::string(kSphere) + "restitution = 1.5\n"),
              AllOf(HasSubstr("key 'solid[0].restitution'"), HasSubstr("[0, 1]"),
                    HasSubstr("got 1.5")));
  EXPECT_THAT(error_of(std::string(kSphere) + "restitution = -0.5\n"),
              AllOf(HasSubstr("key 'solid[0].restitution'"), HasSubstr("[0, 1]")));
  EXPECT_THAT(error_of(std::string(kSphere) + "thickness = -0.01\n"),
              AllOf(HasSubstr("key 'solid[0].thickness'"), HasSubstr("must be >= 0")));
  EXPECT_THAT(error_of(std::string(kSphere) + "drag = 1\n"),
              AllOf(HasSubstr("key 'solid[0].drag'"), HasSubstr("\"free\"")));
  EXPECT_THAT(error_of(std::string(kSphere) + "motion = \"free\"\nmass = 1\ndrag = -1\n"),
              AllOf(HasSubstr("key 'solid[0].drag'"), HasSubstr("must be >= 0")));
}

TEST(SceneSolidsError, KinematicPath) {
  const std::string kinematic = std::string(kSphere) + "motion = \"kinematic\"\n";
  EXPECT_THAT(error_of(kinematic),
              AllOf(HasSubstr("key 'solid[0].velocity'"), HasSubstr("required"),
                    HasSubstr("keyframes")));
  EXPECT_THAT(error_of(kinematic + "velocity = [1, 0, 0]\nstart_time = 2\nend_time = 1\n"),
              AllOf(HasSubstr("key 'solid[0].end_time'"), HasSubstr("must be >= start_time")));
  EXPECT_THAT(
      error_of(kinematic + "velocity = [1, 0, 0]\nkeyframes = [{ time = 0, position = [0, 0, 0] }, "
                           "{ time = 1, position = [1, 0, 0] }]\n"),
      AllOf(HasSubstr("key 'solid[0].velocity'"), HasSubstr("not taken with keyframes")));
  EXPECT_THAT(error_of(kinematic + "keyframes = [{ time = 0, position = [0, 0, 0] }]\n"),
              AllOf(HasSubstr("key 'solid[0].keyframes'"), HasSubstr("at least 2")));
  EXPECT_THAT(
      error_of(kinematic + "keyframes = [{ time = 1, position = [0, 0, 0] }, "
                           "{ time = 1, position = [1, 0, 0] }]\n"),
      AllOf(HasSubstr("key 'solid[0].keyframes[1].time'"), HasSubstr("increase strictly")));
  EXPECT_THAT(
      error_of(kinematic + "keyframes = [{ time = 0, position = [0, 0, 0] }, { time = 1 }]\n"),
      AllOf(HasSubstr("key 'solid[0].keyframes[1].position'"), HasSubstr("required")));
  EXPECT_THAT(error_of(kinematic + "keyframes = [{ time = 0, position = [0, 0, 0] }, "
                                   "{ time = 1, position = [1, 0, 0], speed = 2 }]\n"),
              AllOf(HasSubstr("key 'solid[0].keyframes[1].speed'"), HasSubstr("unknown key")));
}

TEST(SceneSolidsError, LaterBlocksAreNamedByTheirIndex) {
  try {
    parse_scene(scene_with(std::string("[[solid]]\n") + kSphere +
                           "[[solid]]\nshape = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0\n"),
                kPath);
    ADD_FAILURE() << "expected a SceneError";
  } catch (const SceneError& error) {
    EXPECT_THAT(error.what(), HasSubstr("key 'solid[1].radius'"));
  }
}

}  // namespace
}  // namespace cosserat
