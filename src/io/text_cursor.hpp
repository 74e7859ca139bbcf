// A bounds-checked reader over a whole file held in memory, for the mesh readers: tokens,
// lines and raw binary blocks, tracking the line number for messages (docs/SCENE.md "Meshes": name
// the line).
#pragma once

#include "soft_tissue_cutting/io/mesh_error.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace stc::io {

// Loads the whole file; throws MeshError "path: cannot open ..." when it cannot be read.
std::string read_file(const std::string& path);

// "path:line: what" (or "path: what" for line <= 0).
[[noreturn]] void fail(const std::string& path, int line, const std::string& what);

// Number parsing without locale or exceptions; the whole token must be a number.
bool parse_int(std::string_view s, long long& out);
bool parse_double(std::string_view s, double& out);  // accepts nan/inf; caller checks

class TextCursor {
 public:
  // `comment` starts a comment running to the end of the line ('\0': no comments).
  // `first_line`: line number of data[0] when `data` is an excerpt of the file.
  TextCursor(const std::string& path, const std::string& data, char comment = '\0',
             int first_line = 1)
      : path_(path), data_(data), comment_(comment), line_(first_line), last_line_(first_line) {}

  const std::string& path() const { return path_; }
  // Line of the last token read (1-based); the current line before any.
  int line() const { return last_line_; }
  [[noreturn]] void fail(const std::string& what) const { io::fail(path_, last_line_, what); }

  // Skips whitespace and comments; true at end of data.
  bool at_end();
  // Next whitespace-separated token; fails "unexpected end of file, expected <what>".
  std::string_view token(const char* what);
  // Next token if it is on the current line, empty otherwise (end of line or file).
  std::string_view token_on_line();
  // Tokens of the next non-blank line.
  std::vector<std::string_view> line_tokens(const char* what);
  // Rest of the current line (possibly empty) and moves past its newline.
  std::string_view rest_of_line();

  long long integer(const char* what);
  // An integer token in [lo, hi].
  long long integer(const char* what, long long lo, long long hi);
  double real(const char* what);  // finite, else fails
  long long to_integer(std::string_view tok, const char* what);
  double to_real(std::string_view tok, const char* what);

  // Raw bytes for binary blocks: `n` bytes from here, fails when fewer remain.
  const char* raw(std::size_t n, const char* what);
  std::size_t remaining() const { return data_.size() - pos_; }
  std::size_t pos() const { return pos_; }
  // Moves past the next newline (the end of a header line before binary data).
  void skip_past_newline();
  // Finds `needle` from here; moves past it. False (and no move) when absent.
  bool skip_past(std::string_view needle);

 private:
  void skip_space();

  const std::string& path_;
  const std::string& data_;
  char comment_;
  std::size_t pos_ = 0;
  int line_;       // line at pos_
  int last_line_;  // line of the last token
};

// Binary numbers, endianness as the file says.
template <typename T>
T load_binary(const char* p, bool swap) {
  unsigned char b[sizeof(T)];
  for (std::size_t i = 0; i < sizeof(T); ++i)
    b[i] = static_cast<unsigned char>(p[swap ? sizeof(T) - 1 - i : i]);
  T v;
  __builtin_memcpy(&v, b, sizeof(T));
  return v;
}
bool host_is_little_endian();

std::string lower(std::string_view s);
std::string quoted(std::string_view s);  // short, printable excerpt of a token for messages

}  // namespace stc::io
