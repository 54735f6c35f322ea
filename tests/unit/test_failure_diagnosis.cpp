// What the monitor says about the sheet where a run failed (time/failure_diagnosis.hpp): each
// cause it names is recognised on a sheet built to show it, and a smooth sheet blames the step.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "cosserat/time/failure_diagnosis.hpp"

namespace cosserat {
namespace {

constexpr int kM = 16, kN = 16;
constexpr double kH = 0.1;

struct Sheet {
  Block block = Block::whole(kM, kN, MPI_COMM_SELF);
  Field<Vec3> r{block};
  Sheet() {
    for (int l = 0; l < kN; ++l)
      for (int k = 0; k < kM; ++k) r(k, l) = {k * kH, 0.0, l * kH};
  }
};

bool says(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(FailureDiagnosis, SmoothSheetBlamesTheStep) {
  Sheet sheet;
  for (int l = 0; l < kN; ++l)
    for (int k = 0; k < kM; ++k) sheet.r(k, l).y = 0.05 * std::sin(0.3 * k + 0.2 * l);
  const std::string text = diagnose_failure(sheet.r, 8, 8, kH, kH);
  EXPECT_TRUE(says(text, "is smooth")) << text;
  EXPECT_TRUE(says(text, "time.dt")) << text;
}

// Rows l ≥ 8 folded back under rows l < 8, a tenth of a spacing below: rows 9 and 6 meet.
TEST(FailureDiagnosis, SheetThroughItself) {
  Sheet sheet;
  for (int l = 8; l < kN; ++l)
    for (int k = 0; k < kM; ++k) sheet.r(k, l) = {k * kH, -0.01, (15 - l) * kH};
  const std::string text = diagnose_failure(sheet.r, 8, 8, kH, kH);
  EXPECT_TRUE(says(text, "passes through itself near node [8, 8]")) << text;
}

// One cell's far corner pushed through to the other side, beyond the opposite corner: the
// cell folds over its neighbour without coming close to any node far away in the grid.
TEST(FailureDiagnosis, CellFoldedFullyOver) {
  Sheet sheet;
  sheet.r(9, 9) = {8.0 * kH - 0.6 * kH, 0.0, 8.0 * kH - 0.6 * kH};
  const std::string text = diagnose_failure(sheet.r, 8, 8, kH, kH);
  EXPECT_TRUE(says(text, "fold fully over")) << text;
}

TEST(FailureDiagnosis, CollapsedCell) {
  Sheet sheet;
  // Node (9, 8) onto the line of (8, 8)–(8, 9)'s cell diagonal: the cell's edges align.
  sheet.r(8, 9) = {8.0 * kH + 0.999 * kH, 0.0, 8.0 * kH + 0.01 * kH};
  const std::string text = diagnose_failure(sheet.r, 8, 8, kH, kH);
  EXPECT_TRUE(says(text, "collapsed")) << text;
}

}  // namespace
}  // namespace cosserat
