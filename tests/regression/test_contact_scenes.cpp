// The contact scenes of scenes/contact end to end (CONTACT.md §6), each for as long as it takes
// its solids to meet the cloth: no node ends a step deeper than a tolerance inside a solid, and
// the run's max_penetration, which the summary reports, says so.

#include <gtest/gtest.h>

#include <algorithm>
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

// The thin rod (radius 4 mm, a twelfth of the grid spacing) under the middle of a cell, pushed
// 0.3 m up into the pinned sheet: the sheet is carried to the end, not pierced. Only the cells'
// test can hold it, and the tent's tension pulls the cells over the rod's tip faster than the
// rod's radius per step: the side a cell was on at the start of the step must decide.
TEST(ContactScenes, AThinRodCarriesThePinnedSheet) {
  const Scene scene =
      load_scene(std::string(COSSERAT_SOURCE_DIR) + "/scenes/contact/rod_through_sheet.toml");
  Simulation sim(scene, MPI_COMM_SELF);
  Silent silent;
  ASSERT_FALSE(run_step_loop(sim, scene, {}, silent).failure);
  const SolidState& rod = sim.contact()->state(0);
  const double tip = rod.pose.position.y + scene.solids[0].shape.half_length +
                     scene.solids[0].shape.radius;
  double highest = -1e300;
  const Block& b = sim.block();
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) highest = std::max(highest, sim.positions()(k, l).y);
  std::printf("[rod] tip at %.4f m, highest node %.4f m\n", tip, highest);
  EXPECT_GT(tip, 0.2);
  EXPECT_GT(highest, tip - 0.01);
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
