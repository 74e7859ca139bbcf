// Closed surface -> tetrahedral mesh with the TetGen library (docs/SCENE.md "Meshes"). The surface
// is checked first (every edge in exactly two triangles) so an open surface gets a clear message
// instead of whatever TetGen makes of it.
#include "format_readers.hpp"
#include "text_cursor.hpp"

#include <tetgen.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <utility>

namespace stc::io {
namespace {

std::string tetgen_error(int code) {
  switch (code) {
    case 1:
      return "TetGen ran out of memory";
    case 2:
      return "TetGen internal error";
    case 3:
      return "the surface intersects itself (TetGen)";
    case 4:
      return "the surface has a feature too small for TetGen's tolerance";
    case 5:
      return "two surface facets are too close together (TetGen)";
    case 10:
      return "TetGen rejected the input surface";
    default:
      return "TetGen failed with code " + std::to_string(code);
  }
}

void check_closed(const std::string& path, const Surface& s) {
  if (s.triangles.size() < 4)
    fail(path, 0, "surface has fewer than 4 triangles: not a closed surface");
  std::map<std::pair<int, int>, std::pair<int, int>> edges;  // edge -> (uses, first triangle)
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    const Tri& tri = s.triangles[t];
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
      fail(path, s.triangle_line[t], "degenerate triangle (a vertex repeated)");
    for (int e = 0; e < 3; ++e) {
      const int a = tri[e], b = tri[(e + 1) % 3];
      auto& use = edges[{std::min(a, b), std::max(a, b)}];
      if (use.first++ == 0) use.second = static_cast<int>(t);
    }
  }
  for (const auto& [edge, use] : edges)
    if (use.first != 2)
      fail(path, s.triangle_line[static_cast<std::size_t>(use.second)],
           "surface is not closed: edge (" + std::to_string(edge.first) + ", " +
               std::to_string(edge.second) + ") is used by " + std::to_string(use.first) +
               " triangle(s), a closed surface needs exactly 2");
}

}  // namespace

RawMesh tetrahedralize_surface(const std::string& path, const Surface& surface,
                               const std::string& switches) {
  check_closed(path, surface);
  if (switches.find('p') == std::string::npos)
    fail(path, 0, "TetGen switches " + quoted(switches) + " lack 'p' (tetrahedralize the surface)");
  // Only vertices the triangles use go to TetGen: stray OBJ vertices would become interior or
  // outside points.
  std::vector<int> remap(surface.vertices.size(), -1);
  std::vector<Vec3> used;
  for (const Tri& t : surface.triangles)
    for (int v : t)
      if (remap[static_cast<std::size_t>(v)] < 0) {
        remap[static_cast<std::size_t>(v)] = static_cast<int>(used.size());
        used.push_back(surface.vertices[static_cast<std::size_t>(v)]);
      }
  for (const Vec3& x : used)
    if (!x.allFinite()) fail(path, 0, "surface has a non-finite vertex");

  tetgenio in, out;  // their destructors free the arrays allocated here (new[])
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(used.size());
  in.pointlist = new REAL[3 * used.size()];
  for (std::size_t i = 0; i < used.size(); ++i)
    for (int d = 0; d < 3; ++d) in.pointlist[3 * i + d] = used[i][d];
  in.numberoffacets = static_cast<int>(surface.triangles.size());
  in.facetlist = new tetgenio::facet[surface.triangles.size()];
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    tetgenio::facet& f = in.facetlist[t];
    tetgenio::init(&f);
    f.numberofpolygons = 1;
    f.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&f.polygonlist[0]);
    f.polygonlist[0].numberofvertices = 3;
    f.polygonlist[0].vertexlist = new int[3];
    for (int k = 0; k < 3; ++k)
      f.polygonlist[0].vertexlist[k] = remap[static_cast<std::size_t>(surface.triangles[t][k])];
  }

  // Self-intersections are looked for first with TetGen's -d (detect) mode, which reports them
  // instead of failing: TetGen 1.5.0 frees its pools twice when a meshing run ends in an error
  // (terminatetetgen() and ~tetgenmesh() both call freememory()), which crashes the process.
  {
    tetgenbehavior detect;
    char detect_switches[] = "dQ";
    detect.parse_commandline(detect_switches);
    tetgenio found;
    try {
      tetrahedralize(&detect, &in, &found);
    } catch (int code) {
      fail(path, 0, tetgen_error(code));
    }
    if (found.numberoftrifaces > 0)
      fail(path, 0,
           "the surface intersects itself (" + std::to_string(found.numberoftrifaces) +
               " intersecting triangles found by TetGen -d)");
  }

  tetgenbehavior behavior;
  std::vector<char> args(switches.begin(), switches.end());
  args.push_back('\0');
  if (!behavior.parse_commandline(args.data()))
    fail(path, 0, "invalid TetGen switches " + quoted(switches));
  try {
    tetrahedralize(&behavior, &in, &out);
  } catch (int code) {
    fail(path, 0, tetgen_error(code));
  }
  if (out.numberoftetrahedra <= 0 || out.numberofcorners < 4)
    fail(path, 0, "TetGen produced no tetrahedra (is the surface closed and non-degenerate?)");

  RawMesh raw;
  raw.mesh.nodes.reserve(static_cast<std::size_t>(out.numberofpoints));
  for (int i = 0; i < out.numberofpoints; ++i)
    raw.mesh.nodes.emplace_back(out.pointlist[3 * i], out.pointlist[3 * i + 1],
                                out.pointlist[3 * i + 2]);
  raw.mesh.tets.reserve(static_cast<std::size_t>(out.numberoftetrahedra));
  for (int t = 0; t < out.numberoftetrahedra; ++t) {
    Tet tet;
    for (int k = 0; k < 4; ++k)
      tet[k] = out.tetrahedronlist[t * out.numberofcorners + k] - out.firstnumber;
    bool in_range = true;
    for (int v : tet) in_range &= v >= 0 && v < out.numberofpoints;
    // TetGen's own orientation convention is the mirror of ours: orient each tet positively
    // so the result needs no "flipped" warning.
    if (in_range && signed_volume(raw.mesh.nodes[tet[0]], raw.mesh.nodes[tet[1]],
                                  raw.mesh.nodes[tet[2]], raw.mesh.nodes[tet[3]]) < 0)
      std::swap(tet[2], tet[3]);
    raw.mesh.tets.push_back(tet);
  }
  return raw;
}

}  // namespace stc::io
