// Strict typed access to yaml-cpp nodes for the scene loader: every problem becomes a
// SceneError "file:line: key.path: problem" (docs/SCENE.md "Scene file"). Private to src/scene.
#pragma once

#include "soft_tissue_cutting/mesh/tet_mesh.hpp"
#include "soft_tissue_cutting/scene/scene_loader.hpp"

#include <yaml-cpp/yaml.h>

#include <initializer_list>
#include <string>
#include <vector>

namespace stc::scene_yaml {

class Fields {
 public:
  explicit Fields(std::string file) : file_(std::move(file)) {}

  const std::string& file() const { return file_; }

  // The node's line when yaml-cpp has one.
  [[noreturn]] void fail(const YAML::Node& at, const std::string& key,
                         const std::string& what) const;

  // `node` must be a map whose keys are all in `allowed` (no duplicates).
  void check_map(const YAML::Node& node, const std::string& key,
                 std::initializer_list<const char*> allowed) const;
  // How many of `keys` the map has.
  int count_present(const YAML::Node& map, std::initializer_list<const char*> keys) const;

  double number(const YAML::Node& node, const std::string& key) const;        // finite
  double positive(const YAML::Node& node, const std::string& key) const;      // > 0
  double non_negative(const YAML::Node& node, const std::string& key) const;  // >= 0
  long long integer(const YAML::Node& node, const std::string& key, long long lo,
                    long long hi) const;
  std::string string(const YAML::Node& node, const std::string& key) const;
  Vec3 vec3(const YAML::Node& node, const std::string& key) const;
  std::vector<double> numbers(const YAML::Node& node, const std::string& key,
                              std::size_t count) const;

 private:
  std::string file_;
};

}  // namespace stc::scene_yaml
