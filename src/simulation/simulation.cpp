#include "soft_tissue_cutting/simulation/simulation.hpp"

#include "cutting/cut_state.hpp"
#include "cutting/cut_sweep.hpp"
#include "cutting/free_pieces.hpp"
#include "simulation/region_follower.hpp"
#include "soft_tissue_cutting/collision/blade.hpp"
#include "soft_tissue_cutting/collision/edge_contact.hpp"
#include "soft_tissue_cutting/collision/surface_bvh.hpp"
#include "soft_tissue_cutting/cutting/blade_path.hpp"
#include "soft_tissue_cutting/cutting/rest_mapping.hpp"
#include "soft_tissue_cutting/gpu/gl_solver.hpp"
#include "soft_tissue_cutting/mesh/face_adjacency.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/simulation/operation_surface.hpp"
#include "soft_tissue_cutting/simulation/step_times.hpp"
#include "solve/blas_guard.hpp"

#include <algorithm>
#include <chrono>
#include <deque>
#include <future>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace stc {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// A cut path is resampled at this fraction of the operation part's median edge (Simulation::
// cut_path_spacing). The path is carried to rest coordinates point by point and each band
// between two samples is cut as planar triangles there, while the blade's surface maps to
// rest coordinates piecewise linearly over the deformed tets: under a large deformation a band
// a whole edge long lies off it. On the TetGen liver sagging 27 mm (CutFidelityGravity) the open
// walls, carried, lay 1.08 x the Hausdorff tolerance off the blade's path at one median edge,
// 0.82-0.90 x at 0.2-0.5 of it; 0.3: the same path cut again settles in 4 passes (6 at 0.25).
constexpr double kPathSpacingFraction = 0.3;

// Median edge length of the operation part's tets (0 if it has none).
double median_operation_edge(const TetMesh& mesh, const std::vector<std::uint8_t>& operation) {
  std::vector<double> edges;
  for (size_t t = 0; t < mesh.tets.size(); ++t) {
    if (t >= operation.size() || !operation[t]) continue;
    const Tet& k = mesh.tets[t];
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) edges.push_back((mesh.nodes[k[i]] - mesh.nodes[k[j]]).norm());
  }
  if (edges.empty()) return 0;
  std::nth_element(edges.begin(), edges.begin() + edges.size() / 2, edges.end());
  return edges[edges.size() / 2];
}

// One Vec3 per node from a global DOF vector (3 per node), as the rest mapping takes them.
std::vector<Vec3> per_node(const Vector& u) {
  std::vector<Vec3> out(static_cast<size_t>(u.size() / 3));
  for (size_t i = 0; i < out.size(); ++i) out[i] = u.segment<3>(3 * static_cast<long>(i));
  return out;
}

}  // namespace

struct Simulation::Impl {
  Scene initial;  // as loaded: reset() returns here
  Scene scene;    // live parameters (cut pressure, E)
  SimulationOptions options;
  std::string backend_note, renderer, backend = "cpu";
  std::unique_ptr<HybridModel> model;
  // `follow` region only (region_follower.hpp); declared after `model`, so it is destroyed
  // first and its worker, which reads the model, has ended before the model goes.
  std::unique_ptr<RegionFollower> follower;
  // `follow`: the blade's sweeps not cut yet (they wait while the region moves), in order.
  struct Sweep {
    BladePose from, to;
    int moves_tried = 0;
  };
  std::deque<Sweep> pending_sweeps;
  std::vector<int> held_piece_nodes;  // `follow`: every node of a held free piece
  CutState cut_state;
  bool stroke_to_finish = false;  // the blade cut since its stroke's end was conformed
  // The current boundary surface at deformed positions in an AABB tree: rebuilt after cuts,
  // refit before each contact query, so a step never scans the whole surface.
  SurfaceBvh surface_tree;
  OperationSurface boundary;         // the boundary after cuts from part 1 alone
  long surface_tree_extraction = 0;  // boundary.extraction() surface_tree was last built from
  // `follow`: which tets of the whole mesh share each face, kept across cuts and moves (a move
  // changes the partition, not the mesh), so the free-piece search after a cut matches only
  // the faces the cut changed (docs/DESIGN.md section 10a, "Free pieces").
  TetFaceAdjacency mesh_faces;
  std::future<void> retiring;  // `follow`: what a swap replaced, being freed (retire)
  std::future<DisplacementSnapshot> recovering;  // `follow`, online: the old model's S and Q
  std::vector<std::uint8_t> anchored;  // fixed or interface (or held): pieces with one stay put
  ImposedDisplacements held;           // free pieces, held where they came free
  int free_pieces_held = 0;
  bool cut_since_solve = false;  // the next solve first checks the factor (a missed piece)

  enum class BladeState { kFree, kPressing, kCutting } blade_state = BladeState::kFree;
  EdgeContact contact;  // the nodes the blade holds while pressing (tip and edge)
  std::optional<BladePose> last_pose;
  std::vector<BladePose> stroke;  // poses of the current cutting stroke
  // The last cut's end edge carried to rest coordinates, and the pose it was carried for: the
  // next sweep of the same stroke starts from exactly this polyline (no gap, no overlap).
  std::optional<BladePose> last_cut_pose;
  std::vector<Vec3> last_rest_edge;
  // What the blade imposed at the last step (contact): imposed again while the blade stays
  // at that pose (a still step changes nothing, section 7). After a yield the blade holds the
  // pressed tissue until its first motion, whose sweep is carried to rest through it.
  ImposedDisplacements blade_imposed;

  bool cutting_enabled = true;
  std::uint64_t steps = 0, surface_version = 0, mesh_version = 0;
  int cuts = 0, tets_split = 0, nodes_smoothed = 0, flips = 0;
  long cg_iterations_total = 0;
  long solver_fallbacks = 0;
  StepStats last;
  StepTimes step_times;  // every step() since start(), by kind (stats JSON step_ms)

  Backend requested_backend() const { return options.backend.value_or(scene.solver.backend); }

  // The median edge of the initial operation part (of the whole mesh when the region follows
  // the blade): ~cut paths are resampled at kPathSpacingFraction of it whatever the caller's
  // sampling (docs/DESIGN.md (cutting)), and a following region's waiting sweeps are grouped
  // up to it.
  double median_edge = 0;

  std::unique_ptr<LinearSolver> make_solver() {
    backend = "cpu";
    renderer.clear();
    if (requested_backend() == Backend::kGl) {
      std::string why;
      GlSolverOptions gl_options;
      gl_options.context = options.gl;
      if (auto gl = make_gl_solver(gl_options, &why)) {
        backend = "gl";
        renderer = gl->renderer();
        return gl;
      }
      backend_note = "gl backend unavailable (" + why + "); solving on the cpu";
    }
    return make_cpu_solver();
  }

  void start() {
    follower.reset();  // waits for a running move: it reads the model replaced below
    if (recovering.valid()) recovering.wait();  // it reads the old condensed part only
    recovering = {};
    pending_sweeps.clear();
    held_piece_nodes.clear();
    scene = initial;
    refuse_floating_pieces();
    model = std::make_unique<HybridModel>(scene, make_solver());
    model->set_cg_settings(CgSettings{scene.solver.tolerance, scene.solver.max_iterations,
                                      options.wait_for_factor_ahead});
    // Only the operation part is cut; interface nodes stay whole so K0/R stay valid.
    const Partition& p = model->partition();
    std::vector<std::uint8_t> locked(static_cast<size_t>(model->mesh().num_nodes()), 0);
    for (int i : p.interface) locked[static_cast<size_t>(i)] = 1;
    cut_state = make_cut_state(model->mesh_for_cutting(), locked, p.operation_tet);
    median_edge = median_operation_edge(scene.mesh, p.operation_tet);
    anchored = model->fixed_nodes();
    if (scene.operation_region.follows_blade()) {
      // The ball goes anywhere: the blade is sampled at half the median edge of the whole
      // mesh. A moved region condenses tissue the blade has cut, so a piece is anchored by its
      // fixed (or held) nodes only, never by interface nodes.
      median_edge =
          median_operation_edge(scene.mesh, std::vector<std::uint8_t>(scene.mesh.tets.size(), 1));
      follower = std::make_unique<RegionFollower>(scene.operation_region.sphere, *model,
                                                  0.5 * median_edge);
    } else {
      // A fixed region's part 2 is uncut and every piece of it reaches an interface or fixed
      // node: interface nodes anchor.
      for (int i : p.interface) anchored[static_cast<size_t>(i)] = 1;
    }
    held.clear();
    free_pieces_held = 0;
    cut_since_solve = false;
    blade_state = BladeState::kFree;
    contact.release();
    last_pose.reset();
    stroke.clear();
    stroke_to_finish = false;
    last_cut_pose.reset();
    last_rest_edge.clear();
    blade_imposed.clear();
    steps = 0;
    cuts = tets_split = nodes_smoothed = flips = 0;
    cg_iterations_total = 0;
    solver_fallbacks = 0;
    last = StepStats{};
    step_times.clear();
    // The initial equilibrium under the scene's loads.
    last.converged = solve({}, last);
    boundary.init(model->mesh(), model->partition().operation_tet);
    if (follower) {
      std::vector<int> all(model->mesh().tets.size());
      std::iota(all.begin(), all.end(), 0);
      mesh_faces.build(model->mesh(), all);
      mesh_faces.track_cut_off(true);  // pieces_a_cut_may_free
    }
    surface_tree.build(model->mesh(), model->partition().operation_tet, displacements());
    surface_tree_extraction = 0;  // not from `boundary`
    ++surface_version;
    ++mesh_version;
  }

  // A piece of the input with no fixed node would float: refuse it up front with its size,
  // before any factorization fails on it.
  void refuse_floating_pieces() const {
    std::vector<std::uint8_t> fixed(scene.mesh.nodes.size(), 0);
    for (const NodeSelector& selector : scene.fixed)
      for (int n : selector.select(scene.mesh)) fixed[static_cast<size_t>(n)] = 1;
    const std::vector<MeshPiece> floating = free_pieces(scene.mesh, fixed);
    if (!floating.empty())
      throw std::invalid_argument(
          scene.source + ": the mesh has " + std::to_string(floating.size()) +
          " piece(s) with no fixed node (the first has " + std::to_string(floating[0].tets.size()) +
          " tets): fix at least one node of every piece");
  }

  bool solve(const ImposedDisplacements& contact, StepStats& s) {
    const auto t0 = Clock::now();
    // The model factors at first use, once for all the sweeps and held pieces since the last
    // solve; a piece the anchor rule missed is held before the solve needs the factor.
    if (cut_since_solve) hold_what_the_factor_finds_singular();
    cut_since_solve = false;
    ImposedDisplacements imposed = held;
    imposed.insert(contact.begin(), contact.end());  // held pieces win over contact
    const CgResult r = model->solve(imposed);
    s.solve_ms += ms_since(t0);
    s.cg_iterations += r.iterations;
    cg_iterations_total += r.iterations;
    s.residual = r.residual;
    s.solved_by = r.solved_by.empty() ? backend : r.solved_by;
    s.fallback_reason = r.fallback_reason;
    s.solver_message = r.message;
    if (!r.fallback_reason.empty()) ++solver_fallbacks;
    return r.converged;
  }

  // Inserts the sweep between two blade poses; returns true if the mesh changed. The blade
  // moves through the DEFORMED tissue: its edge is carried to rest coordinates through the
  // current deformation (rest_mapping.hpp) before the rest mesh is cut there.
  // The current deformation of the operation part, for carrying blade points to rest: its
  // tets that reach into [lo, hi] as deformed (all of them by default).
  std::shared_ptr<DeformedToRest> current_to_rest(
      const Vec3& lo = Vec3::Constant(-std::numeric_limits<double>::infinity()),
      const Vec3& hi = Vec3::Constant(std::numeric_limits<double>::infinity())) const {
    auto map = std::make_shared<DeformedToRest>();
    map->build(model->mesh(), model->operation_displacement(), model->partition().operation_tets,
               lo, hi);
    return map;
  }

  // A ~cut path's deformation (PathCut::to_rest). A fixed region cuts part 1 only, so the map
  // covers part 1. `follow`: the region moves to each sweep before it is cut
  // (move_region_for_path_sweep), so the path may start or run where the ball is not yet: the
  // map covers the whole tissue, every node's displacement recovered (S and Q from u_I, exact
  // for the linear model), else a path beginning outside the ball would meet no tet of the map
  // and cut nothing.
  std::shared_ptr<DeformedToRest> path_to_rest() const {
    if (!follower) return current_to_rest();
    auto map = std::make_shared<DeformedToRest>();
    map->build(model->mesh(), model->displacement());  // every tet
    return map;
  }

  // frozen: carry the blade through this deformation (a ~cut path's, PathCut::to_rest)
  // instead of the current one.
  bool cut(const BladePose& from, const BladePose& to, StepStats& s,
           const DeformedToRest* frozen = nullptr) {
    const double length = scene.scalpel.blade_length;
    constexpr int kSamples = 9;  // edge points carried; kept only where the map bends
    const bool continues = last_cut_pose && last_cut_pose->position == from.position &&
                           last_cut_pose->orientation.coeffs() == from.orientation.coeffs() &&
                           last_rest_edge.size() == static_cast<size_t>(kSamples);
    // A new stroke: the last one's end is conformed first if no step has done it yet.
    const bool finished = !continues && stroke_to_finish && finish_cut_stroke(s);
    auto t0 = Clock::now();
    const BladeEdge a = blade_edge(from, length), b = blade_edge(to, length);
    std::shared_ptr<DeformedToRest> built;
    if (!frozen) {
      // Every point mapped below lies on the two edges or between them: their box, padded
      // (the locator's own tolerance is barycentric), is all the map needs to cover.
      const Vec3 lo = a.tip.cwiseMin(a.heel).cwiseMin(b.tip).cwiseMin(b.heel);
      const Vec3 hi = a.tip.cwiseMax(a.heel).cwiseMax(b.tip).cwiseMax(b.heel);
      const double pad = 0.01 * (hi - lo).norm() + 1e-6;
      built = current_to_rest(lo.array() - pad, hi.array() + pad);
    }
    const DeformedToRest& to_rest = frozen ? *frozen : *built;
    std::vector<double> params(kSamples);
    for (int i = 0; i < kSamples; ++i) params[i] = static_cast<double>(i) / (kSamples - 1);
    std::optional<std::vector<Vec3>> rest_from =
        continues ? std::optional<std::vector<Vec3>>(last_rest_edge)
                  : to_rest.map_edge(a.tip, a.heel, params);
    std::optional<std::vector<Vec3>> rest_to = to_rest.map_edge(b.tip, b.heel, params);
    // An edge wholly outside the tissue moves with the other edge's deformation.
    auto shifted = [&](const std::vector<Vec3>& rest, const BladeEdge& e, const BladeEdge& other) {
      std::vector<Vec3> out(rest.size());
      for (size_t i = 0; i < rest.size(); ++i)
        out[i] = rest[i] + (e.tip - other.tip) +
                 params[i] * ((e.heel - e.tip) - (other.heel - other.tip));
      return out;
    };
    if (!rest_from && rest_to) rest_from = shifted(*rest_to, a, b);
    if (rest_from && !rest_to) rest_to = shifted(*rest_from, b, a);
    if (!rest_from && !rest_to) {
      // Both ends outside (a sweep across the tissue, e.g. the ~cut service): carry both by
      // the deformation where the edge is in the tissue on the way between them.
      constexpr int kBetween = 16;
      for (int k = 1; k < kBetween && !rest_to; ++k) {
        const double f = static_cast<double>(k) / kBetween;
        BladeEdge mid;
        mid.tip = (1 - f) * a.tip + f * b.tip;
        mid.heel = (1 - f) * a.heel + f * b.heel;
        if (const auto rest_mid = to_rest.map_edge(mid.tip, mid.heel, params)) {
          rest_from = shifted(*rest_mid, a, mid);
          rest_to = shifted(*rest_mid, b, mid);
        }
      }
    }
    last_cut_pose = to;
    last_rest_edge = rest_to ? *rest_to : std::vector<Vec3>{};
    if (!rest_from || !rest_to) {  // the edge never meets the operation part
      s.cutting_ms += ms_since(t0);
      return finished;
    }
    const std::vector<int> keep = simplify_polylines(*rest_from, *rest_to, 0.25e-3);
    std::vector<Vec3> band_from, band_to;
    for (int k : keep) band_from.push_back((*rest_from)[k]), band_to.push_back((*rest_to)[k]);
    const CutResult r =
        cut_band(model->mesh_for_cutting(), cut_state, band_from, band_to, cut_options());
    s.cutting_ms += ms_since(t0);
    return adopt_cut(r, s) || finished;
  }

  // The cutter's options with the scene's shape guard (docs/SCENE.md, scalpel.shape_guard_deg):
  // the scene is its one place, whether it came from a file, was built in code or was tuned
  // live (set_shape_guard_deg), and reset() restores it with the rest of the scene.
  CutOptions cut_options() const {
    CutOptions cut = options.cut;
    cut.split_min_dihedral_deg = scene.scalpel.shape_guard_deg;
    return cut;
  }

  // The stroke ended (the blade left the tissue or its incision, was removed, a new stroke
  // began, or a ~cut path ended): the cut is conformed to where the blade stopped
  // (cut_sweep.hpp).
  bool finish_cut_stroke(StepStats& s) {
    stroke_to_finish = false;
    const auto t0 = Clock::now();
    const CutResult r = finish_stroke(model->mesh_for_cutting(), cut_state, cut_options());
    s.cutting_ms += ms_since(t0);
    const bool cut = adopt_cut(r, s);
    s.stroke_finished |= cut;
    return cut;
  }

  // The model after a cut changed the mesh; returns whether the cut did (CutResult::cut_anything).
  bool adopt_cut(const CutResult& r, StepStats& s) {
    s.reached_interface |= r.reached_interface;
    if (r.changed_tets.empty() && r.new_nodes.empty()) return false;
    const auto t0 = Clock::now();
    ++mesh_version;
    model->update_operation_part(r.changed_tets, r.new_nodes);
    boundary.update(model->mesh(), r.changed_tets);
    if (follower) mesh_faces.update(model->mesh(), r.changed_tets);
    // A copy of a held node stays held (both halves of a cut held piece stay put).
    for (const NewNode& n : r.new_nodes)
      if (n.kind == NewNode::Kind::kDuplicate)
        if (const auto it = held.find(n.a); it != held.end()) held[n.index] = it->second;
    recompute_anchors();
    const int held_before = free_pieces_held;
    hold_free_pieces();
    if (free_pieces_held > held_before) {
      // The held DOFs' rows of the factored matrix change (solve/cpu_cg_solver.cpp, D): the
      // frame takes them when they lie in it; a refactorization frames this cut's nodes,
      // where the next cut is.
      std::vector<int> nodes;
      for (int t : r.changed_tets)
        for (int v : model->mesh().tets[static_cast<size_t>(t)]) nodes.push_back(v);
      std::sort(nodes.begin(), nodes.end());
      nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
      model->expect_cut_near(std::move(nodes));
    }
    pass_held_nodes_to_model();
    cut_since_solve = true;
    rebuild_surface_tree();
    s.assembly_ms += ms_since(t0);
    nodes_smoothed += r.nodes_smoothed;
    flips += r.flips;
    // Only nodes moved (the last stroke's smoothing at a new stroke's first band, or a node
    // taken onto a cut that opened nothing there): the mesh changed, but nothing was cut.
    if (!r.cut_anything()) return false;
    s.tets_split += r.tets_split;
    s.nodes_added += r.nodes_added;
    s.cutting = true;
    tets_split += r.tets_split;
    ++cuts;  // cut insertions: a step that finishes one stroke and begins the next makes two
    return true;
  }

  // Anchored = what really holds a node: fixed, on the interface, or held. Recomputed, not
  // inherited by copies: a copy of an interface node is not attached to the condensed part,
  // and a node marked anchored without an imposed displacement would count towards the three
  // anchors of a piece that in fact floats (a singular system; CG stalls). `follow`: fixed or
  // held only, never interface: a piece whose only support is this partition's interface
  // floats once the region moves; a held piece's condensed nodes follow its held ones.
  void recompute_anchors() {
    anchored = model->fixed_nodes();
    if (!follower)
      for (int i : model->partition().interface) anchored[static_cast<size_t>(i)] = 1;
    for (const auto& [n, u] : held) anchored[static_cast<size_t>(n)] = 1;
    for (int n : held_piece_nodes) anchored[static_cast<size_t>(n)] = 1;
  }

  // The held nodes leave the solver's factor (a piece held by a hinge would make it singular;
  // cpu_cg_solver.cpp).
  void pass_held_nodes_to_model() {
    std::vector<int> nodes;
    nodes.reserve(held.size());
    for (const auto& [n, u] : held) nodes.push_back(n);
    model->set_held_nodes(nodes);
  }

  // The operation surface of the current mesh and partition, at the current displacement.
  // The part-2 triangles come first and stay the same from one extraction of `boundary` to the
  // next (a cut changes part 1 alone): after a cut the tree takes the operation part's anew.
  void rebuild_surface_tree() {
    const Partition& p = model->partition();
    if (surface_tree_extraction != 0 && surface_tree_extraction == boundary.extraction())
      surface_tree.rebuild_after(boundary.condensed_count(), boundary.operation_part(model->mesh()),
                                 model->mesh(), p.operation_tet, displacements());
    else
      surface_tree.build(boundary.current(model->mesh()), model->mesh(), p.operation_tet,
                         displacements());
    surface_tree_extraction = boundary.extraction();
  }

  // docs/SCENE.md "Cut invariants": a piece severed from everything anchored is kept and held where
  // it is.
  void hold_free_pieces() {
    // A fixed region: part 1's pieces, from the faces the cuts kept matched (operation_surface).
    const std::vector<MeshPiece> pieces =
        free_pieces(follower ? pieces_a_cut_may_free() : boundary.part1_pieces(model->mesh()),
                    model->mesh(), anchored);
    for (const MeshPiece& piece : pieces) hold_piece(piece);
    log_pieces_held(pieces);
  }

  // `follow`: the pieces the cut may have freed, sought from where it changed the mesh
  // (TetFaceAdjacency::pieces_cut_off, each walk at most 1/32 of the mesh, 2048 tets at
  // least: the organ liver's walks all met within it, 0.16 ms a cut); the whole
  // mesh's pieces where that cannot decide: two walks ran out without meeting (a cut through
  // the organ), or a piece cut off takes an anchored node (the rest may lose its support).
  std::vector<MeshPiece> pieces_a_cut_may_free() {
    const TetMesh& mesh = model->mesh();
    const size_t budget = std::max<size_t>(2048, mesh.tets.size() / 32);
    if (auto cut_off = mesh_faces.pieces_cut_off(mesh, budget)) {
      const bool takes_anchor =
          std::any_of(cut_off->begin(), cut_off->end(), [&](const MeshPiece& p) {
            return std::any_of(p.nodes.begin(), p.nodes.end(),
                               [&](int v) { return anchored[static_cast<size_t>(v)] != 0; });
          });
      if (!takes_anchor) return std::move(*cut_off);
    }
    return mesh_faces.pieces(mesh);
  }

  // Where pieces can come free. A fixed region: only part 1 (every piece of part 2 reaches a
  // fixed or an interface node - its condensation is nonsingular - and those are anchored).
  // `follow`: a piece may reach into the condensed part (cut there before a move), so the whole
  // mesh.
  TetMesh piece_search_mesh() const {
    return follower ? model->mesh() : tet_subset(model->mesh(), model->partition().operation_tets);
  }

  // Holds every node of `piece` where it is. `follow`: its O and I nodes are held now; its
  // condensed nodes follow them through the condensation, and every later move keeps the whole
  // piece in part 1, where its nodes are held too (adopt_moved_region).
  void hold_piece(const MeshPiece& piece) {
    const Vector& u = model->operation_displacement();
    for (int n : piece.nodes) {
      if (!follower || operation_or_interface(*model, n)) held[n] = u.segment<3>(3 * n);
      anchored[static_cast<size_t>(n)] = 1;
      if (follower) held_piece_nodes.push_back(n);
    }
    ++free_pieces_held;
  }

  // docs/SCENE.md "Cut invariants": the system stays positive definite on its free DOFs. The
  // anchor rule above decides by topology; should the factor of the system still meet a pivot
  // that is not positive, the smallest face-connected piece through the DOF where it failed
  // is held as well (a piece the rule took for anchored), and the log says what it was, so a
  // case the rule misses costs a warning, not a solver that stops converging (a 30-minute
  // soak once lost a minute that way). Never the bulk of the operation part: that is an error
  // no hold can repair, logged as such.
  void hold_what_the_factor_finds_singular() {
    constexpr int kMaxRepairs = 4;
    for (int repair = 0; repair < kMaxRepairs; ++repair) {
      const int dof = model->solver().singular_dof();
      if (dof < 0) return;
      const int node = model->hybrid_dofs().global_of[static_cast<size_t>(dof)] / 3;
      const TetMesh searched = piece_search_mesh();
      const std::vector<MeshPiece> pieces = face_connected_pieces(searched);
      const MeshPiece* piece = smallest_piece_with_node(pieces, node);
      int anchors = 0;
      if (piece)
        for (int n : piece->nodes) anchors += anchored[static_cast<size_t>(n)] != 0;
      const std::string what =
          "after a cut the system was not positive definite at node " + std::to_string(node);
      if (!piece || 2 * piece->tets.size() > searched.tets.size()) {
        if (options.log)
          options.log(LogLevel::kError,
                      what + ", which no small piece holds (" +
                          (piece ? std::to_string(piece->tets.size()) + " tets, " +
                                       std::to_string(anchors) + " anchored nodes"
                                 : std::string("in no operation tet")) +
                          "); the solve will not converge until a reset");
        return;
      }
      hold_piece(*piece);
      if (options.log)
        options.log(LogLevel::kWarn, what + ": the piece of " + std::to_string(piece->tets.size()) +
                                         " tets around it (" + std::to_string(anchors) +
                                         " anchored nodes) is held in place");
      pass_held_nodes_to_model();
    }
  }

  // One line per cut, however many pieces it frees (a cut through slivers frees dozens).
  void log_pieces_held(const std::vector<MeshPiece>& pieces) const {
    if (pieces.empty() || !options.log) return;
    size_t tets = 0;
    for (const MeshPiece& piece : pieces) tets += piece.tets.size();
    options.log(
        LogLevel::kInfo,
        pieces.size() == 1
            ? "a piece of " + std::to_string(tets) + " tets was cut free; it is held in place"
            : std::to_string(pieces.size()) + " pieces (" + std::to_string(tets) +
                  " tets in all) were cut free; they are held in place");
  }

  // ---- `follow`: the operation region moves with the blade (region_follower.hpp)

  // Nodes that must stay O or I in a moved region: those the blade or a holder imposes.
  std::vector<int> imposed_nodes() const {
    std::vector<int> keep = held_piece_nodes;
    for (const auto& h : held) keep.push_back(h.first);
    for (const EdgeHeldNode& e : contact.edge_nodes()) keep.push_back(e.node);
    if (contact.tip_anchor())
      for (int n : contact.tip_anchor()->nodes) keep.push_back(n);
    return keep;
  }

  // cut_points: where the next cut is expected (the waiting sweep, or the blade): the new
  // model's first factorization frames them, so that cut refactors a frame only.
  void start_move(const Vec3& centre, std::string why, std::vector<Vec3> cut_points) {
    std::vector<int> piece_nodes = held_piece_nodes;  // and copies a cut made of held nodes
    for (const auto& h : held) piece_nodes.push_back(h.first);
    follower->start(*model, centre, imposed_nodes(), std::move(piece_nodes), std::move(why),
                    std::move(cut_points));
  }

  bool operation_or_interface(const HybridModel& m, int n) const {
    const NodeSet set = m.partition().node_set[static_cast<size_t>(n)];
    return set == NodeSet::kOperation || set == NodeSet::kInterface;
  }

  // At a step boundary: the moved region's model replaces the old one once the worker has
  // built it (offline, wait_for_region_moves: at the first step after the request, waiting
  // for it). The swap changes no displacement (region_follower.hpp).
  void adopt_moved_region(StepStats& s, bool wait) {
    if (!follower || !follower->moving()) return;
    if (!wait && !(follower->ready() && recovering.valid())) {
      s.region_moving = true;
      return;
    }
    const Vector state = state_for_moved_region();
    std::string failure;
    std::optional<MovedRegion> moved = follower->take(&failure);
    if (!moved) {
      if (options.log)
        options.log(LogLevel::kWarn, "the operation region could not move: " + failure);
      return;
    }
    HybridModel& next = *moved->model;
    for (const auto& h : held)  // a held node must stay imposable (the worker kept them)
      if (!operation_or_interface(next, h.first)) {
        follower->dropped();
        return;
      }
    next.set_displacement(state);
    next.set_cg_settings(model->cg_settings());
    if (backend == "gl") next.set_solver(make_solver());
    std::unique_ptr<HybridModel> replaced = std::move(model);
    model = std::move(moved->model);
    // The old partition's cut view, surface and condensed grid end up in `moved` (swapped),
    // freed with the old model off the loop (below).
    apply_partition_to_cut_state(*moved, cut_state);
    std::swap(boundary, moved->boundary);
    follower->adopted(*moved);
    scene.operation_region.sphere = follower->ball();
    // Nodes the blade took since the request that the new region condenses: let go (it
    // takes them again next step if it still presses there).
    bool release = false;
    for (const EdgeHeldNode& e : contact.edge_nodes())
      release = release || !operation_or_interface(*model, e.node);
    if (contact.tip_anchor())
      for (int n : contact.tip_anchor()->nodes)
        release = release || !operation_or_interface(*model, n);
    if (release) {
      contact.release();
      blade_imposed.clear();
    }
    // Nodes of held pieces that were condensed are part 1 now: held where they are (the
    // worker built the model holding them). A piece it found free that no cut reported (none
    // expected) is held from now on too.
    for (int tets : moved->found_pieces) {
      ++free_pieces_held;
      if (options.log)
        options.log(LogLevel::kWarn, "a piece of " + std::to_string(tets) +
                                         " tets was found free at a region move; it is held "
                                         "in place");
    }
    held_piece_nodes = std::move(moved->held_nodes);
    const Vector& u = model->operation_displacement();
    for (int n : held_piece_nodes)
      if (!held.count(n) && operation_or_interface(*model, n)) held[n] = u.segment<3>(3 * n);
    pass_held_nodes_to_model();  // the worker's set: no refactorization
    recompute_anchors();
    // The worker built the new partition's collision tree (on the rest shape; ~4.5 ms of a swap
    // step at organ scale when built here): taken as it is - every reader of the tree refits it
    // to the deformation first - and the old tree freed with the old model off the loop.
    std::swap(surface_tree, moved->surface_tree);
    surface_tree_extraction = boundary.extraction();
    retire(std::move(replaced), std::move(*moved));
    s.region_moved = true;
  }

  // Online, the old model's S and Q for a swap are recovered on another thread (one solve with
  // its K2_NN factor: ~20 ms at organ scale), from a snapshot of the state a step ends in,
  // started then once the move's worker has finished; the swap, at the next step's start, takes
  // them (state_for_moved_region).
  void recover_for_swap() {
    if (!follower || options.wait_for_region_moves || recovering.valid() || !follower->ready())
      return;
    recovering = std::async(std::launch::async, [snapshot = model->displacement_snapshot()]() {
      DisplacementSnapshot recovered = snapshot;
      recovered.recover();
      return recovered;
    });
  }

  // The whole state, every node current, that the moved region's model starts from: S and Q
  // from the recovery started at the end of the last step when u_I is still what it was then
  // (nothing solves between two steps; they depend on u_I alone), else recovered now.
  Vector state_for_moved_region() {
    if (!recovering.valid()) return model->displacement();
    const DisplacementSnapshot recovered = recovering.get();  // waits for the rest of it
    const Vector& now = model->operation_displacement();
    bool same = recovered.u.size() == now.size();
    for (int n : model->partition().interface)
      same = same && recovered.u.segment<3>(3 * n) == now.segment<3>(3 * n);
    if (!same) return model->displacement();
    Vector u = now;
    for (const std::vector<int>* nodes :
         {&model->partition().surface, &model->partition().interior})
      for (int n : *nodes) u.segment<3>(3 * n) = recovered.u.segment<3>(3 * n);
    return u;
  }

  // The model a swap replaced is freed on another thread: its factors and dense blocks are
  // hundreds of MB at organ scale, ~6 ms of the swap step to give back. Not with the gl
  // backend: its GL objects belong to this thread's context.
  void retire(std::unique_ptr<HybridModel> replaced, MovedRegion old_view) {
    if (backend == "gl") return;  // freed here
    if (retiring.valid()) retiring.wait();
    // The old view too: freeing its grids on the loop took ~2.5 ms of an organ swap step.
    retiring = std::async(std::launch::async,
                          [m = std::move(replaced), v = std::move(old_view)]() mutable {
                            m.reset();
                            v = MovedRegion{};
                          });
  }

  // Cuts the waiting sweeps in order while each fits the region; a sweep that would come
  // within one element layer of the interface asks for a move around it and waits (the cut
  // waits at the interface). A sweep no ball of radius R around it can hold is cut as far as
  // the region reaches, like a fixed region's. Online, cutting stops for this step before a
  // run that would take it past SimulationOptions::waiting_cut_budget_ms, each run expected
  // to cost what this step's runs have cost on average (at least one sweep is cut).
  void drain_sweeps(StepStats& s, bool wait) {
    if (!wait && s.region_moved) return;  // online: from the step after the swap (above)
    const double length = scene.scalpel.blade_length;
    const auto t0 = Clock::now();
    int runs_cut = 0;
    while (!pending_sweeps.empty()) {
      if (!wait && runs_cut > 0 &&
          ms_since(t0) * (runs_cut + 1) / runs_cut > options.waiting_cut_budget_ms)
        return;  // the rest from the next step on
      if (follower->moving()) {
        s.reached_interface = true;  // the cut waits at the interface for the move
        return;
      }
      Sweep& sw = pending_sweeps.front();
      const BladeEdge a = blade_edge(sw.from, length), b = blade_edge(sw.to, length);
      const bool fits = follower->sweep_fits(*model, cut_state, a, b);
      if (sw.moves_tried < 2 && !fits) {
        const Vec3 centre = follower->centre_for(*model, cut_state, follower->sweep_points(a, b),
                                                 sw.to.position - sw.from.position);
        if (follower->worth_moving_to(centre)) {
          ++sw.moves_tried;
          start_move(centre, "the cut came within one element layer of the interface",
                     follower->sweep_points(a, b));
          if (wait) {  // offline: the sweep waits for nothing
            adopt_moved_region(s, true);
            continue;
          }
          s.reached_interface = true;
          return;
        }
      }
      const size_t steps = fits ? straight_waiting_steps() : 1;
      cut(sw.from, pending_sweeps[steps - 1].to, s);
      ++runs_cut;
      pending_sweeps.erase(pending_sweeps.begin(),
                           pending_sweeps.begin() + static_cast<long>(steps));
    }
  }

  // How many waiting sweeps, from the first (which the region holds), one cut takes: those that
  // follow on from each other, that the region holds, and that the blade drew straight (within
  // the 0.25 mm to which the cut's rest polylines are simplified anyway) over at most one
  // median edge. After a move the queue holds every sweep since the request (hundreds at
  // organ scale, 0.2 mm apart), and each cut costs a model update: one cut per straight
  // stretch keeps the swap step short (docs/DESIGN.md section 10a, "Swap").
  size_t straight_waiting_steps() {
    const double length = scene.scalpel.blade_length;
    std::vector<BladePose> run = {pending_sweeps.front().from, pending_sweeps.front().to};
    double travel = blade_travel(run[0], run[1], length);
    for (size_t k = 1; k < pending_sweeps.size() && travel <= median_edge; ++k) {
      const Sweep& next = pending_sweeps[k];
      const BladePose& end = run.back();
      if (next.from.position != end.position ||
          next.from.orientation.coeffs() != end.orientation.coeffs())
        break;  // another stroke
      if (!follower->sweep_fits(*model, cut_state, blade_edge(next.from, length),
                                blade_edge(next.to, length)))
        break;
      travel += blade_travel(next.from, next.to, length);
      run.push_back(next.to);
    }
    return std::max<size_t>(1, straight_sweep_steps(run, length, 0.25e-3, median_edge));
  }

  // A blade near tissue the region does not hold clear of its interface: a move around it.
  void maybe_move_region(const std::optional<BladePose>& blade) {
    if (!blade || follower->moving() || !pending_sweeps.empty()) return;
    const BladeEdge edge = blade_edge(*blade, scene.scalpel.blade_length);
    std::string why = follower->edge_clearance(*model, cut_state, edge);
    if (why.empty()) return;
    // Ahead along the blade's motion while it cuts (its last move: a blade held still for a
    // step must not pull the ball back behind the cut's next sweep); around it while it
    // presses.
    Vec3 motion = Vec3::Zero();
    if (blade_state == BladeState::kCutting)
      for (auto p = stroke.rbegin(); p != stroke.rend() && motion.isZero(0); ++p)
        motion = blade->position - p->position;
    const std::vector<Vec3> points = follower->edge_points(edge);
    const Vec3 centre = follower->centre_for(*model, cut_state, points, motion);
    if (follower->worth_moving_to(centre)) start_move(centre, std::move(why), points);
  }

  // `follow`, ~cut paths: the region moves (waiting for it) to hold each sweep before it is
  // cut, so a path longer than the region cuts end to end.
  // The blade's own waiting sweeps stay waiting (the steps cut them): settling them here, with
  // every move they ask for awaited, held the loop for minutes when a ~cut came while a
  // random-walking blade had queued thousands (the follow soak).
  void move_region_for_path_sweep(const BladePose& from, const BladePose& to) {
    finish_region_move();
    const double length = scene.scalpel.blade_length;
    const BladeEdge a = blade_edge(from, length), b = blade_edge(to, length);
    if (follower->sweep_fits(*model, cut_state, a, b)) return;
    const Vec3 centre = follower->centre_for(*model, cut_state, follower->sweep_points(a, b),
                                             to.position - from.position);
    if (!follower->worth_moving_to(centre)) return;
    start_move(centre, "a ~cut path left the region", follower->sweep_points(a, b));
    finish_region_move();
  }

  // Waits for a running move and swaps it in; waiting sweeps stay waiting.
  void finish_region_move() {
    if (!follower || !follower->moving()) return;
    StepStats s;
    adopt_moved_region(s, true);
    ++surface_version;
  }

  // Waits for a running move, swaps it in and cuts every waiting sweep (moving the region
  // again as they need, waiting each time): offline callers, and before the mesh or E changes.
  void settle_region_move() {
    finish_region_move();
    if (!follower || pending_sweeps.empty()) return;
    StepStats s;
    drain_sweeps(s, true);  // may move the region again, waiting each time
    ++surface_version;
  }

  // O and I current, S as last recovered: the tree's operation triangles (the only ones
  // contact looks at) are exact, and a step does not wait for the recovery of u_S.
  std::vector<Vec3> displacements() const { return per_node(model->operation_displacement()); }

  int cut_face_count() const {
    int n = 0;
    for (const auto& t : surface_tree.surface().triangles) n += t.cut;
    return n;
  }

  // Is the edge in the DEFORMED tissue, where the blade is (issue 9)? The whole closed surface
  // answers, so with a `follow` region the condensed part is tissue too (the blade may wait
  // there for a move).
  bool edge_inside_tissue(const BladeEdge& edge) {
    surface_tree.refit(model->mesh(), model->operation_displacement());
    return edge_in_tissue(edge, 0.05 * scene.scalpel.blade_length,
                          [&](const Vec3& p) { return surface_tree.contains(p); });
  }

  // The cutting state's step (docs/DESIGN.md section 7): the tissue has yielded, and the edge
  // opens it wherever it is in the tissue (the belly too, the tip may be outside). Lifted out,
  // or sliding through its own incision (this step's sweep lies in what the stroke has swept
  // already), it is free again; a fresh press starts a new cut.
  void advance_stroke(const BladePose& blade, const BladeEdge& edge, StepStats& s) {
    const double length = scene.scalpel.blade_length;
    std::vector<BladeEdge> swept;
    for (const BladePose& p : stroke) swept.push_back(blade_edge(p, length));
    const bool retracing = last_pose && swept_before_fraction(swept, blade_edge(*last_pose, length),
                                                              edge, 1e-4, 0.9) >= 0.9;
    if (last_pose && !retracing) {
      if (!follower)
        cut(*last_pose, blade, s);
      else
        pending_sweeps.push_back({*last_pose, blade});
      stroke_to_finish = true;
    }
    stroke.push_back(blade);
    if (retracing || !edge_inside_tissue(edge)) {
      blade_state = BladeState::kFree;
      stroke.clear();
    }
  }

  StepStats step(const std::optional<BladePose>& blade) {
    const auto t_step = Clock::now();
    StepStats s;
    s.step = ++steps;
    adopt_moved_region(s, options.wait_for_region_moves);
    ImposedDisplacements imposed;
    const double length = scene.scalpel.blade_length;
    if (!blade) {
      blade_state = BladeState::kFree;
      contact.release();
    } else {
      const BladeEdge edge = blade_edge(*blade, length);
      auto t0 = Clock::now();
      // A blade held still (the last step's pose, bit for bit) imposes what it imposed and
      // changes no state: a step repeated at one pose is a no-op (docs/DESIGN.md section 7), so
      // a replay ends in the same mesh however many steps each pose was held for. (A still
      // blade used to cut again where the relaxing tissue carried its rest image, to count as
      // retracing right after the yield, and to catch the skin it had just been lifted out of.
      // `follow`: it would also pull the ball back between two moving sweeps.)
      const bool still = last_pose && last_pose->position == blade->position &&
                         last_pose->orientation.coeffs() == blade->orientation.coeffs();
      if (still) {
        imposed = blade_imposed;
      } else if (blade_state == BladeState::kCutting) {
        contact.release();  // held since the yield (blade_imposed)
        advance_stroke(*blade, edge, s);
      } else {
        surface_tree.refit(model->mesh(), model->operation_displacement());
        std::optional<BladeEdge> previous;
        if (last_pose) previous = blade_edge(*last_pose, length);
        imposed = contact.update(surface_tree, model->mesh(), model->operation_displacement(),
                                 previous, edge);
        blade_state = contact.empty() ? BladeState::kFree : BladeState::kPressing;
      }
      s.collision_ms = ms_since(t0) - s.cutting_ms - s.assembly_ms;
    }
    if (follower) {
      const auto t0 = Clock::now();
      const double cut_ms = s.cutting_ms + s.assembly_ms;
      drain_sweeps(s, options.wait_for_region_moves);
      maybe_move_region(blade);
      s.region_moving = follower->moving();
      s.sweeps_waiting = static_cast<int>(pending_sweeps.size());
      for (const Sweep& sw : pending_sweeps)
        s.cut_lag += (sw.to.position - sw.from.position).norm();
      s.collision_ms += ms_since(t0) - (s.cutting_ms + s.assembly_ms - cut_ms);
    }
    // A stroke that ended (the blade left the tissue or its incision, or was removed) opens
    // up to where the blade stopped: after its queued sweeps, and never while a region move is
    // under way (the worker's copy of the mesh is swapped in with only the queued sweeps
    // replayed; the stroke is finished after the swap). A step that cut already leaves it to
    // the next (one model update per step: the slowest organ step was a cut and a finish,
    // 30 ms); a new stroke finishes it first (cut()). Not on a pause: how many steps a blade
    // is held still depends on timing (a bag replayed through the node), and the cut must not.
    if (stroke_to_finish && !s.cutting && blade_state != BladeState::kCutting &&
        (!follower || (pending_sweeps.empty() && !follower->moving())))
      finish_cut_stroke(s);
    s.converged = solve(imposed, s);
    if (!imposed.empty()) {
      s.in_contact = true;
      // The tissue pushes back on the blade with minus the force that holds each node; the
      // torque is about the tip (docs/DESIGN.md (contact)).
      std::vector<Vec3> force;
      for (const auto& [node, u] : imposed) {
        s.contact_nodes.push_back(node);
        s.contact_points.push_back(model->mesh().nodes[node] + u);
        force.push_back(model->reaction_force({node}));
      }
      const BladeWrench w = blade_wrench(blade->position, s.contact_points, force);
      s.contact_force = w.force;
      s.contact_torque = w.torque;
      if (cutting_enabled && s.contact_force.norm() > scene.scalpel.cut_pressure) {
        blade_state = BladeState::kCutting;  // the tissue yields: the next motion cuts
        stroke = {*blade};                   // `contact` lets go at its first motion
      }
    }
    last_pose = blade;
    blade_imposed = std::move(imposed);  // not read below
    if (s.cg_iterations > 0 || s.cutting || s.region_moved)
      ++surface_version;  // the drawn surface changed
    recover_for_swap();
    s.step_ms = ms_since(t_step);
    last = s;
    return s;
  }
};

Simulation::Simulation(Scene scene, SimulationOptions options) : impl_(new Impl) {
  impl_->initial = std::move(scene);
  impl_->options = std::move(options);
  impl_->start();
  // Correct either way (solve/blas_guard.hpp), but slower when moves or the display thread
  // factor beside the loop: say so once.
  if (blas_info().serialized && impl_->options.log)
    impl_->options.log(LogLevel::kInfo,
                       "the BLAS is OpenBLAS's single-threaded build, which is not thread-safe: "
                       "CHOLMOD's calls into it are serialized (install libopenblas0-pthread, "
                       "./tissue setup, to let them run side by side)");
}

Simulation::~Simulation() = default;

StepStats Simulation::step(const std::optional<BladePose>& blade) {
  if (blade && !pose_problem(*blade).empty())
    throw std::invalid_argument("blade pose is not finite (NaN/Inf or a zero quaternion)");
  std::optional<BladePose> normalized = blade;
  if (normalized) normalized->orientation.normalize();
  const StepStats s = impl_->step(normalized);
  impl_->step_times.add(s);
  return s;
}

const StepTimes& Simulation::step_times() const { return impl_->step_times; }

CutOutcome Simulation::cut_along(const std::vector<BladePose>& poses) {
  PathCut path = begin_path_cut(poses);
  while (!path.done()) cut_path_slice(path, Clock::time_point::max());
  CutOutcome out = finish_path_cut(path);
  if (!path.refusal.empty()) return out;
  StepStats s;
  if (!impl_->solve({}, s)) out.message += "; warning: the solver did not converge";
  ++impl_->surface_version;
  return out;
}

PathCut Simulation::begin_path_cut(const std::vector<BladePose>& poses) const {
  PathCut cut;
  if (poses.size() < 2) {
    cut.refusal = "need at least two blade poses to sweep a cut";
    return cut;
  }
  for (size_t i = 0; i < poses.size(); ++i)
    if (!pose_problem(poses[i]).empty()) {
      cut.refusal = "pose " + std::to_string(i) + " is not finite (NaN/Inf) or a zero quaternion";
      return cut;
    }
  cut.poses = resample_blade_path(poses, impl_->scene.scalpel.blade_length, cut_path_spacing());
  cut.faces_before = impl_->cut_face_count();
  return cut;
}

void Simulation::cut_path_slice(PathCut& cut, Clock::time_point deadline) {
  const double length = impl_->scene.scalpel.blade_length;
  bool changed = false;
  do {
    if (cut.done()) break;
    const BladePose& from = cut.poses[cut.next - 1];
    const BladePose& to = cut.poses[cut.next];
    if (!cut.to_rest) cut.to_rest = impl_->path_to_rest();
    // Does the blade edge lie in the (deformed) operation part here? (Tells "already cut" from
    // "missed".)
    if (!cut.crossed) {
      const BladeEdge e = blade_edge(from, length);
      for (const Vec3& x : {e.tip, Vec3(0.5 * (e.tip + e.heel)), e.heel})
        cut.crossed = cut.crossed || cut.to_rest->map(x).has_value();
    }
    StepStats s;
    if (impl_->follower) impl_->move_region_for_path_sweep(from, to);
    changed |= impl_->cut(from, to, s, cut.to_rest.get());
    if (cut.next + 1 == cut.poses.size()) changed |= impl_->finish_cut_stroke(s);  // its end
    cut.tets_split += s.tets_split;
    cut.nodes_added += s.nodes_added;
    cut.reached_interface |= s.reached_interface;
    ++cut.next;
  } while (Clock::now() < deadline);
  if (changed) {
    cut.changed = true;
    ++impl_->surface_version;
  }
}

CutOutcome Simulation::finish_path_cut(const PathCut& cut) const {
  CutOutcome out;
  if (!cut.refusal.empty()) {
    out.message = cut.refusal;
    return out;
  }
  out.tets_split = cut.tets_split;
  out.nodes_added = cut.nodes_added;
  out.cut_faces = impl_->cut_face_count() - cut.faces_before;
  out.success = cut.changed;
  if (cut.changed)
    out.message = "cut inserted";
  else if (cut.crossed)
    out.message =
        "the blade path runs through the operation part only where it is already cut: "
        "no new cut faces";
  else if (cut.reached_interface)
    out.message =
        "the blade path only reaches the interface of the condensed part, which is not "
        "cut";
  else
    out.message = "the blade path does not cross the operation part";
  if (cut.changed && cut.reached_interface)
    out.message += "; stopped at the interface of the condensed part";
  return out;
}

void Simulation::reset() { impl_->start(); }
double Simulation::cut_path_spacing() const { return kPathSpacingFraction * impl_->median_edge; }
void Simulation::set_cutting_enabled(bool enabled) { impl_->cutting_enabled = enabled; }
bool Simulation::cutting_enabled() const { return impl_->cutting_enabled; }
void Simulation::set_cut_pressure(double newtons) { impl_->scene.scalpel.cut_pressure = newtons; }
void Simulation::set_shape_guard_deg(double degrees) {
  // The range the scene loader accepts (scalpel.shape_guard_deg, docs/SCENE.md).
  if (!(degrees >= 0 && degrees <= kMaxShapeGuardDeg))
    throw std::invalid_argument("shape_guard_deg must be in [0, 30] degrees");
  impl_->scene.scalpel.shape_guard_deg = degrees;  // cut_options() reads it
}
void Simulation::set_young_modulus(double pascal) {
  if (!(pascal > 0)) throw std::invalid_argument("young_modulus must be > 0");
  impl_->settle_region_move();  // the worker reads the element matrices
  impl_->scene.material.young_modulus = pascal;
  impl_->model->set_young_modulus(pascal);
}
const Scene& Simulation::scene() const { return impl_->scene; }
const TetMesh& Simulation::mesh() const { return impl_->model->mesh(); }

DeformedSurface Simulation::surface() const {
  SurfaceSnapshot s = surface_snapshot();
  DeformedSurface d = s.compute();
  impl_->model->adopt_recovery(s.displacement);
  return d;
}

SurfaceSnapshot Simulation::surface_snapshot() const {
  SurfaceSnapshot s;
  s.version = impl_->surface_version;
  s.rest = impl_->model->mesh().nodes;
  s.displacement = impl_->model->displacement_snapshot();
  s.triangles = impl_->surface_tree.surface().triangles;
  return s;
}

void Simulation::adopt_recovery(const SurfaceSnapshot& computed) {
  impl_->model->adopt_recovery(computed.displacement);
}

std::uint64_t Simulation::surface_version() const { return impl_->surface_version; }
std::uint64_t Simulation::mesh_version() const { return impl_->mesh_version; }

ModelCounts Simulation::counts() const {
  ModelCounts c;
  static_cast<HybridModelCounts&>(c) = impl_->model->counts();
  c.cuts = impl_->cuts;
  c.tets_split = impl_->tets_split;
  c.free_pieces_held = impl_->free_pieces_held;
  c.nodes_smoothed = impl_->nodes_smoothed;
  c.flips = impl_->flips;
  c.cg_iterations_total = impl_->cg_iterations_total;
  c.solver_fallbacks = impl_->solver_fallbacks;
  c.volume_initial = total_volume(impl_->initial.mesh);
  c.volume_final = total_volume(impl_->model->mesh());
  return c;
}

const StepStats& Simulation::last_stats() const { return impl_->last; }
std::string Simulation::backend() const { return impl_->backend; }
std::string Simulation::renderer() const { return impl_->renderer; }
std::string Simulation::backend_note() const { return impl_->backend_note; }
std::string Simulation::backend_requested() const {
  return backend_name(impl_->requested_backend());
}
std::vector<std::uint8_t> Simulation::tet_regions() const {
  return impl_->model->partition().operation_tet;
}
std::vector<BladePose> Simulation::blade_path() const { return impl_->stroke; }

Eigen::VectorXd Simulation::full_displacement() {
  impl_->model->recover_interior();
  return impl_->model->displacement();
}

const std::map<std::string, double>& Simulation::precompute_timings_ms() const {
  return impl_->model->precompute_timings_ms();
}

const HybridModel& Simulation::model() const { return *impl_->model; }
const RegionMoveStats* Simulation::region_moves() const {
  return impl_->follower ? &impl_->follower->stats() : nullptr;
}
void Simulation::settle_region_move() { impl_->settle_region_move(); }
const std::vector<double>& Simulation::tet_size_classes() const {
  return impl_->cut_state.origin_volume;
}

std::string Simulation::mesh_hash() const { return stc::mesh_hash(impl_->model->mesh()); }

}  // namespace stc
