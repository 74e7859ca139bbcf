// Scalpel poses into the scene frame: the scalpel/pose topic or a tf2 frame, through the
// pose gate (PoseInput), with throttled warnings for what is dropped.
#include "soft_tissue_cutting/ros/conversions.hpp"
#include "soft_tissue_cutting/ros/log_text.hpp"
#include "soft_tissue_cutting/ros/tissue_node.hpp"

#include <tf2_geometry_msgs/tf2_geometry_msgs.h>

namespace stc {
namespace ros_io {

bool TissueNode::to_scene_frame(const geometry_msgs::PoseStamped& in, geometry_msgs::Pose* out,
                                std::string* why) const {
  const std::string frame = strip_slash(in.header.frame_id);
  if (frame.empty() || frame == params_.frame_id) {
    *out = in.pose;
    return true;
  }
  // Latest available transform: a pose is never dropped for its stamp's age (bags are often
  // replayed without sim time).
  try {
    const geometry_msgs::TransformStamped tf =
        tf_buffer_.lookupTransform(params_.frame_id, frame, ros::Time(0));
    tf2::doTransform(in.pose, *out, tf);
    return true;
  } catch (const tf2::TransformException& e) {
    *why = "unknown frame '" + shorten(frame) + "' (" + shorten(e.what()) + ")";
    return false;
  }
}

void TissueNode::offer_pose(const geometry_msgs::Pose& pose, const ros::Time& stamp,
                            const char* source) {
  const PoseDecision d = pose_input_.offer(to_blade_pose(pose, 0.0), stamp.toNSec());
  if (d.verdict == PoseVerdict::kRearmed)
    ROS_WARN_THROTTLE(1.0, "tissue_node: scalpel %s: %s", source, d.why.c_str());
  else if (!d.accepted())
    ROS_WARN_THROTTLE(1.0, "tissue_node: dropped scalpel %s: %s", source, d.why.c_str());
}

void TissueNode::on_pose(const geometry_msgs::PoseStamped::ConstPtr& msg) {
  const std::string problem = pose_problem(msg->pose);
  if (!problem.empty()) {
    ROS_WARN_THROTTLE(1.0, "tissue_node: dropped scalpel pose: %s", problem.c_str());
    return;
  }
  geometry_msgs::Pose pose;
  std::string why;
  if (!to_scene_frame(*msg, &pose, &why)) {
    ROS_WARN_THROTTLE(1.0, "tissue_node: dropped scalpel pose: %s", why.c_str());
    return;
  }
  offer_pose(pose, msg->header.stamp, "pose");
}

std::optional<BladePose> TissueNode::current_blade(std::int64_t* stamp_ns) {
  if (!params_.scalpel_frame.empty()) {
    try {
      const geometry_msgs::TransformStamped tf =
          tf_buffer_.lookupTransform(params_.frame_id, params_.scalpel_frame, ros::Time(0));
      geometry_msgs::Pose pose;
      pose.position.x = tf.transform.translation.x;
      pose.position.y = tf.transform.translation.y;
      pose.position.z = tf.transform.translation.z;
      pose.orientation = tf.transform.rotation;
      const std::string problem = pose_problem(pose);
      if (!problem.empty())
        ROS_WARN_THROTTLE(1.0, "tissue_node: dropped scalpel tf pose: %s", problem.c_str());
      else
        offer_pose(pose, tf.header.stamp, "tf pose");
    } catch (const tf2::TransformException& e) {
      ROS_WARN_THROTTLE(5.0, "tissue_node: no transform %s -> %s: %s",
                        params_.scalpel_frame.c_str(), params_.frame_id.c_str(),
                        shorten(e.what()).c_str());
    }
  }
  return pose_input_.next(stamp_ns);
}

}  // namespace ros_io
}  // namespace stc
