// tissue_node: the ROS 1 face of the simulation (SPEC section 5).
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"

#include <ros/ros.h>
#include <visualization_msgs/Marker.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "tissue");
  ros::NodeHandle pnh("~");
  std::string scene_name = pnh.param<std::string>("scene", "thigh");
  std::string frame_id = pnh.param<std::string>("frame_id", "tissue");
  stc::Simulation sim(stc::make_thigh_scene());
  ros::Publisher pub = pnh.advertise<visualization_msgs::Marker>("surface", 1, true);
  auto publish = [&] {
    const stc::DeformedSurface s = sim.surface();
    visualization_msgs::Marker m;
    m.header.frame_id = frame_id;
    m.header.stamp = ros::Time::now();
    m.ns = "tissue";
    m.type = visualization_msgs::Marker::TRIANGLE_LIST;
    m.pose.orientation.w = 1;
    m.scale.x = m.scale.y = m.scale.z = 1;
    m.color.r = 0.9f; m.color.g = 0.6f; m.color.b = 0.55f; m.color.a = 1;
    for (const auto& t : s.triangles)
      for (int v : t.nodes) {
        geometry_msgs::Point p;
        p.x = s.positions[v].x(); p.y = s.positions[v].y(); p.z = s.positions[v].z();
        m.points.push_back(p);
      }
    pub.publish(m);
  };
  publish();
  ros::Timer timer = pnh.createTimer(ros::Duration(1.0), [&](const ros::TimerEvent&) { publish(); });
  ros::spin();
  return 0;
}
