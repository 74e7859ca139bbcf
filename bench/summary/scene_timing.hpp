// One scene timed the way `./tissue bench --json` reports it (docs/SCENE.md, bench summary):
// precompute, idle steps, the scripted trajectory's pressing and cutting steps, and the
// uncondensed model's exact solve of the same pressing step. Each measurement runs in its own
// child process so its peak RSS is its own.
#pragma once

#include <nlohmann/json.hpp>

#include <functional>
#include <string>

#include "soft_tissue_cutting/scene/scene.hpp"

namespace stc {

struct BenchCase {
  std::string name;
  std::function<Scene()> load;  // the scene, mesh included (TetGen time is measured apart)
};

// Hybrid model: loads, precomputes, idles, plays the trajectory (blade travel <= step_m per
// step). Returns the summary object plus "press_nodes"/"press_u" (the constraint the full
// model reuses). Runs in the calling process.
nlohmann::json time_hybrid(const BenchCase& c, double step_m, int idle_steps);

// The uncondensed model's exact (same tolerance) solve of the pressing constraint recorded by
// time_hybrid; returns {"full_solve_ms_median", "full_precompute_ms", "full_dof", ...}.
nlohmann::json time_full(const BenchCase& c, const nlohmann::json& hybrid, int repetitions);

// Runs `work` in a forked child; returns its JSON with "peak_rss_mb" (the child's max RSS).
nlohmann::json in_child(const std::function<nlohmann::json()>& work);

}  // namespace stc
