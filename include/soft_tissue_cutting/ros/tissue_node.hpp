// tissue_node: the ROS 1 face of the simulation (docs/ROS.md "API"). Thin: all physics is in
// stc::Simulation; this class owns the threads, the topics, services and parameters. One file
// per job (src/ros/): tissue_node.cpp wiring, node_params.cpp parameters, scalpel_input.cpp
// topic/tf2 poses, simulation_loop.cpp the loop (and ~cut slices), node_publishing.cpp
// the loop's messages, node_display.cpp the display thread's, node_services.cpp services,
// node_diagnostics.cpp /diagnostics. Message building
// that needs no master is in the tissue_ros library (conversions, markers, pose_input,
// loop_monitor, log_text).
//
// Threads (docs/ROS.md (threads)): the simulation loop runs in its own std::thread at ~rate
// and publishes ~stats and ~scalpel/wrench; ROS callbacks (pose input, services,
// dynamic_reconfigure) run on an AsyncSpinner; the display thread publishes ~surface,
// ~markers and ~mesh_hash at ~display_rate (node_display.cpp); a fourth thread publishes
// /diagnostics from LoopMonitor without ever taking `sim_mutex_`, so a busy simulation is
// still reported. `sim_mutex_` guards the Simulation and is held for one step (or one ~cut
// slice) at a time: ~cut queues its path for the loop, ~reset builds the fresh Simulation
// outside the lock and swaps it in, ~save copies the state and writes outside it, and the
// display thread only copies under it (Simulation::surface_snapshot): the recovery of u_S,
// the shading and the publishing run outside it, so a step never waits for them. Display
// messages go out under `display_mutex_`, newest state last: a refresh overtaken by a newer
// one (the display thread's by ~reset's) is dropped, so their order on the wire is the order
// of the states they show.
#pragma once

#include "soft_tissue_cutting/ros/loop_monitor.hpp"
#include "soft_tissue_cutting/ros/node_params.hpp"
#include "soft_tissue_cutting/ros/pose_input.hpp"
#include "soft_tissue_cutting/simulation/region_move_stats.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"

#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <soft_tissue_cutting/Cut.h>
#include <soft_tissue_cutting/SaveMesh.h>
#include <soft_tissue_cutting/TissueConfig.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace stc {
namespace ros_io {

// ~every_pose: at most this many accepted poses wait for a step (100 s at 100 Hz); beyond it
// the oldest is dropped with a throttled warning.
constexpr size_t kEveryPoseQueue = 10000;

class TissueNode {
 public:
  TissueNode(ros::NodeHandle nh, ros::NodeHandle pnh, NodeParams params, Scene scene,
             SimulationOptions options, std::unique_ptr<Simulation> sim);
  ~TissueNode();
  TissueNode(const TissueNode&) = delete;
  TissueNode& operator=(const TissueNode&) = delete;

  // Publishes the initial state, starts the loop, display and diagnostics threads.
  void start();
  void stop();  // joins them; queued ~cut requests are answered

 private:
  // A ~cut request waiting for (or being inserted by) the loop.
  struct CutJob {
    std::vector<BladePose> poses;  // scene frame, as requested
    PathCut path;                  // begun by the loop
    bool begun = false;
    bool finished = false;
    CutOutcome outcome;
  };

  // wiring (tissue_node.cpp)
  void publish_trajectory_param();
  void publish_parent_frame();
  PoseGateSettings pose_gate_settings() const;

  // scalpel input (scalpel_input.cpp)
  // Topic or tf2 input, gated; `stamp_ns`: the pose's stamp (~stats scalpel_stamp).
  std::optional<BladePose> current_blade(std::int64_t* stamp_ns);
  bool to_scene_frame(const geometry_msgs::PoseStamped& in, geometry_msgs::Pose* out,
                      std::string* why) const;
  void on_pose(const geometry_msgs::PoseStamped::ConstPtr& msg);
  void offer_pose(const geometry_msgs::Pose& pose, const ros::Time& stamp, const char* source);

  // the loop (simulation_loop.cpp)
  void loop();
  void advance_cut_locked(LoopMonitor::Clock::time_point deadline);
  void finish_cut_locked(const StepStats& step);
  void answer_cuts(std::deque<std::shared_ptr<CutJob>> jobs, const std::string& why);

  // publishing (node_publishing.cpp). Callers hold sim_mutex_.
  // `scalpel_stamp_ns`: the stamp of the pose `blade` came from (0: none).
  void publish_step_locked(const StepStats& s, const std::optional<BladePose>& blade,
                           std::int64_t scalpel_stamp_ns, const ros::Time& stamp, double rate_hz);
  // The last non-converged solve's reason, for /diagnostics (under info_mutex_).
  void remember_solver_failure(const std::string& why);

  // the display (node_display.cpp). One refresh of ~surface / ~markers / ~mesh_hash: what it
  // shows, copied under sim_mutex_ (display_frame_locked), computed and published outside it
  // (publish_frame).
  using MeshKey = std::pair<std::uint64_t, std::uint64_t>;  // (sim_generation_, mesh_version)
  struct DisplayFrame {
    std::uint64_t generation = 0, version = 0;  // the state shown (sim_generation_, version)
    ros::Time stamp;
    bool surface = false;                     // ~surface (and ~mesh_hash) too, not ~markers only
    std::optional<SurfaceSnapshot> snapshot;  // a new state: its surface is computed
    std::shared_ptr<const DeformedSurface> shown;  // else the surface last published
    std::optional<TetMesh> mesh;                   // the mesh changed: its hash
    MeshKey mesh_key{};
    OperationRegion region;
    double blade_length = 0;
    std::optional<BladePose> blade;
    bool cutting = false;
    std::vector<Vec3> contact_points;
  };
  // A computed snapshot, handed back to the model by the display thread's next refresh.
  struct Recovered {
    std::uint64_t generation = 0;
    SurfaceSnapshot snapshot;
  };
  void display_thread();
  // Caller holds sim_mutex_. nullopt: nothing to refresh. force: ~surface from the current
  // state now (start, ~reset).
  std::optional<DisplayFrame> display_frame_locked(bool force);
  void publish_frame(DisplayFrame frame);  // caller holds no lock
  void publish_display_now();              // the current state, on the calling thread

  // services (node_services.cpp)
  bool on_cut(soft_tissue_cutting::Cut::Request& req, soft_tissue_cutting::Cut::Response& res);
  bool on_reset(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool on_set_cutting(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res);
  bool on_save(soft_tissue_cutting::SaveMesh::Request& req,
               soft_tissue_cutting::SaveMesh::Response& res);
  void on_reconfigure(soft_tissue_cutting::TissueConfig& config, uint32_t level);
  // dynamic_reconfigure's values into `sim` (the running one, or a fresh one on ~reset).
  // Throws what the Simulation's setters throw.
  void apply_tuning(Simulation& sim, const soft_tissue_cutting::TissueConfig& config);

  // diagnostics (node_diagnostics.cpp)
  void diagnostics_thread();
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  // The backend and the tuning in use, copied from sim_ (under sim_mutex_) for /diagnostics.
  void remember_backend_locked();

  ros::NodeHandle nh_, pnh_;
  const NodeParams params_;
  const Scene initial_scene_;  // ~reset builds a fresh Simulation from it
  const SimulationOptions options_;
  std::unique_ptr<Simulation> sim_;
  std::mutex sim_mutex_;
  PoseInput pose_input_;
  LoopMonitor monitor_;

  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  tf2_ros::StaticTransformBroadcaster frame_broadcaster_;

  ros::Subscriber pose_sub_;
  ros::Publisher surface_pub_, markers_pub_, wrench_pub_, stats_pub_, hash_pub_;
  ros::ServiceServer cut_srv_, reset_srv_, set_cutting_srv_, save_srv_;

  boost::recursive_mutex reconfigure_mutex_;
  soft_tissue_cutting::TissueConfig config_;  // under reconfigure_mutex_
  std::unique_ptr<dynamic_reconfigure::Server<soft_tissue_cutting::TissueConfig>> reconfigure_;
  diagnostic_updater::Updater diagnostics_;

  std::thread thread_, display_thread_, diagnostics_thread_;
  std::atomic<bool> running_{false};
  std::chrono::steady_clock::time_point started_;

  // ~cut requests: queued by on_cut, taken by the loop (under cut_mutex_); the job in progress
  // is touched only under sim_mutex_. cut_done_ wakes the waiting service calls.
  std::mutex cut_mutex_;
  std::condition_variable cut_done_;
  std::deque<std::shared_ptr<CutJob>> queued_cuts_;
  int cuts_waiting_ = 0;  // service calls waiting for their cut (queued or in progress)
  std::shared_ptr<CutJob> active_cut_;               // under sim_mutex_
  LoopMonitor::Clock::time_point next_cut_slice_{};  // under sim_mutex_

  // What /diagnostics says about the backend: copied under sim_mutex_, read under info_mutex_.
  std::mutex info_mutex_;
  std::string backend_, renderer_, backend_note_;
  std::string solver_failure_;                   // why the last non-converged solve failed
  std::string solved_by_, fallback_reason_;      // the last step's (cpu when a gl solve fell back)
  std::optional<RegionMoveStats> region_moves_;  // `follow` region: as of the last step
  int sweeps_waiting_ = 0;                       // `follow`: the last step's (StepStats)
  double cut_lag_ = 0;                           // m
  std::uint64_t steps_ = 0;                      // loop thread
  std::uint64_t poses_dropped_seen_ = 0;         // loop thread: pose_input_.dropped() last warned
  struct Tuning {  // the running simulation's tuning (remember_backend_locked, info_mutex_)
    double cut_pressure = 0, young_modulus = 0, shape_guard_deg = 0;
  } tuning_;

  // surface versions restart with each fresh Simulation: ~reset bumps it (under sim_mutex_).
  std::uint64_t sim_generation_ = 0;
  // Display bookkeeping: what is on the wire (under display_mutex_; taken after sim_mutex_
  // when both are held).
  std::mutex display_mutex_;
  std::uint64_t published_version_ = 0, published_generation_ = 0;
  bool published_any_ = false;
  ros::WallTime last_surface_pub_, last_markers_pub_;
  std::string last_hash_;
  MeshKey hashed_mesh_{~std::uint64_t{0}, 0};  // the mesh the last ~mesh_hash check hashed
  std::shared_ptr<const DeformedSurface> shown_surface_;  // the last ~surface's
  std::optional<BladePose> shown_blade_;                  // blade in the last ~markers
  bool shown_cutting_ = false;
  std::optional<Recovered> recovered_;
  // The display thread's last surface computation (u_S recovered there when stale), ms.
  std::atomic<double> last_recovery_ms_{0};
};

}  // namespace ros_io
}  // namespace stc
