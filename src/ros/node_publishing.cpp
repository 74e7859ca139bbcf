// What the loop publishes from the simulation state every step: ~stats and ~scalpel/wrench
// (docs/ROS.md (publishing)). ~surface / ~markers / ~mesh_hash: node_display.cpp.
#include "soft_tissue_cutting/ros/conversions.hpp"
#include "soft_tissue_cutting/ros/tissue_node.hpp"

namespace stc {
namespace ros_io {

void TissueNode::publish_step_locked(const StepStats& s, const std::optional<BladePose>& blade,
                                     std::int64_t scalpel_stamp_ns, const ros::Time& stamp,
                                     double rate_hz) {
  // backend: what actually solved (cpu when a gl solve fell back).
  soft_tissue_cutting::SimStats stats =
      to_stats_msg(s, sim_->counts(), s.solved_by.empty() ? sim_->backend() : s.solved_by,
                   sim_->renderer(), rate_hz, last_recovery_ms_.load());
  stats.header.stamp = stamp;
  stats.header.frame_id = params_.frame_id;
  if (scalpel_stamp_ns > 0) stats.scalpel_stamp.fromNSec(scalpel_stamp_ns);
  stats_pub_.publish(stats);
  const bool blade_axes = params_.wrench_frame == "blade";
  geometry_msgs::WrenchStamped wrench = to_wrench_msg(s, blade_axes ? blade : std::nullopt);
  wrench.header = stats.header;
  if (blade_axes)
    wrench.header.frame_id = params_.scalpel_frame.empty() ? "scalpel" : params_.scalpel_frame;
  {
    std::lock_guard<std::mutex> lock(info_mutex_);
    solved_by_ = s.solved_by;
    fallback_reason_ = s.fallback_reason;
    if (const RegionMoveStats* m = sim_->region_moves()) region_moves_ = *m;  // `follow`
    sweeps_waiting_ = s.sweeps_waiting;
    cut_lag_ = s.cut_lag;
  }
  wrench_pub_.publish(wrench);
}

}  // namespace ros_io
}  // namespace stc
