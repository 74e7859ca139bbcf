// Gmsh .msh reader: format 1 ($NOD/$ELM), 2.x and 4.1 ($Nodes/$Elements, entity blocks in
// 4.1), ASCII and binary. Only tetrahedra (element type 4) are kept (docs/SCENE.md "Meshes"); node
// tags may be non-contiguous and are mapped to 0-based indices in file order.
#include "format_readers.hpp"
#include "text_cursor.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace stc::io {
namespace {

constexpr int kGmshTet = 4;

// Nodes per Gmsh element type (needed to skip other element types in binary files).
int gmsh_nodes_per_element(long long type) {
  static const int table[] = {0, 2,  3,  4,  4, 8,  6,  5,  3,  6,  9, 10, 27, 18, 14, 1,
                              8, 20, 15, 13, 9, 10, 12, 15, 15, 21, 4, 5,  6,  20, 35, 56};
  if (type >= 1 && type < static_cast<long long>(sizeof(table) / sizeof(table[0])))
    return table[type];
  if (type == 92) return 64;
  if (type == 93) return 125;
  return 0;  // unknown
}

class GmshReader {
 public:
  GmshReader(const std::string& path, const std::string& data) : data_(data), c_(path, data) {}

  RawMesh read() {
    bool any_nodes = false;
    while (!c_.at_end()) {
      const std::string_view tok = c_.token("a section");
      if (tok == "$NOD") {
        read_v1_nodes();
        any_nodes = true;
      } else if (tok == "$ELM") {
        if (!any_nodes) c_.fail("$ELM before $NOD");
        read_v1_elements();
      } else if (tok == "$MeshFormat") {
        read_format();
      } else if (tok == "$Nodes") {
        require_format("$Nodes");
        if (version_ == 2)
          read_v2_nodes();
        else
          read_v4_nodes();
        any_nodes = true;
      } else if (tok == "$Elements") {
        require_format("$Elements");
        if (!any_nodes) c_.fail("$Elements before $Nodes");
        if (version_ == 2)
          read_v2_elements();
        else
          read_v4_elements();
      } else if (tok.size() > 1 && tok[0] == '$' && tok.substr(0, 4) != "$End" &&
                 tok.substr(0, 4) != "$END") {
        skip_section(tok);
      } else {
        c_.fail("expected a section header such as $MeshFormat, $Nodes or $NOD, got " +
                quoted(tok));
      }
    }
    if (!any_nodes) c_.fail("not a Gmsh mesh: no $Nodes or $NOD section");
    return std::move(out_);
  }

 private:
  void require_format(const char* section) {
    if (version_ == 0) c_.fail(std::string(section) + " without a preceding $MeshFormat");
  }

  void expect(std::string_view end, const std::string& context) {
    const std::string_view tok = c_.token(std::string(end).c_str());
    if (tok != end)
      c_.fail("expected " + std::string(end) + " " + context + ", got " + quoted(tok));
  }

  void skip_section(std::string_view tok) {
    // Unknown or unneeded sections ($PhysicalNames, $Entities, $NodeData, ...) are skipped.
    const std::string end = "$End" + std::string(tok.substr(1));
    const int line = c_.line();
    if (!c_.skip_past(end)) fail(c_.path(), line, "section " + std::string(tok) + " has no " + end);
  }

  void read_format() {
    const std::string_view v = c_.token("format version");
    if (v == "2" || v == "2.0" || v == "2.1" || v == "2.2") {
      version_ = 2;
    } else if (v == "4.1") {
      version_ = 4;
    } else {
      c_.fail("unsupported Gmsh format version " + quoted(v) +
              " (supported: 1, 2.2, 4.1; re-save the mesh with Gmsh as 2.2 or 4.1)");
    }
    binary_ = c_.integer("file-type (0 ASCII, 1 binary)", 0, 1) == 1;
    const long long size = c_.integer("data-size");
    if (binary_) {
      if (size != 8) c_.fail("unsupported binary data-size " + std::to_string(size) + " (need 8)");
      c_.skip_past_newline();
      // The integer 1 written in the file's byte order tells the endianness.
      const char* p = c_.raw(4, "endianness marker");
      if (load_binary<std::int32_t>(p, false) == 1)
        swap_ = false;
      else if (load_binary<std::int32_t>(p, true) == 1)
        swap_ = true;
      else
        c_.fail("bad binary endianness marker (expected the integer 1)");
    }
    expect("$EndMeshFormat", "after the format line");
  }

  void add_node(long long tag, const Vec3& x, int line) {
    const int index = static_cast<int>(out_.mesh.nodes.size());
    if (out_.mesh.nodes.size() >= 0x7fffffff) fail(c_.path(), line, "too many nodes");
    if (!tags_.emplace(tag, index).second)
      fail(c_.path(), line,
           "duplicate node tag " + std::to_string(tag) + " (first on line " +
               std::to_string(out_.lines.node_line[tags_[tag]]) + ")");
    out_.mesh.nodes.push_back(x);
    out_.lines.node_line.push_back(line);
  }

  int node_index(long long tag, int line) {
    const auto it = tags_.find(tag);
    if (it == tags_.end())
      fail(c_.path(), line, "tetrahedron refers to undefined node tag " + std::to_string(tag));
    return it->second;
  }

  void add_tet(const long long tags[4], int line) {
    Tet t;
    for (int k = 0; k < 4; ++k) t[k] = node_index(tags[k], line);
    out_.mesh.tets.push_back(t);
    out_.lines.tet_line.push_back(line);
  }

  // A count from a header, checked against what the rest of the file could hold so that
  // garbage never drives a huge loop or allocation.
  long long count(const char* what, std::size_t min_bytes_each) {
    const long long n = c_.integer(what);
    if (n < 0) c_.fail(std::string("negative ") + what + " " + std::to_string(n));
    if (min_bytes_each > 0 && static_cast<unsigned long long>(n) > c_.remaining() / min_bytes_each)
      c_.fail(std::string(what) + " " + std::to_string(n) +
              " exceeds what the file holds (truncated?)");
    return n;
  }

  double checked(double v, const char* what) {
    if (!std::isfinite(v)) c_.fail(std::string("non-finite ") + what);
    return v;
  }

  // ---- format 1 and 2 ASCII share the node list: "tag x y z" per line.
  void read_ascii_node_list(long long n, const char* end) {
    for (long long i = 0; i < n; ++i) {
      const std::string_view tok = c_.token("node tag");
      if (tok == end)
        c_.fail("found " + std::string(end) + " after " + std::to_string(i) + " of " +
                std::to_string(n) + " nodes");
      const long long tag = c_.to_integer(tok, "node tag");
      const int line = c_.line();
      Vec3 x;
      x.x() = c_.real("x coordinate");
      x.y() = c_.real("y coordinate");
      x.z() = c_.real("z coordinate");
      if (c_.line() != line) fail(c_.path(), line, "node line has fewer than 4 fields");
      add_node(tag, x, line);
    }
    expect(end, "after " + std::to_string(n) + " nodes (node count wrong?)");
  }

  void read_v1_nodes() { read_ascii_node_list(count("node count", 8), "$ENDNOD"); }

  void read_v1_elements() {
    const long long n = count("element count", 10);
    for (long long i = 0; i < n; ++i) {
      const auto tok = c_.line_tokens("an element line");
      const int line = c_.line();
      if (!tok.empty() && tok[0] == "$ENDELM")
        c_.fail("found $ENDELM after " + std::to_string(i) + " of " + std::to_string(n) +
                " elements");
      // elm-number elm-type reg-phys reg-elem number-of-nodes node-list
      if (tok.size() < 5) c_.fail("element line has fewer than 5 fields");
      c_.to_integer(tok[0], "element number");
      const long long type = c_.to_integer(tok[1], "element type");
      const long long nn = c_.to_integer(tok[4], "number of nodes");
      if (nn < 1 || static_cast<std::size_t>(nn) != tok.size() - 5)
        c_.fail("element declares " + std::to_string(nn) + " nodes but lists " +
                std::to_string(tok.size() - 5));
      if (type != kGmshTet) continue;
      if (nn != 4) c_.fail("tetrahedron with " + std::to_string(nn) + " nodes");
      long long tags[4];
      for (int k = 0; k < 4; ++k) tags[k] = c_.to_integer(tok[5 + k], "node tag");
      add_tet(tags, line);
    }
    expect("$ENDELM", "after " + std::to_string(n) + " elements (element count wrong?)");
  }

  // ---- format 2.x
  void read_v2_nodes() {
    const long long n = count("node count", binary_ ? 28 : 8);
    if (!binary_) return read_ascii_node_list(n, "$EndNodes");
    c_.skip_past_newline();
    const char* p = c_.raw(static_cast<std::size_t>(n) * 28, "node data");
    const int line = c_.line();
    for (long long i = 0; i < n; ++i, p += 28) {
      const long long tag = load_binary<std::int32_t>(p, swap_);
      Vec3 x(load_binary<double>(p + 4, swap_), load_binary<double>(p + 12, swap_),
             load_binary<double>(p + 20, swap_));
      if (!x.allFinite())
        fail(c_.path(), line, "non-finite coordinate of node tag " + std::to_string(tag));
      add_node(tag, x, line);
    }
    expect("$EndNodes", "after the binary node data");
  }

  void read_v2_elements() {
    const long long n = count("element count", binary_ ? 12 : 6);
    if (binary_) {
      c_.skip_past_newline();
      long long done = 0;
      while (done < n) {
        const char* h = c_.raw(12, "element block header");
        const int line = c_.line();
        const long long type = load_binary<std::int32_t>(h, swap_);
        const long long follow = load_binary<std::int32_t>(h + 4, swap_);
        const long long ntags = load_binary<std::int32_t>(h + 8, swap_);
        const int nn = gmsh_nodes_per_element(type);
        if (nn == 0) c_.fail("unknown element type " + std::to_string(type));
        if (follow < 1 || follow > n - done)
          c_.fail("bad element block size " + std::to_string(follow));
        if (ntags < 0 || ntags > 1000) c_.fail("bad number of tags " + std::to_string(ntags));
        const std::size_t each = 4 * static_cast<std::size_t>(1 + ntags + nn);
        if (static_cast<std::size_t>(follow) > c_.remaining() / each)
          c_.fail("truncated element data");
        const char* p = c_.raw(each * static_cast<std::size_t>(follow), "element data");
        for (long long e = 0; e < follow; ++e, p += each) {
          if (type != kGmshTet) continue;
          long long tags[4];
          for (int k = 0; k < 4; ++k)
            tags[k] = load_binary<std::int32_t>(p + 4 * (1 + ntags + k), swap_);
          add_tet(tags, line);
        }
        done += follow;
      }
      expect("$EndElements", "after the binary element data");
      return;
    }
    for (long long i = 0; i < n; ++i) {
      const auto tok = c_.line_tokens("an element line");
      if (!tok.empty() && tok[0] == "$EndElements")
        c_.fail("found $EndElements after " + std::to_string(i) + " of " + std::to_string(n) +
                " elements");
      // elm-number elm-type number-of-tags tags... node-list
      if (tok.size() < 3) c_.fail("element line has fewer than 3 fields");
      c_.to_integer(tok[0], "element number");
      const long long type = c_.to_integer(tok[1], "element type");
      const long long ntags = c_.to_integer(tok[2], "number of tags");
      if (ntags < 0 || static_cast<std::size_t>(ntags) > tok.size() - 3)
        c_.fail("bad number of tags " + std::to_string(ntags));
      if (type != kGmshTet) continue;
      const std::size_t nn = tok.size() - 3 - static_cast<std::size_t>(ntags);
      if (nn != 4) c_.fail("tetrahedron with " + std::to_string(nn) + " nodes");
      long long tags[4];
      for (int k = 0; k < 4; ++k) tags[k] = c_.to_integer(tok[3 + ntags + k], "node tag");
      add_tet(tags, c_.line());
    }
    expect("$EndElements", "after " + std::to_string(n) + " elements (element count wrong?)");
  }

  // ---- format 4.1: entity blocks
  std::uint64_t size_t_value(const char*& p) {
    const std::uint64_t v = load_binary<std::uint64_t>(p, swap_);
    p += 8;
    return v;
  }

  // Gmsh 4.1 $Nodes / $Elements header: numBlocks numItems minTag maxTag (four size_t in
  // binary). `min_bytes_per_item` bounds the ASCII item count by the file size.
  void read_v4_section_header(const std::string& what, int min_bytes_per_item, long long& blocks,
                              long long& total) {
    if (binary_) {
      c_.skip_past_newline();
      const std::string header = what + " section header";
      const char* p = c_.raw(32, header.c_str());
      blocks = static_cast<long long>(std::min<std::uint64_t>(size_t_value(p), 1ull << 40));
      total = static_cast<long long>(std::min<std::uint64_t>(size_t_value(p), 1ull << 40));
    } else {
      const std::string n_blocks = "number of " + what + " blocks", n_items = what + " count";
      const std::string min_tag = "minimum " + what + " tag", max_tag = "maximum " + what + " tag";
      blocks = count(n_blocks.c_str(), 4);
      total = count(n_items.c_str(), static_cast<std::size_t>(min_bytes_per_item));
      c_.integer(min_tag.c_str());
      c_.integer(max_tag.c_str());
    }
  }

  void read_v4_nodes() {
    long long blocks, total;
    read_v4_section_header("node", 8, blocks, total);
    long long seen = 0;
    for (long long b = 0; b < blocks; ++b) {
      long long dim, parametric, n;
      if (binary_) {
        const char* p = c_.raw(20, "node block header");
        dim = load_binary<std::int32_t>(p, swap_);
        parametric = load_binary<std::int32_t>(p + 8, swap_);
        p += 12;
        n = static_cast<long long>(std::min<std::uint64_t>(size_t_value(p), 1ull << 40));
      } else {
        dim = c_.integer("entity dimension", 0, 3);
        c_.integer("entity tag");
        parametric = c_.integer("parametric flag", 0, 1);
        n = count("number of nodes in block", 8);
      }
      if (dim < 0 || dim > 3) c_.fail("bad entity dimension " + std::to_string(dim));
      if (parametric < 0 || parametric > 1) c_.fail("bad parametric flag");
      if (n > total - seen)
        c_.fail("node blocks hold more nodes than the declared " + std::to_string(total));
      const int params = parametric ? static_cast<int>(dim) : 0;
      std::vector<long long> tags;
      if (binary_) {
        const std::size_t each = 8 + 8 * (3 + params);
        if (static_cast<std::size_t>(n) > c_.remaining() / each) c_.fail("truncated node data");
        const char* t = c_.raw(8 * static_cast<std::size_t>(n), "node tags");
        const char* x = c_.raw(8 * (3 + params) * static_cast<std::size_t>(n), "node coordinates");
        const int line = c_.line();
        for (long long i = 0; i < n; ++i) {
          const long long tag =
              static_cast<long long>(load_binary<std::uint64_t>(t + 8 * i, swap_));
          const char* q = x + 8 * (3 + params) * i;
          Vec3 v(load_binary<double>(q, swap_), load_binary<double>(q + 8, swap_),
                 load_binary<double>(q + 16, swap_));
          if (!v.allFinite())
            fail(c_.path(), line, "non-finite coordinate of node tag " + std::to_string(tag));
          add_node(tag, v, line);
        }
      } else {
        tags.reserve(static_cast<std::size_t>(n));
        for (long long i = 0; i < n; ++i) tags.push_back(c_.integer("node tag"));
        for (long long i = 0; i < n; ++i) {
          Vec3 v;
          v.x() = c_.real("x coordinate");
          const int line = c_.line();
          v.y() = c_.real("y coordinate");
          v.z() = c_.real("z coordinate");
          for (int k = 0; k < params; ++k) c_.real("parametric coordinate");
          add_node(tags[static_cast<std::size_t>(i)], v, line);
        }
      }
      seen += n;
    }
    if (seen != total)
      c_.fail("node blocks hold " + std::to_string(seen) + " nodes, header says " +
              std::to_string(total));
    expect("$EndNodes", "after the node blocks");
  }

  void read_v4_elements() {
    long long blocks, total;
    read_v4_section_header("element", 4, blocks, total);
    long long seen = 0;
    for (long long b = 0; b < blocks; ++b) {
      long long type, n;
      if (binary_) {
        const char* p = c_.raw(20, "element block header");
        type = load_binary<std::int32_t>(p + 8, swap_);
        p += 12;
        n = static_cast<long long>(std::min<std::uint64_t>(size_t_value(p), 1ull << 40));
      } else {
        c_.integer("entity dimension", 0, 3);
        c_.integer("entity tag");
        type = c_.integer("element type");
        n = count("number of elements in block", 4);
      }
      if (n > total - seen)
        c_.fail("element blocks hold more elements than the declared " + std::to_string(total));
      if (binary_) {
        const int nn = gmsh_nodes_per_element(type);
        if (nn == 0) c_.fail("unknown element type " + std::to_string(type));
        const std::size_t each = 8 * static_cast<std::size_t>(1 + nn);
        if (static_cast<std::size_t>(n) > c_.remaining() / each) c_.fail("truncated element data");
        const char* p = c_.raw(each * static_cast<std::size_t>(n), "element data");
        const int line = c_.line();
        if (type == kGmshTet)
          for (long long e = 0; e < n; ++e) {
            long long tags[4];
            for (int k = 0; k < 4; ++k)
              tags[k] = static_cast<long long>(
                  load_binary<std::uint64_t>(p + each * e + 8 * (1 + k), swap_));
            add_tet(tags, line);
          }
      } else {
        for (long long e = 0; e < n; ++e) {
          const auto tok = c_.line_tokens("an element line");
          if (!tok.empty() && tok[0] == "$EndElements")
            c_.fail("found $EndElements inside an element block");
          if (type != kGmshTet) continue;
          if (tok.size() != 5)
            c_.fail("tetrahedron line needs a tag and 4 node tags, has " +
                    std::to_string(tok.size()) + " fields");
          c_.to_integer(tok[0], "element tag");
          long long tags[4];
          for (int k = 0; k < 4; ++k) tags[k] = c_.to_integer(tok[1 + k], "node tag");
          add_tet(tags, c_.line());
        }
      }
      seen += n;
    }
    if (seen != total)
      c_.fail("element blocks hold " + std::to_string(seen) + " elements, header says " +
              std::to_string(total));
    expect("$EndElements", "after the element blocks");
  }

  [[maybe_unused]] const std::string& data_;
  TextCursor c_;
  RawMesh out_;
  std::unordered_map<long long, int> tags_;
  int version_ = 0;  // 0 = no $MeshFormat yet (format 1), 2 or 4
  bool binary_ = false;
  bool swap_ = false;
};

}  // namespace

RawMesh read_gmsh(const std::string& path, const std::string& data) {
  return GmshReader(path, data).read();
}

}  // namespace stc::io
