// The one exception type of mesh input/output (docs/SCENE.md "Meshes": one clear line naming file
// and line).
#pragma once

#include <stdexcept>
#include <string>

namespace stc {

// what() is a single line: "path:line: what is wrong" (or "path: what is wrong" when no line
// applies, e.g. a face shared by three tets).
class MeshError : public std::runtime_error {
 public:
  explicit MeshError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace stc
