#include "soft_tissue_cutting/solve/backend.hpp"

namespace stc {

std::optional<Backend> parse_backend(const std::string& name) {
  if (name == "cpu") return Backend::kCpu;
  if (name == "gl") return Backend::kGl;
  return std::nullopt;
}

const char* backend_name(Backend backend) { return backend == Backend::kGl ? "gl" : "cpu"; }

}  // namespace stc
