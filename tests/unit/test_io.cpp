// The HDF5 output, its XDMF companion and the run summary, read back the way other tools read
// them: HDF5 through the C API, XDMF and JSON as text.

#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <cmath>

#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numeric>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cosserat/io/frame_writer.hpp"
#include "cosserat/io/summary.hpp"
#include "cosserat/io/xdmf.hpp"

namespace cosserat {
namespace {

namespace fs = std::filesystem;

class Hid {
 public:
  Hid(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Hid() {
    if (id_ >= 0) close_(id_);
  }
  Hid(const Hid&) = delete;
  Hid& operator=(const Hid&) = delete;
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

std::vector<hsize_t> dataset_shape(hid_t file, const char* name) {
  const Hid dataset(H5Dopen2(file, name, H5P_DEFAULT), H5Dclose);
  const Hid space(H5Dget_space(dataset.get()), H5Sclose);
  std::vector<hsize_t> dims(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space.get())));
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return dims;
}

template <typename T>
std::vector<T> read_all(hid_t file, const char* name, hid_t memory_type) {
  std::size_t count = 1;
  for (const hsize_t d : dataset_shape(file, name)) count *= d;
  std::vector<T> values(count);
  const Hid dataset(H5Dopen2(file, name, H5P_DEFAULT), H5Dclose);
  EXPECT_GE(H5Dread(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0);
  return values;
}

std::string read_string_attribute(hid_t file, const char* name) {
  const Hid attribute(H5Aopen(file, name, H5P_DEFAULT), H5Aclose);
  if (!attribute.valid()) return "<missing>";
  const Hid type(H5Aget_type(attribute.get()), H5Tclose);
  EXPECT_EQ(H5Tget_class(type.get()), H5T_STRING);
  EXPECT_EQ(H5Tget_cset(type.get()), H5T_CSET_UTF8);
  EXPECT_TRUE(H5Tis_variable_str(type.get()) > 0) << name << " reads back as bytes in h5py";
  char* text = nullptr;
  EXPECT_GE(H5Aread(attribute.get(), type.get(), &text), 0);
  std::string value = text != nullptr ? text : "<unreadable>";
  H5free_memory(text);
  return value;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

long count_occurrences(const std::string& text, const std::string& pattern) {
  long count = 0;
  for (auto at = text.find(pattern); at != std::string::npos; at = text.find(pattern, at + 1)) {
    ++count;
  }
  return count;
}

// Distinct in every bit position that matters: a swapped k and l, or a shifted component,
// changes the value; the fractions are not exact in binary so a lossy path would show.
std::vector<double> frame_positions(int m, int n, int frame) {
  std::vector<double> positions;
  for (int k = 0; k < m; ++k) {
    for (int l = 0; l < n; ++l) {
      for (int c = 0; c < 3; ++c) {
        positions.push_back(frame * 1000.0 + k * 10.0 + l * 0.1 + c * 0.001 + 1.0 / 3.0);
      }
    }
  }
  return positions;
}

// The same values as a field on a block, which is what the writer takes.
Field<Vec3> frame_field(const Block& block, int frame) {
  const std::vector<double> values = frame_positions(block.m, block.n, frame);
  Field<Vec3> field(block);
  for (int k = 0; k < block.m; ++k)
    for (int l = 0; l < block.n; ++l) {
      const std::size_t at = 3 * (static_cast<std::size_t>(k) * block.n + l);
      field(k, l) = Vec3{values[at], values[at + 1], values[at + 2]};
    }
  return field;
}

class FrameWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    directory_ = fs::temp_directory_path() /
                 ("cosserat_test_io_" + std::to_string(getpid()) + "_" + test->name());
    fs::remove_all(directory_);
    fs::create_directories(directory_);
  }
  void TearDown() override { fs::remove_all(directory_); }

  fs::path directory_;
};

TEST_F(FrameWriterTest, RoundTripsFramesTimesStepsAndAttributes) {
  constexpr int m = 4;
  constexpr int n = 5;
  const fs::path h5 = directory_ / "cloth.h5";
  const fs::path snapshot = directory_ / "snapshot.h5";
  const std::vector<double> times{0.0, 0.1, 0.30000000000000004};
  const std::vector<std::int64_t> steps{0, 100, 300};
  std::vector<double> expected;

  const Block block = Block::whole(m, n, MPI_COMM_SELF);
  FrameWriter writer(h5.string(), block, "[grid]\nnodes = [4, 5]\n", "verlet", "0.1.0",
                     {"time.dt=1e-4", "grid.nodes=[4,5]"});
  EXPECT_EQ(writer.frames(), 0);
  for (int frame = 0; frame < 3; ++frame) {
    const std::vector<double> positions = frame_positions(m, n, frame);
    writer.write_frame(steps[frame], times[frame], frame_field(block, frame));
    expected.insert(expected.end(), positions.begin(), positions.end());
    EXPECT_EQ(writer.frames(), frame + 1);

    // The bytes on disk right now are what a run killed at this point leaves behind.
    fs::copy_file(h5, snapshot, fs::copy_options::overwrite_existing);
    const Hid file(H5Fopen(snapshot.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    ASSERT_TRUE(file.valid()) << "frame " << frame;
    const auto frames = static_cast<hsize_t>(frame + 1);
    EXPECT_EQ(dataset_shape(file.get(), "/positions"), (std::vector<hsize_t>{frames, m, n, 3}));
    EXPECT_EQ(dataset_shape(file.get(), "/time"), std::vector<hsize_t>{frames});
    EXPECT_EQ(dataset_shape(file.get(), "/step"), std::vector<hsize_t>{frames});
    const auto positions_so_far = read_all<double>(file.get(), "/positions", H5T_NATIVE_DOUBLE);
    ASSERT_EQ(positions_so_far.size(), expected.size());
    EXPECT_EQ(std::memcmp(positions_so_far.data(), expected.data(),
                          expected.size() * sizeof(double)),
              0);
    EXPECT_TRUE(fs::exists(directory_ / "cloth.xmf"));
  }
  writer.set_attribute("status", "running");
  writer.set_attribute("status", "ok");

  fs::copy_file(h5, snapshot, fs::copy_options::overwrite_existing);
  const Hid final_file(H5Fopen(snapshot.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  ASSERT_TRUE(final_file.valid());
  const hid_t f = final_file.get();
  EXPECT_EQ(read_all<double>(f, "/time", H5T_NATIVE_DOUBLE), times);
  EXPECT_EQ(read_all<std::int64_t>(f, "/step", H5T_NATIVE_INT64), steps);
  EXPECT_EQ(read_string_attribute(f, "scene"), "[grid]\nnodes = [4, 5]\n");
  EXPECT_EQ(read_string_attribute(f, "integrator"), "verlet");
  EXPECT_EQ(read_string_attribute(f, "version"), "0.1.0");
  EXPECT_EQ(read_string_attribute(f, "overrides"), "time.dt=1e-4\ngrid.nodes=[4,5]");
  EXPECT_EQ(read_string_attribute(f, "status"), "ok");
}

TEST_F(FrameWriterTest, XdmfNamesEveryFrameOfTheHdf5File) {
  const fs::path h5 = directory_ / "sheet.h5";
  const Block block = Block::whole(3, 2, MPI_COMM_SELF);
  FrameWriter writer(h5.string(), block, "", "rk4", "0.1.0", {});
  for (int frame = 0; frame < 3; ++frame) writer.write_frame(frame * 10, frame * 0.5, frame_field(block, frame));

  const std::string xmf = read_text(directory_ / "sheet.xmf");
  EXPECT_NE(xmf.find(R"(CollectionType="Temporal")"), std::string::npos);
  EXPECT_EQ(count_occurrences(xmf, R"(GridType="Uniform")"), 3);
  EXPECT_EQ(count_occurrences(xmf, R"(Dimensions="3 2 3")"), 3);
  EXPECT_NE(xmf.find(">sheet.h5:/positions|2 0 0 0:1 1 1 1:1 3 2 3:3 3 2 3<"), std::string::npos)
      << xmf;
  EXPECT_NE(xmf.find(R"(<Time Value="1"/>)"), std::string::npos);
  EXPECT_FALSE(fs::exists(directory_ / "sheet.xmf.partial"));
}

// Bytes this process has written so far, through any file (Linux's I/O accounting).
long bytes_written() {
  std::ifstream io("/proc/self/io");
  for (std::string key; io >> key;) {
    long value = 0;
    io >> value;
    if (key == "wchar:") return value;
  }
  return -1;
}

// Issue 12, defect 13: the XDMF file was written whole after every frame, so frame N cost O(N)
// and a run of N frames O(N^2) (3000 frames of 32 x 32: 1.9 GB written for 74 MB of frames).
// Now a frame costs the same whatever its number: frames 400-499 write no more than frames
// 10-109 (each about 5 kB here, mostly HDF5's metadata; before, frame 450 wrote 180 kB).
TEST_F(FrameWriterTest, FrameCostDoesNotGrowWithTheFrameCount) {
  const Block block = Block::whole(2, 2, MPI_COMM_SELF);
  FrameWriter writer((directory_ / "long.h5").string(), block, "", "verlet", "0.1.0", {});
  const Field<Vec3> positions = frame_field(block, 1);
  std::vector<long> cost;
  for (int frame = 0; frame < 500; ++frame) {
    const long before = bytes_written();
    writer.write_frame(frame, frame * 1e-3, positions);
    cost.push_back(bytes_written() - before);
  }
  const auto mean = [&](std::size_t first) {
    return std::accumulate(cost.begin() + first, cost.begin() + first + 100, 0.0) / 100.0;
  };
  ASSERT_GT(mean(10), 0.0);
  // HDF5's part varies by a few kB as its chunk index grows.
  EXPECT_LT(mean(400), 2.0 * mean(10)) << "bytes per frame: " << mean(10) << " at frames 10-109, "
                                       << mean(400) << " at frames 400-499";
}

// After every frame the XDMF file is the document a writer starting from scratch would write
// for the frames so far, and after a restart that drops frames, the one of the frames kept.
TEST_F(FrameWriterTest, XdmfAfterEachFrameIsTheWholeDocumentOfTheFramesSoFar) {
  const fs::path h5 = directory_ / "grow.h5";
  const Block block = Block::whole(3, 4, MPI_COMM_SELF);
  std::vector<double> times;
  {
    FrameWriter writer(h5.string(), block, "scene", "verlet", "0.1.0", {});
    for (int frame = 0; frame < 6; ++frame) {
      times.push_back(frame * 0.1);
      writer.write_frame(frame * 10, times.back(), frame_field(block, frame));
      EXPECT_EQ(read_text(directory_ / "grow.xmf"), xdmf_document("grow.h5", 3, 4, times))
          << "after frame " << frame;
    }
  }
  FrameWriter restarted(h5.string(), block, 25, "scene", 20);
  times.resize(3);
  EXPECT_EQ(read_text(directory_ / "grow.xmf"), xdmf_document("grow.h5", 3, 4, times));
  times.push_back(0.3);
  restarted.write_frame(30, times.back(), frame_field(block, 3));
  EXPECT_EQ(read_text(directory_ / "grow.xmf"), xdmf_document("grow.h5", 3, 4, times));
}

// A frame that does not fit (a full disk; here a file size limit) leaves the file describing
// the frames before it, closing tags included, and says which file failed.
TEST_F(FrameWriterTest, XdmfAppendThatFailsLeavesTheEarlierFrames) {
  const fs::path xmf = directory_ / "full.xmf";
  const std::vector<double> times{0.0, 0.5};
  XdmfFile file(xmf.string(), "full.h5", 5, 5, times);
  const auto size = static_cast<rlim_t>(fs::file_size(xmf));
  rlimit limit{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &limit), 0);
  const rlimit restore = limit;
  const auto previous_handler = std::signal(SIGXFSZ, SIG_IGN);
  limit.rlim_cur = size + 100;  // room for part of the next frame's element only
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limit), 0);
  std::string message;
  try {
    file.append(1.0);
  } catch (const std::runtime_error& error) {
    message = error.what();
  }
  setrlimit(RLIMIT_FSIZE, &restore);
  std::signal(SIGXFSZ, previous_handler);
  EXPECT_NE(message.find(xmf.string()), std::string::npos) << message;
  EXPECT_EQ(read_text(xmf), xdmf_document("full.h5", 5, 5, times));
  EXPECT_EQ(file.frames(), 2u);
}

// An attribute kept in the object header is limited to 64 KiB; a scene with long node lists
// must still fit.
TEST_F(FrameWriterTest, StoresLongSceneTextAndEmptyOverrides) {
  const fs::path h5 = directory_ / "plain.h5";
  const std::string scene(100000, '#');
  const Block block = Block::whole(2, 2, MPI_COMM_SELF);
  { FrameWriter writer(h5.string(), block, scene, "verlet", "0.1.0", {}); }
  const Hid file(H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  ASSERT_TRUE(file.valid());
  EXPECT_EQ(read_string_attribute(file.get(), "scene"), scene);
  EXPECT_EQ(read_string_attribute(file.get(), "overrides"), "");
  EXPECT_EQ(dataset_shape(file.get(), "/positions"), (std::vector<hsize_t>{0, 2, 2, 3}));
}

// 20000 x 20000 nodes is 9.6 GB a frame, over HDF5's 4 GiB chunk limit; creating the dataset
// writes no frame, so this costs nothing.
TEST_F(FrameWriterTest, SplitsFramesLargerThanTheChunkLimit) {
  const fs::path h5 = directory_ / "large.h5";
  const Block block = Block::whole(20000, 20000, MPI_COMM_SELF);
  { FrameWriter writer(h5.string(), block, "scene", "verlet", "0.1.0", {}); }
  const Hid file(H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  const Hid dataset(H5Dopen2(file.get(), "/positions", H5P_DEFAULT), H5Dclose);
  const Hid properties(H5Dget_create_plist(dataset.get()), H5Pclose);
  std::vector<hsize_t> chunk(4);
  ASSERT_EQ(H5Pget_chunk(properties.get(), 4, chunk.data()), 4);
  EXPECT_EQ(chunk[0], 1u);
  EXPECT_LT(chunk[1], 20000u);
  EXPECT_EQ(chunk[2], 20000u);
  EXPECT_LT(chunk[0] * chunk[1] * chunk[2] * chunk[3] * sizeof(double), hsize_t{1} << 32);
}

TEST_F(FrameWriterTest, UnwritablePathNamesTheFile) {
  const std::string h5 = (directory_ / "missing" / "run.h5").string();
  try {
    const Block block = Block::whole(2, 2, MPI_COMM_SELF);
    FrameWriter writer(h5, block, "scene", "verlet", "0.1.0", {});
    FAIL() << "created a file in a folder that does not exist";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(h5), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("create file"), std::string::npos) << error.what();
  }
}

// --- Rigid solids (docs/output.md, "HDF5") ---

// A box of half extents (a, b, c): 8 corners, 2 triangles a face.
TriangleMesh box_surface(double a, double b, double c) {
  TriangleMesh box;
  for (int corner = 0; corner < 8; ++corner)
    box.vertices.push_back(Vec3{corner & 1 ? a : -a, corner & 2 ? b : -b, corner & 4 ? c : -c});
  box.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return box;
}

// A sphere of latitude rings and longitude segments between two poles.
TriangleMesh sphere_surface(double radius, int rings, int segments) {
  TriangleMesh sphere;
  sphere.vertices.push_back(Vec3{0.0, 0.0, radius});
  for (int r = 1; r <= rings; ++r) {
    const double polar = M_PI * r / (rings + 1);
    for (int s = 0; s < segments; ++s) {
      const double azimuth = 2.0 * M_PI * s / segments;
      sphere.vertices.push_back(Vec3{radius * std::sin(polar) * std::cos(azimuth),
                                     radius * std::sin(polar) * std::sin(azimuth),
                                     radius * std::cos(polar)});
    }
  }
  const int south = static_cast<int>(sphere.vertices.size());
  sphere.vertices.push_back(Vec3{0.0, 0.0, -radius});
  const auto ring = [&](int r, int s) { return 1 + (r - 1) * segments + (s % segments); };
  for (int s = 0; s < segments; ++s) {
    sphere.triangles.push_back({0, ring(1, s), ring(1, s + 1)});
    for (int r = 1; r < rings; ++r) {
      sphere.triangles.push_back({ring(r, s), ring(r + 1, s), ring(r + 1, s + 1)});
      sphere.triangles.push_back({ring(r, s), ring(r + 1, s + 1), ring(r, s + 1)});
    }
    sphere.triangles.push_back({ring(rings, s), south, ring(rings, s + 1)});
  }
  return sphere;
}

std::vector<SolidOutline> two_solids() {
  return {SolidOutline{"crate", box_surface(0.5, 0.25, 0.125)},
          SolidOutline{"ball <1>", sphere_surface(0.3, 3, 6)}};
}

// Frame f's poses: the box moving along x and turning about z, the ball about a skew axis.
std::vector<Pose> frame_poses(int frame) {
  const auto turn = [](double angle, Vec3 axis) {
    axis = axis / norm(axis);
    const double s = std::sin(angle / 2);
    return Quaternion{std::cos(angle / 2), s * axis.x, s * axis.y, s * axis.z};
  };
  return {Pose{Vec3{0.1 * frame, 1.0, -2.0}, turn(0.5 * frame, Vec3{0, 0, 1})},
          Pose{Vec3{3.0, 0.2 * frame, 0.7}, turn(1.0 + frame, Vec3{1, 2, 3})}};
}

// The rotation by q as q (0, v) q*, written out here apart from the writer's matrix.
Vec3 rotated(const Quaternion& q, const Vec3& v) {
  const auto product = [](const Quaternion& a, const Quaternion& b) {
    return Quaternion{a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
                      a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
                      a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
                      a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
  };
  const Quaternion r = product(product(q, Quaternion{0.0, v.x, v.y, v.z}),
                               Quaternion{q.w, -q.x, -q.y, -q.z});
  return Vec3{r.x, r.y, r.z};
}

std::vector<hsize_t> solid_shape(hid_t file, int solid, const char* dataset) {
  return dataset_shape(file, ("/solids/" + std::to_string(solid) + "/" + dataset).c_str());
}

std::string group_name(hid_t file, int solid) {
  const Hid group(H5Gopen2(file, ("/solids/" + std::to_string(solid)).c_str(), H5P_DEFAULT),
                  H5Gclose);
  if (!group.valid()) return "<missing group>";
  return read_string_attribute(group.get(), "name");
}

// Frames 0 .. frames - 1 of every solid's series in `file` hold the poses of frame_poses and
// the surfaces those poses place.
void expect_solid_frames(hid_t file, const std::vector<SolidOutline>& solids, int frames) {
  for (int i = 0; i < static_cast<int>(solids.size()); ++i) {
    const std::string group = "/solids/" + std::to_string(i);
    const auto nv = static_cast<hsize_t>(solids[i].surface.vertices.size());
    ASSERT_EQ(solid_shape(file, i, "position"), (std::vector<hsize_t>{hsize_t(frames), 3}));
    ASSERT_EQ(solid_shape(file, i, "orientation"), (std::vector<hsize_t>{hsize_t(frames), 4}));
    ASSERT_EQ(solid_shape(file, i, "world_vertices"),
              (std::vector<hsize_t>{hsize_t(frames), nv, 3}));
    const auto position = read_all<double>(file, (group + "/position").c_str(), H5T_NATIVE_DOUBLE);
    const auto orientation =
        read_all<double>(file, (group + "/orientation").c_str(), H5T_NATIVE_DOUBLE);
    const auto world =
        read_all<double>(file, (group + "/world_vertices").c_str(), H5T_NATIVE_DOUBLE);
    for (int f = 0; f < frames; ++f) {
      const Pose pose = frame_poses(f)[static_cast<std::size_t>(i)];
      const Quaternion& q = pose.orientation;
      EXPECT_EQ(std::vector<double>(position.begin() + 3 * f, position.begin() + 3 * f + 3),
                (std::vector<double>{pose.position.x, pose.position.y, pose.position.z}));
      EXPECT_EQ(std::vector<double>(orientation.begin() + 4 * f, orientation.begin() + 4 * f + 4),
                (std::vector<double>{q.w, q.x, q.y, q.z}));
      for (hsize_t v = 0; v < nv; ++v) {
        const Vec3 expected = pose.position + rotated(q, solids[i].surface.vertices[v]);
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(world[(f * nv + v) * 3 + c], expected[c], 1e-14)
              << group << " frame " << f << " vertex " << v << " component " << c;
      }
    }
  }
}

// Two solids over three frames: their surfaces as given, their poses and placed surfaces per
// frame, each named in every frame of the XDMF file beside the cloth.
TEST_F(FrameWriterTest, WritesSolidsBesideTheCloth) {
  const fs::path h5 = directory_ / "contact.h5";
  const Block block = Block::whole(3, 4, MPI_COMM_SELF);
  const std::vector<SolidOutline> solids = two_solids();
  std::vector<double> times;
  {
    FrameWriter writer(h5.string(), block, "scene", "verlet", "0.1.0", {}, solids);
    for (int frame = 0; frame < 3; ++frame) {
      times.push_back(frame * 0.25);
      writer.write_frame(frame * 10, times.back(), frame_field(block, frame), frame_poses(frame));
    }
    EXPECT_THROW(writer.write_frame(30, 1.0, frame_field(block, 3)), std::invalid_argument);
    EXPECT_EQ(writer.frames(), 3);
  }
  const Hid file(H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  ASSERT_TRUE(file.valid());
  const hid_t f = file.get();
  EXPECT_EQ(dataset_shape(f, "/positions"), (std::vector<hsize_t>{3, 3, 4, 3}));
  H5G_info_t info{};
  ASSERT_GE(H5Gget_info_by_name(f, "/solids", &info, H5P_DEFAULT), 0);
  EXPECT_EQ(info.nlinks, 2u);
  for (int i = 0; i < 2; ++i) {
    const TriangleMesh& surface = solids[static_cast<std::size_t>(i)].surface;
    EXPECT_EQ(group_name(f, i), solids[static_cast<std::size_t>(i)].name);
    const std::string group = "/solids/" + std::to_string(i);
    EXPECT_EQ(solid_shape(f, i, "vertices"),
              (std::vector<hsize_t>{surface.vertices.size(), 3}));
    EXPECT_EQ(solid_shape(f, i, "triangles"),
              (std::vector<hsize_t>{surface.triangles.size(), 3}));
    std::vector<double> vertices;
    for (const Vec3& v : surface.vertices) vertices.insert(vertices.end(), {v.x, v.y, v.z});
    EXPECT_EQ(read_all<double>(f, (group + "/vertices").c_str(), H5T_NATIVE_DOUBLE), vertices);
    std::vector<int> triangles;
    for (const auto& t : surface.triangles) triangles.insert(triangles.end(), t.begin(), t.end());
    EXPECT_EQ(read_all<int>(f, (group + "/triangles").c_str(), H5T_NATIVE_INT), triangles);
  }
  expect_solid_frames(f, solids, 3);
  // Half a radian about z, spelled out: the box's corner (0.5, 0.25, 0.125) at frame 1 is at
  // (0.1, 1, -2) + R(0.5 rad about z) corner.
  const auto world = read_all<double>(f, "/solids/0/world_vertices", H5T_NATIVE_DOUBLE);
  const std::size_t corner = (1 * 8 + 7) * 3;
  EXPECT_NEAR(world[corner], 0.1 + 0.5 * std::cos(0.5) - 0.25 * std::sin(0.5), 1e-15);
  EXPECT_NEAR(world[corner + 1], 1.0 + 0.5 * std::sin(0.5) + 0.25 * std::cos(0.5), 1e-15);
  EXPECT_NEAR(world[corner + 2], -2.0 + 0.125, 1e-15);

  const std::string xmf = read_text(directory_ / "contact.xmf");
  std::vector<XdmfSolid> described{{"crate", 8, 12}, {"ball <1>", 20, 36}};
  EXPECT_EQ(xmf, xdmf_document("contact.h5", 3, 4, times, described));
  EXPECT_EQ(count_occurrences(xmf, R"(CollectionType="Spatial")"), 3);
  EXPECT_EQ(count_occurrences(xmf, R"(TopologyType="Triangle")"), 6);
  EXPECT_EQ(count_occurrences(xmf, R"(<Grid Name="crate" GridType="Uniform">)"), 3);
  EXPECT_EQ(count_occurrences(xmf, R"(<Grid Name="ball &lt;1&gt;" GridType="Uniform">)"), 3);
  EXPECT_EQ(count_occurrences(xmf, ">contact.h5:/solids/1/triangles<"), 3);
  for (int frame = 0; frame < 3; ++frame) {
    const std::string slab = std::to_string(frame) + " 0 0:1 1 1:1 8 3:" +
                             std::to_string(frame + 1) + " 8 3<";
    EXPECT_EQ(count_occurrences(xmf, ">contact.h5:/solids/0/world_vertices|" + slab), 1) << xmf;
  }
}

TEST_F(FrameWriterTest, WithoutSolidsTheFileHasNoSolidsGroup) {
  const fs::path h5 = directory_ / "plain.h5";
  const Block block = Block::whole(2, 2, MPI_COMM_SELF);
  {
    FrameWriter writer(h5.string(), block, "scene", "verlet", "0.1.0", {});
    writer.write_frame(0, 0.0, frame_field(block, 0));
  }
  const Hid file(H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  EXPECT_EQ(H5Lexists(file.get(), "/solids", H5P_DEFAULT), 0);
  EXPECT_EQ(read_text(directory_ / "plain.xmf"), xdmf_document("plain.h5", 2, 2, {0.0}));
}

TEST_F(FrameWriterTest, RefusesASolidWhoseTrianglesNameMissingVertices) {
  const Block block = Block::whole(2, 2, MPI_COMM_SELF);
  TriangleMesh broken = box_surface(1, 1, 1);
  broken.triangles[3][1] = 8;
  EXPECT_THROW(FrameWriter((directory_ / "a.h5").string(), block, "scene", "verlet", "0.1.0", {},
                           {SolidOutline{"box", broken}}),
               std::invalid_argument);
  EXPECT_THROW(FrameWriter((directory_ / "b.h5").string(), block, "scene", "verlet", "0.1.0", {},
                           {SolidOutline{"nothing", TriangleMesh{}}}),
               std::invalid_argument);
}

// A restart keeps the solids' frames up to the checkpoint with the cloth's, drops the later
// ones, and continues them; a file of other solids, or whose solids lack kept frames, is refused
// and left as it was.
TEST_F(FrameWriterTest, RestartCutsTheSolidsWithTheCloth) {
  const fs::path h5 = directory_ / "resume.h5";
  const Block block = Block::whole(3, 2, MPI_COMM_SELF);
  const std::vector<SolidOutline> solids = two_solids();
  std::vector<double> times;
  {
    FrameWriter writer(h5.string(), block, "scene", "verlet", "0.1.0", {}, solids);
    for (int frame = 0; frame < 5; ++frame) {
      times.push_back(frame * 0.5);
      writer.write_frame(frame * 10, times.back(), frame_field(block, frame), frame_poses(frame));
    }
  }
  const auto expect_refused = [&](const std::vector<SolidOutline>& other, const char* why) {
    try {
      FrameWriter restarted(h5.string(), block, 25, "scene", 20, 0.0, other);
      ADD_FAILURE() << "restart accepted " << why;
    } catch (const std::runtime_error& error) {
      EXPECT_NE(std::string(error.what()).find(h5.string()), std::string::npos) << error.what();
    }
    const Hid file(H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    EXPECT_EQ(dataset_shape(file.get(), "/positions")[0], 5u) << why;
    EXPECT_EQ(solid_shape(file.get(), 1, "world_vertices")[0], 5u) << why;
  };
  expect_refused({}, "without solids");
  expect_refused({solids[0]}, "with one solid of two");
  std::vector<SolidOutline> renamed = solids;
  renamed[1].name = "ball";
  expect_refused(renamed, "with a renamed solid");
  std::vector<SolidOutline> moved = solids;
  moved[0].surface.vertices[2].y += 1e-9;
  expect_refused(moved, "with another surface");

  {
    FrameWriter restarted(h5.string(), block, 25, "scene", 20, 0.0, solids);
    EXPECT_EQ(restarted.frames(), 3);
    times.resize(3);
    EXPECT_EQ(read_text(directory_ / "resume.xmf"),
              xdmf_document("resume.h5", 3, 2, times, {{"crate", 8, 12}, {"ball <1>", 20, 36}}));
    {
      const Hid file(H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
      expect_solid_frames(file.get(), solids, 3);
    }
    times.push_back(1.5);
    restarted.write_frame(30, times.back(), frame_field(block, 3), frame_poses(3));
  }
  const Hid file(H5Fopen(h5.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
  expect_solid_frames(file.get(), solids, 4);
  EXPECT_EQ(read_text(directory_ / "resume.xmf"),
            xdmf_document("resume.h5", 3, 2, times, {{"crate", 8, 12}, {"ball <1>", 20, 36}}));

  // A run killed inside a frame's write may leave a solid's series shorter than the cloth's.
  {
    const Hid dataset(H5Dopen2(file.get(), "/solids/1/orientation", H5P_DEFAULT), H5Dclose);
    const std::array<hsize_t, 2> two{2, 4};
    ASSERT_GE(H5Dset_extent(dataset.get(), two.data()), 0);
  }
  H5Fflush(file.get(), H5F_SCOPE_GLOBAL);
  try {
    FrameWriter restarted(h5.string(), block, 25, "scene", 20, 0.0, solids);
    ADD_FAILURE() << "restart accepted a solid missing kept frames";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("/solids/1/orientation"), std::string::npos)
        << error.what();
  }
}

// One value per node, distinct per frame, node and field, as a scalar output field takes it.
Field<double> scalar_field(const Block& block, int frame, double offset) {
  Field<double> field(block);
  for (int k = 0; k < block.m; ++k)
    for (int l = 0; l < block.n; ++l)
      field(k, l) = offset + frame * 100.0 + k + l * 0.01 + 1.0 / 7.0;
  return field;
}

const std::vector<NodeField> kFields{{"velocity", "m/s", true}, {"curvature", "1/m", false}};

std::string dataset_units(hid_t file, const char* name) {
  const Hid dataset(H5Dopen2(file, name, H5P_DEFAULT), H5Dclose);
  return read_string_attribute(dataset.get(), "units");
}

// Each field is a series of the grid's shape beside /positions, in the same [k][l] order, with
// its units; the XDMF file names each as a node attribute of every frame.
TEST_F(FrameWriterTest, WritesFieldsBesideThePositions) {
  const fs::path h5 = directory_ / "fields.h5";
  const Block block = Block::whole(3, 4, MPI_COMM_SELF);
  std::vector<double> times;
  {
    FrameWriter writer(h5.string(), block, "scene", "verlet", "0.1.0", {}, {}, kFields);
    for (int frame = 0; frame < 3; ++frame) {
      const Field<Vec3> velocity = frame_field(block, frame + 7);
      const Field<double> curvature = scalar_field(block, frame, 0.5);
      times.push_back(frame * 0.25);
      writer.write_frame(frame * 10, times.back(), frame_field(block, frame), {},
                         {&velocity, &curvature});
    }
    const Field<double> curvature = scalar_field(block, 0, 0.0);
    EXPECT_THROW(writer.write_frame(30, 1.0, frame_field(block, 3), {}, {&curvature}),
                 std::invalid_argument);
    EXPECT_THROW(writer.write_frame(30, 1.0, frame_field(block, 3), {}, {&curvature, &curvature}),
                 std::invalid_argument);
    EXPECT_EQ(writer.frames(), 3);
  }
  const Hid file(H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  EXPECT_EQ(dataset_shape(file.get(), "/fields/velocity"), (std::vector<hsize_t>{3, 3, 4, 3}));
  EXPECT_EQ(dataset_shape(file.get(), "/fields/curvature"), (std::vector<hsize_t>{3, 3, 4}));
  EXPECT_EQ(dataset_units(file.get(), "/fields/velocity"), "m/s");
  EXPECT_EQ(dataset_units(file.get(), "/fields/curvature"), "1/m");
  std::vector<double> velocity, curvature;
  for (int frame = 0; frame < 3; ++frame) {
    const std::vector<double> v = frame_positions(3, 4, frame + 7);
    velocity.insert(velocity.end(), v.begin(), v.end());
    const Field<double> c = scalar_field(block, frame, 0.5);
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 4; ++l) curvature.push_back(c(k, l));
  }
  EXPECT_EQ(read_all<double>(file.get(), "/fields/velocity", H5T_NATIVE_DOUBLE), velocity);
  EXPECT_EQ(read_all<double>(file.get(), "/fields/curvature", H5T_NATIVE_DOUBLE), curvature);

  const std::string xmf = read_text(directory_ / "fields.xmf");
  EXPECT_EQ(xmf, xdmf_document("fields.h5", 3, 4, times, {},
                               {{"velocity", true}, {"curvature", false}}));
  EXPECT_EQ(count_occurrences(
                xmf, R"(<Attribute Name="velocity" AttributeType="Vector" Center="Node">)"),
            3);
  EXPECT_EQ(count_occurrences(
                xmf, R"(<Attribute Name="curvature" AttributeType="Scalar" Center="Node">)"),
            3);
  EXPECT_NE(xmf.find(">fields.h5:/fields/velocity|2 0 0 0:1 1 1 1:1 3 4 3:3 3 4 3<"),
            std::string::npos) << xmf;
  EXPECT_NE(xmf.find(">fields.h5:/fields/curvature|1 0 0:1 1 1:1 3 4:2 3 4<"), std::string::npos)
      << xmf;
}

TEST_F(FrameWriterTest, WithoutFieldsTheFileHasNoFieldsGroup) {
  const fs::path h5 = directory_ / "plain.h5";
  const Block block = Block::whole(3, 2, MPI_COMM_SELF);
  {
    FrameWriter writer(h5.string(), block, "scene", "verlet", "0.1.0", {});
    writer.write_frame(0, 0.0, frame_field(block, 0));
  }
  const Hid file(H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  EXPECT_EQ(H5Lexists(file.get(), "fields", H5P_DEFAULT), 0);
  EXPECT_EQ(read_text(directory_ / "plain.xmf").find("<Attribute"), std::string::npos);
  EXPECT_THROW(FrameWriter((directory_ / "twice.h5").string(), block, "scene", "verlet", "0.1.0",
                           {}, {}, {kFields[1], kFields[1]}),
               std::invalid_argument);
}

// A restart keeps the fields' frames up to the checkpoint with the cloth's; a file of other
// fields (another output.fields) is refused and left as it was.
TEST_F(FrameWriterTest, RestartCutsTheFieldsWithTheCloth) {
  const fs::path h5 = directory_ / "resume_fields.h5";
  const Block block = Block::whole(3, 2, MPI_COMM_SELF);
  const Field<Vec3> velocity = frame_field(block, 9);
  const Field<double> curvature = scalar_field(block, 1, 0.0);
  std::vector<double> times;
  {
    FrameWriter writer(h5.string(), block, "scene", "verlet", "0.1.0", {}, {}, kFields);
    for (int frame = 0; frame < 5; ++frame) {
      times.push_back(frame * 0.5);
      writer.write_frame(frame * 10, times.back(), frame_field(block, frame), {},
                         {&velocity, &curvature});
    }
  }
  const auto expect_refused = [&](const std::vector<NodeField>& other, const char* why) {
    try {
      FrameWriter restarted(h5.string(), block, 25, "scene", 20, 0.0, {}, other);
      ADD_FAILURE() << "restart accepted " << why;
    } catch (const std::runtime_error& error) {
      EXPECT_NE(std::string(error.what()).find(h5.string()), std::string::npos) << error.what();
    }
    const Hid file(H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    EXPECT_EQ(dataset_shape(file.get(), "/fields/curvature")[0], 5u) << why;
  };
  expect_refused({}, "without fields");
  expect_refused({kFields[0]}, "with one field of two");
  expect_refused({kFields[0], {"curvature", "1/mm", false}}, "with other units");
  {
    FrameWriter restarted(h5.string(), block, 25, "scene", 20, 0.0, {}, kFields);
    EXPECT_EQ(restarted.frames(), 3);
    times.resize(3);
    times.push_back(1.5);
    restarted.write_frame(30, times.back(), frame_field(block, 3), {}, {&velocity, &curvature});
  }
  const Hid file(H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  EXPECT_EQ(dataset_shape(file.get(), "/fields/velocity"), (std::vector<hsize_t>{4, 3, 2, 3}));
  EXPECT_EQ(dataset_shape(file.get(), "/fields/curvature"), (std::vector<hsize_t>{4, 3, 2}));
  EXPECT_EQ(read_text(directory_ / "resume_fields.xmf"),
            xdmf_document("resume_fields.h5", 3, 2, times, {},
                          {{"velocity", true}, {"curvature", false}}));
}

RunSummary example_summary() {
  RunSummary summary;
  summary.scene = "hanging_sheet";
  summary.m = 32;
  summary.n = 48;
  summary.ranks = 4;
  summary.threads = 2;
  summary.integrator = "verlet";
  summary.dt = 1e-4;
  summary.steps = 5000;
  summary.sim_time = 0.5;
  summary.wall_seconds = 1.25;
  summary.node_steps_per_second = 6.144e6;
  summary.status = "ok";
  summary.area_ratio = 0.9987;
  summary.max_speed = 1.5;
  summary.kinetic_energy = 0.25;
  summary.center_of_mass = {0.5, -0.25, 0.0};
  summary.output = "hanging_sheet.h5";
  return summary;
}

// The keys of docs/output.md, "Run summary", in its order, with the decomposition and halo time of
// issue 3 added, the contact figures (null and empty without solids) and self-contact's (null
// without it).
TEST(RunSummaryTest, HasExactlyTheDesignKeysInOrder) {
  const std::string json = to_json(example_summary());
  const std::regex key(R"re(\n  "(\w+)":)re");
  std::vector<std::string> keys;
  for (auto it = std::sregex_iterator(json.begin(), json.end(), key); it != std::sregex_iterator();
       ++it) {
    keys.push_back((*it)[1]);
  }
  const std::vector<std::string> expected{
      "scene",         "grid",          "ranks",          "threads",  "thread_steps",  "split",
      "integrator",    "discretisation", "dt",          "steps",          "sim_time",
      "wall_seconds",  "node_steps_per_second",           "halo_seconds",
      "restarted_from", "status",
      "unstable_step", "area_ratio",    "max_speed",      "kinetic_energy",
      "elastic_energy", "gravitational_energy",
      "center_of_mass", "output",        "linear_solves",  "rest",          "adaptive",
      "max_penetration", "max_contacts", "solids", "self_contact"};
  EXPECT_EQ(keys, expected);
  EXPECT_NE(json.find(R"("self_contact": null)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("max_penetration": null,)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("solids": [])"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("linear_solves": null,)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("adaptive": null,)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("grid": [32, 48])"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("restarted_from": null,)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("dt": 0.0001,)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("center_of_mass": [0.5, -0.25, 0])"), std::string::npos) << json;
  EXPECT_EQ(json.front(), '{');
}

// Self-contact's figures as an object; a run whose layers never came within the thickness has
// no closest pair, written null rather than an infinity JSON cannot hold.
TEST(RunSummaryTest, SelfContactFiguresAreAnObject) {
  RunSummary summary = example_summary();
  summary.self_contact = SelfContactSummary{0.0005, 12, 0.0008};
  std::string json = to_json(summary);
  EXPECT_NE(
      json.find(R"("self_contact": {"thickness": 0.0005, "max_pairs": 12, "closest": 0.0008})"),
      std::string::npos)
      << json;
  summary.self_contact = SelfContactSummary{0.0005, 0, std::numeric_limits<double>::infinity()};
  json = to_json(summary);
  EXPECT_NE(json.find(R"("self_contact": {"thickness": 0.0005, "max_pairs": 0, "closest": null})"),
            std::string::npos)
      << json;
}

// The semi-implicit integrator's solves and --until-rest's result, as objects.
TEST(RunSummaryTest, WritesLinearSolvesAndRest) {
  RunSummary summary = example_summary();
  summary.linear_solves = LinearSolveStats{10, 25, 4, 0.5, 3, 0.25, 0.125};
  summary.rest = RestSummary{1e-6, 2.0, 840};
  const std::string json = to_json(summary);
  EXPECT_NE(json.find(R"("linear_solves": {"solves": 10, "iterations": 25, "mean_iterations": 2.5, "most_iterations": 4, "jacobian_seconds": 0.5, "jacobians": 3, "solve_seconds": 0.25, "setup_seconds": 0.125},)"),
            std::string::npos)
      << json;
  EXPECT_NE(json.find(R"("rest": {"fraction": 1e-06, "peak_kinetic_energy": 2, "step": 840})"),
            std::string::npos)
      << json;
}

// With solids: the run's contact figures and each solid's final state.
TEST(RunSummaryTest, WritesContactFiguresAndEachSolidsState) {
  RunSummary summary = example_summary();
  summary.contact = ContactSummary{2.5e-4, 120};
  SolidState cube;
  cube.pose = {{1.0, 2.0, 3.0}, {0.5, 0.5, 0.5, 0.5}};
  cube.velocity = {0.0, -1.5, 0.0};
  cube.angular_velocity = {0.0, 0.0, 2.0};
  summary.solids.push_back({"cube", "free", cube});
  summary.solids.push_back({"floor", "fixed", SolidState{}});
  const std::string json = to_json(summary);
  EXPECT_NE(json.find(R"("max_penetration": 0.00025,)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("max_contacts": 120,)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"({"name": "cube", "motion": "free", "position": [1, 2, 3], )"
                      R"("orientation": [0.5, 0.5, 0.5, 0.5], "velocity": [0, -1.5, 0], )"
                      R"("angular_velocity": [0, 0, 2]},)"),
            std::string::npos)
      << json;
  EXPECT_NE(json.find(R"({"name": "floor", "motion": "fixed")"), std::string::npos) << json;
}

TEST(RunSummaryTest, WritesNullForMissingAndNonFiniteValues) {
  RunSummary summary = example_summary();
  summary.kinetic_energy = std::numeric_limits<double>::quiet_NaN();
  summary.center_of_mass.y = std::numeric_limits<double>::infinity();
  const std::string json = to_json(summary);
  EXPECT_NE(json.find(R"("unstable_step": null,)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("kinetic_energy": null,)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("center_of_mass": [0.5, null, 0])"), std::string::npos) << json;

  summary.status = "unstable";
  summary.unstable_step = 1234;
  EXPECT_NE(to_json(summary).find(R"("unstable_step": 1234,)"), std::string::npos);
}

TEST(RunSummaryTest, EscapesStrings) {
  RunSummary summary = example_summary();
  summary.scene = "say \"hi\"\\\n\x01";
  EXPECT_NE(to_json(summary).find(R"("scene": "say \"hi\"\\\n\u0001",)"), std::string::npos)
      << to_json(summary);
}

TEST(RunSummaryTest, WriteSummaryFailsLoudly) {
  EXPECT_THROW(write_summary("/nonexistent-folder/summary.json", example_summary()),
               std::runtime_error);
}

}  // namespace
}  // namespace cosserat
