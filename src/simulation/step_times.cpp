#include "soft_tissue_cutting/simulation/step_times.hpp"

#include <algorithm>

namespace stc {

StepKind step_kind(const StepStats& s) {
  if (s.cutting) return StepKind::kCutting;
  if (s.in_contact) return StepKind::kPressing;
  return StepKind::kIdle;
}

StepTimeSummary summarize_step_times(std::vector<double> ms) {
  StepTimeSummary out;
  out.n = static_cast<int>(ms.size());
  if (ms.empty()) return out;
  std::sort(ms.begin(), ms.end());
  const size_t h = ms.size() / 2;
  out.median = ms.size() % 2 ? ms[h] : 0.5 * (ms[h - 1] + ms[h]);
  out.max = ms.back();
  return out;
}

void StepTimes::add(const StepStats& s) {
  switch (step_kind(s)) {
    case StepKind::kIdle:
      idle.push_back(s.step_ms);
      break;
    case StepKind::kPressing:
      pressing.push_back(s.step_ms);
      break;
    case StepKind::kCutting:
      cutting.push_back(s.step_ms);
      break;
  }
}

}  // namespace stc
