// Closed triangle surfaces: Wavefront OBJ, STL (ASCII and binary), OFF. Polygons are split
// into triangle fans; tetrahedralize_surface then checks closure and runs TetGen (docs/SCENE.md
// "Meshes").
#include "format_readers.hpp"
#include "text_cursor.hpp"

#include <array>
#include <cmath>
#include <map>

namespace stc::io {
namespace {

void add_polygon(TextCursor& c, Surface& s, const std::vector<long long>& poly) {
  if (poly.size() < 3) c.fail("face with fewer than 3 vertices");
  for (std::size_t k = 1; k + 1 < poly.size(); ++k) {
    s.triangles.push_back(
        {static_cast<int>(poly[0]), static_cast<int>(poly[k]), static_cast<int>(poly[k + 1])});
    s.triangle_line.push_back(c.line());
  }
}

}  // namespace

Surface read_obj(const std::string& path, const std::string& data) {
  TextCursor c(path, data, '#');
  Surface s;
  while (!c.at_end()) {
    const auto tok = c.line_tokens("an OBJ statement");
    if (tok.empty()) continue;
    if (tok[0] == "v") {
      if (tok.size() < 4 || tok.size() > 5) c.fail("vertex needs x y z [w]");
      s.vertices.emplace_back(c.to_real(tok[1], "x coordinate"), c.to_real(tok[2], "y coordinate"),
                              c.to_real(tok[3], "z coordinate"));
    } else if (tok[0] == "f") {
      std::vector<long long> poly;
      for (std::size_t k = 1; k < tok.size(); ++k) {
        // v, v/vt, v//vn or v/vt/vn: the vertex index comes first; negative counts back.
        const std::string_view ref = tok[k].substr(0, tok[k].find('/'));
        long long v = c.to_integer(ref, "vertex index");
        const long long n = static_cast<long long>(s.vertices.size());
        if (v < 0)
          v += n;
        else
          v -= 1;
        if (v < 0 || v >= n)
          c.fail("vertex index " + std::string(ref) + " out of range (" + std::to_string(n) +
                 " vertices so far)");
        poly.push_back(v);
      }
      add_polygon(c, s, poly);
    } else if (tok[0] == "vn" || tok[0] == "vt" || tok[0] == "vp" || tok[0] == "g" ||
               tok[0] == "o" || tok[0] == "s" || tok[0] == "usemtl" || tok[0] == "mtllib") {
      // normals, texture and grouping: not needed for the volume
    } else if (tok[0] == "l" || tok[0] == "p") {
      c.fail("OBJ line/point elements: the surface must be made of faces only");
    } else {
      c.fail("unknown OBJ statement " + quoted(tok[0]));
    }
  }
  return s;
}

Surface read_stl(const std::string& path, const std::string& data) {
  Surface s;
  std::map<std::array<double, 3>, int> index;  // STL repeats vertices per facet: merge equal ones
  auto vertex = [&](const Vec3& x) {
    const auto [it, added] = index.emplace(std::array<double, 3>{x.x(), x.y(), x.z()},
                                           static_cast<int>(s.vertices.size()));
    if (added) s.vertices.push_back(x);
    return it->second;
  };
  const bool binary_size_matches =
      data.size() >= 84 &&
      data.size() ==
          84 + 50ull * load_binary<std::uint32_t>(data.data() + 80, !host_is_little_endian());
  // Some binary writers also start the header with "solid"; text never holds a NUL byte.
  const bool text = data.find('\0') == std::string::npos;
  if (!binary_size_matches && text && data.compare(0, 5, "solid") == 0) {
    TextCursor c(path, data);
    c.line_tokens("solid");
    while (true) {
      const std::string_view key = c.token("facet or endsolid");
      if (key == "endsolid") break;
      if (key != "facet") c.fail("expected facet or endsolid, got " + quoted(key));
      if (c.token("normal") != "normal") c.fail("expected 'normal'");
      for (int k = 0; k < 3; ++k) c.real("normal component");
      if (c.token("outer") != "outer" || c.token("loop") != "loop") c.fail("expected 'outer loop'");
      Tri t;
      for (int k = 0; k < 3; ++k) {
        if (c.token("vertex") != "vertex") c.fail("expected 'vertex' (triangles only)");
        Vec3 x;
        x.x() = c.real("x coordinate");
        x.y() = c.real("y coordinate");
        x.z() = c.real("z coordinate");
        t[k] = vertex(x);
      }
      if (c.token("endloop") != "endloop") c.fail("expected 'endloop' (triangles only)");
      if (c.token("endfacet") != "endfacet") c.fail("expected 'endfacet'");
      s.triangles.push_back(t);
      s.triangle_line.push_back(c.line());
    }
    return s;
  }
  if (data.size() < 84) fail(path, 0, "too short for a binary STL and not an ASCII STL");
  if (!binary_size_matches)
    fail(path, 0,
         "binary STL size " + std::to_string(data.size()) +
             " does not match its triangle count (truncated?)");
  const std::uint32_t n = load_binary<std::uint32_t>(data.data() + 80, !host_is_little_endian());
  for (std::uint32_t i = 0; i < n; ++i) {
    const char* p = data.data() + 84 + 50ull * i + 12;  // skip the normal
    Tri t;
    for (int k = 0; k < 3; ++k) {
      Vec3 x;
      for (int d = 0; d < 3; ++d)
        x[d] = load_binary<float>(p + 12 * k + 4 * d, !host_is_little_endian());
      if (!x.allFinite()) fail(path, 0, "non-finite vertex in triangle " + std::to_string(i));
      t[k] = vertex(x);
    }
    s.triangles.push_back(t);
    s.triangle_line.push_back(0);
  }
  return s;
}

Surface read_off(const std::string& path, const std::string& data) {
  TextCursor c(path, data, '#');
  Surface s;
  const std::string_view magic = c.token("OFF");
  if (magic != "OFF") c.fail("not an OFF file (expected 'OFF', got " + quoted(magic) + ")");
  const long long nv = c.integer("vertex count", 0, static_cast<long long>(data.size()));
  const long long nf = c.integer("face count", 0, static_cast<long long>(data.size()));
  c.integer("edge count");
  for (long long i = 0; i < nv; ++i) {
    Vec3 x;
    x.x() = c.real("x coordinate");
    x.y() = c.real("y coordinate");
    x.z() = c.real("z coordinate");
    s.vertices.push_back(x);
  }
  for (long long f = 0; f < nf; ++f) {
    const auto tok = c.line_tokens("a face line");
    const long long k = c.to_integer(tok[0], "face vertex count");
    if (k < 3 || static_cast<std::size_t>(k) > tok.size() - 1)
      c.fail("bad face vertex count " + std::to_string(k));
    std::vector<long long> poly;
    for (long long j = 0; j < k; ++j) {
      const long long v = c.to_integer(tok[1 + j], "vertex index");
      if (v < 0 || v >= nv)
        c.fail("vertex index " + std::to_string(v) + " out of range [0, " + std::to_string(nv) +
               ")");
      poly.push_back(v);
    }
    add_polygon(c, s, poly);  // extra fields (colours) after the indices are ignored
  }
  return s;
}

}  // namespace stc::io
