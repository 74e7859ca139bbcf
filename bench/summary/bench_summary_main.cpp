// tissue_bench_summary --json OUT.json [--cases thigh1,thigh2,liver_organ,liver_200k]
//                      [--step-mm 1.0] [--idle-steps 50]
// The summary of `./tissue bench --json OUT.json` (docs/SCENE.md): paper_scale (the built-in
// thigh), organ_scale (config/scenes/liver_organ.yaml) and the scaling table (~3k to ~200k
// tets). Each scene's hybrid run and its full-model reference run in their own child process,
// so peak_rss_mb is the hybrid model's alone. Times are medians over the trajectory's steps of
// one run on a shared machine: compare ratios within one run.
#include "scene_timing.hpp"

#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/scene/scene_loader.hpp"
#include "soft_tissue_cutting/solve/blas_kernels.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#ifndef TISSUE_SOURCE_DIR
#error "TISSUE_SOURCE_DIR must name the package source directory (CMake defines it)"
#endif

namespace {

int usage(const char* why) {
  std::fprintf(stderr,
               "tissue_bench_summary: %s\nusage: tissue_bench_summary --json OUT.json "
               "[--cases thigh1,thigh2,liver_organ,liver_200k] [--step-mm MM] "
               "[--idle-steps N]\n",
               why);
  return 2;
}

std::vector<stc::BenchCase> all_cases() {
  const std::string scenes = std::string(TISSUE_SOURCE_DIR) + "/config/scenes/";
  const std::string bench_scenes = std::string(TISSUE_SOURCE_DIR) + "/bench/scenes/";
  return {
      {"thigh1", [] { return stc::make_thigh_scene(1.0); }},
      {"thigh2", [] { return stc::make_thigh_scene(2.0); }},
      {"liver_organ", [scenes] { return stc::load_scene(scenes + "liver_organ.yaml"); }},
      {"liver_200k",
       [bench_scenes] { return stc::load_scene(bench_scenes + "liver_organ_200k.yaml"); }},
  };
}

}  // namespace

int main(int argc, char** argv) {
  stc::reexec_with_native_blas_kernels(argv);  // before anything runs (blas_kernels.hpp)
  std::string out, cases = "thigh1,thigh2,liver_organ,liver_200k";
  double step_mm = 1.0;
  int idle_steps = 50;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) return usage(("missing value after " + a).c_str());
    const std::string v = argv[++i];
    if (a == "--json")
      out = v;
    else if (a == "--cases")
      cases = "," + v + ",";
    else if (a == "--step-mm")
      step_mm = std::stod(v);
    else if (a == "--idle-steps")
      idle_steps = std::stoi(v);
    else
      return usage(("unknown option " + a).c_str());
  }
  if (out.empty()) return usage("--json OUT.json is required");
  if (cases.front() != ',') cases = "," + cases + ",";

  nlohmann::json scaling = nlohmann::json::array(), paper, organ;
  std::printf("%-12s %8s %9s %6s %11s %9s %9s %9s %9s %9s %9s\n", "scene", "tets", "op DOF", "I",
              "precomp ms", "idle ms", "press ms", "cut med", "cut max", "full ms", "RSS MB");
  for (const stc::BenchCase& c : all_cases()) {
    if (cases.find("," + c.name + ",") == std::string::npos) continue;
    nlohmann::json h =
        stc::in_child([&] { return stc::time_hybrid(c, 1e-3 * step_mm, idle_steps); });
    if (h.contains("error")) {
      std::fprintf(stderr, "tissue_bench_summary: %s: %s\n", c.name.c_str(),
                   h["error"].get<std::string>().c_str());
      return 1;
    }
    const nlohmann::json f = stc::in_child([&] { return stc::time_full(c, h, 5); });
    for (const auto& [k, v] : f.items()) h[k == "peak_rss_mb" ? "full_peak_rss_mb" : k] = v;
    h.erase("press_nodes");
    h.erase("press_u");
    std::printf("%-12s %8d %9d %6d %11.0f %9.3f %9.3f %9.2f %9.2f %9.2f %9.0f\n", c.name.c_str(),
                h["tets"].get<int>(), h["dof_operation"].get<int>(),
                h["nodes_interface"].get<int>(), h["precompute_ms"].get<double>(),
                h["idle_step_ms_median"].get<double>(), h["step_ms_median"].get<double>(),
                h["cut_step_ms_median"].get<double>(), h["cut_step_ms_max"].get<double>(),
                h.value("full_solve_ms_median", 0.0), h["peak_rss_mb"].get<double>());
    const nlohmann::json& cpu = h["cpu_ms"];
    std::printf("%-12s %8s %9s %6s %11.0f %9.3f %9.3f %9.2f %9.2f %9.2f   (processor time)\n",
                "  cpu", "", "", "", cpu["precompute"].get<double>(),
                cpu["idle_step_median"].get<double>(), cpu["step_median"].get<double>(),
                cpu["cut_step_median"].get<double>(), cpu["cut_step_max"].get<double>(),
                h.value("full_solve_cpu_ms_median", 0.0));
    std::fflush(stdout);
    if (c.name == "thigh1") paper = h;
    if (c.name == "liver_organ") organ = h;
    scaling.push_back(h);
  }
  nlohmann::ordered_json j;
  j["paper_scale"] = paper.is_null() ? nlohmann::json::object() : paper;
  j["organ_scale"] = organ.is_null() ? nlohmann::json::object() : organ;
  j["scaling"] = scaling;
  std::ofstream o(out);
  o << j.dump(2) << "\n";
  if (!o) {
    std::fprintf(stderr, "tissue_bench_summary: %s: write failed\n", out.c_str());
    return 1;
  }
  std::printf("summary written to %s\n", out.c_str());
  return 0;
}
