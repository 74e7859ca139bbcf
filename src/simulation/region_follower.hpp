// The operation region that follows the scalpel (scene `operation_region: {follow: {radius}}`,
// docs/DESIGN.md "Moving operation region"): a ball of radius R around the blade. When the
// blade comes within one element layer of the interface (or reaches condensed tissue), the
// model is re-partitioned around the blade and part 2 re-condensed on a worker thread while
// the old model keeps running; the simulation swaps the new model in at the start of a later
// step (the swap is one step).
//
// Why the swap changes no displacement: re-partitioning changes only which tets are condensed,
// not the tissue (same mesh with every cut, loads, fixed nodes, element matrices), and both
// hybrid models are exact for the linear model, so the new model's solution of the same loads
// and contacts is the old one's (to solver precision). Cut tets outside the new ball are
// condensed with the rest; tets around held nodes stay in part 1.
#pragma once

#include "cutting/cut_state.hpp"
#include "cutting/tet_grid.hpp"
#include "soft_tissue_cutting/collision/blade.hpp"
#include "soft_tissue_cutting/collision/surface_bvh.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/simulation/operation_surface.hpp"
#include "soft_tissue_cutting/simulation/region_move_stats.hpp"

#include <chrono>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace stc {

// What a move builds on the worker: the new model and everything the step needs of its
// partition, so the swap itself only exchanges pointers.
struct MovedRegion {
  std::unique_ptr<HybridModel> model;
  OperationSurface boundary;  // the new partition's operation surface
  // Its collision tree, built on the rest shape (the mesh does not change while a move runs:
  // the sweeps wait); its readers refit it to the deformation before each query.
  SurfaceBvh surface_tree;
  std::vector<std::uint8_t> cuttable;  // per tet: part 1 of the new partition
  std::vector<std::uint8_t> locked;    // per node: a node of a condensed tet
  TetGrid cut_grid;                    // the part-1 tets
  TetGrid condensed_grid;              // the part-2 tets
  Vec3 centre = Vec3::Zero();          // the new ball's centre
  double ms = 0;                       // worker time
  // Every node of a free piece (ascending), all in part 1 and held in the new model from its
  // first factorization: the caller's held-piece nodes plus those of any piece the worker
  // finds free against the fixed and held nodes (none expected: the simulation holds each
  // piece as it comes free; a move must never build a singular model all the same).
  std::vector<int> held_nodes;
  std::vector<int> found_pieces;  // tets of each piece found free on the worker
};

// The cutter's view of a partition (same rule as make_cut_state): only part-1 tets are
// cuttable and every node of a condensed tet is locked (never duplicated), so K0 and the
// recovery stay valid. Keeps the state's history (size classes, node stars, the stroke).
// The state's old view is left in `moved`.
void apply_partition_to_cut_state(MovedRegion& moved, CutState& state);

class RegionFollower {
 public:
  // `model` was partitioned with `ball`; `spacing`: how finely the blade is sampled (m).
  RegionFollower(const Sphere& ball, const HybridModel& model, double spacing);
  ~RegionFollower();  // waits for a running worker
  RegionFollower(const RegionFollower&) = delete;
  RegionFollower& operator=(const RegionFollower&) = delete;

  // Does p lie in the rest tissue (either part)?
  bool inside_tissue(const HybridModel& model, const CutState& cut, const Vec3& p) const;
  // Can the sweep from `a` to `b` be cut whole in the current partition: every tet it can
  // meet is a part-1 tet with no interface node (one element layer from the interface)?
  bool sweep_fits(const HybridModel& model, const CutState& cut, const BladeEdge& a,
                  const BladeEdge& b) const;
  // Is the blade clear of the interface by one element layer plus a look-ahead (0.25 R):
  // the edge's points within that reach of tissue meet only part-1 tets with no interface
  // node? Empty: clear; else why not (one line, for /diagnostics).
  std::string edge_clearance(const HybridModel& model, const CutState& cut,
                             const BladeEdge& edge) const;
  // Where the ball goes for these blade points: the mean of those within reach of tissue,
  // pushed up to 0.4 R along the blade's motion (a stroke crosses fewer moves), no farther
  // than keeps them clear of the new interface (docs/DESIGN.md section 10a).
  Vec3 centre_for(const HybridModel& model, const CutState& cut, const std::vector<Vec3>& points,
                  const Vec3& motion) const;
  std::vector<Vec3> edge_points(const BladeEdge& edge) const;
  std::vector<Vec3> sweep_points(const BladeEdge& a, const BladeEdge& b) const;
  // Is `centre` far enough (> 0.1 R) from the current ball to change anything?
  bool worth_moving_to(const Vec3& centre) const;

  // Starts the re-partition around `centre` and the re-condensation on a worker thread. The
  // worker reads `from`'s mesh, loads, fixed nodes and element matrices: until take(), the
  // caller must not cut or change E (solving is fine: it never writes those).
  // keep_nodes: nodes that must stay O or I (imposed ones); held_nodes: every node of a free
  // piece (MovedRegion::held_nodes). A piece is anchored by fixed (or held) nodes only, never
  // by interface nodes: the interface is the old partition's, not the new one's.
  // cut_points: where the next cut is expected (the waiting sweep's or the blade's samples):
  // the new model's first factorization frames the nodes of part-1 tets near them, so that
  // cut refactors a frame (HybridModel's expected_cut_nodes).
  void start(const HybridModel& from, const Vec3& centre, std::vector<int> keep_nodes,
             std::vector<int> held_nodes, std::string reason, std::vector<Vec3> cut_points = {});
  bool moving() const { return work_.valid(); }
  bool ready() const;  // the worker has finished
  // The moved region (waits for the worker if needed); nullopt if it failed (the reason
  // goes to *why and `failed`; the old model stays). Call adopted() once it is in use.
  std::optional<MovedRegion> take(std::string* why = nullptr);
  void adopted(MovedRegion& moved);
  void dropped();  // a taken region was not used after all
  void cancel();   // waits for the worker and drops its result

  const RegionMoveStats& stats() const { return stats_; }
  const Sphere& ball() const { return stats_.ball; }
  double spacing() const { return spacing_; }

 private:
  // Every tet near p is part 1 with no interface node.
  bool clear_at(const HybridModel& model, const CutState& cut, const Vec3& p, double reach) const;
  bool near_tissue(const HybridModel& model, const CutState& cut, const Vec3& p,
                   double reach) const;

  RegionMoveStats stats_;
  double spacing_ = 0;
  TetGrid condensed_grid_;  // part-2 tets (cuts never change them)
  std::future<MovedRegion> work_;
  std::chrono::steady_clock::time_point requested_at_;
};

}  // namespace stc
