// Scalpel pose input: the gate that drops bad poses (NaN/Inf, a zero quaternion, absurd jumps,
// a first pose far from the tissue) and the thread-safe "latest accepted pose" the simulation
// loop reads every step.
#pragma once

#include "soft_tissue_cutting/scene/scene.hpp"

#include <cstdint>
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
  // The last accepted pose, if any.
  // `stamp_ns` (if given): its stamp, read under the same lock (0 if none).
  std::optional<BladePose> latest(std::int64_t* stamp_ns = nullptr) const;
  // Forget the last accepted pose (after ~reset): the next pose is a first pose again.
  void clear();
  const PoseGateSettings& settings() const { return settings_; }

 private:
  // Accepts `pose` as a first pose unless it is far from the tissue. Caller holds mutex_.
  PoseDecision offer_first_locked(const BladePose& pose, std::int64_t stamp_ns,
                                  PoseVerdict on_success);

  mutable std::mutex mutex_;
  const PoseGateSettings settings_;
  std::optional<BladePose> last_;
  std::int64_t last_stamp_ns_ = 0;
  int consecutive_jumps_ = 0;
};

// Distance (m) from p to the box; 0 inside.
double distance_to_box(const Box& box, const Vec3& p);

}  // namespace ros_io
}  // namespace stc
