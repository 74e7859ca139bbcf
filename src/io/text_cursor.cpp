#include "text_cursor.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

namespace stc::io {
namespace {

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

}  // namespace

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, 0, "cannot open file");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) fail(path, 0, "cannot read file");
  return ss.str();
}

void fail(const std::string& path, int line, const std::string& what) {
  if (line > 0) throw MeshError(path + ":" + std::to_string(line) + ": " + what);
  throw MeshError(path + ": " + what);
}

bool parse_int(std::string_view s, long long& out) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

bool parse_double(std::string_view s, double& out) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

bool host_is_little_endian() {
  const std::uint16_t one = 1;
  unsigned char b;
  __builtin_memcpy(&b, &one, 1);
  return b == 1;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return out;
}

std::string quoted(std::string_view s) {
  std::string out = "'";
  for (std::size_t i = 0; i < s.size() && i < 24; ++i) {
    const char c = s[i];
    out += (c >= 32 && c < 127) ? c : '?';
  }
  if (s.size() > 24) out += "...";
  return out + "'";
}

void TextCursor::skip_space() {
  while (pos_ < data_.size()) {
    const char c = data_[pos_];
    if (c == '\n') {
      ++line_;
      ++pos_;
    } else if (is_space(c)) {
      ++pos_;
    } else if (comment_ != '\0' && c == comment_) {
      while (pos_ < data_.size() && data_[pos_] != '\n') ++pos_;
    } else {
      break;
    }
  }
}

bool TextCursor::at_end() {
  skip_space();
  return pos_ >= data_.size();
}

std::string_view TextCursor::token(const char* what) {
  skip_space();
  last_line_ = line_;
  if (pos_ >= data_.size()) fail(std::string("unexpected end of file, expected ") + what);
  const std::size_t start = pos_;
  while (pos_ < data_.size() && !is_space(data_[pos_]) &&
         !(comment_ != '\0' && data_[pos_] == comment_))
    ++pos_;
  return std::string_view(data_).substr(start, pos_ - start);
}

std::string_view TextCursor::token_on_line() {
  while (pos_ < data_.size() && data_[pos_] != '\n' && is_space(data_[pos_])) ++pos_;
  if (pos_ < data_.size() && comment_ != '\0' && data_[pos_] == comment_)
    while (pos_ < data_.size() && data_[pos_] != '\n') ++pos_;
  if (pos_ >= data_.size() || data_[pos_] == '\n') return {};
  last_line_ = line_;
  const std::size_t start = pos_;
  while (pos_ < data_.size() && !is_space(data_[pos_]) &&
         !(comment_ != '\0' && data_[pos_] == comment_))
    ++pos_;
  return std::string_view(data_).substr(start, pos_ - start);
}

std::vector<std::string_view> TextCursor::line_tokens(const char* what) {
  skip_space();
  last_line_ = line_;
  if (pos_ >= data_.size()) fail(std::string("unexpected end of file, expected ") + what);
  const int line = line_;
  std::vector<std::string_view> out;
  for (std::string_view t = token_on_line(); !t.empty(); t = token_on_line()) out.push_back(t);
  last_line_ = line;
  if (pos_ < data_.size()) {  // at the newline
    ++pos_;
    ++line_;
  }
  return out;
}

std::string_view TextCursor::rest_of_line() {
  last_line_ = line_;
  const std::size_t start = pos_;
  while (pos_ < data_.size() && data_[pos_] != '\n') ++pos_;
  std::string_view out = std::string_view(data_).substr(start, pos_ - start);
  if (pos_ < data_.size()) {
    ++pos_;
    ++line_;
  }
  while (!out.empty() && is_space(out.back())) out.remove_suffix(1);
  while (!out.empty() && is_space(out.front())) out.remove_prefix(1);
  return out;
}

long long TextCursor::to_integer(std::string_view tok, const char* what) {
  long long v = 0;
  if (!parse_int(tok, v))
    fail(std::string("expected ") + what + " (an integer), got " + quoted(tok));
  return v;
}

double TextCursor::to_real(std::string_view tok, const char* what) {
  double v = 0;
  if (!parse_double(tok, v))
    fail(std::string("expected ") + what + " (a number), got " + quoted(tok));
  if (!std::isfinite(v)) fail(std::string("non-finite ") + what + " " + quoted(tok));
  return v;
}

long long TextCursor::integer(const char* what) { return to_integer(token(what), what); }

long long TextCursor::integer(const char* what, long long lo, long long hi) {
  const long long v = integer(what);
  if (v < lo || v > hi)
    fail(std::string(what) + " " + std::to_string(v) + " out of range [" + std::to_string(lo) +
         ", " + std::to_string(hi) + "]");
  return v;
}

double TextCursor::real(const char* what) { return to_real(token(what), what); }

const char* TextCursor::raw(std::size_t n, const char* what) {
  last_line_ = line_;
  if (n > remaining())
    fail(std::string("truncated binary ") + what + ": need " + std::to_string(n) +
         " bytes, file has " + std::to_string(remaining()) + " left");
  const char* p = data_.data() + pos_;
  // Count newline bytes so later messages show the line an editor would.
  for (std::size_t i = 0; i < n; ++i)
    if (p[i] == '\n') ++line_;
  pos_ += n;
  return p;
}

void TextCursor::skip_past_newline() {
  while (pos_ < data_.size() && data_[pos_] != '\n') ++pos_;
  if (pos_ < data_.size()) {
    ++pos_;
    ++line_;
  }
}

bool TextCursor::skip_past(std::string_view needle) {
  const std::size_t at = data_.find(needle, pos_);
  if (at == std::string::npos) return false;
  for (std::size_t i = pos_; i < at + needle.size(); ++i)
    if (data_[i] == '\n') ++line_;
  pos_ = at + needle.size();
  last_line_ = line_;
  return true;
}

}  // namespace stc::io
