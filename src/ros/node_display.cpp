// The display: ~surface, ~markers and ~mesh_hash from their own thread at ~display_rate
// (docs/ROS.md (threads), (publishing)). Each refresh copies what it shows under sim_mutex_
// (a SurfaceSnapshot: rest positions, u, triangles, the shared condensed factor; the marker
// inputs; the mesh when it changed) and does everything costly outside it: the recovery of
// u_S from u_I (one sparse solve, tens of ms at organ scale), shading, hashing, publishing.
// So the loop never waits for a recovery; a step waits at most for those copies.
#include "soft_tissue_cutting/ros/markers.hpp"
#include "soft_tissue_cutting/ros/tissue_node.hpp"

#include <std_msgs/String.h>
#include <visualization_msgs/MarkerArray.h>

#include <cstdint>

namespace stc {
namespace ros_io {

void TissueNode::display_thread() {
  using Clock = std::chrono::steady_clock;
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / params_.display_rate));
  while (running_ && ros::ok()) {
    const Clock::time_point t0 = Clock::now();
    // The last refresh's recovery goes back to the model (only copies), so a loop-side
    // displacement() (a region swap, ~save) need not solve it again.
    std::optional<Recovered> recovered;
    {
      std::lock_guard<std::mutex> lock(display_mutex_);
      recovered.swap(recovered_);
    }
    std::optional<DisplayFrame> frame;
    {
      std::lock_guard<std::mutex> lock(sim_mutex_);
      if (recovered && recovered->generation == sim_generation_)
        sim_->adopt_recovery(recovered->snapshot);
      frame = display_frame_locked(false);
    }
    recovered.reset();  // may hold a replaced model's factor: freed outside the lock
    if (frame) publish_frame(std::move(*frame));
    std::this_thread::sleep_until(t0 + period);  // at most ~display_rate refreshes
  }
}

std::optional<TissueNode::DisplayFrame> TissueNode::display_frame_locked(bool force) {
  const ros::WallTime now = ros::WallTime::now();
  std::lock_guard<std::mutex> lock(display_mutex_);
  // ~surface when the surface changed, and at least once a second; ~markers (always every
  // namespace, so the latched message is complete) with it, or alone when the blade moved.
  const bool changed = !published_any_ || sim_generation_ != published_generation_ ||
                       sim_->surface_version() != published_version_;
  const std::optional<BladePose> blade = pose_input_.latest();
  const bool cutting = sim_->last_stats().cutting;
  const bool blade_moved =
      blade.has_value() != shown_blade_.has_value() ||
      (blade && (blade->position != shown_blade_->position ||
                 !blade->orientation.coeffs().isApprox(shown_blade_->orientation.coeffs(), 0))) ||
      cutting != shown_cutting_;
  const bool surface = force || changed || (now - last_surface_pub_).toSec() >= 1.0;
  if (!surface && !blade_moved) return std::nullopt;

  DisplayFrame f;
  f.generation = sim_generation_;
  f.version = sim_->surface_version();
  f.stamp = ros::Time::now();
  f.surface = surface;
  if (force || changed || !shown_surface_)
    f.snapshot = sim_->surface_snapshot();  // copies; recovered in publish_frame
  else
    f.shown = shown_surface_;  // the state on the wire already: nothing to recover
  const MeshKey mesh_key{sim_generation_, sim_->mesh_version()};
  if (surface && mesh_key != hashed_mesh_) {
    f.mesh = sim_->mesh();  // hashed in publish_frame
    f.mesh_key = mesh_key;
  }
  f.region = sim_->scene().operation_region;
  f.blade_length = sim_->scene().scalpel.blade_length;
  f.blade = blade;
  f.cutting = cutting;
  f.contact_points = sim_->last_stats().contact_points;
  return f;
}

void TissueNode::publish_frame(DisplayFrame f) {
  std::shared_ptr<const DeformedSurface> surface = f.shown;
  const bool recovers = f.snapshot && f.snapshot->displacement.stale;
  if (f.snapshot) {  // ~stats recovery_ms: the last surface computed (u_S recovered if stale)
    const auto t0 = std::chrono::steady_clock::now();
    surface = std::make_shared<const DeformedSurface>(f.snapshot->compute());
    last_recovery_ms_ =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  std::string hash;
  if (f.mesh) hash = mesh_hash(*f.mesh);

  visualization_msgs::Marker whole;
  if (f.surface) {
    whole = surface_marker(*surface, SurfacePart::kAll);
    whole.header.frame_id = params_.frame_id;
    whole.header.stamp = f.stamp;
    // The surface state's version travels as the header's sequence number (roscpp sends it
    // as set), not in `text`: rviz flags a TRIANGLE_LIST with text ("Non-empty text is
    // ignored").
    whole.header.seq = static_cast<std::uint32_t>(f.version);
  }
  visualization_msgs::MarkerArray array;
  array.markers.push_back(surface_marker(*surface, SurfacePart::kSkin));
  array.markers.push_back(surface_marker(*surface, SurfacePart::kCut));
  for (auto& m : operation_region_markers(f.region).markers) array.markers.push_back(m);
  for (auto& m : scalpel_markers(f.blade, f.blade_length, f.cutting).markers)
    array.markers.push_back(m);
  array.markers.push_back(contact_marker(f.contact_points));
  for (auto& m : array.markers) {
    m.header.frame_id = params_.frame_id;
    m.header.stamp = f.stamp;
  }

  std::optional<Recovered> replaced;  // declared first: destroyed after the lock is released
  std::lock_guard<std::mutex> lock(display_mutex_);
  // The wire shows states in order: a refresh that took longer than a newer one (the display
  // thread's against ~reset's) is dropped, and markers alone only go with the surface they
  // were drawn on.
  const bool older =
      published_any_ && (f.generation < published_generation_ ||
                         (f.generation == published_generation_ && f.version < published_version_));
  const bool stale_markers =
      !f.surface && (f.generation != published_generation_ || f.version != published_version_);
  if (older || stale_markers) return;
  if (f.surface) {
    surface_pub_.publish(whole);
    published_version_ = f.version;
    published_generation_ = f.generation;
    shown_surface_ = surface;
    last_surface_pub_ = ros::WallTime::now();
    if (f.mesh && (hash != last_hash_ || !published_any_)) {
      std_msgs::String h;
      h.data = hash;
      hash_pub_.publish(h);
      last_hash_ = hash;
    }
    if (f.mesh) hashed_mesh_ = f.mesh_key;
    published_any_ = true;
  }
  markers_pub_.publish(array);
  shown_blade_ = f.blade;
  shown_cutting_ = f.cutting;
  last_markers_pub_ = ros::WallTime::now();
  if (recovers) {
    replaced.swap(recovered_);
    recovered_ = Recovered{f.generation, std::move(*f.snapshot)};
  }
}

void TissueNode::publish_display_now() {
  std::optional<DisplayFrame> frame;
  {
    std::lock_guard<std::mutex> lock(sim_mutex_);
    frame = display_frame_locked(true);
  }
  publish_frame(std::move(*frame));
}

}  // namespace ros_io
}  // namespace stc
