// tissue_node: the ROS 1 face of the simulation (docs/ROS.md "API"). See tissue_node.hpp.
#include "soft_tissue_cutting/ros/heap_release.hpp"
#include "soft_tissue_cutting/ros/tissue_node.hpp"
#include "soft_tissue_cutting/solve/blas_kernels.hpp"

#include <ros/ros.h>

#include <cstdlib>
#include <exception>
#include <string>

int main(int argc, char** argv) {
  stc::reexec_with_native_blas_kernels(argv);  // before anything runs (blas_kernels.hpp)
  stc::ros_io::configure_heap();               // heap_release.hpp: RSS that follows what is in use
  ros::init(argc, argv, "tissue");
  ros::NodeHandle nh, pnh("~");
  stc::ros_io::NodeParams params;
  stc::Scene scene;
  stc::SimulationOptions options;
  std::unique_ptr<stc::Simulation> sim;
  try {
    params = stc::ros_io::read_params(pnh);
  } catch (const std::exception& e) {
    ROS_FATAL("tissue_node: bad parameter: %s", e.what());
    return 2;
  }
  try {
    options.backend = params.backend;
    // The gl switches of the environment (docs/ROS.md), read here: the core reads none.
    options.gl = stc::gl_context_options_from(std::getenv("TISSUE_FORCE_NO_EGL"),
                                              std::getenv("TISSUE_GL_API"),
                                              std::getenv("TISSUE_SHADER_DIR"));
    // The core's messages go to rosconsole (and /rosout).
    options.log = [](stc::LogLevel level, const std::string& message) {
      if (level == stc::LogLevel::kError)
        ROS_ERROR("%s", message.c_str());
      else if (level == stc::LogLevel::kWarn)
        ROS_WARN("%s", message.c_str());
      else
        ROS_INFO("%s", message.c_str());
    };
    // ~every_pose promises the same cut on every replay: a factor refactored ahead (organ-scale
    // meshes) is then awaited as offline, so no solve depends on timing.
    options.wait_for_factor_ahead = params.every_pose;
    scene = stc::ros_io::load_scene_param(params.scene);
    sim = std::make_unique<stc::Simulation>(scene, options);
  } catch (const std::exception& e) {
    ROS_FATAL("tissue_node: cannot load scene '%s': %s", params.scene.c_str(), e.what());
    return 1;
  }
  stc::ros_io::TissueNode node(nh, pnh, params, std::move(scene), options, std::move(sim));
  // Six callback threads: up to three ~cut calls wait for the loop while the pose callback and
  // the other services go on.
  ros::AsyncSpinner spinner(6);
  spinner.start();
  node.start();
  ros::waitForShutdown();
  node.stop();
  return 0;
}
