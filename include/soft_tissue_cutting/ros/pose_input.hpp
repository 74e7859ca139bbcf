// Scalpel pose input: the gate that drops bad poses (NaN/Inf, a zero quaternion, absurd jumps,
// a first pose far from the tissue) and the thread-safe "latest accepted pose" the simulation
// loop reads every step.
#pragma once

#include "soft_tissue_cutting/scene/scene.hpp"

#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>

namespace stc {
namespace ros_io {

struct PoseGateSettings {
  double max_jump = 0.05;  // m: largest move from the last accepted pose (~max_pose_jump)
  // The tissue's bounding box (scene frame): a first pose (at start, after ~reset or on
  // re-arming) must lie within max_jump of it, so one stray pose cannot become the anchor
  // every later pose is measured from.
  Box tissue_box;
  // After this many consecutive jump refusals the gate re-arms: the newest pose is judged as a
  // first pose (~pose_rearm_count). A real scalpel that moved while its poses were lost (or
  // after one bad accepted pose) is followed again instead of being refused forever.
  int rearm_after = 20;
  // 0: the loop steps on the newest accepted pose (a pose overtaken by the next before a step
  // is never stepped on). N > 0 (~every_pose): on every accepted pose in order, one per step, at
  // most N waiting (beyond that the oldest is dropped and counted): a replayed bag then cuts
  // the same at any pace the loop keeps up with.
  size_t queue_limit = 0;
};

enum class PoseVerdict {
  kAccepted,
  kRefused,
  kRearmed,  // accepted as a new first pose after rearm_after consecutive jumps
};

struct PoseDecision {
  PoseVerdict verdict = PoseVerdict::kRefused;
  std::string why;  // refusal reason, or what re-arming did
  bool accepted() const { return verdict != PoseVerdict::kRefused; }
};

class PoseInput {
 public:
  explicit PoseInput(PoseGateSettings settings) : settings_(std::move(settings)) {}

  // `stamp_ns`: the pose's stamp (a PoseStamped's header, a tf transform's), nanoseconds; it
  // travels with the accepted pose so ~stats can say which pose a step used.
  PoseDecision offer(const BladePose& pose, std::int64_t stamp_ns = 0);
  // The pose the loop steps on next: the newest accepted one, or (queue_limit > 0) the oldest
  // waiting one, taken off the queue, else the last one taken. `stamp_ns` (if given): its
  // stamp, read under the same lock (0 if none).
  std::optional<BladePose> next(std::int64_t* stamp_ns = nullptr);
  // What the loop steps on now, for display: the newest accepted pose, or (queue_limit > 0)
  // the last one next() took.
  std::optional<BladePose> latest() const;
  // Poses dropped from a full queue since the start.
  std::uint64_t dropped() const;
  // Forget the last accepted pose and every waiting one (after ~reset): the next pose is a
  // first pose again.
  void clear();
  const PoseGateSettings& settings() const { return settings_; }

 private:
  // Accepts `pose` as a first pose unless it is far from the tissue. Caller holds mutex_.
  PoseDecision offer_first_locked(const BladePose& pose, std::int64_t stamp_ns,
                                  PoseVerdict on_success);
  void accept_locked(const BladePose& pose, std::int64_t stamp_ns);

  struct Stamped {
    BladePose pose;
    std::int64_t stamp_ns = 0;
  };
  mutable std::mutex mutex_;
  const PoseGateSettings settings_;
  std::optional<Stamped> last_;    // the last accepted pose: jumps are measured from it
  std::deque<Stamped> waiting_;    // queue_limit > 0: accepted, not yet stepped on
  std::optional<Stamped> served_;  // queue_limit > 0: the last pose next() took
  std::uint64_t dropped_ = 0;
  int consecutive_jumps_ = 0;

  // What the loop steps on now: the last pose taken (queue_limit > 0), else the newest.
  const std::optional<Stamped>& current_locked() const {
    return settings_.queue_limit > 0 ? served_ : last_;
  }
};

// Distance (m) from p to the box; 0 inside.
double distance_to_box(const Box& box, const Vec3& p);

}  // namespace ros_io
}  // namespace stc
