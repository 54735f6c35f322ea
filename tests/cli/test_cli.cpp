// The `cosserat` command line as a user meets it (DESIGN.md "Interfaces"): exit statuses,
// messages, what a failed run leaves behind. Runs the real executable in a child process.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

struct Result {
  int status;
  std::string output;  // stdout and stderr together
};

Result cosserat(const std::string& arguments) {
  const std::string command = std::string(COSSERAT_EXE) + " " + arguments + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  std::string output;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe)) output += buffer.data();
  const int raw = pclose(pipe);
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, output};
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
  for (const char* option : {"--set", "--output", "--summary", "--quiet"})
    EXPECT_THAT(run.output, HasSubstr(option));
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

TEST_F(Cli, UnwritableOutputIsBadInput) {
  const std::string scene = write_scene("s.toml", kSmallScene);
  const Result r = cosserat("run " + scene + " --output " + path("no/such/dir/out.h5"));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("out.h5"));
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

}  // namespace
