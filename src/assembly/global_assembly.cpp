#include "soft_tissue_cutting/assembly/global_assembly.hpp"

#include <algorithm>
#include <cmath>

namespace stc {
namespace {

// Per node, its first DOF in `map` when all three of its DOFs are there, consecutive (what
// make_dof_map writes); -1 when none is. False when some node has another layout.
bool node_first_dofs(const DofMap& map, std::vector<int>& first) {
  const size_t nodes = map.row_of.size() / 3;
  first.assign(nodes, -1);
  for (size_t n = 0; n < nodes; ++n) {
    const int* d = &map.row_of[3 * n];
    if (d[0] < 0 && d[1] < 0 && d[2] < 0) continue;
    if (d[0] < 0 || d[1] != d[0] + 1 || d[2] != d[0] + 2) return false;
    first[n] = d[0];
  }
  return true;
}

}  // namespace

void add_element_triplets(const TetMesh& mesh, const ElementStiffnessCache& elements,
                          const std::vector<int>& tets, const std::vector<int>& row_of,
                          const std::vector<int>& col_of, std::vector<Triplet>& out) {
  for (int t : tets) {
    const Tet& e = mesh.tets[static_cast<size_t>(t)];
    const Mat12& k = elements[t];
    for (int a = 0; a < 12; ++a) {
      const int r = row_of[static_cast<size_t>(3 * e[a / 3] + a % 3)];
      if (r < 0) continue;
      for (int b = 0; b < 12; ++b) {
        const int c = col_of[static_cast<size_t>(3 * e[b / 3] + b % 3)];
        if (c >= 0) out.emplace_back(r, c, k(a, b));
      }
    }
  }
}

SparseMatrix assemble_stiffness(const TetMesh& mesh, const ElementStiffnessCache& elements,
                                const std::vector<int>& tets, const DofMap& map) {
  return assemble_block(mesh, elements, tets, map, map);
}

SparseMatrix assemble_block(const TetMesh& mesh, const ElementStiffnessCache& elements,
                            const std::vector<int>& tets, const DofMap& map_rows,
                            const DofMap& map_cols) {
  // Straight into compressed rows (docs/DESIGN.md eq. (5)): the pattern from node pairs (16 per
  // tet, not 144 DOF triplets to sort), then each element's 3 x 3 blocks added in place. The
  // organ liver's part 1 (a cut re-assembles it): 1.7 + 3.5 ms through triplets.
  std::vector<int> row_first, col_first;
  if (node_first_dofs(map_rows, row_first) && node_first_dofs(map_cols, col_first)) {
    const size_t nodes = row_first.size();
    // Column nodes of each row node, sorted by their first column DOF, without repeats.
    std::vector<int> start(nodes + 1, 0);
    for (int t : tets)
      for (int a : mesh.tets[static_cast<size_t>(t)])
        if (row_first[static_cast<size_t>(a)] >= 0) start[static_cast<size_t>(a) + 1] += 4;
    for (size_t n = 0; n < nodes; ++n) start[n + 1] += start[n];
    std::vector<int> fill(start.begin(), start.end() - 1),
        adjacent(static_cast<size_t>(start.back()));
    for (int t : tets) {
      const Tet& e = mesh.tets[static_cast<size_t>(t)];
      for (int a : e)
        if (row_first[static_cast<size_t>(a)] >= 0)
          for (int b : e)
            if (col_first[static_cast<size_t>(b)] >= 0)
              adjacent[static_cast<size_t>(fill[static_cast<size_t>(a)]++)] = b;
    }
    std::vector<int> length(nodes, 0);
    for (size_t n = 0; n < nodes; ++n) {
      int* begin = adjacent.data() + start[n];
      int* end = adjacent.data() + fill[n];
      std::sort(begin, end, [&](int x, int y) {
        return col_first[static_cast<size_t>(x)] < col_first[static_cast<size_t>(y)];
      });
      length[n] = static_cast<int>(std::unique(begin, end) - begin);
    }
    SparseMatrix k(map_rows.rows(), map_cols.rows());
    long nonzeros = 0;
    for (int r = 0; r < map_rows.rows(); ++r)
      nonzeros += 3L * length[static_cast<size_t>(map_rows.global_of[static_cast<size_t>(r)] / 3)];
    k.resizeNonZeros(nonzeros);
    int* outer = k.outerIndexPtr();
    int* inner = k.innerIndexPtr();
    double* value = k.valuePtr();
    std::fill(value, value + nonzeros, 0.0);
    int out = 0;
    for (int r = 0; r < map_rows.rows(); ++r) {
      outer[r] = out;
      const size_t n = static_cast<size_t>(map_rows.global_of[static_cast<size_t>(r)] / 3);
      for (int i = 0; i < length[n]; ++i)
        for (int c = 0; c < 3; ++c)
          inner[out++] =
              col_first[static_cast<size_t>(adjacent[static_cast<size_t>(start[n] + i)])] + c;
    }
    outer[map_rows.rows()] = out;
    for (int t : tets) {
      const Tet& e = mesh.tets[static_cast<size_t>(t)];
      const Mat12& ke = elements[t];
      for (int a = 0; a < 4; ++a) {
        const size_t na = static_cast<size_t>(e[a]);
        if (row_first[na] < 0) continue;
        const int* list = adjacent.data() + start[na];
        for (int b = 0; b < 4; ++b) {
          if (col_first[static_cast<size_t>(e[b])] < 0) continue;
          const int slot = static_cast<int>(std::find(list, list + length[na], e[b]) - list);
          for (int ci = 0; ci < 3; ++ci) {
            double* row = value + outer[row_first[na] + ci] + 3 * slot;
            for (int cj = 0; cj < 3; ++cj) row[cj] += ke(3 * a + ci, 3 * b + cj);
          }
        }
      }
    }
    return k;
  }
  std::vector<Triplet> triplets;
  triplets.reserve(tets.size() * 144);
  add_element_triplets(mesh, elements, tets, map_rows.row_of, map_cols.row_of, triplets);
  SparseMatrix k(map_rows.rows(), map_cols.rows());
  k.setFromTriplets(triplets.begin(), triplets.end());  // duplicates are summed
  return k;
}

void add_difference(SparseMatrix& a, const SparseMatrix& d,
                    const std::vector<std::uint8_t>& touched, double drop, SparseMatrix& spare) {
  const int n = static_cast<int>(d.rows()), n_old = static_cast<int>(a.rows());
  a.makeCompressed();
  Vector diag = Vector::Zero(n);
  diag.head(n_old) = a.diagonal();
  diag += d.diagonal();
  const auto cancelled = [&](int r, int c, double v) {
    return touched[static_cast<size_t>(c)] &&
           std::abs(v) <= drop * std::sqrt(std::abs(diag[r] * diag[c]));
  };
  // The rows before the first touched one stay where they are (on the hybrid matrix: the dense
  // interface rows, most of its entries, unless the cut reached them); the rest is rebuilt in
  // `spare` and copied after them.
  int first = 0;
  while (first < n && first < n_old && !touched[static_cast<size_t>(first)]) ++first;
  const int base = first < n_old ? a.outerIndexPtr()[first] : static_cast<int>(a.nonZeros());
  const int tail_old = static_cast<int>(a.nonZeros()) - base;
  spare.resize(1, 1);  // its arrays only: inner indices and values of the tail
  spare.resizeNonZeros(tail_old + d.nonZeros());
  int* inner = spare.innerIndexPtr();
  double* value = spare.valuePtr();
  std::vector<int> outer(static_cast<size_t>(n - first) + 1);
  const int* ai = a.innerIndexPtr();
  const double* av = a.valuePtr();
  const int* di = d.innerIndexPtr();
  const double* dv = d.valuePtr();
  int k = 0;
  for (int r = first; r < n; ++r) {
    outer[static_cast<size_t>(r - first)] = k;
    const int a0 = r < n_old ? a.outerIndexPtr()[r] : 0;
    const int a1 = r < n_old ? a.outerIndexPtr()[r + 1] : 0;
    if (!touched[static_cast<size_t>(r)]) {  // copied bit for bit
      std::copy(ai + a0, ai + a1, inner + k);
      std::copy(av + a0, av + a1, value + k);
      k += a1 - a0;
      continue;
    }
    int i = a0, j = d.outerIndexPtr()[r];
    const int j1 = d.outerIndexPtr()[r + 1];
    while (i < a1 || j < j1) {
      int c;
      double v;
      if (j >= j1 || (i < a1 && ai[i] < di[j])) {
        c = ai[i], v = av[i++];
      } else if (i >= a1 || di[j] < ai[i]) {
        c = di[j], v = dv[j++];
      } else {
        c = ai[i], v = av[i++] + dv[j++];
      }
      if (cancelled(r, c, v)) continue;
      inner[k] = c, value[k++] = v;
    }
  }
  outer[static_cast<size_t>(n - first)] = k;
  a.conservativeResize(n, n);  // new rows empty; the compressed prefix kept
  a.resizeNonZeros(base + k);  // keeps the first `base` entries
  std::copy(inner, inner + k, a.innerIndexPtr() + base);
  std::copy(value, value + k, a.valuePtr() + base);
  for (int r = first; r <= n; ++r)
    a.outerIndexPtr()[r] = base + outer[static_cast<size_t>(r - first)];
}

DofMap make_dof_map(int num_nodes, const std::vector<int>& nodes,
                    const std::vector<std::uint8_t>& fixed_node) {
  DofMap map;
  map.row_of.assign(static_cast<size_t>(3 * num_nodes), -1);
  for (int n : nodes) {
    if (!fixed_node.empty() && fixed_node[static_cast<size_t>(n)]) continue;
    for (int c = 0; c < 3; ++c) {
      map.row_of[static_cast<size_t>(3 * n + c)] = map.rows();
      map.global_of.push_back(3 * n + c);
    }
  }
  return map;
}

Vector gather(const Vector& global, const DofMap& map) {
  Vector local(map.rows());
  for (int i = 0; i < map.rows(); ++i) local[i] = global[map.global_of[static_cast<size_t>(i)]];
  return local;
}

void scatter(const Vector& local, const DofMap& map, Vector& global) {
  for (int i = 0; i < map.rows(); ++i) global[map.global_of[static_cast<size_t>(i)]] = local[i];
}

}  // namespace stc
