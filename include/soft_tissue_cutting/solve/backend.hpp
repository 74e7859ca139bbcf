// The solver backends (docs/SCENE.md "Scene file", `solver.backend`): one enum and one parser for
// every place that names them (scene loader, ~backend, `tissue solve --backend`, Simulation).
#pragma once

#include <optional>
#include <string>

namespace stc {

enum class Backend { kCpu, kGl };

// "cpu" -> kCpu, "gl" -> kGl, anything else -> nullopt.
std::optional<Backend> parse_backend(const std::string& name);
// The name parse_backend reads ("cpu", "gl"); also what stats and messages report.
const char* backend_name(Backend backend);
// For error messages: "cpu or gl".
constexpr const char* kBackendChoices = "cpu or gl";

}  // namespace stc
