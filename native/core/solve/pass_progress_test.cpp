#include "core/solve/pass_progress.h"

#include <gtest/gtest.h>

namespace radiosity {
namespace {

TEST(PassProgress, RefiningMovesWithTheLeavesAndIsHalfWayAtTheExpectedCount) {
  PassProgress p;
  p.start(100);  // no pass before: a doubling is expected
  EXPECT_DOUBLE_EQ(p.within(), 0.0);
  p.refined(150);
  const double part = p.within();
  EXPECT_GT(part, 0.0);
  p.refined(200);
  EXPECT_DOUBLE_EQ(p.within(), 0.5 * PassProgress::kRefiningShare);
  p.refined(100000);
  EXPECT_GT(p.within(), part);
  EXPECT_LT(p.within(), PassProgress::kRefiningShare);  // refinement alone never ends a pass
}

TEST(PassProgress, ExpectsThePreviousPassesGrowth) {
  PassProgress p;
  p.start(100);
  p.start(1000);  // the pass before grew tenfold: 9,000 new leaves expected
  p.refined(10000);
  EXPECT_DOUBLE_EQ(p.within(), 0.5 * PassProgress::kRefiningShare);
}

TEST(PassProgress, GatheringCountsTheResidualsDecadesToTheTolerance) {
  PassProgress p;
  p.start(10);
  p.gathered(1e-1, 1e-5, 1, 100);
  EXPECT_DOUBLE_EQ(p.within(), 0.0);
  p.gathered(1e-3, 1e-5, 2, 100);
  EXPECT_NEAR(p.within(), 0.5 * (1.0 - PassProgress::kRefiningShare), 1e-12);
  p.gathered(1e-2, 1e-5, 3, 100);  // a residual that rose again does not move it back
  EXPECT_NEAR(p.within(), 0.5 * (1.0 - PassProgress::kRefiningShare), 1e-12);
  p.gathered(1e-6, 1e-5, 4, 100);
  EXPECT_DOUBLE_EQ(p.within(), 1.0 - PassProgress::kRefiningShare);
}

TEST(PassProgress, FixedIterationsCountIterations) {
  PassProgress p;
  p.start(10);
  p.gathered(0.5, -1.0, 1, 4);
  EXPECT_DOUBLE_EQ(p.within(), 0.25 * (1.0 - PassProgress::kRefiningShare));
}

}  // namespace
}  // namespace radiosity
