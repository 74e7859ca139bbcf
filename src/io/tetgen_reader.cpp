// TetGen .node + .ele reader (docs/SCENE.md "Meshes": named by the .node; 0- or 1-based as the
// first point index in .node says). Attributes and boundary markers are read past and ignored.
#include "format_readers.hpp"
#include "text_cursor.hpp"

namespace stc::io {
namespace {

long long header_field(TextCursor& c, const std::vector<std::string_view>& tok, std::size_t i,
                       const char* what, long long lo, long long hi, long long fallback) {
  if (i >= tok.size()) return fallback;
  const long long v = c.to_integer(tok[i], what);
  if (v < lo || v > hi)
    c.fail(std::string(what) + " " + std::to_string(v) + " out of range [" + std::to_string(lo) +
           ", " + std::to_string(hi) + "]");
  return v;
}

}  // namespace

RawMesh read_tetgen(const std::string& node_path) {
  RawMesh out;
  const std::string node_data = read_file(node_path);
  TextCursor c(node_path, node_data, '#');
  // <# of points> <dimension (3)> <# of attributes> <boundary markers (0 or 1)>
  auto head = c.line_tokens("the .node header");
  const long long n = header_field(c, head, 0, "number of points", 1,
                                   static_cast<long long>(node_data.size() / 8 + 1), 0);
  header_field(c, head, 1, "dimension", 3, 3, 3);
  const long long attributes = header_field(c, head, 2, "number of attributes", 0, 1000, 0);
  const long long markers = header_field(c, head, 3, "boundary marker flag", 0, 1, 0);
  if (head.size() > 4) c.fail(".node header has more than 4 fields");
  long long base = 0;
  for (long long i = 0; i < n; ++i) {
    const auto tok = c.line_tokens("a point line");
    if (tok.size() != static_cast<std::size_t>(4 + attributes + markers))
      c.fail("point line has " + std::to_string(tok.size()) + " fields, expected " +
             std::to_string(4 + attributes + markers));
    const long long index = c.to_integer(tok[0], "point index");
    if (i == 0) {
      if (index != 0 && index != 1)
        c.fail("first point index must be 0 or 1, got " + std::to_string(index));
      base = index;
    } else if (index != base + i) {
      c.fail("points must be numbered consecutively: expected " + std::to_string(base + i) +
             ", got " + std::to_string(index));
    }
    out.mesh.nodes.emplace_back(c.to_real(tok[1], "x coordinate"),
                                c.to_real(tok[2], "y coordinate"),
                                c.to_real(tok[3], "z coordinate"));
    out.lines.node_line.push_back(c.line());
  }
  if (!c.at_end()) {
    c.token("");
    c.fail("unexpected data after the " + std::to_string(n) + " points (point count wrong?)");
  }

  std::string ele_path = node_path.substr(0, node_path.size() - 5) + ".ele";
  const std::string ele_data = read_file(ele_path);
  TextCursor e(ele_path, ele_data, '#');
  // <# of tetrahedra> <nodes per tetrahedron (4 or 10)> <region attribute (0 or 1)>
  head = e.line_tokens("the .ele header");
  const long long m = header_field(e, head, 0, "number of tetrahedra", 0,
                                   static_cast<long long>(ele_data.size() / 8 + 1), 0);
  const long long corners = header_field(e, head, 1, "nodes per tetrahedron", 4, 10, 4);
  if (corners != 4 && corners != 10) e.fail("nodes per tetrahedron must be 4 or 10");
  const long long region = header_field(e, head, 2, "region attribute flag", 0, 1, 0);
  if (head.size() > 3) e.fail(".ele header has more than 3 fields");
  for (long long t = 0; t < m; ++t) {
    const auto tok = e.line_tokens("a tetrahedron line");
    if (tok.size() != static_cast<std::size_t>(1 + corners + region))
      e.fail("tetrahedron line has " + std::to_string(tok.size()) + " fields, expected " +
             std::to_string(1 + corners + region));
    const long long index = e.to_integer(tok[0], "tetrahedron index");
    if (index != base + t)
      e.fail("tetrahedra must be numbered consecutively from " + std::to_string(base) +
             ": expected " + std::to_string(base + t) + ", got " + std::to_string(index));
    Tet tet;
    for (int k = 0; k < 4; ++k) {  // the first four are the corners (also for 10-node tets)
      const long long v = e.to_integer(tok[1 + k], "node index");
      if (v < base || v >= base + n)
        e.fail("node index " + std::to_string(v) + " out of range [" + std::to_string(base) + ", " +
               std::to_string(base + n - 1) + "]");
      tet[k] = static_cast<int>(v - base);
    }
    out.mesh.tets.push_back(tet);
    out.lines.tet_line.push_back(e.line());
  }
  if (!e.at_end()) {
    e.token("");
    e.fail("unexpected data after the " + std::to_string(m) + " tetrahedra (count wrong?)");
  }
  return out;
}

}  // namespace stc::io
