// Scalpel pose input: the gate that drops bad poses (NaN/Inf, absurd jumps) and the
// thread-safe "latest accepted pose" the simulation loop reads every step.
#pragma once

#include "soft_tissue_cutting/scene/scene.hpp"

#include <mutex>
#include <optional>
#include <string>

namespace stc {
namespace ros_io {

class PoseInput {
 public:
  explicit PoseInput(double max_jump) : max_jump_(max_jump) {}

  // Accepts `pose` (scene frame) unless it is not finite or jumps more than max_jump (m) from
  // the last accepted pose; the first pose is never a jump. On refusal `why` says why.
  bool offer(const BladePose& pose, std::string* why);
  // The last accepted pose, if any.
  std::optional<BladePose> latest() const;
  // Forget the last accepted pose (after ~reset): the next pose is a first pose again.
  void clear();
  double max_jump() const { return max_jump_; }

 private:
  mutable std::mutex mutex_;
  double max_jump_;
  std::optional<BladePose> last_;
};

}  // namespace ros_io
}  // namespace stc
