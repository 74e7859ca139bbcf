// The stats JSON's step_ms bookkeeping (docs/SCENE.md "Offline run"): kinds and their summaries.
#include "soft_tissue_cutting/simulation/step_times.hpp"

#include <gtest/gtest.h>

namespace stc {
namespace {

StepStats stats(bool contact, bool cut, double ms) {
  StepStats s;
  s.in_contact = contact;
  s.cutting = cut;
  s.step_ms = ms;
  return s;
}

TEST(StepTimes, KindsFollowContactAndCut) {
  EXPECT_EQ(step_kind(stats(false, false, 1)), StepKind::kIdle);
  EXPECT_EQ(step_kind(stats(true, false, 1)), StepKind::kPressing);
  EXPECT_EQ(step_kind(stats(true, true, 1)), StepKind::kCutting);
  EXPECT_EQ(step_kind(stats(false, true, 1)), StepKind::kCutting);  // a cut is a change
  StepTimes t;
  t.add(stats(false, false, 1.0));
  t.add(stats(true, false, 2.0));
  t.add(stats(true, false, 4.0));
  t.add(stats(false, true, 8.0));
  EXPECT_EQ(t.idle.size(), 1u);
  EXPECT_EQ(t.pressing.size(), 2u);
  EXPECT_EQ(t.cutting.size(), 1u);
}

TEST(StepTimes, SummaryMedianAndMax) {
  const StepTimeSummary none = summarize_step_times({});
  EXPECT_EQ(none.n, 0);
  EXPECT_EQ(none.median, 0.0);
  EXPECT_EQ(none.max, 0.0);
  const StepTimeSummary odd = summarize_step_times({5.0, 1.0, 3.0});
  EXPECT_EQ(odd.n, 3);
  EXPECT_DOUBLE_EQ(odd.median, 3.0);
  EXPECT_DOUBLE_EQ(odd.max, 5.0);
  const StepTimeSummary even = summarize_step_times({4.0, 1.0, 2.0, 10.0});
  EXPECT_DOUBLE_EQ(even.median, 3.0);
  EXPECT_DOUBLE_EQ(even.max, 10.0);
}

}  // namespace
}  // namespace stc
