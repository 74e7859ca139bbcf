#include "yaml_fields.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <set>

namespace stc::scene_yaml {
namespace {

std::string describe(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "nothing";
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a map";
  std::string s = n.Scalar();
  if (s.size() > 30) s = s.substr(0, 30) + "...";
  return "'" + s + "'";
}

}  // namespace

void Fields::fail(const YAML::Node& at, const std::string& key, const std::string& what) const {
  std::string message = file_;
  if (at.IsDefined()) {
    const YAML::Mark mark = at.Mark();
    if (!mark.is_null() && mark.line >= 0) message += ":" + std::to_string(mark.line + 1);
  }
  throw SceneError(message + ": " + key + ": " + what);
}

void Fields::check_map(const YAML::Node& node, const std::string& key,
                       std::initializer_list<const char*> allowed) const {
  if (!node.IsMap()) fail(node, key, "expected a map, got " + describe(node));
  std::set<std::string> seen;
  for (const auto& kv : node) {
    if (!kv.first.IsScalar()) fail(kv.first, key, "map keys must be plain names");
    const std::string name = kv.first.Scalar();
    bool ok = false;
    for (const char* a : allowed) ok |= name == a;
    const std::string where = key.empty() ? name : key + "." + name;
    if (!ok) {
      std::string list;
      for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
      fail(kv.first, where, "unknown key (allowed here: " + list + ")");
    }
    if (!seen.insert(name).second) fail(kv.first, where, "duplicate key");
  }
}

int Fields::count_present(const YAML::Node& map, std::initializer_list<const char*> keys) const {
  int n = 0;
  for (const char* k : keys) n += map[k] ? 1 : 0;
  return n;
}

double Fields::number(const YAML::Node& node, const std::string& key) const {
  // Quoted scalars are strings, not numbers (tag "!").
  if (!node.IsScalar() || node.Tag() == "!")
    fail(node, key, "expected a number, got " + describe(node));
  std::string s = node.Scalar();
  const std::string low = [&] {
    std::string l = s;
    for (char& c : l) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return l;
  }();
  if (low == ".nan" || low == ".inf" || low == "-.inf" || low == "+.inf" || low == "nan" ||
      low == "inf" || low == "-inf" || low == "infinity" || low == "-infinity")
    fail(node, key, "must be a finite number, got '" + s + "'");
  std::string_view v = s;
  if (!v.empty() && v[0] == '+') v.remove_prefix(1);
  double out = 0;
  const auto r = std::from_chars(v.data(), v.data() + v.size(), out);
  if (v.empty() || r.ec != std::errc() || r.ptr != v.data() + v.size())
    fail(node, key, "expected a number, got " + describe(node));
  if (!std::isfinite(out)) fail(node, key, "must be a finite number, got '" + s + "'");
  return out;
}

double Fields::positive(const YAML::Node& node, const std::string& key) const {
  const double v = number(node, key);
  if (!(v > 0)) fail(node, key, "must be > 0, got " + node.Scalar());
  return v;
}

double Fields::non_negative(const YAML::Node& node, const std::string& key) const {
  const double v = number(node, key);
  if (!(v >= 0)) fail(node, key, "must be >= 0, got " + node.Scalar());
  return v;
}

long long Fields::integer(const YAML::Node& node, const std::string& key, long long lo,
                          long long hi) const {
  if (!node.IsScalar() || node.Tag() == "!")
    fail(node, key, "expected an integer, got " + describe(node));
  std::string_view v = node.Scalar();
  if (!v.empty() && v[0] == '+') v.remove_prefix(1);
  long long out = 0;
  const auto r = std::from_chars(v.data(), v.data() + v.size(), out);
  if (v.empty() || r.ec != std::errc() || r.ptr != v.data() + v.size())
    fail(node, key, "expected an integer, got " + describe(node));
  if (out < lo || out > hi)
    fail(node, key,
         std::to_string(out) + " out of range [" + std::to_string(lo) + ", " + std::to_string(hi) +
             "]");
  return out;
}

std::string Fields::string(const YAML::Node& node, const std::string& key) const {
  if (!node.IsScalar()) fail(node, key, "expected a string, got " + describe(node));
  return node.Scalar();
}

std::vector<double> Fields::numbers(const YAML::Node& node, const std::string& key,
                                    std::size_t count) const {
  if (!node.IsSequence() || node.size() != count)
    fail(node, key,
         "expected a list of " + std::to_string(count) + " numbers, got " +
             (node.IsSequence() ? "a list of " + std::to_string(node.size()) : describe(node)));
  std::vector<double> out;
  for (std::size_t i = 0; i < count; ++i)
    out.push_back(number(node[i], key + "[" + std::to_string(i) + "]"));
  return out;
}

Vec3 Fields::vec3(const YAML::Node& node, const std::string& key) const {
  const auto v = numbers(node, key, 3);
  return Vec3(v[0], v[1], v[2]);
}

}  // namespace stc::scene_yaml
