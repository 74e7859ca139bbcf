#include "soft_tissue_cutting/cutting/invariants.hpp"

#include "soft_tissue_cutting/mesh/boundary_surface.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

namespace stc {

std::vector<std::string> check_cut_invariants(const TetMesh& mesh,
                                              const std::vector<double>& size_class,
                                              const InvariantLimits& limits) {
  std::vector<std::string> violated;
  auto report = [&](const std::string& what) { violated.push_back(what); };
  if (size_class.size() != mesh.tets.size()) report("size_class does not have one entry per tet");
  if (!mesh.cut_faces.empty() && mesh.cut_faces.size() != mesh.tets.size())
    report("cut_faces does not have one entry per tet");

  std::vector<char> used(mesh.nodes.size(), 0);
  std::set<Tet> seen;
  int small = 0, bad_index = 0, duplicates = 0;
  double worst_fraction = 1e300;
  for (int t = 0; t < mesh.num_tets(); ++t) {
    Tet sorted = mesh.tets[t];
    bool valid = true;
    for (int v : sorted) valid &= v >= 0 && v < mesh.num_nodes();
    if (!valid) {
      ++bad_index;
      continue;
    }
    for (int v : sorted) used[v] = 1;
    std::sort(sorted.begin(), sorted.end());
    if (!seen.insert(sorted).second) ++duplicates;
    if (size_class.size() == mesh.tets.size()) {
      const double fraction = tet_volume(mesh, t) / size_class[t];
      worst_fraction = std::min(worst_fraction, fraction);
      if (!(fraction > limits.min_volume_fraction * (1 - 1e-9))) ++small;
    }
  }
  if (bad_index) report(std::to_string(bad_index) + " tets reference nodes that do not exist");
  if (small) {
    std::ostringstream s;
    s << small << " tets at or below " << limits.min_volume_fraction
      << " of their size class (worst " << worst_fraction << ")";
    report(s.str());
  }
  if (duplicates) report(std::to_string(duplicates) + " duplicate tets");
  const long unused = std::count(used.begin(), used.end(), 0);
  if (unused) report(std::to_string(unused) + " unreferenced nodes");

  const double volume = total_volume(mesh);
  const double error = std::abs(volume - limits.initial_volume) / std::abs(limits.initial_volume);
  if (!(error <= limits.volume_relative_tolerance)) {
    std::ostringstream s;
    s << "total volume " << volume << " differs from the initial " << limits.initial_volume
      << " by " << error << " relative";
    report(s.str());
  }
  if (bad_index == 0 && !is_closed_oriented_manifold(extract_boundary_surface(mesh)))
    report("boundary surface is not a closed, consistently oriented 2-manifold");
  return violated;
}

}  // namespace stc
