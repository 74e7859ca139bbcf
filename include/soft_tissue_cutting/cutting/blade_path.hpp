// A blade path for a cut (the ~cut service, Simulation::cut_along) resampled at a fixed
// spacing, so the cut depends on the path and not on how densely the caller sampled it: ten
// or ten thousand poses along one stroke give the same sweeps. Very short sweeps are the
// reason: the cut of a 4 um sweep is decided by snapping and inside tolerances, not by the
// blade.
#pragma once

#include "soft_tissue_cutting/scene/scene.hpp"

#include <vector>

namespace stc {

// How far the blade edge moves between two poses: the larger of the tip's and the heel's
// displacement (a rotation about the tip moves the heel by blade_length * angle).
double blade_travel(const BladePose& a, const BladePose& b, double blade_length);

// Total travel along the poses.
double blade_path_length(const std::vector<BladePose>& poses, double blade_length);

// Poses at travel 0, h, 2h, ... along the path (positions interpolated linearly, orientations
// slerped within each input segment) with h = length / ceil(length / spacing), so the last
// pose is the path's end. Orientations are normalised. Fewer than two poses, or a path that
// does not move, come back as they are (normalised).
std::vector<BladePose> resample_blade_path(const std::vector<BladePose>& poses, double blade_length,
                                           double spacing);

// How many steps of `poses` (a blade's consecutive poses) one straight sweep from poses[0] to
// poses[k] can stand for: the largest k whose travel is at most `max_travel` and at whose
// every pose in between the tip and the heel lie within `tolerance` of where that straight
// sweep has them (interpolated by travel). At least 1 when there are two poses or more, 0
// otherwise. Waiting sweeps of a `follow` region are cut this way after a move
// (docs/DESIGN.md section 10a, "Swap").
size_t straight_sweep_steps(const std::vector<BladePose>& poses, double blade_length,
                            double tolerance, double max_travel);

}  // namespace stc
