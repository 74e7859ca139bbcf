// Closed surface -> tetrahedral mesh with the TetGen library (docs/SCENE.md "Meshes"). The surface
// is checked first (every edge in exactly two triangles) so an open surface gets a clear message
// instead of whatever TetGen makes of it. TetGen itself runs in a forked child
// (isolated_child.hpp): TetGen 1.5 can abort or double-free on some bad surfaces, and that must
// become one error line naming the file, not a dead process.
#include "format_readers.hpp"
#include "isolated_child.hpp"
#include "text_cursor.hpp"

#include <tetgen.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <utility>
#include <vector>

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

// Generous: the liver surface at the default switches (~46k tets) takes a few seconds.
constexpr double kTetgenTimeoutS = 600.0;

template <typename T>
void put(std::string& out, const T* data, std::size_t count) {
  if (count == 0) return;
  out.append(reinterpret_cast<const char*>(data), count * sizeof(T));
}

template <typename T>
void get(const std::string& in, std::size_t& at, T* data, std::size_t count) {
  std::memcpy(data, in.data() + at, count * sizeof(T));
  at += count * sizeof(T);
}

// The child's answer: point count, tet count, corners per tet, then the two arrays.
std::string pack(const tetgenio& out) {
  std::string bytes;
  const int header[3] = {out.numberofpoints, out.numberoftetrahedra, out.numberofcorners};
  put(bytes, header, 3);
  put(bytes, out.pointlist, 3 * static_cast<std::size_t>(std::max(0, out.numberofpoints)));
  put(bytes, out.tetrahedronlist,
      static_cast<std::size_t>(std::max(0, out.numberoftetrahedra)) *
          static_cast<std::size_t>(std::max(0, out.numberofcorners)));
  // firstnumber last, so a short answer is detected by the size check below
  put(bytes, &out.firstnumber, 1);
  return bytes;
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

  // Everything TetGen touches happens in the child; only the packed result comes back.
  const std::string answer = run_isolated(
      path, "TetGen",
      [&]() -> std::string {
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
            f.polygonlist[0].vertexlist[k] =
                remap[static_cast<std::size_t>(surface.triangles[t][k])];
        }

        // Self-intersections are looked for first with TetGen's -d (detect) mode, which reports
        // them instead of failing: TetGen 1.5.0 frees its pools twice when a meshing run ends in an
        // error (terminatetetgen() and ~tetgenmesh() both call freememory()), which crashes the
        // process.
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
        return pack(out);
      },
      kTetgenTimeoutS);
  int header[3];
  std::size_t at = 0;
  if (answer.size() < sizeof header) fail(path, 0, "TetGen returned a truncated result");
  get(answer, at, header, 3);
  const int points = header[0], tets = header[1], corners = header[2];
  if (tets <= 0 || corners < 4 || points < 4)
    fail(path, 0, "TetGen produced no tetrahedra (is the surface closed and non-degenerate?)");
  const std::size_t expected =
      sizeof header + 3 * sizeof(REAL) * static_cast<std::size_t>(points) +
      sizeof(int) * static_cast<std::size_t>(tets) * static_cast<std::size_t>(corners) +
      sizeof(int);
  if (answer.size() != expected) fail(path, 0, "TetGen returned a truncated result");
  std::vector<REAL> pointlist(3 * static_cast<std::size_t>(points));
  std::vector<int> tetlist(static_cast<std::size_t>(tets) * static_cast<std::size_t>(corners));
  int firstnumber = 0;
  get(answer, at, pointlist.data(), pointlist.size());
  get(answer, at, tetlist.data(), tetlist.size());
  get(answer, at, &firstnumber, 1);

  RawMesh raw;
  raw.mesh.nodes.reserve(static_cast<std::size_t>(points));
  for (std::size_t i = 0; i < static_cast<std::size_t>(points); ++i)
    raw.mesh.nodes.emplace_back(pointlist[3 * i], pointlist[3 * i + 1], pointlist[3 * i + 2]);
  raw.mesh.tets.reserve(static_cast<std::size_t>(tets));
  for (std::size_t t = 0; t < static_cast<std::size_t>(tets); ++t) {
    Tet tet;
    for (std::size_t k = 0; k < 4; ++k)
      tet[k] = tetlist[t * static_cast<std::size_t>(corners) + k] - firstnumber;
    bool in_range = true;
    for (int v : tet) in_range &= v >= 0 && v < points;
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
