// The contact scenes of scenes/contact end to end (CONTACT.md §6), each for as long as it takes
// its solids to meet the cloth: no node ends a step deeper than a tolerance inside a solid, and
// the run's max_penetration, which the summary reports, says so.

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "cosserat/time/step_loop.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

class Silent : public StepObserver {
 public:
  void frame() override {}
  void checkpoint(const LoopCarry&) override {}
  void progress(long) override {}
};

struct ContactScene {
  std::string file;
  std::string duration;  // seconds simulated: past the solids' first contacts
};

class ContactScenes : public ::testing::TestWithParam<ContactScene> {};

// 1e-9 m: the response puts nodes on the offset surface up to round-off; a node left inside
// by the bounded repeats of the response would show here.
TEST_P(ContactScenes, NoNodeIsLeftInsideASolid) {
  const ContactScene& c = GetParam();
  const Scene scene = load_scene(std::string(COSSERAT_SOURCE_DIR) + "/scenes/contact/" + c.file,
                                 {"time.duration=" + c.duration});
  Simulation sim(scene, MPI_COMM_SELF);
  Silent silent;
  const StepLoopResult result = run_step_loop(sim, scene, {}, silent);
  ASSERT_FALSE(result.failure) << c.file;
  const ContactSummary summary = sim.contact_summary();
  std::printf("[%s] %.2f s: max_penetration %.3g m, max_contacts %ld\n", c.file.c_str(),
              sim.time(), summary.max_penetration, summary.max_contacts);
  EXPECT_GT(summary.max_contacts, 0) << c.file << ": the solids never met the cloth";
  EXPECT_LE(summary.max_penetration, 1e-9) << c.file;
}

std::string scene_test_name(const ::testing::TestParamInfo<ContactScene>& info) {
  return info.param.file.substr(0, info.param.file.find('.'));
}

INSTANTIATE_TEST_SUITE_P(
    Contact, ContactScenes,
    ::testing::Values(ContactScene{"pressed_sheet.toml", "3.3"},
                      ContactScene{"draped_table.toml", "1.0"},
                      ContactScene{"cube_net_25.toml", "0.3"},
                      ContactScene{"cube_net_500.toml", "0.15"},
                      ContactScene{"tablecloth_round_table.toml", "0.6"},
                      ContactScene{"sphere_drape.toml", "0.6"},
                      ContactScene{"curtain_sphere.toml", "1.5"},
                      ContactScene{"rod_through_sheet.toml", "1.0"},
                      ContactScene{"s3_bench_solids.toml", "1.2"},
                      ContactScene{"s5_armchair_solids.toml", "1.3"}),
    scene_test_name);

}  // namespace
}  // namespace cosserat
