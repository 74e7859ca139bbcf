// The offline outputs of docs/SCENE.md "Offline run": the VTK state and the JSON statistics.
#include "simulation/region_follower.hpp"
#include "soft_tissue_cutting/io/vtk_writer.hpp"
#include "soft_tissue_cutting/simulation/model_counts_json.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"
#include "soft_tissue_cutting/simulation/step_times.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <stdexcept>

namespace stc {

void Simulation::write_vtk(const std::string& path) {
  const Eigen::VectorXd u = full_displacement();  // interior condensed nodes recovered
  stc::write_vtk(path, mesh(), u, tet_regions());
}

namespace {

nlohmann::ordered_json summary_json(const std::vector<double>& ms) {
  const StepTimeSummary s = summarize_step_times(ms);
  nlohmann::ordered_json j;
  j["n"] = s.n;
  j["median"] = s.median;
  j["max"] = s.max;
  return j;
}

}  // namespace

std::string Simulation::stats_json(double total_ms, const StepTimes* steps) {
  const ModelCounts c = counts();
  const StepStats& s = last_stats();
  nlohmann::ordered_json j;
  add_model_sizes(j, c);
  j["cuts"] = c.cuts;
  j["tets_split"] = c.tets_split;
  j["free_pieces_held"] = c.free_pieces_held;
  j["nodes_smoothed"] = c.nodes_smoothed;
  j["flips"] = c.flips;
  if (const RegionMoveStats* m = region_moves()) {  // `follow` region
    std::vector<double> d = m->durations_ms;
    std::sort(d.begin(), d.end());
    j["region_moves"] = {
        {"moves", m->moves},
        {"failed", m->failed},
        {"median_ms", d.empty() ? 0.0 : d[d.size() / 2]},
        {"max_ms", m->max_ms},
        {"ball_center", {m->ball.center.x(), m->ball.center.y(), m->ball.center.z()}},
        {"radius", m->ball.radius}};
  }
  j["volume_initial"] = c.volume_initial;
  j["volume_final"] = c.volume_final;
  j["cg_iterations"] = c.cg_iterations_total;  // the whole run: initial equilibrium + steps
  j["cg_iterations_last_step"] = s.cg_iterations;
  j["residual"] = s.residual;
  j["converged"] = s.converged;
  if (!s.converged) j["solver_message"] = s.solver_message;
  // What actually solved the final state (docs/SCENE.md "Offline run"): a gl solve finished on the
  // cpu says cpu.
  const std::string solved_by = s.solved_by.empty() ? backend() : s.solved_by;
  j["backend"] = solved_by;
  j["backend_requested"] = backend_requested();
  if (backend() == "gl") j["renderer"] = renderer();
  if (!backend_note().empty()) j["backend_note"] = backend_note();
  if (!s.fallback_reason.empty()) j["fallback_reason"] = s.fallback_reason;
  j["solver_fallbacks"] = c.solver_fallbacks;
  j["steps"] = s.step;
  nlohmann::ordered_json t;
  for (const auto& [stage, ms] : precompute_timings_ms()) t["precompute_" + stage] = ms;
  t["last_step_collision"] = s.collision_ms;
  t["last_step_cutting"] = s.cutting_ms;
  t["last_step_assembly"] = s.assembly_ms;
  t["last_step_solve"] = s.solve_ms;
  t["last_step"] = s.step_ms;
  t["total"] = total_ms;
  j["timings_ms"] = t;
  const StepTimes& times = steps ? *steps : step_times();
  nlohmann::ordered_json by_kind;
  by_kind["idle"] = summary_json(times.idle);
  by_kind["pressing"] = summary_json(times.pressing);
  by_kind["cutting"] = summary_json(times.cutting);
  j["step_ms"] = by_kind;
  return j.dump(2);
}

void Simulation::write_stats_json(const std::string& path, double total_ms,
                                  const StepTimes* steps) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot open for writing");
  out << stats_json(total_ms, steps) << "\n";
  if (!out) throw std::runtime_error(path + ": write failed");
}

}  // namespace stc
