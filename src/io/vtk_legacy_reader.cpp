// VTK legacy UNSTRUCTURED_GRID reader, ASCII and BINARY (big-endian), classic CELLS layout
// and the 5.1 OFFSETS/CONNECTIVITY layout. Only VTK_TETRA (10) cells are kept (docs/SCENE.md
// "Meshes").
#include "format_readers.hpp"
#include "text_cursor.hpp"

#include <cmath>

namespace stc::io {
namespace {

constexpr long long kVtkTetra = 10;

class VtkLegacyReader {
 public:
  VtkLegacyReader(const std::string& path, const std::string& data) : c_(path, data) {}

  RawMesh read() {
    const std::string_view magic = c_.rest_of_line();
    if (magic.substr(0, 22) != "# vtk DataFile Version")
      c_.fail("not a VTK legacy file (first line must be '# vtk DataFile Version x.y')");
    std::string_view v = magic.substr(22);
    while (!v.empty() && v.front() == ' ') v.remove_prefix(1);
    double version = 0;
    if (!parse_double(v, version)) c_.fail("bad VTK version " + quoted(v));
    new_layout_ = version >= 5.0;  // 5.1 writes CELLS as OFFSETS + CONNECTIVITY
    c_.rest_of_line();             // title
    const std::string_view mode = c_.rest_of_line();
    if (mode == "ASCII")
      binary_ = false;
    else if (mode == "BINARY")
      binary_ = true;
    else
      c_.fail("third line must be ASCII or BINARY, got " + quoted(mode));
    expect_word("DATASET");
    const std::string_view type = c_.token("a dataset type");
    if (type != "UNSTRUCTURED_GRID")
      c_.fail("only DATASET UNSTRUCTURED_GRID is supported, got " + quoted(type));

    bool have_points = false, have_cells = false, have_types = false;
    while (!(have_points && have_cells && have_types)) {
      if (c_.at_end()) break;
      const std::string_view key = c_.token("a keyword");
      if (key == "POINTS") {
        read_points();
        have_points = true;
      } else if (key == "CELLS") {
        read_cells();
        have_cells = true;
      } else if (key == "CELL_TYPES") {
        read_types();
        have_types = true;
      } else if (key == "METADATA") {
        // Information keys (VTK >= 8): runs to the next blank line.
        c_.skip_past_newline();
        while (c_.remaining() > 0 && !c_.rest_of_line().empty()) {
        }
      } else if (key == "FIELD" || key == "POINT_DATA" || key == "CELL_DATA") {
        break;  // attribute data after the geometry: not needed
      } else {
        c_.fail("unexpected keyword " + quoted(key));
      }
    }
    if (!have_points) c_.fail("no POINTS section");
    if (!have_cells) c_.fail("no CELLS section");
    if (!have_types) c_.fail("no CELL_TYPES section");
    if (types_.size() + 1 != offsets_.size())
      fail(c_.path(), types_line_,
           "CELL_TYPES has " + std::to_string(types_.size()) + " cells, CELLS has " +
               std::to_string(offsets_.size() - 1));
    const long long n = static_cast<long long>(out_.mesh.nodes.size());
    for (std::size_t i = 0; i < types_.size(); ++i) {
      if (types_[i] != kVtkTetra) continue;
      const int line = i < cell_lines_.size() ? cell_lines_[i] : cells_line_;
      const long long begin = offsets_[i], end = offsets_[i + 1];
      if (end - begin != 4)
        fail(c_.path(), line,
             "cell " + std::to_string(i) + " is a tetrahedron (type 10) with " +
                 std::to_string(end - begin) + " points");
      Tet tet;
      for (int k = 0; k < 4; ++k) {
        const long long v = conn_[static_cast<std::size_t>(begin + k)];
        if (v < 0 || v >= n)
          fail(c_.path(), line,
               "cell " + std::to_string(i) + " refers to point " + std::to_string(v) +
                   ", out of range [0, " + std::to_string(n) + ")");
        tet[k] = static_cast<int>(v);
      }
      out_.mesh.tets.push_back(tet);
      out_.lines.tet_line.push_back(line);
    }
    return std::move(out_);
  }

 private:
  void expect_word(const char* word) {
    const std::string_view tok = c_.token(word);
    if (tok != word) c_.fail(std::string("expected ") + word + ", got " + quoted(tok));
  }

  long long count(const char* what) {
    const long long n = c_.integer(what);
    if (n < 0) c_.fail(std::string("negative ") + what);
    if (static_cast<unsigned long long>(n) > c_.remaining())
      c_.fail(std::string(what) + " " + std::to_string(n) +
              " exceeds what the file holds (truncated?)");
    return n;
  }

  // Integer arrays: ASCII tokens or big-endian int32/int64.
  std::vector<long long> integers(long long n, int bytes, const char* what) {
    std::vector<long long> v;
    if (binary_) {
      if (static_cast<unsigned long long>(n) > c_.remaining() / static_cast<unsigned>(bytes))
        c_.fail(std::string("truncated binary ") + what);
      const char* p = c_.raw(static_cast<std::size_t>(n) * bytes, what);
      v.reserve(static_cast<std::size_t>(n));
      for (long long i = 0; i < n; ++i)
        v.push_back(bytes == 8 ? load_binary<std::int64_t>(p + 8 * i, swap_)
                               : load_binary<std::int32_t>(p + 4 * i, swap_));
    } else {
      for (long long i = 0; i < n; ++i) v.push_back(c_.integer(what));
    }
    return v;
  }

  int integer_type_bytes(std::string_view type) {
    if (type == "vtktypeint64" || type == "long" || type == "vtkIdType") return 8;
    if (type == "vtktypeint32" || type == "int") return 4;
    c_.fail("unsupported integer type " + quoted(type));
  }

  void read_points() {
    const long long n = count("number of points");
    const std::string_view type = c_.token("point data type");
    int bytes = 0;
    if (type == "float")
      bytes = 4;
    else if (type == "double")
      bytes = 8;
    else
      c_.fail("POINTS type must be float or double, got " + quoted(type));
    out_.mesh.nodes.reserve(static_cast<std::size_t>(n));
    if (binary_) {
      c_.skip_past_newline();
      if (static_cast<unsigned long long>(n) > c_.remaining() / (3u * bytes))
        c_.fail("truncated binary POINTS");
      const char* p = c_.raw(static_cast<std::size_t>(n) * 3 * bytes, "POINTS");
      const int line = c_.line();
      for (long long i = 0; i < 3 * n; i += 3) {
        Vec3 x;
        for (int k = 0; k < 3; ++k)
          x[k] = bytes == 4 ? load_binary<float>(p + 4 * (i + k), swap_)
                            : load_binary<double>(p + 8 * (i + k), swap_);
        if (!x.allFinite())
          fail(c_.path(), line, "non-finite coordinate of point " + std::to_string(i / 3));
        out_.mesh.nodes.push_back(x);
        out_.lines.node_line.push_back(line);
      }
    } else {
      for (long long i = 0; i < n; ++i) {
        Vec3 x;
        x.x() = c_.real("x coordinate");
        const int line = c_.line();
        x.y() = c_.real("y coordinate");
        x.z() = c_.real("z coordinate");
        out_.mesh.nodes.push_back(x);
        out_.lines.node_line.push_back(line);
      }
    }
  }

  void read_cells() {
    const long long a = count("CELLS first size");
    const long long b = count("CELLS second size");
    cells_line_ = c_.line();
    if (new_layout_) {
      // CELLS <offsets count> <connectivity size>, then OFFSETS <type> and CONNECTIVITY <type>.
      expect_word("OFFSETS");
      const int ob = integer_type_bytes(c_.token("offset type"));
      if (binary_) c_.skip_past_newline();
      offsets_ = integers(a, ob, "offset");
      expect_word("CONNECTIVITY");
      const int cb = integer_type_bytes(c_.token("connectivity type"));
      if (binary_) c_.skip_past_newline();
      conn_ = integers(b, cb, "connectivity index");
      if (offsets_.empty() || offsets_.front() != 0 || offsets_.back() != b)
        fail(c_.path(), cells_line_, "OFFSETS must start at 0 and end at the connectivity size");
      for (std::size_t i = 1; i < offsets_.size(); ++i)
        if (offsets_[i] < offsets_[i - 1]) fail(c_.path(), cells_line_, "OFFSETS decrease");
      return;
    }
    // CELLS <n> <size>, then per cell: <k> <k indices>; size counts every integer.
    if (binary_) c_.skip_past_newline();
    const std::vector<long long> all = integers(b, 4, "CELLS entry");
    offsets_.assign(1, 0);
    std::size_t at = 0;
    for (long long i = 0; i < a; ++i) {
      if (at >= all.size())
        fail(c_.path(), cells_line_,
             "CELLS size " + std::to_string(b) + " too small for " + std::to_string(a) + " cells");
      const long long k = all[at];
      if (k < 1 || static_cast<std::size_t>(k) > all.size() - at - 1)
        fail(c_.path(), cells_line_,
             "cell " + std::to_string(i) + " has a bad point count " + std::to_string(k));
      conn_.insert(conn_.end(), all.begin() + static_cast<long>(at + 1),
                   all.begin() + static_cast<long>(at + 1 + k));
      offsets_.push_back(static_cast<long long>(conn_.size()));
      at += static_cast<std::size_t>(k) + 1;
    }
    if (at != all.size())
      fail(c_.path(), cells_line_,
           "CELLS size " + std::to_string(b) + " does not match the cell list (" +
               std::to_string(at) + " integers)");
    if (!binary_) {
      // ASCII: one line per cell in practice; remember it for messages.
      for (long long i = 0; i < a; ++i)
        cell_lines_.push_back(cells_line_ + 1 + static_cast<int>(i));
    }
  }

  void read_types() {
    const long long n = count("number of cell types");
    types_line_ = c_.line();
    if (binary_) c_.skip_past_newline();
    types_ = integers(n, 4, "cell type");
  }

  TextCursor c_;
  RawMesh out_;
  bool binary_ = false;
  bool new_layout_ = false;
  bool swap_ = host_is_little_endian();  // binary legacy VTK is big-endian
  std::vector<long long> offsets_, conn_, types_;
  std::vector<int> cell_lines_;
  int cells_line_ = 0, types_line_ = 0;
};

}  // namespace

RawMesh read_vtk_legacy(const std::string& path, const std::string& data) {
  return VtkLegacyReader(path, data).read();
}

}  // namespace stc::io
