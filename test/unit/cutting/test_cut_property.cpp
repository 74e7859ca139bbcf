// Property tests of cut insertion: thousands of seeded random blade sweeps on the box, the
// thigh's operation part and the SOFA liver, biased to the hard cases (through nodes, along
// edges and faces, repeated, continued, severing). After EVERY sweep all invariants of
// docs/SCENE.md "Cut invariants" must hold (cutting/invariants.hpp).
#include "common/cut_measures.hpp"
#include "cutting/cut_state.hpp"
#include "cutting/cut_sweep.hpp"
#include "cutting/free_pieces.hpp"
#include "soft_tissue_cutting/cutting/invariants.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/io/mesh_reader.hpp"
#include "soft_tissue_cutting/mesh/quality.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

namespace stc {
namespace {

// A mesh with its operation part, ready to be cut again and again from the same start.
struct Specimen {
  std::string name;
  TetMesh mesh;
  std::vector<std::uint8_t> locked;
  std::vector<std::uint8_t> cuttable;
  Vec3 centre = Vec3::Zero();  // where the blade works
  double reach = 0;            // ... and how far from there
  double edge = 0;             // mean edge length of the operation part
};

Vec3 centroid(const TetMesh& mesh, int t) {
  Vec3 c = Vec3::Zero();
  for (int v : mesh.tets[t]) c += mesh.nodes[v] / 4;
  return c;
}

// Operation part = tets whose centroid `in_region` accepts; locked = nodes they share with
// the rest (make_cut_state locks every node of a non-cuttable tet).
Specimen make_specimen(std::string name, TetMesh mesh,
                       const std::function<bool(const Vec3&)>& in_region) {
  Specimen s;
  s.name = std::move(name);
  s.mesh = std::move(mesh);
  s.cuttable.resize(s.mesh.tets.size());
  s.locked.assign(s.mesh.nodes.size(), 0);
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  double edges = 0;
  int count = 0;
  for (int t = 0; t < s.mesh.num_tets(); ++t) {
    s.cuttable[t] = in_region(centroid(s.mesh, t));
    if (!s.cuttable[t]) continue;
    for (int v : s.mesh.tets[t]) {
      lo = lo.cwiseMin(s.mesh.nodes[v]);
      hi = hi.cwiseMax(s.mesh.nodes[v]);
    }
    edges += (s.mesh.nodes[s.mesh.tets[t][0]] - s.mesh.nodes[s.mesh.tets[t][1]]).norm();
    ++count;
  }
  s.centre = 0.5 * (lo + hi);
  s.reach = 0.5 * (hi - lo).norm();
  s.edge = edges / count;
  return s;
}

Specimen box_specimen() {
  GeneratorParams g;
  g.size = Vec3(0.04, 0.03, 0.02);
  g.cells = {8, 6, 4};
  Specimen s = make_specimen("box", make_box_mesh(g), [](const Vec3&) { return true; });
  // The x = 0 face is held (an anchored, uncuttable layer of nodes).
  for (int v = 0; v < s.mesh.num_nodes(); ++v) s.locked[v] = s.mesh.nodes[v].x() == 0.0;
  return s;
}

Specimen thigh_specimen() {
  Scene scene = make_thigh_scene();
  const OperationRegion region = scene.operation_region;
  return make_specimen("thigh", scene.mesh, [&](const Vec3& c) { return region.contains(c); });
}

Specimen liver_specimen() {
  TetMesh mesh = read_mesh(std::string(TISSUE_SHARED_MESH_DIR) + "/sofa_liver.msh");
  // Operation part: the half of the liver with x above its middle; the rest is condensed.
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const Vec3& x : mesh.nodes) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const double middle = 0.5 * (lo.x() + hi.x());
  return make_specimen("liver", std::move(mesh), [=](const Vec3& c) { return c.x() > middle; });
}

Vec3 random_unit(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vec3 v(n(rng), n(rng), n(rng));
  return v.norm() > 1e-12 ? v.normalized() : Vec3::UnitX();
}

// The kinds of sweep the generator draws from: the hard cases on purpose.
enum class SweepKind { kRandom, kThroughNode, kAlongEdge, kAlongFace, kRepeat, kContinue, kSever };

struct Sweep {
  BladeEdge from, to;
  SweepKind kind;
};

class SweepGenerator {
 public:
  SweepGenerator(const Specimen& s, unsigned seed) : s_(s), rng_(seed) {}

  Sweep next(const TetMesh& mesh, const CutState& state) {
    std::uniform_int_distribution<int> pick(0, 6);
    const SweepKind kind =
        has_last_ ? static_cast<SweepKind>(pick(rng_)) : static_cast<SweepKind>(pick(rng_) % 4);
    Sweep sweep = make(kind, mesh, state);
    last_ = sweep;
    has_last_ = true;
    return sweep;
  }

 private:
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }

  // A random cuttable tet's nodes.
  Tet some_tet(const TetMesh& mesh, const CutState& state) {
    std::uniform_int_distribution<int> t(0, mesh.num_tets() - 1);
    for (;;) {
      const int k = t(rng_);
      if (state.cuttable[k]) return mesh.tets[k];
    }
  }

  // A blade whose edge line contains p, running along dir, moved by motion.
  Sweep through(const Vec3& p, const Vec3& dir, const Vec3& motion, double length, SweepKind kind) {
    Sweep s;
    s.kind = kind;
    s.from.tip = p - uniform(0.2, 0.8) * length * dir;
    s.from.heel = s.from.tip + length * dir;
    s.to.tip = s.from.tip + motion;
    s.to.heel = s.from.heel + motion;
    return s;
  }

  Sweep make(SweepKind kind, const TetMesh& mesh, const CutState& state) {
    const double h = s_.edge;
    switch (kind) {
      case SweepKind::kRandom: {
        const Vec3 p = s_.centre + s_.reach * uniform(0, 0.8) * random_unit(rng_);
        return through(p, random_unit(rng_), uniform(0.5, 4) * h * random_unit(rng_),
                       uniform(1, 6) * h, kind);
      }
      case SweepKind::kThroughNode: {
        const Tet t = some_tet(mesh, state);
        return through(mesh.nodes[t[0]], random_unit(rng_), uniform(0.5, 4) * h * random_unit(rng_),
                       uniform(1, 6) * h, kind);
      }
      case SweepKind::kAlongEdge: {  // the sweep plane contains a mesh edge
        const Tet t = some_tet(mesh, state);
        const Vec3 e = (mesh.nodes[t[1]] - mesh.nodes[t[0]]).normalized();
        return through(mesh.nodes[t[0]], e, uniform(0.5, 4) * h * random_unit(rng_),
                       uniform(2, 6) * h, kind);
      }
      case SweepKind::kAlongFace: {  // the sweep plane is a face's plane
        const Tet t = some_tet(mesh, state);
        const Vec3 a = mesh.nodes[t[0]], b = mesh.nodes[t[1]], c = mesh.nodes[t[2]];
        const Vec3 e = (b - a).normalized();
        const Vec3 in_plane = ((c - a) - (c - a).dot(e) * e).normalized();
        return through(a, e, uniform(-4, 4) * h * in_plane, uniform(2, 6) * h, kind);
      }
      case SweepKind::kRepeat: {  // the same sweep again, exactly or nudged by a hair
        Sweep s = last_;
        s.kind = kind;
        if (uniform(0, 1) < 0.5) {
          const Vec3 nudge = uniform(1e-9, 1e-3) * h * random_unit(rng_);
          for (Vec3* p : {&s.from.tip, &s.from.heel, &s.to.tip, &s.to.heel}) *p += nudge;
        }
        return s;
      }
      case SweepKind::kContinue: {  // carry on from where the last sweep stopped, turning a bit
        Sweep s;
        s.kind = kind;
        s.from = last_.to;
        const Vec3 last_motion = last_.to.tip - last_.from.tip;
        const Vec3 motion = last_motion + 0.3 * last_motion.norm() * random_unit(rng_);
        s.to.tip = s.from.tip + motion;
        s.to.heel = s.from.heel + motion + 0.1 * h * random_unit(rng_);
        return s;
      }
      case SweepKind::kSever:  // a long blade right across the operation part
      default: {
        const Vec3 p = s_.centre + s_.reach * uniform(0, 0.5) * random_unit(rng_);
        const Vec3 dir = random_unit(rng_);
        Vec3 motion = random_unit(rng_);
        motion = (motion - motion.dot(dir) * dir).normalized() * 2.2 * s_.reach;
        Sweep s = through(p - 0.5 * motion, dir, motion, 2.2 * s_.reach, kind);
        return s;
      }
    }
  }

  const Specimen& s_;
  std::mt19937 rng_;
  Sweep last_;
  bool has_last_ = false;
};

const char* kind_name(SweepKind k) {
  static const char* names[] = {"random", "through-node", "along-edge", "along-face",
                                "repeat", "continue",     "sever"};
  return names[static_cast<int>(k)];
}

struct RunStats {
  int sweeps = 0, failures = 0, cutting_sweeps = 0, interface_hits = 0, free_pieces = 0;
  long tets_split = 0;
};

// `sequences` runs of `length` sweeps, each from the uncut specimen; invariants after each.
RunStats run_property(const Specimen& s, unsigned seed, int sequences, int length) {
  RunStats stats;
  for (int q = 0; q < sequences && stats.failures == 0; ++q) {
    TetMesh mesh = s.mesh;
    CutState state = make_cut_state(mesh, s.locked, s.cuttable);
    InvariantLimits limits;
    limits.initial_volume = total_volume(mesh);
    limits.min_volume_fraction = CutOptions{}.min_volume_fraction;
    SweepGenerator gen(s, seed + 7919u * q);
    for (int k = 0; k < length; ++k) {
      const Sweep sweep = gen.next(mesh, state);
      const CutResult r = cut_sweep(mesh, state, sweep.from, sweep.to);
      ++stats.sweeps;
      stats.cutting_sweeps += r.cut_faces_added > 0;
      stats.interface_hits += r.reached_interface;
      stats.tets_split += r.tets_split;
      std::vector<std::string> violated = check_cut_invariants(mesh, state.origin_volume, limits);
      // The cut state's bound on every edge (earlier_triangles.cpp relies on it).
      for (int t = 0; t < mesh.num_tets() && violated.empty(); ++t)
        for (int i = 0; i < 4; ++i)
          for (int j = i + 1; j < 4; ++j)
            if (const double e = (mesh.nodes[mesh.tets[t][i]] - mesh.nodes[mesh.tets[t][j]]).norm();
                e > state.longest_edge_bound)
              violated.push_back("an edge of " + std::to_string(e) +
                                 " m passes the cut state's bound " +
                                 std::to_string(state.longest_edge_bound) + " m");
      if (!violated.empty()) {
        ++stats.failures;
        ADD_FAILURE() << s.name << " seed " << seed << " sequence " << q << " sweep " << k << " ("
                      << kind_name(sweep.kind) << "): " << violated.front();
        break;
      }
    }
    std::vector<std::uint8_t> anchored(mesh.nodes.size(), 0);
    for (int v = 0; v < mesh.num_nodes(); ++v) anchored[v] = state.locked[v];
    stats.free_pieces += static_cast<int>(free_pieces(mesh, anchored).size());
  }
  std::printf("%s: %d sweeps (%d cut, %d reached the interface), %ld tet splits, %d free pieces\n",
              s.name.c_str(), stats.sweeps, stats.cutting_sweeps, stats.interface_hits,
              stats.tets_split, stats.free_pieces);
  return stats;
}

TEST(CutProperty, BoxThousandSweeps) {
  const RunStats stats = run_property(box_specimen(), 1234u, 25, 40);
  EXPECT_EQ(stats.failures, 0);
  EXPECT_EQ(stats.sweeps, 1000);
  EXPECT_GT(stats.cutting_sweeps, 300);  // most sweeps really cut something
}

TEST(CutProperty, ThighThousandSweeps) {
  const RunStats stats = run_property(thigh_specimen(), 2024u, 25, 40);
  EXPECT_EQ(stats.failures, 0);
  EXPECT_EQ(stats.sweeps, 1000);
  EXPECT_GT(stats.cutting_sweeps, 300);
  EXPECT_GT(stats.interface_hits, 0);  // severing sweeps reach the condensed part
}

TEST(CutProperty, LiverThousandSweeps) {
  const RunStats stats = run_property(liver_specimen(), 77u, 25, 40);
  EXPECT_EQ(stats.failures, 0);
  EXPECT_EQ(stats.sweeps, 1000);
  EXPECT_GT(stats.cutting_sweeps, 300);
}

// Quality after 100 cuts: what the element shapes degrade to. Bisection at t in [0.1, 0.9]
// can make thin children; the thresholds below are what the measured values clear with
// margin, and the volume guard bounds the size loss independently of shape.
struct Quality {
  MeshQuality q;
  int thin = 0;  // tets with a smallest dihedral angle under 5 deg
  int cuts = 0;
  double worst_fraction = 1;  // smallest volume / size class
};

Quality quality_after_100_cuts(const Specimen& s, unsigned seed, const CutOptions& options) {
  TetMesh mesh = s.mesh;
  CutState state = make_cut_state(mesh, s.locked, s.cuttable);
  SweepGenerator gen(s, seed);
  Quality out;
  for (int k = 0; k < 100; ++k) {
    const Sweep sweep = gen.next(mesh, state);
    out.cuts += cut_sweep(mesh, state, sweep.from, sweep.to, options).cut_faces_added > 0;
  }
  out.q = mesh_quality(mesh);
  for (int t = 0; t < mesh.num_tets(); ++t) {
    out.worst_fraction = std::min(out.worst_fraction, tet_volume(mesh, t) / state.origin_volume[t]);
    const Tet& e = mesh.tets[t];
    const auto angles =
        dihedral_angles_deg(mesh.nodes[e[0]], mesh.nodes[e[1]], mesh.nodes[e[2]], mesh.nodes[e[3]]);
    out.thin += *std::min_element(angles.begin(), angles.end()) < 5.0;
  }
  return out;
}

// Seeds 99, 2, 1 and 3, each with neither the smoothing nor the flips of docs/DESIGN.md
// section 8 ("Smooth", "Flip"), with the smoothing alone and with both (the default): the
// smallest angle and volume ratio stay above the thresholds in every run. Returns the tets under
// 5 deg in all runs, in those three modes.
std::array<int, 3> report_quality_after_100_cuts(const Specimen& s, double min_dihedral,
                                                 double min_ratio) {
  const MeshQuality before = mesh_quality(s.mesh);
  std::array<int, 3> thin = {0, 0, 0};
  const char* names[3] = {"neither", "smoothed", "smoothed and flipped"};
  for (unsigned seed : {99u, 2u, 1u, 3u}) {
    for (int mode = 0; mode < 3; ++mode) {
      CutOptions options;
      if (mode == 0) options.smooth_below_deg = 0;
      options.flip_thin_tets = mode == 2;
      const Quality a = quality_after_100_cuts(s, seed, options);
      thin[static_cast<size_t>(mode)] += a.thin;
      std::printf(
          "%s seed %u, %s: %d of 100 sweeps cut; min dihedral %.2f deg (%.2f before), %d tets "
          "under 5 deg; max %.2f deg; min volume ratio %.4f (%.4f before); smallest tet %.4f of "
          "its size class\n",
          s.name.c_str(), seed, names[mode], a.cuts, a.q.min_dihedral_deg, before.min_dihedral_deg,
          a.thin, a.q.max_dihedral_deg, a.q.min_volume_ratio, before.min_volume_ratio,
          a.worst_fraction);
      EXPECT_GT(a.q.min_dihedral_deg, min_dihedral) << s.name << " seed " << seed;
      EXPECT_GT(a.q.min_volume_ratio, min_ratio) << s.name << " seed " << seed;
      EXPECT_GE(a.worst_fraction, CutOptions{}.min_volume_fraction * (1 - 1e-9));
    }
  }
  std::printf("%s: tets under 5 deg after 100 sweeps, 4 seeds: %d -> %d smoothed -> %d flipped\n",
              s.name.c_str(), thin[0], thin[1], thin[2]);
  return thin;
}

TEST(CutProperty, QualityAfter100Cuts) {
  // Measured (seed 99): thigh 0.64 deg / 0.0023, box 2.57 deg / 0.0053, liver 0.85 deg /
  // 0.0030 (from 18.2 / 45 / 6.2 deg uncut; the minimum over the mesh moves with any change of
  // the cut sequence: 0.39 / 2.91 / 1.77 deg before slivers were kept attached, 0.64 / 2.66 /
  // 1.49 before nodes on the stroke were tested against each triangle's plane). Bisection only
  // bounds SIZE (t in [0.1, 0.9], guard 1 %), not shape, so angles can fall this far; the
  // thresholds catch regressions.
  // With conformed borders (stop 27): thigh 0.61 deg / 0.0039, box 0.91 / 0.0031, liver
  // 0.52 / 0.0027, and 30-50 % more tets after the 100 sweeps (the tets a border runs through
  // are cut twice): the price of opening up to the blade.
  // Stop 36, seeds 99 / 1 / 2 / 3 / 4 without -> with smoothing: the minima scatter with the cut
  // sequence (thigh 0.44-1.02 -> 0.69-1.17 deg, ratio 0.0018-0.0039 -> 0.0015-0.0049; box
  // 0.91-1.42 -> 0.85-1.36 deg, 0.0026-0.0033 -> 0.0021-0.0031; liver 0.52-0.93 -> 0.41-0.88 deg,
  // 0.0014-0.0029 -> 0.0012-0.0025), so the thresholds are below every run; the tets under
  // 5 deg fall by a fifth to a quarter on average (thigh 192 -> 152, box 184 -> 138, liver
  // 132 -> 113), though not in every run (box seed 1: 118 -> 144).
  // Stop 37 (marks held closed instead of dropped where a copy would make a non-manifold edge;
  // every random sweep's cut sequence after the first such event changes): seeds 99 / 2 / 1 / 3
  // without -> with smoothing, tets under 5 deg thigh 831 -> 641 (-23 %), box 754 -> 645
  // (-14 %), liver 476 -> 467 (-2 %; seeds 1 and 3 more with it: the smoothing changes which
  // sweeps cut, 67-77 of 100), box seed 99 smoothed min 0.39 deg. The smoothing's gain is
  // within the seeds' scatter on one specimen, so it is asserted over all twelve runs.
  // Stop 38 (nodes on a crease slide along it, nodes on a cut that has not opened slide within
  // its plane: node_moves.hpp): with smoothing thigh 641 -> 497, box 645 -> 421, liver 467 ->
  // 317; against none, 2061 -> 1235 (-40 %, was -15 %; smoothed minima 0.50-1.80 deg).
  // Asserted: at least a quarter fewer.
  // Stop 44 (the shape guard's 1 deg default, docs/DESIGN.md section 8 "Shape guard"): no run
  // ends under 1 deg (least 1.01, liver seed 99 unsmoothed; all runs 1.01-1.80 deg), so that is
  // asserted now; box seed 2 smoothed ends at a volume ratio of 0.00112 (the box's guard was
  // 0.0012) - the smallest angle and the volume ratio are different measures, and the guard
  // bounds only the first.
  // Stop 55 (the tip's border on the path the tip took: every random sweep's cut sequence
  // changes): liver seed 99 smoothed and flipped ends at a volume ratio of 0.00078 (its other
  // eleven runs 0.0008-0.0028, every run's smallest angle 5.00-5.04 deg), so the liver's floor
  // is 0.0007, as the heel's border snap measured at stop 48.
  std::array<int, 3> thin = {0, 0, 0};
  for (const auto& [specimen, min_ratio] :
       {std::make_pair(thigh_specimen(), 0.0008), std::make_pair(box_specimen(), 0.001),
        std::make_pair(liver_specimen(), 0.0007)}) {
    const std::array<int, 3> here = report_quality_after_100_cuts(
        specimen, CutOptions{}.split_min_dihedral_deg - 1e-6, min_ratio);
    for (size_t m = 0; m < 3; ++m) thin[m] += here[m];
  }
  std::printf("all specimens: tets under 5 deg %d -> %d smoothed -> %d smoothed and flipped\n",
              thin[0], thin[1], thin[2]);
  EXPECT_LE(thin[1], 0.75 * thin[0]) << "the smoothing removes at least a quarter of the thin tets";
  // Stop 39 (flips, cutting/tet_flips.hpp): 1235 -> 939 (-24 %; thigh 497 -> 381, box 421 ->
  // 291, liver 317 -> 267). Asserted over the twelve runs: at least 15 % fewer.
  // Stop 42 (vertex insertion among the flips, cutting/vertex_insertion.hpp; off by default,
  // measured with it on): 939 -> 914 (thigh 381 -> 309, box 291 -> 289, liver 267 -> 316: each
  // run's cut sequence changes, and on these single sweeps the gain is within the scatter; on
  // the sagging TetGen liver's strokes it is -28 %, TetGenLiverInsertionLeavesFewerThinTets),
  // and the Gmsh liver's seed 2 then ends with a volume ratio of 0.0007.
  EXPECT_LE(thin[2], 0.85 * thin[1]) << "the flips remove at least 15 % of what the smoothing left";
}

}  // namespace
}  // namespace stc
