#include "cutting/separation.hpp"

#include <algorithm>
#include <map>
#include <optional>
#include <unordered_map>
#include <unordered_set>

namespace stc {
namespace {

// A node's star split into pieces connected through shared unmarked faces.
std::vector<std::vector<int>> star_components(const TetMesh& mesh, const CutState& state, int v) {
  const std::vector<int>& star = state.node_tets[v];
  const std::vector<std::array<int, 4>> across = star_neighbours(mesh, state, v);
  std::vector<int> component(star.size(), -1);
  std::vector<std::vector<int>> pieces;
  for (size_t seed = 0; seed < star.size(); ++seed) {
    if (component[seed] >= 0) continue;
    const int id = static_cast<int>(pieces.size());
    pieces.emplace_back();
    std::vector<size_t> stack = {seed};
    component[seed] = id;
    while (!stack.empty()) {
      const size_t k = stack.back();
      stack.pop_back();
      const int t = star[k];
      pieces[id].push_back(t);
      for (int f = 0; f < 4; ++f) {
        if (mesh.tets[t][f] == v || mesh.is_cut_face(t, f)) continue;  // faces through v only
        const int j = across[k][f];
        if (j >= 0 && component[static_cast<size_t>(j)] < 0) {
          component[static_cast<size_t>(j)] = id;
          stack.push_back(static_cast<size_t>(j));
        }
      }
    }
  }
  return pieces;
}

bool is_interior_marked(const TetMesh& mesh, const CutState& state, int t, int f) {
  return mesh.is_cut_face(t, f) && neighbour_across(mesh, state, t, f).first >= 0;
}

// Unmarks closed marked face f of tet t on both of its tets.
void unmark_face(TetMesh& mesh, const CutState& state, int t, int f, std::set<FaceKey>& new_faces) {
  const auto [other, other_face] = neighbour_across(mesh, state, t, f);
  mesh.cut_faces[t] &= static_cast<std::uint8_t>(~(1u << f));
  mesh.cut_faces[other] &= static_cast<std::uint8_t>(~(1u << other_face));
  new_faces.erase(face_key(mesh.tets[t], f));
}

// Unmarks the still-closed marked faces that contain all of `nodes` (1 or 2 of them).
// Returns how many faces were unmarked.
int unmark_closed_faces(TetMesh& mesh, const CutState& state, const std::vector<int>& nodes,
                        std::set<FaceKey>& new_faces) {
  int dropped = 0;
  for (int t : state.node_tets[nodes[0]]) {
    for (int f = 0; f < 4; ++f) {
      if (!is_interior_marked(mesh, state, t, f)) continue;
      const FaceKey key = face_key(mesh.tets[t], f);
      bool all = true;
      for (int v : nodes) all &= std::find(key.begin(), key.end(), v) != key.end();
      if (!all) continue;
      unmark_face(mesh, state, t, f, new_faces);
      ++dropped;
    }
  }
  return dropped;
}

struct Duplication {
  int node;
  std::vector<std::vector<int>> pieces;  // pieces[0] keeps the node, the others get copies
};

std::uint64_t edge_key(int a, int b) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
         static_cast<std::uint32_t>(b);
}

// Edges that would lie in other than exactly two (oppositely wound) boundary triangles after
// applying `plan`, as pairs of current node ids. Only edges at nodes of the renamed tets can
// change, and all their boundary triangles belong to tets one ring further out, which this
// looks at with the planned numbering.
std::vector<std::pair<int, int>> planned_bad_edges(const TetMesh& mesh, const CutState& state,
                                                   const std::vector<Duplication>& plan) {
  if (plan.empty()) return {};
  std::unordered_map<int, Tet> renamed;  // tet -> planned nodes
  std::vector<int> original;             // planned id - num_nodes -> node it copies
  for (const Duplication& d : plan)
    for (size_t p = 1; p < d.pieces.size(); ++p) {
      const int copy = mesh.num_nodes() + static_cast<int>(original.size());
      original.push_back(d.node);
      for (int t : d.pieces[p]) {
        auto it = renamed.emplace(t, mesh.tets[t]).first;
        std::replace(it->second.begin(), it->second.end(), d.node, copy);
      }
    }
  auto planned = [&](int t) {
    auto it = renamed.find(t);
    return it == renamed.end() ? mesh.tets[t] : it->second;
  };
  auto current_id = [&](int v) {
    return v < mesh.num_nodes() ? v : original[v - mesh.num_nodes()];
  };

  std::unordered_set<int> inner_tets, watched_nodes, outer_tets;
  for (const Duplication& d : plan)
    for (int t : state.node_tets[d.node]) inner_tets.insert(t);
  for (int t : inner_tets)
    for (int v : planned(t)) watched_nodes.insert(v);
  for (int v : watched_nodes)
    for (int t : state.node_tets[current_id(v)]) outer_tets.insert(t);

  std::map<FaceKey, std::pair<int, Tri>> faces;  // planned face -> (uses, winding)
  for (int t : outer_tets) {
    const Tet tet = planned(t);
    for (int f = 0; f < 4; ++f) {
      const Tri tri = {tet[kTetFaces[f][0]], tet[kTetFaces[f][1]], tet[kTetFaces[f][2]]};
      if (!watched_nodes.count(tri[0]) && !watched_nodes.count(tri[1]) &&
          !watched_nodes.count(tri[2]))
        continue;
      FaceKey key = {tri[0], tri[1], tri[2]};
      std::sort(key.begin(), key.end());
      auto& entry = faces[key];
      ++entry.first;
      entry.second = tri;
    }
  }
  std::unordered_map<std::uint64_t, int> directed;
  for (const auto& [key, use] : faces) {
    if (use.first != 1) continue;
    for (int e = 0; e < 3; ++e) {
      const int p = use.second[e], q = use.second[(e + 1) % 3];
      if (watched_nodes.count(p) || watched_nodes.count(q)) ++directed[edge_key(p, q)];
    }
  }
  std::vector<std::pair<int, int>> bad;
  for (const auto& [key, count] : directed) {
    const int p = static_cast<int>(key >> 32), q = static_cast<int>(key & 0xffffffffu);
    if (count != 1 || !directed.count(edge_key(q, p)))
      bad.emplace_back(current_id(p), current_id(q));
  }
  return bad;
}

// A few tets that the marks around them would cut loose (a tet lying flat in the crease of two
// sweep triangles, marked on every face): one of their closed marks is dropped - the piece is
// an artefact of the discretisation, not tissue the blade severed.
constexpr size_t kSliverPieceTets = 8;

void keep_slivers_attached(TetMesh& mesh, const CutState& state,
                           const std::vector<int>& region_tets, std::set<FaceKey>& new_faces) {
  // Every tet of a new mark (some lie outside the region: marks in the stroke's earlier
  // triangles) and the region's.
  std::vector<int> seeds = region_tets;
  for (const FaceKey& key : new_faces)
    for (int t : tets_with_edge(state, key[0], key[1])) {
      const Tet& k = mesh.tets[t];
      if (std::find(k.begin(), k.end(), key[2]) != k.end()) seeds.push_back(t);
    }
  std::sort(seeds.begin(), seeds.end());
  seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
  // Each tet's neighbour across a face, looked up once: the tets do not change here (marks
  // only), and the searches below overlap (the organ liver's follow stroke: this function
  // ~0.55 -> ~0.42 s of 442 cuts, most of it in neighbour_across).
  std::unordered_map<long, int> across_cache;
  auto across = [&](int t, int f) {
    const long key = 4L * t + f;
    if (const auto it = across_cache.find(key); it != across_cache.end()) return it->second;
    const int other = neighbour_across(mesh, state, t, f).first;
    across_cache.emplace(key, other);
    return other;
  };
  // Tets known to lie in a piece larger than the limit. Marks are only dropped here, which
  // joins pieces, so such a piece stays larger: a walk that reaches one of its tets stops
  // there, and most seeds (the region's tets, nearly all in the body) cost one look-up instead
  // of a walk of kSliverPieceTets + 1 tets (the organ liver's follow stroke: ~0.75 ms a cut).
  std::vector<std::uint8_t> large(mesh.tets.size(), 0);
  // The tets reachable from seed through unmarked interior faces, in the order a walk finds
  // them; none if they are more than the limit.
  auto piece_of = [&](int seed) -> std::optional<std::vector<int>> {
    std::vector<int> piece = {seed};
    const auto larger = [&] {
      for (int t : piece) large[static_cast<size_t>(t)] = 1;
      return std::nullopt;
    };
    if (large[static_cast<size_t>(seed)]) return std::nullopt;
    for (size_t i = 0; i < piece.size(); ++i)
      for (int f = 0; f < 4; ++f) {
        if (mesh.is_cut_face(piece[i], f)) continue;
        const int other = across(piece[i], f);
        if (other < 0 || std::find(piece.begin(), piece.end(), other) != piece.end()) continue;
        if (large[static_cast<size_t>(other)]) return larger();
        piece.push_back(other);
        if (piece.size() > kSliverPieceTets) return larger();
      }
    return piece;
  };
  for (int seed : seeds) {
    for (bool dropped = true; dropped;) {
      dropped = false;
      const std::optional<std::vector<int>> small = piece_of(seed);
      if (!small) break;
      const std::vector<int>& piece = *small;
      // A small closed piece: drop one closed mark, best one that joins it to a large piece,
      // and a new one before an old.
      int best_tet = -1, best_face = -1, best_score = -1;
      for (int t : piece)
        for (int f = 0; f < 4; ++f) {
          if (!is_interior_marked(mesh, state, t, f)) continue;
          const int other = across(t, f);
          if (std::find(piece.begin(), piece.end(), other) != piece.end()) continue;
          const int score = 2 * !piece_of(other) + (new_faces.count(face_key(mesh.tets[t], f)) > 0);
          if (score > best_score) best_tet = t, best_face = f, best_score = score;
        }
      if (best_tet < 0) break;  // cut loose earlier (open walls only): nothing to undo here
      unmark_face(mesh, state, best_tet, best_face, new_faces);
      dropped = true;
    }
  }
}

}  // namespace

void separate_along_cuts(TetMesh& mesh, CutState& state, const std::vector<int>& region_tets,
                         CutResult& result, std::set<FaceKey>& new_faces) {
  keep_slivers_attached(mesh, state, region_tets, new_faces);
  std::vector<Duplication> plan;
  std::set<int> held_back;  // nodes left whole this time (their marks stay closed)
  for (;;) {
    // Nodes of still-closed marked faces: only their stars can fall apart.
    std::set<int> watch;
    for (int t : region_tets)
      for (int f = 0; f < 4; ++f)
        if (is_interior_marked(mesh, state, t, f))
          for (int k = 0; k < 3; ++k) watch.insert(mesh.tets[t][kTetFaces[f][k]]);
    plan.clear();
    std::vector<int> locked_hits;
    for (int v : watch) {
      auto pieces = star_components(mesh, state, v);
      if (pieces.size() < 2 || held_back.count(v)) continue;
      if (state.locked[v])
        locked_hits.push_back(v);
      else
        plan.push_back({v, std::move(pieces)});
    }
    if (!locked_hits.empty()) {
      // The blade stops at the interface: drop the marks that would split a locked node.
      // (A locked star already in pieces with no closed marks left is left as it is.)
      int dropped = 0;
      for (int v : locked_hits) dropped += unmark_closed_faces(mesh, state, {v}, new_faces);
      if (dropped > 0) {
        result.reached_interface = true;
        continue;
      }
    }
    const auto bad = planned_bad_edges(mesh, state, plan);
    if (bad.empty()) break;
    // First leave whole the nodes whose duplication puts the bad edge into more boundary
    // triangles: the third corners of the closed marks on it (and its own ends). Their marks
    // stay closed, and open once later marks complete the surface around them.
    bool held = false;
    for (const auto& [p, q] : bad) {
      std::vector<int> culprits = {p, q};
      for (int t : tets_with_edge(state, p, q))
        for (int f = 0; f < 4; ++f) {
          if (!is_interior_marked(mesh, state, t, f)) continue;
          const FaceKey key = face_key(mesh.tets[t], f);
          if (std::find(key.begin(), key.end(), p) == key.end() ||
              std::find(key.begin(), key.end(), q) == key.end())
            continue;
          for (int v : key)
            if (v != p && v != q) culprits.push_back(v);
        }
      for (int v : culprits)
        for (const Duplication& d : plan)
          if (d.node == v && held_back.insert(v).second) held = true;
    }
    if (held) continue;
    int dropped = 0;
    for (const auto& [p, q] : bad) {
      int here = unmark_closed_faces(mesh, state, {p, q}, new_faces);
      if (here == 0)
        here = unmark_closed_faces(mesh, state, {p}, new_faces) +
               unmark_closed_faces(mesh, state, {q}, new_faces);
      dropped += here;
    }
    if (dropped == 0) break;  // nothing closed left to drop: cannot happen from a valid state
  }

  for (const Duplication& d : plan) {
    for (size_t p = 1; p < d.pieces.size(); ++p) {
      const int copy = mesh.num_nodes();
      mesh.nodes.push_back(mesh.nodes[d.node]);
      state.locked.push_back(0);
      state.node_tets.emplace_back();
      if (is_on_stroke(state, d.node)) set_on_stroke(state, copy);
      for (int t : d.pieces[p]) {
        std::replace(mesh.tets[t].begin(), mesh.tets[t].end(), d.node, copy);
        auto& star = state.node_tets[d.node];
        star.erase(std::find(star.begin(), star.end(), t));
        state.node_tets[copy].push_back(t);
        result.changed_tets.push_back(t);
      }
      NewNode node;
      node.index = copy;
      node.kind = NewNode::Kind::kDuplicate;
      node.a = d.node;
      result.new_nodes.push_back(node);
    }
  }
}

}  // namespace stc
