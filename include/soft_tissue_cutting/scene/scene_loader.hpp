// Loading and validating a scene file (docs/SCENE.md "Scene file", a contract).
#pragma once

#include "soft_tissue_cutting/scene/scene.hpp"

#include <stdexcept>
#include <string>

namespace stc {

// what() is one line: "scene.yaml:LINE: key.path: problem" (LINE when yaml-cpp knows it).
class SceneError : public std::runtime_error {
 public:
  explicit SceneError(const std::string& message) : std::runtime_error(message) {}
};

// Loads a scene YAML file, or the built-in scene when given "thigh". Mesh paths are relative
// to the scene file; the mesh is scaled by mesh.scale before any selector, region or pose is
// applied. Strict: unknown keys, wrong types or lengths, non-finite or out-of-range values, a
// selector that matches no node, no fixed node at all, or an unusable mesh throw SceneError;
// nothing is half-loaded. Mesh warnings land in Scene::warnings.
Scene load_scene(const std::string& path_or_builtin);

}  // namespace stc
