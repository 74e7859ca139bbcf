// Operation part / non-operation part and the node sets O, I, S, Q (docs/DESIGN.md section 3).
#pragma once

#include "soft_tissue_cutting/scene/scene.hpp"

#include <cstdint>
#include <vector>

namespace stc {

enum class NodeSet : std::uint8_t {
  kOperation,  // O: touched only by part-1 (operation) tets
  kInterface,  // I: shared by both parts
  kSurface,    // S: part-2-only, on the boundary surface (visible)
  kInterior,   // Q: part-2-only, interior (never seen, never touched)
  kUnused,     // referenced by no tet
};

struct Partition {
  std::vector<std::uint8_t> operation_tet;  // per tet: 1 = part 1 (operation), 0 = part 2
  std::vector<NodeSet> node_set;            // per node
  // The sets as ascending node lists. Fixed nodes are in their set like any other.
  std::vector<int> operation, interface, surface, interior;
  std::vector<int> operation_tets, condensed_tets;  // part 1 and part 2 tet lists

  // `all`: every tet is in part 1 (no I, S, Q: nothing is condensed).
  // `none`: every tet is in part 2 (no O, no I): the hybrid system is empty and the condensed
  // part is solved directly, u_N = K2_NN^-1 f_N (fixed nodes eliminated).
  bool everything_operation() const { return condensed_tets.empty(); }
  bool nothing_operation() const { return operation_tets.empty(); }
};

// Part 1 = tets whose centroid lies in `region`.
Partition partition_mesh(const TetMesh& mesh, const OperationRegion& region);

// Node sets from a given per-tet labelling (S uses extract_boundary_surface).
Partition partition_from_labels(const TetMesh& mesh, std::vector<std::uint8_t> operation_tet);

// The partition after a change of the operation part only (a cut): `changed_tets` (replaced
// or appended) become part-1 tets, appended nodes join O. Part 2 is untouched, so S and Q
// stay as they are and only the part-1 tets are scanned (no boundary extraction of the whole
// mesh). Returns false if the change reached part 2 (a changed tet was a part-2 tet, or an
// interface node stopped being shared): the caller refuses the change, and p is as it was.
bool update_partition_for_operation_change(const TetMesh& mesh,
                                           const std::vector<int>& changed_tets, Partition& p);

}  // namespace stc
