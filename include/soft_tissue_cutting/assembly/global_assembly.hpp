// Global sparse assembly over a chosen set of tets and DOFs (docs/DESIGN.md sections 2-4): the
// same routine builds the full K, K^(1) of the operation part and K^(2) of the condensed part.
#pragma once

#include "soft_tissue_cutting/assembly/element_cache.hpp"
#include "soft_tissue_cutting/solve/linear_solver.hpp"  // SparseMatrix, Vector

#include <Eigen/SparseCore>

#include <cstdint>
#include <vector>

namespace stc {

using Triplet = Eigen::Triplet<double, int>;

// A numbering of global DOFs (3 * node + component) into the rows of one system; -1 = the DOF
// is not in this system (fixed, or outside the part). Fixed DOFs are eliminated by giving
// them -1 (their displacement is zero, so they contribute nothing to the right-hand side).
struct DofMap {
  std::vector<int> row_of;     // size 3n
  std::vector<int> global_of;  // size = rows
  int rows() const { return static_cast<int>(global_of.size()); }
};

// Appends the element blocks of `tets` restricted to rows/columns of `map` (row map and
// column map may differ, for the off-diagonal blocks K2_IN, K2_NI).
void add_element_triplets(const TetMesh& mesh, const ElementStiffnessCache& elements,
                          const std::vector<int>& tets, const std::vector<int>& row_of,
                          const std::vector<int>& col_of, std::vector<Triplet>& out);

// Square symmetric matrix over `map` from `tets`.
SparseMatrix assemble_stiffness(const TetMesh& mesh, const ElementStiffnessCache& elements,
                                const std::vector<int>& tets, const DofMap& map);

// Rectangular block rows(map_rows) x cols(map_cols) from `tets`.
SparseMatrix assemble_block(const TetMesh& mesh, const ElementStiffnessCache& elements,
                            const std::vector<int>& tets, const DofMap& map_rows,
                            const DofMap& map_cols);

// a += d for a symmetric a and a difference d whose rows are non-zero only where `touched`
// (a cut's changed element matrices, docs/DESIGN.md section 6.2), in one pass: the rows d does
// not touch are copied bit for bit, the touched ones merged, and d may have more rows (new DOFs,
// appended). An entry in a touched row and a touched column that sums to within
// `drop` x sqrt(|a_rr a_cc|) of zero is dropped: couplings the change removed cancel to
// rounding, not to zero. In place from the first touched row on (the rows before it are not
// moved); `spare` holds the rebuilt rows meanwhile (its arrays re-used, not fresh pages).
void add_difference(SparseMatrix& a, const SparseMatrix& d,
                    const std::vector<std::uint8_t>& touched, double drop, SparseMatrix& spare);

// DOF map of every DOF of `nodes` (in that order) that is not fixed.
DofMap make_dof_map(int num_nodes, const std::vector<int>& nodes,
                    const std::vector<std::uint8_t>& fixed_node);

// Gather / scatter between a global 3n vector and a system vector.
Vector gather(const Vector& global, const DofMap& map);
void scatter(const Vector& local, const DofMap& map, Vector& global);

}  // namespace stc
