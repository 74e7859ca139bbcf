// rviz markers for the deformed surface, the scalpel and the operation region.
//
// rviz TRIANGLE_LIST markers carry no normals, so the surface is shaded here: each vertex gets
// a normal averaged over its adjacent triangles of the same kind (cut / not cut, so the sharp
// crease along a cut stays sharp), and its colour is lit by a fixed light direction.
#pragma once

#include "soft_tissue_cutting/simulation/simulation.hpp"

#include <visualization_msgs/Marker.h>
#include <visualization_msgs/MarkerArray.h>

#include <optional>
#include <string>

namespace stc {
namespace ros_io {

enum class SurfacePart { kAll, kSkin, kCut };

// TRIANGLE_LIST of the surface triangles of `part`, with shaded per-vertex colours: skin
// coloured by displacement magnitude (tissue pink -> yellow at `max_displacement` m), cut
// faces a dark tissue-interior red.
visualization_msgs::Marker surface_marker(const DeformedSurface& surface, SurfacePart part,
                                          double max_displacement = 0.005);

// Blade (a thin triangle: tip at the pose origin, edge along local +x for blade_length, body
// in the local x-z plane) and a handle box, in namespace "scalpel". Without a pose the two
// markers are DELETE actions.
visualization_msgs::MarkerArray scalpel_markers(const std::optional<BladePose>& blade,
                                                double blade_length, bool cutting);

// The contact region: the surface nodes the blade holds while pressing, as a SPHERE_LIST in
// namespace "contact" (id 0); a DELETE action when it holds none.
visualization_msgs::Marker contact_marker(const std::vector<Vec3>& held_points);

// Outline of the operation region (three great circles of the sphere, or the box's edges) in
// namespace "operation_region"; empty for `all` / `none`.
visualization_msgs::MarkerArray operation_region_markers(const OperationRegion& region);

}  // namespace ros_io
}  // namespace stc
