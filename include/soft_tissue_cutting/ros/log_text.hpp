// Caller-supplied text (paths, frame names) echoed in service replies and log lines is
// shortened, so a 1 MB string in a request does not come back (or reach rosout) whole.
#pragma once

#include <cstddef>
#include <string>

namespace stc {
namespace ros_io {

constexpr std::size_t kMaxEchoedChars = 160;

// `text` if it is at most max_chars long, else its first max_chars characters followed by
// "... (N bytes)".
std::string shorten(const std::string& text, std::size_t max_chars = kMaxEchoedChars);

}  // namespace ros_io
}  // namespace stc
