// tissue_node: the ROS 1 face of the simulation (docs/ROS.md "API"). See tissue_node.hpp.
#include "soft_tissue_cutting/ros/tissue_node.hpp"

#include <ros/ros.h>

#include <exception>

int main(int argc, char** argv) {
  ros::init(argc, argv, "tissue");
  ros::NodeHandle nh, pnh("~");
  stc::ros_io::NodeParams params;
  std::unique_ptr<stc::Simulation> sim;
  try {
    params = stc::ros_io::read_params(pnh);
  } catch (const std::exception& e) {
    ROS_FATAL("tissue_node: bad parameter: %s", e.what());
    return 2;
  }
  try {
    stc::SimulationOptions options;
    options.backend = params.backend;
    sim = std::make_unique<stc::Simulation>(stc::ros_io::load_scene_param(params.scene), options);
  } catch (const std::exception& e) {
    ROS_FATAL("tissue_node: cannot load scene '%s': %s", params.scene.c_str(), e.what());
    return 1;
  }
  stc::ros_io::TissueNode node(nh, pnh, params, std::move(sim));
  ros::AsyncSpinner spinner(2);  // services never stall the pose callback, nor the loop
  spinner.start();
  node.start();
  ros::waitForShutdown();
  node.stop();
  return 0;
}
