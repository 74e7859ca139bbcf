// What the node publishes from the simulation state: ~stats and ~scalpel/wrench every step,
// ~surface / ~markers / ~mesh_hash at the display rate (docs/ROS.md (publishing)).
#include "soft_tissue_cutting/ros/conversions.hpp"
#include "soft_tissue_cutting/ros/markers.hpp"
#include "soft_tissue_cutting/ros/tissue_node.hpp"

#include <std_msgs/String.h>
#include <visualization_msgs/MarkerArray.h>

#include <cstdint>

namespace stc {
namespace ros_io {

void TissueNode::publish_step_locked(const StepStats& s, const std::optional<BladePose>& blade,
                                     const ros::Time& stamp, double rate_hz) {
  // backend: what actually solved (cpu when a gl solve fell back).
  soft_tissue_cutting::SimStats stats =
      to_stats_msg(s, sim_->counts(), s.solved_by.empty() ? sim_->backend() : s.solved_by,
                   sim_->renderer(), rate_hz);
  stats.header.stamp = stamp;
  stats.header.frame_id = params_.frame_id;
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
  }
  wrench_pub_.publish(wrench);
}

void TissueNode::publish_display_locked(const StepStats& s, const ros::Time& stamp) {
  // Display (<= display_rate): ~surface when the surface changed, ~markers (always every
  // namespace, so the latched message is complete) when the surface or the blade moved; both
  // at least once a second.
  const ros::WallTime now = ros::WallTime::now();
  const double min_gap = 1.0 / params_.display_rate;
  const bool changed =
      sim_generation_ != published_generation_ || sim_->surface_version() != published_version_;
  const std::optional<BladePose> shown = pose_input_.latest();
  const bool blade_moved =
      shown.has_value() != shown_blade_.has_value() ||
      (shown && (shown->position != shown_blade_->position ||
                 !shown->orientation.coeffs().isApprox(shown_blade_->orientation.coeffs(), 0))) ||
      s.cutting != shown_cutting_;
  if ((changed && (now - last_surface_pub_).toSec() >= min_gap) ||
      (now - last_surface_pub_).toSec() >= 1.0)
    publish_surface_locked(stamp);
  else if (blade_moved && (now - last_markers_pub_).toSec() >= min_gap)
    publish_markers_locked(stamp);
}

void TissueNode::publish_surface_locked(const ros::Time& stamp) {
  const DeformedSurface s = sim_->surface();
  visualization_msgs::Marker m = surface_marker(s, SurfacePart::kAll);
  m.header.frame_id = params_.frame_id;
  m.header.stamp = stamp;
  published_version_ = sim_->surface_version();
  published_generation_ = sim_generation_;
  // The surface state's version travels as the header's sequence number (roscpp sends it as
  // set), not in `text`: rviz flags a TRIANGLE_LIST with text ("Non-empty text is ignored").
  m.header.seq = static_cast<std::uint32_t>(published_version_);
  surface_pub_.publish(m);
  last_surface_pub_ = ros::WallTime::now();

  std::string hash = sim_->mesh_hash();
  if (hash != last_hash_ || !published_any_) {
    std_msgs::String h;
    h.data = hash;
    hash_pub_.publish(h);
    last_hash_ = hash;
  }
  published_any_ = true;
  publish_markers_locked(stamp, &s);
}

void TissueNode::publish_markers_locked(const ros::Time& stamp, const DeformedSurface* surface) {
  visualization_msgs::MarkerArray array;
  const DeformedSurface s = surface ? *surface : sim_->surface();
  array.markers.push_back(surface_marker(s, SurfacePart::kSkin));
  array.markers.push_back(surface_marker(s, SurfacePart::kCut));
  for (auto& m : operation_region_markers(sim_->scene().operation_region).markers)
    array.markers.push_back(m);
  shown_blade_ = pose_input_.latest();
  shown_cutting_ = sim_->last_stats().cutting;
  for (auto& m :
       scalpel_markers(shown_blade_, sim_->scene().scalpel.blade_length, shown_cutting_).markers)
    array.markers.push_back(m);
  array.markers.push_back(contact_marker(sim_->last_stats().contact_points));
  for (auto& m : array.markers) {
    m.header.frame_id = params_.frame_id;
    m.header.stamp = stamp;
  }
  markers_pub_.publish(array);
  last_markers_pub_ = ros::WallTime::now();
}

}  // namespace ros_io
}  // namespace stc
