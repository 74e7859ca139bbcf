// VTK XML UnstructuredGrid (.vtu) reader, ascii DataArrays only: Points, and Cells'
// connectivity/offsets/types. Only VTK_TETRA (10) cells are kept (docs/SCENE.md "Meshes"). The XML
// subset VTK writes is scanned directly (elements, attributes, comments); binary/appended data and
// compressed files are refused with a clear message.
#include "format_readers.hpp"
#include "text_cursor.hpp"

#include <algorithm>
#include <map>

namespace stc::io {
namespace {

struct Tag {
  std::string name;
  std::map<std::string, std::string> attributes;
  bool closing = false;       // </name>
  bool self_closing = false;  // <name/>
  std::size_t end = 0;        // just past '>'
  int line = 0;
};

class XmlScanner {
 public:
  XmlScanner(const std::string& path, const std::string& data) : path_(path), data_(data) {}

  int line_at(std::size_t pos) {
    for (; counted_ < pos && counted_ < data_.size(); ++counted_)
      if (data_[counted_] == '\n') ++line_;
    return line_;
  }

  // Next element tag from `pos_` (comments, declarations and text skipped); false at end.
  bool next(Tag& tag) {
    while (true) {
      const std::size_t lt = data_.find('<', pos_);
      if (lt == std::string::npos) return false;
      if (data_.compare(lt, 4, "<!--") == 0) {
        const std::size_t e = data_.find("-->", lt + 4);
        if (e == std::string::npos) fail(path_, line_at(lt), "unterminated XML comment");
        pos_ = e + 3;
        continue;
      }
      if (data_.compare(lt, 2, "<?") == 0 || data_.compare(lt, 2, "<!") == 0) {
        const std::size_t e = data_.find('>', lt);
        if (e == std::string::npos) fail(path_, line_at(lt), "unterminated XML declaration");
        pos_ = e + 1;
        continue;
      }
      return parse_tag(lt, tag);
    }
  }

  std::size_t pos() const { return pos_; }
  void set_pos(std::size_t p) { pos_ = p; }

 private:
  static bool is_name_char(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == ':' || c == '-' || c == '.';
  }
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

  bool parse_tag(std::size_t lt, Tag& tag) {
    tag = Tag();
    tag.line = line_at(lt);
    std::size_t p = lt + 1;
    if (p < data_.size() && data_[p] == '/') {
      tag.closing = true;
      ++p;
    }
    const std::size_t name_start = p;
    while (p < data_.size() && is_name_char(data_[p])) ++p;
    tag.name = data_.substr(name_start, p - name_start);
    if (tag.name.empty()) fail(path_, tag.line, "malformed XML tag");
    while (true) {
      while (p < data_.size() && is_space(data_[p])) ++p;
      if (p >= data_.size()) fail(path_, tag.line, "unterminated XML tag <" + tag.name + ">");
      if (data_[p] == '>') {
        ++p;
        break;
      }
      if (data_[p] == '/' && p + 1 < data_.size() && data_[p + 1] == '>') {
        tag.self_closing = true;
        p += 2;
        break;
      }
      const std::size_t a = p;
      while (p < data_.size() && is_name_char(data_[p])) ++p;
      const std::string key = data_.substr(a, p - a);
      while (p < data_.size() && is_space(data_[p])) ++p;
      if (key.empty() || p >= data_.size() || data_[p] != '=')
        fail(path_, line_at(p), "malformed attribute in <" + tag.name + ">");
      ++p;
      while (p < data_.size() && is_space(data_[p])) ++p;
      if (p >= data_.size() || (data_[p] != '"' && data_[p] != '\''))
        fail(path_, line_at(p), "attribute " + key + " of <" + tag.name + "> is not quoted");
      const char q = data_[p++];
      const std::size_t e = data_.find(q, p);
      if (e == std::string::npos) fail(path_, line_at(p), "unterminated attribute " + key);
      tag.attributes[key] = data_.substr(p, e - p);
      p = e + 1;
    }
    tag.end = p;
    pos_ = p;
    return true;
  }

  const std::string& path_;
  const std::string& data_;
  std::size_t pos_ = 0;
  std::size_t counted_ = 0;
  int line_ = 1;
};

struct Array {
  bool present = false;
  std::string text;
  int line = 0;  // line where the text starts
};

std::string attribute(const Tag& t, const char* key) {
  const auto it = t.attributes.find(key);
  return it == t.attributes.end() ? std::string() : it->second;
}

}  // namespace

RawMesh read_vtu(const std::string& path, const std::string& data) {
  XmlScanner xml(path, data);
  Tag tag;
  if (!xml.next(tag) || tag.name != "VTKFile")
    fail(path, tag.line, "not a VTK XML file (no <VTKFile>)");
  if (attribute(tag, "type") != "UnstructuredGrid")
    fail(path, tag.line,
         "VTKFile type must be UnstructuredGrid, got " + quoted(attribute(tag, "type")));
  if (!attribute(tag, "compressor").empty())
    fail(path, tag.line, "compressed .vtu files are not supported (write ascii DataArrays)");
  long long num_points = -1, num_cells = -1;
  int piece_line = 0;
  Array points, connectivity, offsets, types;
  std::vector<std::string> stack = {"VTKFile"};
  while (xml.next(tag)) {
    if (tag.closing) {
      if (stack.empty() || stack.back() != tag.name)
        fail(path, tag.line, "unexpected </" + tag.name + ">");
      stack.pop_back();
      continue;
    }
    if (tag.name == "AppendedData")
      fail(path, tag.line, "appended data is not supported (write ascii DataArrays)");
    if (tag.name == "Piece") {
      if (num_points >= 0) fail(path, tag.line, "more than one <Piece> is not supported");
      piece_line = tag.line;
      long long v;
      if (!parse_int(attribute(tag, "NumberOfPoints"), v) || v < 0)
        fail(path, tag.line, "bad or missing NumberOfPoints");
      num_points = v;
      if (!parse_int(attribute(tag, "NumberOfCells"), v) || v < 0)
        fail(path, tag.line, "bad or missing NumberOfCells");
      num_cells = v;
      if (static_cast<unsigned long long>(num_points) > data.size() ||
          static_cast<unsigned long long>(num_cells) > data.size())
        fail(path, tag.line, "NumberOfPoints/NumberOfCells exceed what the file holds");
    }
    if (tag.name == "DataArray" && !tag.self_closing && !stack.empty() &&
        (stack.back() == "Points" || stack.back() == "Cells")) {
      Array* target = nullptr;
      const std::string name = attribute(tag, "Name");
      if (stack.back() == "Points")
        target = &points;
      else if (name == "connectivity")
        target = &connectivity;
      else if (name == "offsets")
        target = &offsets;
      else if (name == "types")
        target = &types;
      if (target) {
        if (target->present) fail(path, tag.line, "duplicate DataArray " + quoted(name));
        const std::string format = attribute(tag, "format");
        if (format != "ascii")
          fail(path, tag.line,
               "DataArray " + quoted(name) + " has format " + quoted(format) +
                   "; only ascii is supported");
        if (target == &points && attribute(tag, "NumberOfComponents") != "3")
          fail(path, tag.line, "Points DataArray must have NumberOfComponents=\"3\"");
        const std::size_t end = data.find("</DataArray", tag.end);
        if (end == std::string::npos) fail(path, tag.line, "unterminated DataArray");
        target->present = true;
        target->text = data.substr(tag.end, end - tag.end);
        target->line = xml.line_at(tag.end);
        xml.set_pos(end);
      }
    }
    if (!tag.self_closing) stack.push_back(tag.name);
  }
  if (!stack.empty()) fail(path, 0, "unterminated <" + stack.back() + "> (truncated file?)");
  if (num_points < 0) fail(path, 0, "no <Piece> element");
  if (!points.present) fail(path, piece_line, "no Points DataArray");
  if (!connectivity.present || !offsets.present || !types.present)
    fail(path, piece_line, "Cells needs connectivity, offsets and types DataArrays");

  RawMesh out;
  {
    TextCursor c(path, points.text, '\0', points.line);
    for (long long i = 0; i < num_points; ++i) {
      Vec3 x;
      x.x() = c.real("x coordinate");
      const int line = c.line();
      x.y() = c.real("y coordinate");
      x.z() = c.real("z coordinate");
      out.mesh.nodes.push_back(x);
      out.lines.node_line.push_back(line);
    }
    if (!c.at_end()) {
      c.token("");
      c.fail("Points has more values than 3 x NumberOfPoints");
    }
  }
  auto read_ints = [&](const Array& a, long long n, const char* what, std::vector<int>* lines) {
    TextCursor c(path, a.text, '\0', a.line);
    std::vector<long long> v;
    for (long long i = 0; i < n; ++i) {
      v.push_back(c.integer(what));
      if (lines) lines->push_back(c.line());
    }
    if (!c.at_end()) {
      c.token("");
      c.fail(std::string("more ") + what + " values than expected");
    }
    return v;
  };
  std::vector<int> offset_lines;
  const std::vector<long long> off = read_ints(offsets, num_cells, "offset", &offset_lines);
  const std::vector<long long> type = read_ints(types, num_cells, "cell type", nullptr);
  long long conn_size = off.empty() ? 0 : off.back();
  if (conn_size < 0 || static_cast<unsigned long long>(conn_size) > data.size())
    fail(path, connectivity.line, "bad last offset " + std::to_string(conn_size));
  const std::vector<long long> conn =
      read_ints(connectivity, conn_size, "connectivity index", nullptr);
  long long prev = 0;
  for (long long i = 0; i < num_cells; ++i) {
    const long long end = off[static_cast<std::size_t>(i)];
    const int line = offset_lines[static_cast<std::size_t>(i)];
    if (end < prev) fail(path, line, "offsets decrease at cell " + std::to_string(i));
    if (type[static_cast<std::size_t>(i)] == 10) {
      if (end - prev != 4)
        fail(path, line,
             "cell " + std::to_string(i) + " is a tetrahedron (type 10) with " +
                 std::to_string(end - prev) + " points");
      Tet t;
      for (int k = 0; k < 4; ++k) {
        const long long v = conn[static_cast<std::size_t>(prev + k)];
        if (v < 0 || v >= num_points)
          fail(path, connectivity.line,
               "cell " + std::to_string(i) + " refers to point " + std::to_string(v) +
                   ", out of range [0, " + std::to_string(num_points) + ")");
        t[k] = static_cast<int>(v);
      }
      out.mesh.tets.push_back(t);
      out.lines.tet_line.push_back(line);
    }
    prev = end;
  }
  return out;
}

}  // namespace stc::io
