#include "soft_tissue_cutting/ros/pose_input.hpp"

#include "soft_tissue_cutting/ros/conversions.hpp"

#include <cstdio>

namespace stc {
namespace ros_io {

double distance_to_box(const Box& box, const Vec3& p) {
  const Vec3 outside = (box.min - p).cwiseMax(p - box.max).cwiseMax(0.0);
  return outside.norm();
}

PoseDecision PoseInput::offer(const BladePose& pose, std::int64_t stamp_ns) {
  PoseDecision d;
  d.why = pose_problem(pose);
  if (!d.why.empty()) return d;  // not a jump: does not count towards re-arming
  std::lock_guard<std::mutex> lock(mutex_);
  if (!last_) return offer_first_locked(pose, stamp_ns, PoseVerdict::kAccepted);
  const double jump = (pose.position - last_->pose.position).norm();
  if (jump <= settings_.max_jump) {
    accept_locked(pose, stamp_ns);
    d.verdict = PoseVerdict::kAccepted;
    return d;
  }
  if (++consecutive_jumps_ >= settings_.rearm_after) {
    d = offer_first_locked(pose, stamp_ns, PoseVerdict::kRearmed);
    if (d.accepted()) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "re-armed on the newest pose after %d consecutive jumps over "
                    "~max_pose_jump = %.4g m",
                    settings_.rearm_after, settings_.max_jump);
      d.why = buf;
      return d;
    }
    return d;  // the newest pose is far from the tissue too: keep the last accepted one
  }
  char buf[160];
  std::snprintf(buf, sizeof buf,
                "jump of %.4g m from the last accepted pose exceeds ~max_pose_jump = %.4g m", jump,
                settings_.max_jump);
  d.why = buf;
  return d;
}

PoseDecision PoseInput::offer_first_locked(const BladePose& pose, std::int64_t stamp_ns,
                                           PoseVerdict on_success) {
  PoseDecision d;
  const double off = distance_to_box(settings_.tissue_box, pose.position);
  if (off > settings_.max_jump) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "first pose is %.4g m from the tissue's bounding box (more than "
                  "~max_pose_jump = %.4g m)",
                  off, settings_.max_jump);
    d.why = buf;
    return d;
  }
  accept_locked(pose, stamp_ns);
  d.verdict = on_success;
  return d;
}

void PoseInput::accept_locked(const BladePose& pose, std::int64_t stamp_ns) {
  consecutive_jumps_ = 0;
  last_ = Stamped{pose, stamp_ns};
  last_->pose.orientation.normalize();
  if (settings_.queue_limit == 0) return;
  waiting_.push_back(*last_);
  if (waiting_.size() > settings_.queue_limit) {
    waiting_.pop_front();
    ++dropped_;
  }
}

std::optional<BladePose> PoseInput::next(std::int64_t* stamp_ns) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (settings_.queue_limit > 0 && !waiting_.empty()) {
    served_ = waiting_.front();
    waiting_.pop_front();
  }
  const auto& current = current_locked();
  if (stamp_ns) *stamp_ns = current ? current->stamp_ns : 0;
  if (!current) return std::nullopt;
  return current->pose;
}

std::optional<BladePose> PoseInput::latest() const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto& current = current_locked();
  if (!current) return std::nullopt;
  return current->pose;
}

std::uint64_t PoseInput::dropped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_;
}

void PoseInput::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  last_.reset();
  served_.reset();
  waiting_.clear();
  consecutive_jumps_ = 0;
}

}  // namespace ros_io
}  // namespace stc
