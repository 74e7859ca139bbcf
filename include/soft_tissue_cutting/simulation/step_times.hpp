// Step wall times by kind, for the stats JSON's `step_ms` (docs/SCENE.md, offline run):
//   idle      no blade contact and no cut inserted,
//   pressing  the blade holds the tissue (contact), no cut inserted,
//   cutting   a cut was inserted this step.
// A step is timed by Simulation::step itself (StepStats::step_ms).
#pragma once

#include "soft_tissue_cutting/simulation/simulation.hpp"

#include <vector>

namespace stc {

enum class StepKind { kIdle, kPressing, kCutting };

StepKind step_kind(const StepStats& s);

// n, median and max of one kind (all 0 when n = 0); the median of an even count is the mean
// of the two middle values.
struct StepTimeSummary {
  int n = 0;
  double median = 0, max = 0;
};
StepTimeSummary summarize_step_times(std::vector<double> ms);

struct StepTimes {
  std::vector<double> idle, pressing, cutting;
  void add(const StepStats& s);
  void clear() { idle.clear(), pressing.clear(), cutting.clear(); }
};

}  // namespace stc
