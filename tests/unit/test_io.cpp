// The HDF5 output, its XDMF companion and the run summary, read back the way other tools read
// them: HDF5 through the C API, XDMF and JSON as text.

#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>

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

// DESIGN.md's keys, in its order, with the decomposition and halo time of issue 3 added.
TEST(RunSummaryTest, HasExactlyTheDesignKeysInOrder) {
  const std::string json = to_json(example_summary());
  const std::regex key(R"re(\n  "(\w+)":)re");
  std::vector<std::string> keys;
  for (auto it = std::sregex_iterator(json.begin(), json.end(), key); it != std::sregex_iterator();
       ++it) {
    keys.push_back((*it)[1]);
  }
  const std::vector<std::string> expected{
      "scene",         "grid",          "ranks",          "threads",       "split",
      "integrator",    "discretisation", "dt",          "steps",          "sim_time",
      "wall_seconds",  "node_steps_per_second",           "halo_seconds",
      "restarted_from", "status",
      "unstable_step", "area_ratio",    "max_speed",      "kinetic_energy",
      "elastic_energy", "gravitational_energy",
      "center_of_mass", "output",        "linear_solves",  "rest",          "adaptive"};
  EXPECT_EQ(keys, expected);
  EXPECT_NE(json.find(R"("linear_solves": null,)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("adaptive": null)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("grid": [32, 48])"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("restarted_from": null,)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("dt": 0.0001,)"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("center_of_mass": [0.5, -0.25, 0])"), std::string::npos) << json;
  EXPECT_EQ(json.front(), '{');
}

// The semi-implicit integrator's solves and --until-rest's result, as objects.
TEST(RunSummaryTest, WritesLinearSolvesAndRest) {
  RunSummary summary = example_summary();
  summary.linear_solves = LinearSolveStats{10, 25, 4, 0.5, 0.25};
  summary.rest = RestSummary{1e-6, 2.0, 840};
  const std::string json = to_json(summary);
  EXPECT_NE(json.find(R"("linear_solves": {"solves": 10, "iterations": 25, "mean_iterations": 2.5, "most_iterations": 4, "jacobian_seconds": 0.5, "solve_seconds": 0.25},)"),
            std::string::npos)
      << json;
  EXPECT_NE(json.find(R"("rest": {"fraction": 1e-06, "peak_kinetic_energy": 2, "step": 840})"),
            std::string::npos)
      << json;
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
