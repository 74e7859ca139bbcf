// The hybrid condensed model equals the full (uncondensed) model (docs/DESIGN.md section 4: "exact,
// not an approximation"), for operation regions none / all / sphere / box, with gravity, with
// imposed displacements, after a change of the operation part, and after a change of E. A cut
// updates the hybrid matrix by the difference of its tets' element matrices: after a stroke it
// equals a fresh assembly of the cut mesh, with no coupling the cut removed left behind.
#include "soft_tissue_cutting/assembly/full_model.hpp"
#include "soft_tissue_cutting/cutting/blade_path.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include <gtest/gtest.h>

#include <set>

namespace stc {
namespace {

constexpr double kTight = 1e-13;

// The full model on the hybrid model's current mesh, loads and supports, solved directly.
struct Reference {
  Vector u;  // 3n
  FullModel model;
  Vector x;  // free DOFs
};
Reference full_reference(const HybridModel& h, const ImposedDisplacements& imposed = {}) {
  Reference r;
  const ElementStiffnessCache cache(h.mesh(), h.material());
  r.model = assemble_full_model(h.mesh(), cache, h.loads(), h.fixed_nodes());
  r.x = Vector::Zero(r.model.K.rows());
  std::vector<std::uint8_t> constrained(static_cast<size_t>(r.x.size()), 0);
  for (const auto& [node, d] : imposed)
    for (int c = 0; c < 3; ++c) {
      const int row = r.model.dofs.row_of[static_cast<size_t>(3 * node + c)];
      if (row >= 0) r.x[row] = d[c], constrained[static_cast<size_t>(row)] = 1;
    }
  solve_direct(r.model.K, r.model.f, r.x, constrained);
  r.u = Vector::Zero(3 * h.mesh().num_nodes());
  scatter(r.x, r.model.dofs, r.u);
  return r;
}

// max over `nodes` of |u - u_ref| / max over all nodes of |u_ref|.
double nodal_error(const Vector& u, const Vector& ref, const std::vector<int>& nodes) {
  double scale = 0, err = 0;
  for (Eigen::Index n = 0; n < ref.size() / 3; ++n)
    scale = std::max(scale, ref.segment<3>(3 * n).norm());
  for (int n : nodes) err = std::max(err, (u.segment<3>(3 * n) - ref.segment<3>(3 * n)).norm());
  return err / scale;
}
std::vector<int> all_nodes(const TetMesh& m) {
  std::vector<int> v(static_cast<size_t>(m.num_nodes()));
  for (int i = 0; i < m.num_nodes(); ++i) v[static_cast<size_t>(i)] = i;
  return v;
}
std::vector<int> part1_nodes(const Partition& p) {
  std::vector<int> v = p.operation;
  v.insert(v.end(), p.interface.begin(), p.interface.end());
  return v;
}

Scene thigh_with(OperationRegion::Kind kind, bool gravity) {
  Scene s = make_thigh_scene();
  if (kind != OperationRegion::Kind::kSphere) s.operation_region.kind = kind;
  if (kind == OperationRegion::Kind::kBox)
    s.operation_region.box = Box{Vec3(0.02, -0.03, 0.02), Vec3(0.07, 0.03, 0.07)};
  if (gravity) s.gravity = Vec3(0, -9.81, 0);
  return s;
}

struct Case {
  OperationRegion::Kind kind;
  bool gravity;
  const char* name;
};

class HybridVsFull : public ::testing::TestWithParam<Case> {};

TEST_P(HybridVsFull, Thigh) {
  const Case c = GetParam();
  HybridModel h(thigh_with(c.kind, c.gravity));
  h.set_cg_settings(CgSettings{kTight, 20000});
  const HybridModelCounts n = h.counts();
  const Partition& p = h.partition();
  switch (c.kind) {
    case OperationRegion::Kind::kAll:
      EXPECT_EQ(n.nodes_interface + n.nodes_surface_condensed + n.nodes_interior_condensed, 0);
      break;
    case OperationRegion::Kind::kNone:
      EXPECT_EQ(n.nodes_interface + n.nodes_operation + n.dof_operation, 0);
      break;
    default:
      EXPECT_GT(n.nodes_interface, 0);
      EXPECT_GT(n.nodes_operation, 0);
      EXPECT_GT(n.nodes_surface_condensed, 0);
      EXPECT_GT(n.nodes_interior_condensed, 0);
  }
  EXPECT_EQ(n.nodes_operation + n.nodes_interface + n.nodes_surface_condensed +
                n.nodes_interior_condensed,
            n.nodes);
  const CgResult r = h.solve();
  EXPECT_TRUE(r.converged);
  const Reference ref = full_reference(h);
  // O, I and S are current after solve (S recovered from u_I through K2_NN's factor, docs/DESIGN.md
  // eq. (13)).
  std::vector<int> visible = part1_nodes(p);
  visible.insert(visible.end(), p.surface.begin(), p.surface.end());
  const double e_visible = nodal_error(h.displacement(), ref.u, visible);
  const double e_surface = nodal_error(h.displacement(), ref.u, p.surface);
  h.recover_interior();
  const double e_all = nodal_error(h.displacement(), ref.u, all_nodes(h.mesh()));
  EXPECT_LE(e_visible, 1e-9);
  EXPECT_LE(e_surface, 1e-9);
  EXPECT_LE(e_all, 1e-9);
  std::printf(
      "[ hybrid   ] thigh %-14s part2 tets=%zu O=%d I=%d S=%d Q=%d dof=%d cg=%d: O+I+S %.2e, S "
      "%.2e, all %.2e\n",
      c.name, p.condensed_tets.size(), n.nodes_operation, n.nodes_interface,
      n.nodes_surface_condensed, n.nodes_interior_condensed, n.dof_operation, r.iterations,
      e_visible, e_surface, e_all);
}

INSTANTIATE_TEST_SUITE_P(
    Regions, HybridVsFull,
    ::testing::Values(Case{OperationRegion::Kind::kSphere, false, "sphere"},
                      Case{OperationRegion::Kind::kSphere, true, "sphere+gravity"},
                      Case{OperationRegion::Kind::kBox, true, "box+gravity"},
                      Case{OperationRegion::Kind::kAll, true, "all+gravity"},
                      Case{OperationRegion::Kind::kNone, false, "none"},
                      Case{OperationRegion::Kind::kNone, true, "none+gravity"}),
    [](const auto& info) {
      std::string s = info.param.name;
      for (char& ch : s)
        if (ch == '+') ch = '_';
      return s;
    });

TEST(HybridModel, ImposedDisplacementAndReactionForce) {
  HybridModel h(thigh_with(OperationRegion::Kind::kSphere, true));
  h.set_cg_settings(CgSettings{kTight, 20000});
  h.solve();
  // Push the first loaded outer-wall node (the scalpel contact) and one interface node.
  const Scene s = make_thigh_scene();
  const int contact = s.loads[0].where.nodes[0];
  ASSERT_EQ(h.partition().node_set[contact], NodeSet::kOperation);
  const int iface = h.partition().interface.front();
  const ImposedDisplacements imposed = {{contact, Vec3(-2e-3, 1e-4, 0)}, {iface, Vec3(0, 0, 1e-4)}};
  const CgResult r = h.solve(imposed);
  EXPECT_TRUE(r.converged);
  const Reference ref = full_reference(h, imposed);
  h.recover_interior();
  EXPECT_LE(nodal_error(h.displacement(), ref.u, all_nodes(h.mesh())), 1e-9);
  EXPECT_EQ(h.displacement().segment<3>(3 * contact), imposed.at(contact));
  // Reaction K u - f of the full model on the imposed nodes.
  const Vector res = ref.model.K * ref.x - ref.model.f;
  for (int node : {contact, iface}) {
    Vec3 expect = Vec3::Zero();
    for (int c = 0; c < 3; ++c) {
      const int row = ref.model.dofs.row_of[static_cast<size_t>(3 * node + c)];
      if (row >= 0) expect[c] = res[row];
    }
    const Vec3 got = h.reaction_force({node});
    EXPECT_LE((got - expect).norm(), 1e-7 * expect.norm()) << node;
    std::printf("[ reaction ] node %d: hybrid (%.6e %.6e %.6e) full (%.6e %.6e %.6e)\n", node,
                got.x(), got.y(), got.z(), expect.x(), expect.y(), expect.z());
  }
  // Imposing on a condensed node is refused.
  EXPECT_THROW(h.solve({{h.partition().surface.front(), Vec3::Zero()}}), std::invalid_argument);
}

// Splits edge (a, b) at its midpoint: every tet containing both gets two children (b -> m
// in place, a -> m appended); conforming because all tets around the edge are split.
void split_edge(HybridModel& h, int a, int b) {
  TetMesh& m = h.mesh_for_cutting();
  const int mid = m.num_nodes();
  m.nodes.push_back(0.5 * (m.nodes[a] + m.nodes[b]));
  std::vector<int> changed;
  const int ntets = m.num_tets();
  for (int t = 0; t < ntets; ++t) {
    Tet e = m.tets[t];
    const bool has_a = std::count(e.begin(), e.end(), a) > 0,
               has_b = std::count(e.begin(), e.end(), b) > 0;
    if (!has_a || !has_b) continue;
    Tet e1 = e, e2 = e;
    for (int& v : e1)
      if (v == b) v = mid;
    for (int& v : e2)
      if (v == a) v = mid;
    m.tets[t] = e1;
    m.tets.push_back(e2);
    if (!m.cut_faces.empty()) m.cut_faces.push_back(0);
    changed.push_back(t);
    changed.push_back(m.num_tets() - 1);
  }
  ASSERT_FALSE(changed.empty());
  h.update_operation_part(changed, {NewNode::on_edge(mid, a, b, 0.5)});
}

// An edge of a part-1 tet between nodes of the given sets.
std::pair<int, int> find_edge(const HybridModel& h, NodeSet sa, NodeSet sb) {
  const auto& p = h.partition();
  for (int t : p.operation_tets) {
    const Tet& e = h.mesh().tets[t];
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        if (i != j && p.node_set[e[i]] == sa && p.node_set[e[j]] == sb) return {e[i], e[j]};
  }
  return {-1, -1};
}

TEST(HybridModel, UpdateOperationPartMatchesFullModelOnNewMesh) {
  HybridModel h(thigh_with(OperationRegion::Kind::kSphere, true));
  h.set_cg_settings(CgSettings{kTight, 20000});
  h.solve();
  const HybridModelCounts before = h.counts();
  const auto [a, b] = find_edge(h, NodeSet::kOperation, NodeSet::kOperation);
  ASSERT_GE(a, 0);
  split_edge(h, a, b);
  const auto [c, d] = find_edge(h, NodeSet::kInterface, NodeSet::kOperation);
  ASSERT_GE(c, 0);
  split_edge(h, c, d);
  const HybridModelCounts after = h.counts();
  EXPECT_EQ(after.nodes, before.nodes + 2);
  EXPECT_GT(after.tets, before.tets + 4);
  EXPECT_EQ(after.nodes_operation, before.nodes_operation + 2);
  EXPECT_EQ(after.dof_operation, before.dof_operation + 6);
  EXPECT_EQ(after.nodes_interface, before.nodes_interface);
  const CgResult r = h.solve();
  EXPECT_TRUE(r.converged);
  const Reference ref = full_reference(h);
  h.recover_interior();
  const double e = nodal_error(h.displacement(), ref.u, all_nodes(h.mesh()));
  EXPECT_LE(e, 1e-9);
  std::printf("[ update   ] after 2 edge splits (%d -> %d tets): hybrid vs full %.2e, cg %d\n",
              before.tets, after.tets, e, r.iterations);
  // Touching a part-2 tet is refused.
  const int part2 = h.partition().condensed_tets.front();
  EXPECT_THROW(h.update_operation_part({part2}, {}), std::logic_error);
}

// Solves (asserting convergence) and returns the error of every node against the full model.
double solved_error_vs_full(HybridModel& h) {
  EXPECT_TRUE(h.solve().converged);
  const Reference ref = full_reference(h);
  h.recover_interior();
  return nodal_error(h.displacement(), ref.u, all_nodes(h.mesh()));
}

// A node inserted inside part-1 tet t at barycentric w (the tet becomes four through it, as a
// vertex insertion's cavity of one tet would): its displacement starts at sum w_k u_k, and the
// hybrid solution still matches the full model's on the new mesh.
TEST(HybridModel, ANodeInsertedInATetStartsInterpolatedAndSolvesAsTheFullModel) {
  HybridModel h(thigh_with(OperationRegion::Kind::kSphere, true));
  h.set_cg_settings(CgSettings{kTight, 20000});
  h.solve();
  const HybridModelCounts before = h.counts();
  TetMesh& m = h.mesh_for_cutting();
  int t = -1;  // a part-1 tet with no interface node
  for (int c : h.partition().operation_tets) {
    bool inner = true;
    for (int v : m.tets[static_cast<size_t>(c)])
      inner = inner && h.partition().node_set[static_cast<size_t>(v)] == NodeSet::kOperation;
    if (inner) {
      t = c;
      break;
    }
  }
  ASSERT_GE(t, 0);
  const Tet host = m.tets[static_cast<size_t>(t)];
  const std::array<double, 4> w = {0.1, 0.2, 0.3, 0.4};
  const int node = m.num_nodes();
  Vec3 x = Vec3::Zero(), u = Vec3::Zero();
  for (size_t i = 0; i < 4; ++i) {
    x += w[i] * m.nodes[static_cast<size_t>(host[i])];
    u += w[i] * h.displacement().segment<3>(3 * host[i]);
  }
  m.nodes.push_back(x);
  std::vector<int> changed = {t};
  for (size_t i = 0; i < 4; ++i) {
    Tet k = host;
    k[i] = node;
    if (i == 0) {
      m.tets[static_cast<size_t>(t)] = k;
    } else {
      m.tets.push_back(k);
      if (!m.cut_faces.empty()) m.cut_faces.push_back(0);
      changed.push_back(m.num_tets() - 1);
    }
  }
  NewNode inserted;
  inserted.index = node;
  inserted.kind = NewNode::Kind::kInTet;
  inserted.corners = host;
  inserted.weights = w;
  h.update_operation_part(changed, {inserted});
  EXPECT_LT((h.displacement().segment<3>(3 * node) - u).norm(), 1e-15);
  EXPECT_EQ(h.counts().nodes, before.nodes + 1);
  EXPECT_EQ(h.counts().tets, before.tets + 3);
  EXPECT_EQ(h.counts().dof_operation, before.dof_operation + 3);
  EXPECT_LE(solved_error_vs_full(h), 1e-9);
  // A corner index past the new node is refused.
  NewNode bad = inserted;
  bad.index = node + 1;
  bad.corners[0] = node + 1;
  m.nodes.push_back(x);
  EXPECT_THROW(h.update_operation_part({}, {bad}), std::invalid_argument);
}

TEST(HybridModel, CutsUpdateTheMatrixAsAFreshAssemblyWould) {
  Scene scene = make_thigh_scene();
  scene.trajectory = resample_blade_path(scene.trajectory, scene.scalpel.blade_length, 1e-3);
  Simulation sim(scene);
  for (const BladePose& pose : scene.trajectory) sim.step(pose);
  const HybridModel& h = sim.model();
  ASSERT_GE(sim.counts().cuts, 10);
  std::vector<int> held;
  for (int n = 0; n < h.mesh().num_nodes(); ++n)
    if (h.held_nodes()[static_cast<size_t>(n)]) held.push_back(n);
  // The same mesh, partition and held nodes condensed and assembled from scratch.
  const HybridModel fresh(h, h.partition().operation_tet, held, make_cpu_solver());
  ASSERT_EQ(fresh.hybrid_dofs().global_of, h.hybrid_dofs().global_of);
  const SparseMatrix& a = h.hybrid_matrix();
  const SparseMatrix& f = fresh.hybrid_matrix();
  const double scale = f.coeffs().cwiseAbs().maxCoeff();
  const double diff = SparseMatrix(a - f).coeffs().cwiseAbs().maxCoeff();
  EXPECT_LE(diff, 1e-12 * scale);
  int stray = 0;  // entries of the updated matrix the fresh one does not have
  for (int r = 0; r < a.outerSize(); ++r)
    for (SparseMatrix::InnerIterator it(a, r); it; ++it)
      stray += f.coeff(r, static_cast<int>(it.index())) == 0.0 && it.value() != 0.0;
  EXPECT_EQ(stray, 0);
  std::printf(
      "[ update   ] %d cuts, %d tets: updated vs fresh hybrid matrix %.2e (relative), "
      "%ld vs %ld entries\n",
      sim.counts().cuts, h.mesh().num_tets(), diff / scale, static_cast<long>(a.nonZeros()),
      static_cast<long>(f.nonZeros()));
}

TEST(HybridModel, SetYoungModulusEqualsFreshPrecompute) {
  Scene s = thigh_with(OperationRegion::Kind::kSphere, true);
  HybridModel rescaled(s);
  rescaled.set_cg_settings(CgSettings{kTight, 20000});
  rescaled.solve();
  rescaled.set_young_modulus(7300.0);
  s.material.young_modulus = 7300.0;
  HybridModel fresh(s);
  fresh.set_cg_settings(CgSettings{kTight, 20000});
  const SparseMatrix diff = rescaled.hybrid_matrix() - fresh.hybrid_matrix();
  EXPECT_LE(diff.norm(), 1e-13 * fresh.hybrid_matrix().norm());
  EXPECT_LE((rescaled.hybrid_rhs() - fresh.hybrid_rhs()).norm(), 1e-13 * fresh.hybrid_rhs().norm());
  rescaled.solve();
  fresh.solve();
  const std::vector<int> visible = all_nodes(fresh.mesh());
  const double e_surface =
      nodal_error(rescaled.displacement(), fresh.displacement(), fresh.partition().surface);
  rescaled.recover_interior();
  fresh.recover_interior();
  const double e_all = nodal_error(rescaled.displacement(), fresh.displacement(), visible);
  EXPECT_LE(e_surface, 1e-9);
  EXPECT_LE(e_all, 1e-9);
  std::printf("[ young    ] set_young_modulus vs fresh precompute: S %.2e, all %.2e\n", e_surface,
              e_all);
}

TEST(HybridModel, PrecomputeTimingsReported) {
  const HybridModel h(make_thigh_scene());
  const auto& t = h.precompute_timings_ms();
  double parts = 0;
  for (const char* k :
       {"partition", "element_stiffness", "condensation_assembly", "condensation_factor",
        "condensation_solve", "condensation_products", "hybrid_assembly"}) {
    ASSERT_TRUE(t.count(k)) << k;
    EXPECT_GE(t.at(k), 0.0);
    parts += t.at(k);
    std::printf("[ precomp  ] %-22s %8.3f ms\n", k, t.at(k));
  }
  EXPECT_GE(t.at("total") * (1 + 1e-9), parts);
  std::printf("[ precomp  ] %-22s %8.3f ms\n", "total", t.at("total"));
}

}  // namespace
}  // namespace stc
