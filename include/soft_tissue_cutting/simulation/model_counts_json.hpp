// The model's sizes as JSON keys (docs/SCENE.md "Offline run"): the one writer for the stats JSON
// of `tissue solve` (simulation_output.cpp) and the bench summary (bench/summary). Header-only:
// `Json` is nlohmann::json or nlohmann::ordered_json (keys added in this order).
#pragma once

#include "soft_tissue_cutting/simulation/model_counts.hpp"

namespace stc {

template <class Json>
void add_model_sizes(Json& j, const HybridModelCounts& c) {
  j["nodes"] = c.nodes;
  j["tets"] = c.tets;
  j["dof_operation"] = c.dof_operation;
  j["nodes_interface"] = c.nodes_interface;
  j["nodes_surface_condensed"] = c.nodes_surface_condensed;
  j["nodes_interior_condensed"] = c.nodes_interior_condensed;
}

}  // namespace stc
