// The `cosserat` command line as a user meets it (docs/design.md, "Interfaces"): exit statuses,
// messages, what a failed run leaves behind. Runs the real executable in a child process.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sched.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/dataset_bytes.hpp"

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

struct Result {
  int status;
  std::string output;  // stdout and stderr together
};

// A shell command line's exit status and everything it printed.
Result shell(const std::string& command_line) {
  const std::string command = command_line + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  std::string output;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe)) output += buffer.data();
  const int raw = pclose(pipe);
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, output};
}

Result cosserat(const std::string& arguments) {
  return shell(std::string(COSSERAT_EXE) + " " + arguments);
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("cosserat_cli_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write_scene(const std::string& name, const std::string& text) const {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

const char* kSmallScene = R"(title = "small"
[grid]
nodes = [6, 6]
size = [10.0, 10.0]
[material]
mass = 10.0
zeta = 100.0
xi = 0.3
phi = 0.001
[environment]
gravity = [0.0, -9.8, 0.0]
damping = 0.2
[time]
dt = 0.001
steps = 200
output_every = 50
[[fix]]
nodes = [[0, 0], [0, 5]]
)";

TEST_F(Cli, HelpDocumentsEveryOption) {
  const Result top = cosserat("--help");
  EXPECT_EQ(top.status, 0);
  EXPECT_THAT(top.output, HasSubstr("run"));
  EXPECT_THAT(top.output, HasSubstr("Exit status"));
  const Result run = cosserat("run --help");
  EXPECT_EQ(run.status, 0);
  for (const char* option : {"--set", "--output", "--summary", "--quiet", "--checkpoint-every",
                             "--restart", "--until-rest", "--petsc", "--threads", "--overwrite"})
    EXPECT_THAT(run.output, HasSubstr(option));
  const Result stable = cosserat("stable-dt --help");
  EXPECT_EQ(stable.status, 0);
  for (const char* option : {"--integrator", "--time", "--tolerance", "--set", "--csv"})
    EXPECT_THAT(stable.output, HasSubstr(option));
}

TEST_F(Cli, MissingSceneFileIsBadInput) {
  const Result r = cosserat("run " + path("absent.toml"));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("absent.toml"));
}

TEST_F(Cli, UnknownOptionIsBadInput) {
  EXPECT_EQ(cosserat("run --no-such-option x.toml").status, 2);
  EXPECT_EQ(cosserat("").status, 2);
}

TEST_F(Cli, InvalidSceneIsBadInputAndWritesNothing) {
  const std::string scene = write_scene("bad.toml", std::string(kSmallScene) + "[time2]\nx = 1\n");
  const Result r = cosserat("run " + scene + " --output " + path("out.h5"));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("time2"));
  EXPECT_FALSE(fs::exists(path("out.h5")));
}

TEST_F(Cli, BadOverrideIsBadInput) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const Result bad_value = cosserat("run " + scene + " --set time.dt=-1 -o " + path("o.h5"));
  EXPECT_EQ(bad_value.status, 2);
  EXPECT_THAT(bad_value.output, HasSubstr("time.dt"));
  const Result bad_name = cosserat("run " + scene + " --set time.integrator=\\\"nope\\\" -o " + path("o.h5"));
  EXPECT_EQ(bad_name.status, 2);
  EXPECT_THAT(bad_name.output, HasSubstr("velocity-verlet"));
  EXPECT_EQ(cosserat("run " + scene + " --set nokey -o " + path("o.h5")).status, 2);
}

// The wind's keys are checked like every other: a bad gust key, from the file or from --set,
// and the wind given under both its names are bad input naming the keys, before any output.
TEST_F(Cli, BadWindIsBadInputAndWritesNothing) {
  const auto wind = [](const std::string& correlation_time) {
    return std::string(kSmallScene) +
           "[environment.wind]\ndrag = 1.0\nvelocity = [5.0, 0.0, 0.0]\n"
           "gust = { amplitude = 1.0, correlation_time = " + correlation_time +
           ", correlation_length = 2.0, seed = 3 }\n";
  };
  const std::string scene = write_scene("wind.toml", wind("1.0"));
  const Result seed =
      cosserat("run " + scene + " --set environment.wind.gust.seed=-1 -o " + path("o.h5"));
  EXPECT_EQ(seed.status, 2) << seed.output;
  EXPECT_THAT(seed.output, HasSubstr("(from --set): key 'environment.wind.gust.seed'"));
  const Result time =
      cosserat("run " + write_scene("time.toml", wind("0.0")) + " -o " + path("o.h5"));
  EXPECT_EQ(time.status, 2) << time.output;
  EXPECT_THAT(time.output, HasSubstr("key 'environment.wind.gust.correlation_time'"));
  const std::string fluid = "[environment.fluid]\nviscosity = 1.0\nvelocity = [5.0, 0.0, 0.0]\n";
  const Result both =
      cosserat("run " + write_scene("both.toml", wind("1.0") + fluid) + " -o " + path("o.h5"));
  EXPECT_EQ(both.status, 2) << both.output;
  EXPECT_THAT(both.output, HasSubstr("key 'environment.fluid'"));
  EXPECT_THAT(both.output, HasSubstr("environment.wind"));
  EXPECT_FALSE(fs::exists(path("o.h5")));
  const Result gusty = cosserat("run " + scene + " -q --set time.steps=20 -o " + path("g.h5"));
  EXPECT_EQ(gusty.status, 0) << gusty.output;
}

TEST_F(Cli, BadSolidIsBadInputAndWritesNothing) {
  const std::string scene = write_scene(
      "solid.toml", std::string(kSmallScene) +
                        "[[solid]]\nshape = \"sphere\"\ncenter = [5, -3, 5]\nradius = 1\n"
                        "restitution = 1.5\n");
  const Result r = cosserat("run " + scene + " --output " + path("out.h5"));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("solid[0].restitution"));
  EXPECT_FALSE(fs::exists(path("out.h5")));
}

TEST_F(Cli, BadFixVelocityIsBadInputAndWritesNothing) {
  const std::string scene = write_scene(
      "velocity.toml",
      std::string(kSmallScene) + "[[fix]]\nnodes = [[5, 5]]\nvelocity = [0.1, 0.0]\n");
  const Result r = cosserat("run " + scene + " --output " + path("out.h5"));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("fix[1].velocity"));
  EXPECT_FALSE(fs::exists(path("out.h5")));
}

TEST_F(Cli, UnwritableOutputIsBadInput) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const Result r = cosserat("run " + scene + " --output " + path("no/such/dir/out.h5"));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("out.h5"));
}

// Nothing the user did not name as output is written over, and nothing is run first: an output
// that is the scene, an output whose XDMF would be itself, a summary that is the output or the
// scene, a scene whose default output is itself, a summary that cannot be written.
TEST_F(Cli, OutputsThatWouldOverwriteInputsOrEachOtherAreBadInput) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const auto expect_refused = [&](const std::string& arguments, const std::string& says) {
    const Result r = arguments.starts_with("cd ") ? shell(arguments) : cosserat(arguments);
    EXPECT_EQ(r.status, 2) << arguments << "\n" << r.output;
    EXPECT_THAT(r.output, HasSubstr(says)) << arguments;
  };
  expect_refused("run " + scene + " -o " + scene, "would be written over the scene file");
  expect_refused("run " + scene + " -o " + path("x.xmf"), "would be the same file");
  expect_refused("run " + scene + " -o " + path("o.h5") + " --summary " + path("o.h5"),
                 "would be the same file");
  expect_refused("run " + scene + " -o " + path("o.h5") + " --summary " + scene,
                 "would be written over the scene file");
  expect_refused("run " + scene + " -o " + path("o.h5") + " --summary " + path("nodir/s.json"),
                 "cannot write a file in");
  const std::string own = write_scene("scene.h5", kSmallScene);
  expect_refused("cd " + dir_.string() + " && " + std::string(COSSERAT_EXE) + " run scene.h5",
                 "would be written over the scene file");
  // Nothing ran: no frames anywhere, and the scene files are as written.
  EXPECT_FALSE(fs::exists(path("o.h5")));
  EXPECT_FALSE(fs::exists(path("x.xmf")));
  std::ifstream kept(scene);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(kept), {}), kSmallScene);
  std::ifstream kept_own(own);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(kept_own), {}), kSmallScene);
}

TEST_F(Cli, GridTooLargeForTheMachineIsBadInput) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const Result r = cosserat("run " + scene + " --set grid.nodes=[200000,200000] -o " + path("big.h5"));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("200000 x 200000 grid needs about"));
  EXPECT_FALSE(fs::exists(path("big.h5")));
}

// Frames of an output file and whether every stored position is finite.
std::pair<long, bool> read_frames(const std::string& file) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return {-1, false};
  const hid_t d = H5Dopen2(f, "/positions", H5P_DEFAULT);
  const hid_t s = H5Dget_space(d);
  std::array<hsize_t, 4> dims{};
  H5Sget_simple_extent_dims(s, dims.data(), nullptr);
  std::vector<double> data(dims[0] * dims[1] * dims[2] * dims[3]);
  H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data());
  bool finite = true;
  for (double x : data) finite = finite && std::isfinite(x);
  H5Sclose(s);
  H5Dclose(d);
  H5Fclose(f);
  return {static_cast<long>(dims[0]), finite};
}

TEST_F(Cli, SuccessfulRunWritesFramesAndSummary) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const Result r = cosserat("run " + scene + " -o " + path("ok.h5") + " --summary " + path("ok.json"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(read_frames(path("ok.h5")).first, 5);  // steps 0, 50, 100, 150, 200
  EXPECT_TRUE(fs::exists(path("ok.xmf")));
  std::stringstream json;
  json << std::ifstream(path("ok.json")).rdbuf();
  for (const char* key : {"\"scene\"", "\"grid\"", "\"ranks\"", "\"threads\"", "\"integrator\"",
                          "\"dt\"", "\"steps\"", "\"sim_time\"", "\"wall_seconds\"",
                          "\"node_steps_per_second\"", "\"status\": \"ok\"", "\"unstable_step\": null",
                          "\"area_ratio\"", "\"max_speed\"", "\"kinetic_energy\"", "\"center_of_mass\""})
    EXPECT_THAT(json.str(), HasSubstr(key));
}

TEST_F(Cli, OverridesMayComeBeforeTheScene) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const Result r = cosserat("run --set time.steps=100 --set time.output_every=25 " + scene +
                            " -o " + path("o.h5"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(read_frames(path("o.h5")).first, 5);  // steps 0, 25, 50, 75, 100
}

// A step far above the stability limit: the monitor stops the run with status 3, names the
// step and node, and the file keeps the frames written so far plus the last good state.
TEST_F(Cli, BlowUpStopsWithItsOwnStatusAndKeepsWork) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const Result r = cosserat("run " + scene + " --set time.dt=0.05 --set time.steps=2000 --set time.output_every=2 -o " +
                            path("bad.h5") + " --summary " + path("bad.json"));
  EXPECT_EQ(r.status, 3) << r.output;
  EXPECT_THAT(r.output, HasSubstr("unstable at step"));
  EXPECT_THAT(r.output, HasSubstr("node ["));
  const auto [frames, finite] = read_frames(path("bad.h5"));
  EXPECT_GE(frames, 3);  // step 0, at least one more, and the last good state
  EXPECT_TRUE(finite);
  std::stringstream json;
  json << std::ifstream(path("bad.json")).rdbuf();
  EXPECT_THAT(json.str(), HasSubstr("\"status\": \"unstable\""));
  EXPECT_THAT(json.str(), ::testing::Not(HasSubstr("\"unstable_step\": null")));
}

// The per-node fields a small grid writes by default (docs/output.md, "Fields").
constexpr std::array<const char*, 4> kFieldDatasets{"/fields/velocity", "/fields/area_ratio",
                                                    "/fields/curvature", "/fields/energy_density"};

// /positions, /time, /step and the fields of an output file as raw bytes, in that order.
std::vector<std::vector<unsigned char>> read_datasets(const std::string& file) {
  std::vector<std::vector<unsigned char>> all;
  for (const char* name : {"/positions", "/time", "/step"})
    all.push_back(cosserat::testing::dataset_bytes(file, name));
  for (const char* name : kFieldDatasets)
    all.push_back(cosserat::testing::dataset_bytes(file, name));
  return all;
}

// A run stopped after a checkpoint and restarted with more steps ends where an uninterrupted
// run ends, bitwise; its output file holds the frames of both parts.
TEST_F(Cli, RestartContinuesARunBitwise) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  ASSERT_EQ(cosserat("run " + scene + " -q -o " + path("whole.h5")).status, 0);
  const Result first = cosserat("run " + scene + " -q --set time.steps=120 --checkpoint-every 50 -o " +
                                path("part.h5"));
  ASSERT_EQ(first.status, 0) << first.output;
  ASSERT_TRUE(fs::exists(path("part.checkpoint.h5")));
  EXPECT_FALSE(fs::exists(path("part.checkpoint.h5.partial")));
  const Result second = cosserat("run " + scene + " --restart " + path("part.checkpoint.h5") +
                                 " -o " + path("part.h5") + " --summary " + path("part.json"));
  ASSERT_EQ(second.status, 0) << second.output;
  EXPECT_THAT(second.output, HasSubstr("at step 120"));
  // Frames 0, 50, 100, 120 from the first part, 150 and 200 from the second.
  EXPECT_EQ(read_frames(path("part.h5")).first, 6);
  const auto whole = read_datasets(path("whole.h5")), part = read_datasets(path("part.h5"));
  const std::size_t frame_bytes = 6 * 6 * 3 * sizeof(double);
  ASSERT_EQ(part[0].size(), 6 * frame_bytes);
  ASSERT_EQ(whole[0].size(), 5 * frame_bytes);
  EXPECT_TRUE(std::equal(part[0].end() - frame_bytes, part[0].end(), whole[0].end() - frame_bytes))
      << "the last frames differ";
  std::stringstream json;
  json << std::ifstream(path("part.json")).rdbuf();
  EXPECT_THAT(json.str(), HasSubstr("\"restarted_from\": 120"));
}

// With self-contact on, a checkpoint written before the cloth ever touches itself (no pair, so no
// closest distance yet) restarts as any other, to the uninterrupted run's last frame; it was
// refused as holding a number that is not finite.
TEST_F(Cli, RestartWithSelfContactBeforeAnyPairContinuesBitwise) {
  std::string text = std::string(kSmallScene) + "[self_contact]\n";
  text.replace(text.find("phi = 0.001\n"), 12, "phi = 0.001\nthickness = 0.001\n");
  const std::string scene = write_scene("s.toml", text);
  ASSERT_EQ(
      cosserat("run " + scene + " -q -o " + path("whole.h5") + " --summary " + path("whole.json"))
          .status,
      0);
  std::stringstream summary;
  summary << std::ifstream(path("whole.json")).rdbuf();
  ASSERT_THAT(summary.str(), HasSubstr(R"("max_pairs": 0, "closest": null)")) << summary.str();
  ASSERT_EQ(cosserat("run " + scene + " -q --set time.steps=120 --checkpoint-every 50 -o " +
                     path("part.h5"))
                .status,
            0);
  const Result second = cosserat("run " + scene + " -q --restart " + path("part.checkpoint.h5") +
                                 " -o " + path("part.h5"));
  ASSERT_EQ(second.status, 0) << second.output;
  const auto whole = read_datasets(path("whole.h5")), part = read_datasets(path("part.h5"));
  const std::size_t frame_bytes = 6 * 6 * 3 * sizeof(double);
  ASSERT_GE(part[0].size(), frame_bytes);
  EXPECT_TRUE(std::equal(part[0].end() - frame_bytes, part[0].end(), whole[0].end() - frame_bytes))
      << "the last frames differ";
}

// Issue 12: a restart continues only the output of the run it restarts. Another scene's file and
// a file of the same scene that lacks frames before the checkpoint are refused, unchanged.
TEST_F(Cli, RestartIntoAnotherRunsOutputIsBadInput) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  ASSERT_EQ(cosserat("run " + scene + " -q --set time.steps=120 --checkpoint-every 50 -o " +
                     path("part.h5"))
                .status,
            0);
  std::string other_text = kSmallScene;
  other_text.replace(other_text.find("nodes = [6, 6]"), 14, "nodes = [8, 8]");
  const std::string other = write_scene("other.toml", other_text);
  ASSERT_EQ(cosserat("run " + other + " -q --set time.steps=50 -o " + path("other.h5")).status, 0);
  ASSERT_EQ(cosserat("run " + scene + " -q --set time.steps=50 -o " + path("short.h5")).status, 0);
  const auto bytes_of = [&](const std::string& name) {
    std::ifstream in(path(name), std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string other_before = bytes_of("other.h5"), short_before = bytes_of("short.h5");

  const Result into_other = cosserat("run " + scene + " --restart " +
                                     path("part.checkpoint.h5") + " -o " + path("other.h5"));
  EXPECT_EQ(into_other.status, 2) << into_other.output;
  EXPECT_THAT(into_other.output, HasSubstr("written for another scene text"));
  const Result into_short = cosserat("run " + scene + " --restart " +
                                     path("part.checkpoint.h5") + " -o " + path("short.h5"));
  EXPECT_EQ(into_short.status, 2) << into_short.output;
  EXPECT_THAT(into_short.output, HasSubstr("frames up to step 50"));
  EXPECT_EQ(bytes_of("other.h5"), other_before);
  EXPECT_EQ(bytes_of("short.h5"), short_before);
}

// A run killed (SIGKILL) soon after its first checkpoint (step 1500, between two frames), then
// restarted: the output file ends up identical, dataset by dataset, to that of a run never
// interrupted, whatever frames the killed run had written past its checkpoint.
TEST_F(Cli, KilledRunRestartsToTheUninterruptedOutput) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  // 6500 steps past the checkpoint: far more than the kill takes to land (about 300 steps in
  // the release build), few enough for the sanitizer build (3 runs of this took 93 s at 20000).
  const std::string longer = " --set grid.nodes=[30,30] --set time.steps=8000 --set time.output_every=1000 ";
  ASSERT_EQ(cosserat("run " + scene + longer + "-q -o " + path("whole.h5")).status, 0);
  const std::string run = std::string(COSSERAT_EXE) + " run " + scene + longer +
                          "-q --checkpoint-every 1500 -o " + path("killed.h5");
  const std::string kill_after_checkpoint =
      "sh -c '" + run + " & pid=$!; while [ ! -f " + path("killed.checkpoint.h5") +
      " ]; do sleep 0.01; done; sleep 0.05; kill -9 $pid; wait $pid; echo killed $?'";
  FILE* pipe = popen(kill_after_checkpoint.c_str(), "r");
  std::array<char, 256> line{};
  std::string said;
  while (std::fgets(line.data(), line.size(), pipe)) said += line.data();
  pclose(pipe);
  ASSERT_THAT(said, HasSubstr("killed 137")) << "the run ended before it was killed: " << said;

  const Result restarted = cosserat("run " + scene + longer + "-q --restart " +
                                    path("killed.checkpoint.h5") + " -o " + path("killed.h5"));
  ASSERT_EQ(restarted.status, 0) << restarted.output;
  const auto whole = read_datasets(path("whole.h5")), killed = read_datasets(path("killed.h5"));
  ASSERT_FALSE(whole[0].empty());
  EXPECT_TRUE(killed[0] == whole[0]) << "/positions differ";
  EXPECT_TRUE(killed[1] == whole[1]) << "/time differs";
  EXPECT_TRUE(killed[2] == whole[2]) << "/step differs";
  for (std::size_t i = 0; i < kFieldDatasets.size(); ++i) {
    EXPECT_FALSE(whole[3 + i].empty()) << kFieldDatasets[i];
    EXPECT_TRUE(killed[3 + i] == whole[3 + i]) << kFieldDatasets[i] << " differs";
  }
}

// Issue 12, defect 13: the XDMF file grows by one element per frame, in place. A run killed
// at any moment leaves an XDMF file that parses (Python's XML parser standing in for ParaView's)
// and names frames the HDF5 file holds: all of them, or all but the one being written.
TEST_F(Cli, XdmfOfAKilledRunParsesAndNamesItsFrames) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const std::string run = std::string(COSSERAT_EXE) + " run " + scene +
                          " --set grid.nodes=[30,30] --set time.steps=20000 "
                          "--set time.output_every=40 -q -o " + path("killed.h5");
  const Result killed =
      shell("sh -c '" + run + " & pid=$!; until grep -qs frame_3 " + path("killed.xmf") +
            "; do sleep 0.01; done; sleep 0.05; kill -9 $pid; wait $pid; echo killed $?'");
  ASSERT_THAT(killed.output, HasSubstr("killed 137")) << killed.output;
  std::ofstream(path("count.py")) << "import sys, xml.etree.ElementTree as tree\n"
                                     "root = tree.parse(sys.argv[1]).getroot()\n"
                                     "print(len(root.findall(\".//Grid[@GridType='Uniform']\")))\n";
  const Result parsed = shell("/usr/bin/python3 " + path("count.py") + " " + path("killed.xmf"));
  ASSERT_EQ(parsed.status, 0) << parsed.output;
  const long named = std::stol(parsed.output);
  const long frames = read_frames(path("killed.h5")).first;
  EXPECT_GE(named, 2) << "killed before its second frame; kill later";
  EXPECT_TRUE(named == frames || named == frames - 1) << named << " named, " << frames << " held";
}

// The shape of a dataset, and its `units` attribute; empty when it is absent.
std::pair<std::vector<hsize_t>, std::string> shape_and_units(const std::string& file,
                                                             const char* name) {
  std::pair<std::vector<hsize_t>, std::string> found;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return found;
  if (H5Lexists(f, "fields", H5P_DEFAULT) > 0 && H5Lexists(f, name, H5P_DEFAULT) > 0) {
    const hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    const hid_t s = H5Dget_space(d);
    found.first.resize(static_cast<std::size_t>(H5Sget_simple_extent_ndims(s)));
    H5Sget_simple_extent_dims(s, found.first.data(), nullptr);
    const hid_t a = H5Aopen(d, "units", H5P_DEFAULT);
    const hid_t type = H5Aget_type(a);
    char* text = nullptr;
    H5Aread(a, type, &text);
    found.second = text != nullptr ? text : "";
    H5free_memory(text);
    H5Tclose(type);
    H5Aclose(a);
    H5Sclose(s);
    H5Dclose(d);
  }
  H5Fclose(f);
  return found;
}

long xdmf_attributes(const std::string& file) {
  std::stringstream text;
  text << std::ifstream(file).rdbuf();
  long count = 0;
  const std::string xml = text.str();
  for (auto at = xml.find("<Attribute "); at != std::string::npos;
       at = xml.find("<Attribute ", at + 1))
    ++count;
  return count;
}

// A small grid writes every field by default, each with its units and named in every frame of
// the XDMF file; output.fields chooses, and a name it does not know is bad input.
TEST_F(Cli, SmallGridsWriteEveryFieldAndOutputFieldsChooses) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  ASSERT_EQ(cosserat("run " + scene + " -q -o " + path("all.h5")).status, 0);
  using Shape = std::vector<hsize_t>;
  EXPECT_EQ(shape_and_units(path("all.h5"), "/fields/velocity"),
            std::pair(Shape{5, 6, 6, 3}, std::string("m/s")));
  EXPECT_EQ(shape_and_units(path("all.h5"), "/fields/area_ratio"),
            std::pair(Shape{5, 6, 6}, std::string("1")));
  EXPECT_EQ(shape_and_units(path("all.h5"), "/fields/curvature"),
            std::pair(Shape{5, 6, 6}, std::string("1/m")));
  EXPECT_EQ(shape_and_units(path("all.h5"), "/fields/energy_density"),
            std::pair(Shape{5, 6, 6}, std::string("J/m^2")));
  EXPECT_EQ(xdmf_attributes(path("all.xmf")), 4 * 5);

  ASSERT_EQ(cosserat("run " + scene + " -q --set output.fields=[] -o " + path("none.h5")).status, 0);
  EXPECT_TRUE(shape_and_units(path("none.h5"), "/fields/velocity").first.empty());
  EXPECT_EQ(xdmf_attributes(path("none.xmf")), 0);
  ASSERT_EQ(cosserat("run " + scene + " -q --set 'output.fields=[\"curvature\"]' -o " +
                     path("one.h5"))
                .status,
            0);
  EXPECT_TRUE(shape_and_units(path("one.h5"), "/fields/velocity").first.empty());
  EXPECT_EQ(shape_and_units(path("one.h5"), "/fields/curvature").first, (Shape{5, 6, 6}));
  EXPECT_EQ(xdmf_attributes(path("one.xmf")), 5);

  const Result bad = cosserat("run " + scene + " --set 'output.fields=[\"speed\"]' -o " +
                              path("bad.h5"));
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_THAT(bad.output, HasSubstr("key 'output.fields[0]': unknown field \"speed\"; allowed: "
                                    "velocity, area_ratio, curvature, energy_density"));
  EXPECT_FALSE(fs::exists(path("bad.h5")));
}

TEST_F(Cli, RestartFromAnotherScenesCheckpointIsBadInput) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  ASSERT_EQ(cosserat("run " + scene + " -q --set time.steps=10 --checkpoint-every 10 -o " + path("a.h5")).status, 0);
  const Result r = cosserat("run " + scene + " --set time.dt=0.002 --restart " +
                            path("a.checkpoint.h5") + " -o " + path("b.h5"));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("dt = 0.002"));
  EXPECT_EQ(cosserat("run " + scene + " --restart " + path("absent.h5")).status, 2);
}

// More ranks than a 3 x 6 grid can be split over (every block must be two nodes wide).
// The command line of `cosserat ARGUMENTS` under mpiexec on `ranks` ranks.
std::string on_ranks(int ranks, const std::string& arguments) {
  return std::string(COSSERAT_MPIEXEC) + " -n " + std::to_string(ranks) + " " +
         COSSERAT_MPIEXEC_FLAGS + " " + COSSERAT_EXE + " " + arguments;
}

// The whole output of 4 ranks, fields included, is that of one, dataset by dataset.
TEST_F(Cli, OutputOfFourRanksIsThatOfOne) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const std::string grid = " --set grid.nodes=[13,11] -q --threads 1 -o ";
  ASSERT_EQ(cosserat("run " + scene + grid + path("one.h5")).status, 0);
  const Result four = shell(on_ranks(4, "run " + scene + grid + path("four.h5")));
  ASSERT_EQ(four.status, 0) << four.output;
  const auto one_rank = read_datasets(path("one.h5")), four_ranks = read_datasets(path("four.h5"));
  for (std::size_t i = 0; i < one_rank.size(); ++i) {
    EXPECT_FALSE(one_rank[i].empty()) << i;
    EXPECT_TRUE(one_rank[i] == four_ranks[i]) << "dataset " << i << " differs";
  }
}

TEST_F(Cli, GridTooSmallForTheRanksIsBadInput) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const Result r =
      shell(on_ranks(4, "run " + scene + " --set grid.nodes=[3,6] -o " + path("x.h5")));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("cannot be split over 4 MPI ranks"));
  EXPECT_FALSE(fs::exists(path("x.h5")));
}

// Issue 12: an error on one rank ends every rank, promptly. Rank 0 alone writes the XDMF file,
// through out.xmf.partial; where a folder stands in its way, rank 0 fails at the first frame
// while rank 1 goes on to its first step. Before, both hung (rank 0 closing the HDF5 file
// collectively while unwinding); the timeout turns a hang into a failure here, not in CI.
TEST_F(Cli, ErrorOnOneRankEndsEveryRank) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  fs::create_directories(path("out.xmf.partial"));
  const auto start = std::chrono::steady_clock::now();
  const Result r = shell("timeout 60 " + on_ranks(2, "run " + scene + " -o " + path("out.h5")));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_NE(r.status, 0) << r.output;
  EXPECT_NE(r.status, 124) << "hung until the timeout: " << r.output;
  EXPECT_LT(seconds, 30.0);
  EXPECT_THAT(r.output, HasSubstr("out.xmf"));
}

// Issue 12, defect 4: a second run on the output of a run still writing it is refused, on one
// rank and on two (both ranks end promptly; the timeout turns a hang into a failure), with exit
// status 2 and a message naming the file, and the first run's file is left alone. The lock dies
// with its process: after the first run is killed, a new run on the same output goes ahead.
// Before, both runs wrote the file, exited 0 and left it unreadable. The later runs pass
// --overwrite: the lock, not the output's existing, is what refuses the second.
TEST_F(Cli, SecondRunOnAnOutputBeingWrittenIsRefused) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const std::string first = std::string(COSSERAT_EXE) + " run " + scene +
                            " --set grid.nodes=[30,30] --set time.steps=200000 "
                            "--set time.output_every=500 -q -o " + path("out.h5");
  const std::string second = "run " + scene + " -q --overwrite -o " + path("out.h5");
  const Result r = shell(
      "sh -c '" + first + " & pid=$!; until grep -qs frame_1 " + path("out.xmf") +
      "; do sleep 0.01; done; " + COSSERAT_EXE + " " + second + "; echo second $?; timeout 60 " +
      on_ranks(2, second) + "; echo ranks $?; kill -0 $pid && echo first running; kill -9 $pid; " +
      "wait $pid; " + COSSERAT_EXE + " " + second + "; echo third $?'");
  EXPECT_THAT(r.output, HasSubstr("second 2\n"));
  EXPECT_THAT(r.output, HasSubstr("ranks 2\n"));
  EXPECT_THAT(r.output, HasSubstr("first running\n"));
  EXPECT_THAT(r.output, HasSubstr("third 0\n")) << r.output;
  EXPECT_THAT(r.output, HasSubstr(path("out.h5") + " is locked by another process"));
  const auto [frames, finite] = read_frames(path("out.h5"));
  EXPECT_EQ(frames, 5) << "the third run's steps 0, 50, 100, 150, 200";
  EXPECT_TRUE(finite);
}

// The "threads" of a run's summary JSON, or -1.
int summary_threads(const std::string& summary_path) {
  std::stringstream json;
  json << std::ifstream(summary_path).rdbuf();
  const std::string text = json.str(), key = "\"threads\": ";
  const auto at = text.find(key);
  return at == std::string::npos ? -1 : std::stoi(text.substr(at + key.size()));
}

int cores_of_this_process() {
  cpu_set_t mask;
  CPU_ZERO(&mask);
  if (sched_getaffinity(0, sizeof(mask), &mask) != 0) return 1;
  return CPU_COUNT(&mask);
}

// Issue 12, defect 15: two ranks given the same cores share them. Open MPI is told not to bind
// (the environment variable, which another MPI ignores), so both ranks see every core of this
// process; before, each started one thread per core, twice as many threads as cores.
TEST_F(Cli, RanksSharingTheirCoresSplitThem) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const std::string summary = path("s.json");
  const Result r = shell("env -u OMP_NUM_THREADS OMPI_MCA_hwloc_base_binding_policy=none "
                         "timeout 120 " +
                         on_ranks(2, "run " + scene + " --set time.steps=10 -o " +
                                         path("o.h5") + " --summary " + summary));
  ASSERT_EQ(r.status, 0) << r.output;
  const int threads = summary_threads(summary);
  EXPECT_GE(threads, 1) << r.output;
  EXPECT_LE(threads, std::max(1, cores_of_this_process() / 2)) << r.output;
  EXPECT_THAT(r.output, Not(HasSubstr("warning")));
}

// Open MPI binds one rank to one core by default: on a machine of more cores the rank runs
// one thread and says how to use the cores left idle (measured at half the speed of two
// threads: docs/parallel.md, "Threads that fit"). Given a thread count, it says nothing.
TEST_F(Cli, ARankBoundToOneOfSeveralCoresSaysTheOthersAreIdle) {
  if (cores_of_this_process() < 2) GTEST_SKIP() << "needs 2 cores";
  const std::string scene = write_scene("s.toml", kSmallScene);
  const std::string run = "run " + scene + " --set time.steps=10 --overwrite -o " + path("o.h5") +
                          " --summary " + path("s.json");
  const Result bound = shell("env -u OMP_NUM_THREADS -u OMPI_MCA_hwloc_base_binding_policy "
                             "timeout 120 " + on_ranks(1, run));
  ASSERT_EQ(bound.status, 0) << bound.output;
  if (summary_threads(path("s.json")) > 1) GTEST_SKIP() << "this MPI did not bind the rank";
  EXPECT_THAT(bound.output, HasSubstr("stays idle; to use it"));
  EXPECT_THAT(bound.output, HasSubstr("--map-by slot:PE="));
  const Result asked = shell("env -u OMP_NUM_THREADS -u OMPI_MCA_hwloc_base_binding_policy "
                             "timeout 120 " + on_ranks(1, run + " --threads 1"));
  ASSERT_EQ(asked.status, 0) << asked.output;
  EXPECT_THAT(asked.output, Not(HasSubstr("idle")));
}

// An explicit count wins over the default, --threads over OMP_NUM_THREADS, and more threads
// than cores are run as asked, with a warning.
TEST_F(Cli, ExplicitThreadCountWinsWithAWarningWhenCoresAreShort) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const int more = cores_of_this_process() + 1;
  const std::string run = "run " + scene + " --set time.steps=10 --overwrite -o " + path("o.h5") +
                          " --summary " + path("s.json");
  const Result from_environment =
      shell("OMP_NUM_THREADS=" + std::to_string(more) + " " + COSSERAT_EXE + " " + run);
  ASSERT_EQ(from_environment.status, 0) << from_environment.output;
  EXPECT_EQ(summary_threads(path("s.json")), more);
  EXPECT_THAT(from_environment.output, HasSubstr("warning: 1 rank on a node of"));
  const Result from_option = shell("OMP_NUM_THREADS=1 " + std::string(COSSERAT_EXE) + " " + run +
                                   " --threads " + std::to_string(more));
  ASSERT_EQ(from_option.status, 0) << from_option.output;
  EXPECT_EQ(summary_threads(path("s.json")), more);
  EXPECT_EQ(cosserat(run + " --threads 0").status, 2);
}

// Writes `values` over the stretch [start, start + count) of a dataset of a closed HDF5 file.
template <class T>
void overwrite(const std::string& file, const std::string& dataset, std::vector<hsize_t> start,
               std::vector<hsize_t> count, hid_t memory_type, const std::vector<T>& values) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t d = H5Dopen2(f, dataset.c_str(), H5P_DEFAULT);
  const hid_t space = H5Dget_space(d);
  H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
  const hid_t memory = H5Screate_simple(static_cast<int>(count.size()), count.data(), nullptr);
  ASSERT_GE(H5Dwrite(d, memory_type, memory, space, H5P_DEFAULT, values.data()), 0);
  H5Sclose(memory);
  H5Sclose(space);
  H5Dclose(d);
  ASSERT_GE(H5Fclose(f), 0);
}

// Issue 12, defect 12: a checkpoint whose positions hold a NaN, or whose constraints name a node
// outside the grid, is bad input on 2 ranks: exit 2 naming the file, promptly, before a step.
// The NaN lies in rank 1's block. Before, the first restarted and stopped unstable (exit 3)
// with the NaN as its "last good state", and the second ran as if the node were not there.
TEST_F(Cli, CorruptCheckpointIsBadInputOnEveryRank) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const std::string checkpoint = path("a.checkpoint.h5");
  const auto restart = [&] {
    return shell("timeout 60 " + on_ranks(2, "run " + scene + " --restart " + checkpoint +
                                                  " -o " + path("b.h5")));
  };
  const auto checkpoint_at_step_10 = [&] {
    const Result first = shell(on_ranks(2, "run " + scene + " -q --set time.steps=10 "
                                           "--checkpoint-every 10 --overwrite -o " + path("a.h5")));
    ASSERT_EQ(first.status, 0) << first.output;
  };
  checkpoint_at_step_10();
  overwrite<double>(checkpoint, "/positions", {5, 5, 0}, {1, 1, 3}, H5T_NATIVE_DOUBLE,
                    {std::nan(""), 0.0, 0.0});
  const Result nan_position = restart();
  EXPECT_EQ(nan_position.status, 2) << nan_position.output;
  EXPECT_THAT(nan_position.output, HasSubstr("checkpoint '" + checkpoint + "'"));
  EXPECT_THAT(nan_position.output, HasSubstr("/positions at node [5, 5] is (nan, 0, 0), not finite"));
  EXPECT_FALSE(fs::exists(path("b.h5")));

  checkpoint_at_step_10();
  overwrite<std::int32_t>(checkpoint, "/constraint_nodes", {1, 0}, {1, 2}, H5T_NATIVE_INT32,
                          {0, 60});
  const Result outside = restart();
  EXPECT_EQ(outside.status, 2) << outside.output;
  EXPECT_THAT(outside.output, HasSubstr("constraint node [0, 60] is outside the 6 x 6 grid"));
  EXPECT_FALSE(fs::exists(path("b.h5")));
}

// Issue 12: outputs that are devices or folders are bad input before any work; before, -o
// /dev/null and -o /dev/full ran, failed to write, and crashed in MPI_Finalize (exit 139).
TEST_F(Cli, OutputThatIsNotARegularFileIsBadInput) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  for (const std::string output : {"/dev/null", "/dev/full"}) {
    const Result r = cosserat("run " + scene + " -o " + output);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_THAT(r.output, HasSubstr("is not a regular file"));
  }
  fs::create_directories(path("out.xmf"));
  const Result r = cosserat("run " + scene + " -o " + path("out.h5"));
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("the XDMF file"));
  EXPECT_FALSE(fs::exists(path("out.h5")));
}


// The complaint: a preset given on the command line to a scene with its own material changed
// nothing, silently. Now one warning, from rank 0 alone, names the keys that override it and
// where each is; the whole table replaced by the preset gives none.
TEST_F(Cli, PresetOverriddenByTheSceneIsWarnedOnce) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const Result r = shell("timeout 120 " + on_ranks(2, "run " + scene +
                                                         " -q --set material.preset=silk "
                                                         "--set time.steps=10 -o " +
                                                         path("x.h5")));
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string expected =
      "warning: " + scene + " (from --set): key 'material.preset': preset \"silk\" is "
      "overridden by material.mass (" + scene + ":6), material.zeta (" + scene +
      ":7), material.xi (" + scene + ":8), material.phi (" + scene +
      ":9), so the preset changes nothing";
  EXPECT_THAT(r.output, HasSubstr(expected));
  EXPECT_EQ(r.output.find("is overridden by"), r.output.rfind("is overridden by")) << r.output;
  const Result whole = cosserat("run " + scene + " -q --set 'material={preset=\"silk\"}' " +
                                "--set time.steps=10 -o " + path("y.h5"));
  ASSERT_EQ(whole.status, 0) << whole.output;
  EXPECT_THAT(whole.output, Not(HasSubstr("warning")));
}

// The bytes of a file, for "left untouched".
std::string file_bytes(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A second run into the files of the first is bad input before any work, naming the file and
// the way out, and leaves every file as it was: the default output, an -o output, its XDMF file,
// its checkpoint, its summary. --overwrite replaces them. Before, the second run wrote over the
// first's results without a word.
TEST_F(Cli, ExistingOutputIsNotReplacedUnasked) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const std::string in_dir = "cd " + dir_.string() + " && " + COSSERAT_EXE + " run s.toml -q";
  ASSERT_EQ(shell(in_dir).status, 0);
  const std::string first = file_bytes(path("s.h5"));
  const Result again = shell(in_dir);
  EXPECT_EQ(again.status, 2) << again.output;
  EXPECT_THAT(again.output, HasSubstr("--output (s.h5) exists, from an earlier run; pass "
                                      "--overwrite to replace it"));
  EXPECT_EQ(file_bytes(path("s.h5")), first);

  const std::string run = "run " + scene + " -q --set time.steps=100 -o " + path("o.h5") +
                          " --summary " + path("o.json") + " --checkpoint-every 50";
  ASSERT_EQ(cosserat(run).status, 0);
  const std::string output = file_bytes(path("o.h5")), xdmf = file_bytes(path("o.xmf")),
                    checkpoint = file_bytes(path("o.checkpoint.h5")),
                    summary = file_bytes(path("o.json"));
  const Result second = cosserat(run);
  EXPECT_EQ(second.status, 2) << second.output;
  EXPECT_THAT(second.output, HasSubstr(path("o.h5") + ") exists"));
  EXPECT_THAT(second.output, HasSubstr("--restart " + path("o.checkpoint.h5")));
  EXPECT_EQ(file_bytes(path("o.h5")), output);
  EXPECT_EQ(file_bytes(path("o.xmf")), xdmf);
  EXPECT_EQ(file_bytes(path("o.checkpoint.h5")), checkpoint);
  EXPECT_EQ(file_bytes(path("o.json")), summary);

  // Each file on its own is enough to refuse: an XDMF file, a checkpoint, a summary.
  for (const std::string kept : {"o.h5", "o.json"}) fs::remove(path(kept));
  const Result xdmf_only = cosserat(run);
  EXPECT_EQ(xdmf_only.status, 2) << xdmf_only.output;
  EXPECT_THAT(xdmf_only.output, HasSubstr("the XDMF file (" + path("o.xmf") + ") exists"));
  fs::remove(path("o.xmf"));
  EXPECT_THAT(cosserat(run).output, HasSubstr("the checkpoint (" + path("o.checkpoint.h5") + ") exists"));
  fs::remove(path("o.checkpoint.h5"));
  ASSERT_EQ(cosserat("run " + scene + " -q --set time.steps=10 -o " + path("p.h5") +
                     " --summary " + path("o.json"))
                .status,
            0);
  const Result summary_only = cosserat(run);
  EXPECT_EQ(summary_only.status, 2) << summary_only.output;
  EXPECT_THAT(summary_only.output,
              HasSubstr("--summary (" + path("o.json") + ") exists, from an earlier run; pass "
                        "--overwrite to replace it, or name another --summary"));

  // With --overwrite the run goes ahead and replaces them all.
  const Result replaced = cosserat(run + " --overwrite --set time.steps=50");
  ASSERT_EQ(replaced.status, 0) << replaced.output;
  EXPECT_EQ(read_frames(path("o.h5")).first, 2);  // steps 0 and 50
  EXPECT_THAT(file_bytes(path("o.json")), HasSubstr("\"steps\": 50"));
}

// A restart is the run that continues its output: it needs no --overwrite, and replaces the
// XDMF file, the checkpoint and the summary of the run it continues. An empty output (left by a
// run killed before its file was created) holds nothing and is no obstacle.
TEST_F(Cli, RestartAndEmptyOutputNeedNoOverwrite) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  ASSERT_EQ(cosserat("run " + scene + " -q --set time.steps=120 --checkpoint-every 50 -o " +
                     path("part.h5") + " --summary " + path("part.json"))
                .status,
            0);
  const Result restarted = cosserat("run " + scene + " -q --checkpoint-every 50 --restart " +
                                    path("part.checkpoint.h5") + " -o " + path("part.h5") +
                                    " --summary " + path("part.json"));
  ASSERT_EQ(restarted.status, 0) << restarted.output;
  EXPECT_EQ(read_frames(path("part.h5")).first, 6);  // 0, 50, 100, 120, then 150 and 200
  EXPECT_THAT(file_bytes(path("part.json")), HasSubstr("\"restarted_from\": 120"));

  std::ofstream(path("empty.h5")).close();
  const Result into_empty = cosserat("run " + scene + " -q -o " + path("empty.h5"));
  ASSERT_EQ(into_empty.status, 0) << into_empty.output;
  EXPECT_EQ(read_frames(path("empty.h5")).first, 5);
}

std::string fmt_run(const std::string& scene, double dt, long steps, const std::string& output) {
  std::ostringstream command;
  command.precision(17);
  command << "run " << scene << " -q --set time.dt=" << dt << " --set time.steps=" << steps
          << " --set time.output_every=" << steps << " -o " << output;
  return command.str();
}

std::string read_text(const std::string& file) {
  std::stringstream text;
  text << std::ifstream(file).rdbuf();
  return text.str();
}

// The number after "key": in a JSON text (NaN when absent or null).
double json_value(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\": ");
  if (at == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + at + key.size() + 4, nullptr);
}

// Field `column` of the first data row of a CSV file whose header names it.
std::string csv_field(const std::string& file, const std::string& column) {
  std::ifstream in(file);
  std::string header, row;
  std::getline(in, header);
  std::getline(in, row);
  auto split = [](const std::string& line) {
    std::vector<std::string> fields;
    std::stringstream s(line);
    for (std::string f; std::getline(s, f, ',');) fields.push_back(f);
    return fields;
  };
  const auto names = split(header), values = split(row);
  const auto it = std::find(names.begin(), names.end(), column);
  if (it == names.end() || values.size() < names.size()) return {};
  return values[static_cast<std::size_t>(it - names.begin())];
}

// stable-dt brackets the limit to its tolerance, and `run` agrees with it on both sides: the
// stable step runs to the end, the unstable one is stopped by the monitor (exit 3).
TEST_F(Cli, StableDtBracketsTheLimitThatRunSees) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const Result r = cosserat("stable-dt " + scene + " --time 0.5 -q --csv " + path("dt.csv"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("CFL estimate"));
  const double stable = std::stod(csv_field(path("dt.csv"), "stable_dt"));
  const double unstable = std::stod(csv_field(path("dt.csv"), "unstable_dt"));
  ASSERT_GT(stable, 0.0);
  EXPECT_GT(unstable, stable);
  EXPECT_LE(unstable, 1.02 * stable);
  for (const auto& [dt, status] : {std::pair{stable, 0}, std::pair{unstable, 3}}) {
    const long steps = std::lround(std::ceil(0.5 / dt - 1e-9));
    const Result run = cosserat(fmt_run(scene, dt, steps, path("b" + std::to_string(status) + ".h5")));
    EXPECT_EQ(run.status, status) << "dt = " << dt << "\n" << run.output;
  }
}

TEST_F(Cli, StableDtBadInputIsExitTwo) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  EXPECT_EQ(cosserat("stable-dt " + path("absent.toml")).status, 2);
  const Result unknown = cosserat("stable-dt " + scene + " --integrator sideways");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_THAT(unknown.output, HasSubstr("sideways"));
  EXPECT_EQ(cosserat("stable-dt " + scene + " --time -1").status, 2);
  EXPECT_EQ(cosserat("stable-dt " + scene + " --tolerance 2").status, 2);
}

// --until-rest stops at the first step below the fraction of the peak kinetic energy and says
// which step that was; the run is "ok" and its last frame is that step.
TEST_F(Cli, UntilRestStopsAtRest) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const Result r = cosserat("run " + scene + " --set time.steps=40000 --until-rest 1e-3 -o " +
                            path("r.h5") + " --summary " + path("r.json"));
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string json = read_text(path("r.json"));
  const double rest_step = json_value(json, "step");
  EXPECT_GT(rest_step, 100.0);
  EXPECT_LT(rest_step, 40000.0);
  EXPECT_EQ(json_value(json, "steps"), rest_step);
  EXPECT_LT(json_value(json, "kinetic_energy"), 1e-3 * json_value(json, "peak_kinetic_energy"));
  EXPECT_THAT(json, HasSubstr("\"status\": \"ok\""));
}

// Issue 12: the stop at rest survives a restart. The peak kinetic energy so far travels in the
// checkpoint, so a run checkpointed before it comes to rest and restarted stops at the step an
// uninterrupted run stops at (before, the restart started its peak from zero and stopped later).
TEST_F(Cli, UntilRestIsRestartSafe) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const std::string rest = " --set time.steps=40000 --until-rest 1e-3";
  ASSERT_EQ(cosserat("run " + scene + rest + " -q -o " + path("whole.h5") + " --summary " +
                     path("whole.json"))
                .status,
            0);
  const double whole_step = json_value(read_text(path("whole.json")), "step");
  ASSERT_GT(whole_step, 1500.0);
  ASSERT_EQ(cosserat("run " + scene + " --set time.steps=1500 --until-rest 1e-3 -q "
                     "--checkpoint-every 1500 -o " + path("part.h5"))
                .status,
            0);
  const Result restarted = cosserat("run " + scene + rest + " -q --restart " +
                                    path("part.checkpoint.h5") + " -o " + path("part.h5") +
                                    " --summary " + path("part.json"));
  ASSERT_EQ(restarted.status, 0) << restarted.output;
  EXPECT_EQ(json_value(read_text(path("part.json")), "step"), whole_step);
}

#if defined(COSSERAT_HAVE_PETSC)
// The semi-implicit run reports one linear solve per step and its iterations.
TEST_F(Cli, SemiImplicitReportsItsSolves) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const Result r = cosserat("run " + scene + " --set time.integrator=semi-implicit --set time.steps=30 -o " +
                            path("si.h5") + " --summary " + path("si.json"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("Krylov iterations per step"));
  const std::string json = read_text(path("si.json"));
  EXPECT_EQ(json_value(json, "solves"), 30.0);
  EXPECT_GE(json_value(json, "mean_iterations"), 1.0);
}

// Solver names PETSc does not know, from the scene or from --petsc: bad input before any work.
TEST_F(Cli, UnknownSolverIsBadInput) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const Result ksp = cosserat("run " + scene + " --set time.integrator=semi-implicit " +
                              "--set time.solver.ksp=sideways -o " + path("k.h5"));
  EXPECT_EQ(ksp.status, 2) << ksp.output;
  EXPECT_THAT(ksp.output, HasSubstr("time.solver.ksp"));
  EXPECT_FALSE(fs::exists(path("k.h5")));
  const Result option = cosserat("run " + scene + " --set time.integrator=semi-implicit " +
                                 "--petsc \"-pc_type sideways\" -o " + path("p.h5"));
  EXPECT_EQ(option.status, 2) << option.output;
  EXPECT_FALSE(fs::exists(path("p.h5")));
}

// PETSc's profile asked for by --petsc: printed at the end, and the run ends as it would without
// it. While --petsc's options reached PETSc only after it had started, the log was never begun
// and the run ended in an abort (status 134), its output written.
TEST_F(Cli, PetscLogViewFromTheCommandLineIsPrinted) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const Result r = cosserat("run " + scene + " --set time.integrator=semi-implicit " +
                            "--set time.steps=2 --petsc -log_view -o " + path("l.h5"));
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("KSPSolve"));
}
#endif

}  // namespace
