#include "soft_tissue_cutting/ros/log_text.hpp"

namespace stc {
namespace ros_io {

std::string shorten(const std::string& text, std::size_t max_chars) {
  if (text.size() <= max_chars) return text;
  return text.substr(0, max_chars) + "... (" + std::to_string(text.size()) + " bytes)";
}

}  // namespace ros_io
}  // namespace stc
