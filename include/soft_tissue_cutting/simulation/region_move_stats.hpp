// What the `follow` operation region has done so far (docs/DESIGN.md "Moving operation
// region"): read by the ROS node's diagnostics and by `tissue solve`'s stats. The mover itself
// is internal (src/simulation/region_follower.hpp).
#pragma once

#include "soft_tissue_cutting/scene/scene.hpp"  // Sphere

#include <string>
#include <vector>

namespace stc {

struct RegionMoveStats {
  int moves = 0;        // new models swapped in since the start (or the last reset)
  int failed = 0;       // re-condensations that failed or were dropped (the old model stayed)
  bool moving = false;  // a re-condensation is running on the worker thread now
  double last_ms = 0;   // worker time of the last completed move (partition + condensation)
  double max_ms = 0, total_ms = 0;
  std::vector<double> durations_ms;  // every completed move's worker time, in order
  double last_wait_ms = 0;           // from the last request to its swap (the cut waited)
  Sphere ball;                       // where the region is now
  std::string last_reason;           // why the last move was requested
};

}  // namespace stc
