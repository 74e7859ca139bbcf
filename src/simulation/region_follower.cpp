#include "simulation/region_follower.hpp"

#include "collision/tissue_samples.hpp"
#include "cutting/free_pieces.hpp"
#include "soft_tissue_cutting/partition/follow_region.hpp"
#include "solve/blas_guard.hpp"

#include <algorithm>
#include <exception>

namespace stc {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

constexpr double kReach = 0.25;     // of R: how far ahead of the blade the region must be clear
constexpr double kLookahead = 0.4;  // of R: the new centre, along the blade's motion
constexpr double kMinShift = 0.1;   // of R: a smaller move changes nothing

TetGrid grid_of(const TetMesh& mesh, const std::vector<std::uint8_t>& include) {
  TetGrid g;
  g.build(mesh, include);
  return g;
}

}  // namespace

void apply_partition_to_cut_state(MovedRegion& moved, CutState& state) {
  // Swapped, not moved: the old partition's view is left in `moved`, for the caller to free
  // off the loop (the grids are many small vectors).
  std::swap(state.cuttable, moved.cuttable);
  std::swap(state.locked, moved.locked);
  std::swap(state.grid, moved.cut_grid);
}

RegionFollower::RegionFollower(const Sphere& ball, const HybridModel& model, double spacing)
    : spacing_(spacing) {
  stats_.ball = ball;
  std::vector<std::uint8_t> condensed(model.partition().operation_tet.size());
  for (size_t t = 0; t < condensed.size(); ++t) condensed[t] = !model.partition().operation_tet[t];
  condensed_grid_ = grid_of(model.mesh(), condensed);
}

RegionFollower::~RegionFollower() { cancel(); }

bool RegionFollower::inside_tissue(const HybridModel& model, const CutState& cut,
                                   const Vec3& p) const {
  return tet_containing(model.mesh(), cut.grid, p) >= 0 ||
         tet_containing(model.mesh(), condensed_grid_, p) >= 0;
}

bool RegionFollower::near_tissue(const HybridModel& model, const CutState& cut, const Vec3& p,
                                 double reach) const {
  return any_tet_near(model.mesh(), cut.grid, p, reach) ||
         any_tet_near(model.mesh(), condensed_grid_, p, reach);
}

bool RegionFollower::clear_at(const HybridModel& model, const CutState& cut, const Vec3& p,
                              double reach) const {
  if (any_tet_near(model.mesh(), condensed_grid_, p, reach)) return false;
  const Partition& part = model.partition();
  for (int t : tets_near(model.mesh(), cut.grid, p, reach)) {
    if (!cut.cuttable[static_cast<size_t>(t)]) return false;
    for (int v : model.mesh().tets[static_cast<size_t>(t)])
      if (part.node_set[static_cast<size_t>(v)] != NodeSet::kOperation) return false;
  }
  return true;
}

std::vector<Vec3> RegionFollower::edge_points(const BladeEdge& edge) const {
  return edge_samples(edge, spacing_);
}

std::vector<Vec3> RegionFollower::sweep_points(const BladeEdge& a, const BladeEdge& b) const {
  return sweep_samples(a, b, spacing_);
}

bool RegionFollower::sweep_fits(const HybridModel& model, const CutState& cut, const BladeEdge& a,
                                const BladeEdge& b) const {
  // Every point of the swept surface is within `spacing` of a sample, so the tets it meets
  // are among those near the samples.
  for (const Vec3& p : sweep_points(a, b))
    if (!clear_at(model, cut, p, spacing_)) return false;
  return true;
}

std::string RegionFollower::edge_clearance(const HybridModel& model, const CutState& cut,
                                           const BladeEdge& edge) const {
  const double reach = spacing_ + kReach * stats_.ball.radius;
  for (const Vec3& p : edge_points(edge)) {
    if (any_tet_near(model.mesh(), condensed_grid_, p, spacing_))
      return "the blade reached condensed tissue";
    if (!clear_at(model, cut, p, reach))
      return "the blade is within one element layer (plus look-ahead) of the interface";
  }
  return "";
}

Vec3 RegionFollower::centre_for(const HybridModel& model, const CutState& cut,
                                const std::vector<Vec3>& points, const Vec3& motion) const {
  std::vector<Vec3> in_reach;
  for (double reach : {spacing_, spacing_ + kReach * stats_.ball.radius}) {
    for (const Vec3& p : points)
      if (near_tissue(model, cut, p, reach)) in_reach.push_back(p);
    if (!in_reach.empty()) break;
  }
  Vec3 mean = points.front();
  if (!in_reach.empty()) {
    mean.setZero();
    for (const Vec3& p : in_reach) mean += p;
    mean /= static_cast<double>(in_reach.size());
  }
  if (!(motion.norm() > 0)) return mean;
  // Ahead along the motion, but no farther than keeps these points clear of the new
  // interface (edge_clearance: reach, plus the element layer, ~2 spacings, plus a tet's
  // extent): a ball pushed so far ahead that the blade it was placed for is not clear in it
  // asks for the next move at once, and the region crept along a few millimetres per move
  // (91 moves over the 9 cm liver stroke). The farthest look-ahead that keeps them clear;
  // the whole look-ahead where no centre can (an edge deeper in the tissue than the ball
  // holds clear: the region moves at every few millimetres whatever, and the sweeps ahead
  // should fit).
  const double radius = stats_.ball.radius;
  const double clear_within = radius - (kReach * radius + 5 * spacing_);
  const Vec3 ahead = motion.normalized();
  auto clear_around = [&](const Vec3& centre) {
    return std::all_of(in_reach.begin(), in_reach.end(),
                       [&](const Vec3& p) { return (p - centre).norm() <= clear_within; });
  };
  if (!clear_around(mean)) return mean + kLookahead * radius * ahead;
  for (int tenths = 4; tenths >= 1; --tenths) {  // kLookahead = 0.4 R down to 0.1 R
    const Vec3 centre = mean + 0.1 * tenths * radius * ahead;
    if (clear_around(centre)) return centre;
  }
  return mean;
}

bool RegionFollower::worth_moving_to(const Vec3& centre) const {
  // A shift equal to the threshold up to rounding counts as equal (not worth it): a trajectory
  // advancing exactly 0.1 R per pose (thigh_follow: 2.5 mm, R = 2.5 cm) otherwise moved or not
  // by the last digits of the poses, and the cut with it (docs/DESIGN.md section 10a).
  constexpr double kRoundOff = 1e-9;
  return (centre - stats_.ball.center).norm() > kMinShift * stats_.ball.radius * (1 + kRoundOff);
}

void RegionFollower::start(const HybridModel& from, const Vec3& centre, std::vector<int> keep_nodes,
                           std::vector<int> held_nodes, std::string reason,
                           std::vector<Vec3> cut_points) {
  if (moving()) return;
  requested_at_ = Clock::now();
  stats_.moving = true;
  stats_.last_reason = std::move(reason);
  const Sphere ball{centre, stats_.ball.radius};
  // The second core: the old model keeps solving on the caller's thread meanwhile.
  work_ = std::async(
      std::launch::async, [&from, ball, keep = std::move(keep_nodes), held = std::move(held_nodes),
                           points = std::move(cut_points), reach = spacing_]() mutable {
        const auto t0 = Clock::now();
        settle_openmp_on_this_thread();  // CHOLMOD at full speed here too (blas_guard.hpp)
        MovedRegion r;
        r.centre = ball.center;
        // The free pieces: anchored by fixed or held nodes only (any interface is the old
        // partition's). Every node of one stays in part 1 (keep) and is held before the new
        // model's first factorization (its rigid modes would make the hybrid matrix singular).
        std::vector<std::uint8_t> anchored = from.fixed_nodes();
        anchored.resize(from.mesh().nodes.size(), 0);
        for (int n : held) anchored[static_cast<size_t>(n)] = 1;
        for (const MeshPiece& piece : free_pieces(from.mesh(), anchored)) {
          held.insert(held.end(), piece.nodes.begin(), piece.nodes.end());
          r.found_pieces.push_back(static_cast<int>(piece.tets.size()));
        }
        std::sort(held.begin(), held.end());
        held.erase(std::unique(held.begin(), held.end()), held.end());
        keep.insert(keep.end(), held.begin(), held.end());
        std::vector<std::uint8_t> labels = follow_region_labels(from.mesh(), ball, keep);
        // The nodes of the new part-1 tets near where the next cut is expected.
        std::vector<int> expected;
        if (!points.empty()) {
          const TetGrid part1 = grid_of(from.mesh(), labels);
          for (const Vec3& p : points)
            for (int t : tets_near(from.mesh(), part1, p, reach))
              for (int v : from.mesh().tets[static_cast<size_t>(t)]) expected.push_back(v);
          std::sort(expected.begin(), expected.end());
          expected.erase(std::unique(expected.begin(), expected.end()), expected.end());
        }
        r.model = std::make_unique<HybridModel>(from, std::move(labels), held, make_cpu_solver(),
                                                expected);
        r.held_nodes = std::move(held);
        const TetMesh& mesh = r.model->mesh();
        const Partition& p = r.model->partition();
        r.boundary.init(mesh, p.operation_tet);
        r.surface_tree.build(r.boundary.current(mesh), mesh, p.operation_tet, {});
        r.cuttable = p.operation_tet;
        r.locked.assign(mesh.nodes.size(), 0);
        std::vector<std::uint8_t> condensed(p.operation_tet.size(), 0);
        for (int t : p.condensed_tets) {
          condensed[static_cast<size_t>(t)] = 1;
          for (int v : mesh.tets[static_cast<size_t>(t)]) r.locked[static_cast<size_t>(v)] = 1;
        }
        r.cut_grid = grid_of(mesh, r.cuttable);
        r.condensed_grid = grid_of(mesh, condensed);
        r.ms = ms_since(t0);
        return r;
      });
}

bool RegionFollower::ready() const {
  return work_.valid() && work_.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

std::optional<MovedRegion> RegionFollower::take(std::string* why) {
  if (!work_.valid()) return std::nullopt;
  stats_.moving = false;
  try {
    MovedRegion r = work_.get();
    stats_.last_ms = r.ms;
    stats_.max_ms = std::max(stats_.max_ms, r.ms);
    stats_.total_ms += r.ms;
    stats_.durations_ms.push_back(r.ms);
    return r;
  } catch (const std::exception& e) {
    ++stats_.failed;
    if (why) *why = e.what();
    return std::nullopt;
  }
}

void RegionFollower::adopted(MovedRegion& moved) {
  ++stats_.moves;
  stats_.ball.center = moved.centre;
  stats_.last_wait_ms = ms_since(requested_at_);
  std::swap(condensed_grid_, moved.condensed_grid);  // the old one left in `moved` (above)
}

void RegionFollower::dropped() { ++stats_.failed; }

void RegionFollower::cancel() {
  if (!work_.valid()) return;
  try {
    work_.get();
  } catch (...) {  // dropped anyway
  }
  stats_.moving = false;
}

}  // namespace stc
