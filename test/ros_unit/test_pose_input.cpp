// The pose gate without a master: NaN/zero-quaternion refusal, jumps, the first pose near the
// tissue's bounding box, re-arming after N consecutive jumps, clear(), the accepted pose's stamp
// (~stats scalpel_stamp), ~every_pose's queue.
#include "soft_tissue_cutting/ros/pose_input.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace stc::ros_io {
namespace {

PoseGateSettings settings() {
  PoseGateSettings s;
  s.max_jump = 0.05;
  s.tissue_box = Box{Vec3(-0.06, -0.06, 0.0), Vec3(0.06, 0.06, 0.1)};
  s.rearm_after = 5;
  return s;
}

BladePose at(double x, double y, double z) {
  BladePose p;
  p.position = Vec3(x, y, z);
  return p;
}

TEST(PoseInput, DistanceToBox) {
  const Box b = settings().tissue_box;
  EXPECT_EQ(distance_to_box(b, Vec3(0, 0, 0.05)), 0.0);
  EXPECT_DOUBLE_EQ(distance_to_box(b, Vec3(0.10, 0, 0.05)), 0.04);
  EXPECT_DOUBLE_EQ(distance_to_box(b, Vec3(0.09, 0.10, 0.05)), 0.05);
}

TEST(PoseInput, RefusesNonFiniteAndZeroQuaternionWithTheirReasons) {
  PoseInput gate(settings());
  BladePose p = at(0, 0, 0.05);
  p.position.x() = std::numeric_limits<double>::quiet_NaN();
  PoseDecision d = gate.offer(p);
  EXPECT_FALSE(d.accepted());
  EXPECT_EQ(d.why, "not finite (NaN/Inf)");
  BladePose q = at(0, 0, 0.05);
  q.orientation = Eigen::Quaterniond(0, 0, 0, 0);
  d = gate.offer(q);
  EXPECT_FALSE(d.accepted());
  EXPECT_EQ(d.why, "zero quaternion");
  EXPECT_FALSE(gate.latest());
}

TEST(PoseInput, FirstPoseMustBeNearTheTissue) {
  PoseInput gate(settings());
  PoseDecision d = gate.offer(at(10.0, 0, 0));
  EXPECT_FALSE(d.accepted());
  EXPECT_NE(d.why.find("first pose is 9.94 m from the tissue's bounding box"), std::string::npos)
      << d.why;
  EXPECT_FALSE(gate.offer(at(1e300, 0, 0)).accepted());
  EXPECT_FALSE(gate.latest());
  d = gate.offer(at(0.10, 0, 0.05));  // 4 cm outside the box: within max_jump
  EXPECT_EQ(d.verdict, PoseVerdict::kAccepted);
  ASSERT_TRUE(gate.latest());
  EXPECT_EQ(gate.latest()->position, Vec3(0.10, 0, 0.05));
}

TEST(PoseInput, JumpsAreRefusedSmallMovesAccepted) {
  PoseInput gate(settings());
  ASSERT_TRUE(gate.offer(at(0, 0, 0.05)).accepted());
  PoseDecision d = gate.offer(at(0.2, 0, 0.05));
  EXPECT_FALSE(d.accepted());
  EXPECT_NE(d.why.find("jump of 0.2 m"), std::string::npos) << d.why;
  EXPECT_TRUE(gate.offer(at(0.04, 0, 0.05)).accepted());
  BladePose q = at(0.05, 0, 0.05);
  q.orientation = Eigen::Quaterniond(0, 0, 0, 3);  // stored normalised
  ASSERT_TRUE(gate.offer(q).accepted());
  EXPECT_NEAR(gate.latest()->orientation.z(), 1.0, 1e-15);
}

TEST(PoseInput, RearmsOnTheNewestPoseAfterNConsecutiveJumps) {
  PoseInput gate(settings());
  ASSERT_TRUE(gate.offer(at(0.10, 0, 0.05)).accepted());
  // The scalpel really moved to the other side of the tissue: four refusals, then re-armed.
  for (int i = 0; i < 4; ++i) EXPECT_FALSE(gate.offer(at(-0.06, 0, 0.05 + 0.001 * i)).accepted());
  const PoseDecision d = gate.offer(at(-0.06, 0, 0.06));
  EXPECT_EQ(d.verdict, PoseVerdict::kRearmed);
  EXPECT_NE(d.why.find("re-armed on the newest pose after 5 consecutive jumps"), std::string::npos)
      << d.why;
  EXPECT_EQ(gate.latest()->position, Vec3(-0.06, 0, 0.06));
  EXPECT_EQ(gate.offer(at(-0.055, 0, 0.06)).verdict, PoseVerdict::kAccepted);
}

TEST(PoseInput, AnAcceptedPoseOrAFarNewestPoseDoesNotRearm) {
  PoseInput gate(settings());
  ASSERT_TRUE(gate.offer(at(0, 0, 0.05)).accepted());
  for (int i = 0; i < 4; ++i) EXPECT_FALSE(gate.offer(at(0.3, 0, 0.05)).accepted());
  ASSERT_TRUE(gate.offer(at(0.01, 0, 0.05)).accepted());  // the count starts again
  for (int i = 0; i < 4; ++i) EXPECT_FALSE(gate.offer(at(-0.06, 0, 0.05)).accepted());
  EXPECT_EQ(gate.latest()->position, Vec3(0.01, 0, 0.05));
  // Far from the tissue: re-arming refuses it as a first pose; the last pose stays.
  for (int i = 0; i < 10; ++i) EXPECT_FALSE(gate.offer(at(5.0, 0, 0.05)).accepted());
  EXPECT_EQ(gate.latest()->position, Vec3(0.01, 0, 0.05));
}

TEST(PoseInput, ClearMakesTheNextPoseAFirstPose) {
  PoseInput gate(settings());
  ASSERT_TRUE(gate.offer(at(0, 0, 0.05)).accepted());
  gate.clear();
  EXPECT_FALSE(gate.latest());
  EXPECT_FALSE(gate.offer(at(0.5, 0, 0.05)).accepted());  // far: refused as a first pose
  EXPECT_TRUE(gate.offer(at(0.05, 0.05, 0.05)).accepted());
}

// The stamp travels with the accepted pose: a refused pose leaves the last accepted one's, a
// re-armed pose brings its own, clear() forgets it.
TEST(PoseInput, TheStampOfTheAcceptedPose) {
  PoseInput gate(settings());
  std::int64_t stamp = -1;
  EXPECT_FALSE(gate.next(&stamp));
  EXPECT_EQ(stamp, 0);
  ASSERT_TRUE(gate.offer(at(0, 0, 0.05), 1000).accepted());
  ASSERT_TRUE(gate.next(&stamp));
  EXPECT_EQ(stamp, 1000);
  ASSERT_TRUE(gate.offer(at(0.01, 0, 0.05), 2000).accepted());
  gate.next(&stamp);
  EXPECT_EQ(stamp, 2000);
  EXPECT_FALSE(gate.offer(at(0.3, 0, 0.05), 3000).accepted());  // a jump: refused
  gate.next(&stamp);
  EXPECT_EQ(stamp, 2000);
  // Jumps 2 to 4 of rearm_after = 5 refused, the fifth re-arms on its own pose and stamp.
  for (int i = 0; i < 3; ++i) EXPECT_FALSE(gate.offer(at(-0.05, 0, 0.05), 4000 + i).accepted());
  EXPECT_EQ(gate.offer(at(-0.05, 0, 0.05), 4003).verdict, PoseVerdict::kRearmed);
  gate.next(&stamp);
  EXPECT_EQ(stamp, 4003);
  gate.clear();
  EXPECT_FALSE(gate.next(&stamp));
  EXPECT_EQ(stamp, 0);
}

// ~every_pose (queue_limit > 0): every accepted pose is handed to the loop once, in order; a
// refused one never; the last one taken stays the blade until the next arrives; a full queue
// drops its oldest and counts it; clear() empties it.
TEST(PoseInput, EveryPoseInOrder) {
  PoseGateSettings settings3 = settings();
  settings3.queue_limit = 3;
  PoseInput gate(settings3);
  std::int64_t stamp = 0;
  EXPECT_FALSE(gate.next(&stamp));
  ASSERT_TRUE(gate.offer(at(0.00, 0, 0.05), 1).accepted());
  ASSERT_TRUE(gate.offer(at(0.01, 0, 0.05), 2).accepted());
  EXPECT_FALSE(gate.offer(at(0.30, 0, 0.05), 9).accepted());  // a jump: never stepped on
  ASSERT_TRUE(gate.offer(at(0.02, 0, 0.05), 3).accepted());
  for (std::int64_t want : {1, 2, 3, 3, 3}) {
    const auto p = gate.next(&stamp);
    ASSERT_TRUE(p);
    EXPECT_EQ(stamp, want);
    EXPECT_DOUBLE_EQ(p->position.x(), 0.01 * static_cast<double>(want - 1));
    EXPECT_EQ(gate.latest()->position, p->position);  // the display shows what is stepped on
  }
  EXPECT_EQ(gate.dropped(), 0u);
  for (int k = 4; k <= 8; ++k) ASSERT_TRUE(gate.offer(at(0.005 * k, 0, 0.05), k).accepted());
  EXPECT_EQ(gate.dropped(), 2u);                 // 4 and 5: the queue holds 3
  EXPECT_EQ(gate.latest()->position.x(), 0.02);  // nothing taken since
  for (std::int64_t want : {6, 7, 8}) {
    gate.next(&stamp);
    EXPECT_EQ(stamp, want);
  }
  ASSERT_TRUE(gate.offer(at(0.045, 0, 0.05), 10).accepted());
  gate.clear();
  EXPECT_FALSE(gate.next(&stamp));
  EXPECT_EQ(stamp, 0);
  EXPECT_FALSE(gate.latest());
}

// Without a queue the loop steps on the newest pose: one overtaken before a step is skipped.
TEST(PoseInput, NewestPoseWithoutAQueue) {
  PoseInput gate(settings());
  std::int64_t stamp = 0;
  ASSERT_TRUE(gate.offer(at(0.00, 0, 0.05), 1).accepted());
  ASSERT_TRUE(gate.offer(at(0.01, 0, 0.05), 2).accepted());
  gate.next(&stamp);
  EXPECT_EQ(stamp, 2);
  gate.next(&stamp);
  EXPECT_EQ(stamp, 2);
  EXPECT_EQ(gate.dropped(), 0u);
}

}  // namespace
}  // namespace stc::ros_io
