// How many free pieces one core log message reports: the simulation says "a piece of T tets
// was cut free; ..." or "N pieces (T tets in all) were cut free; ..." once per cut (a test
// helper for the tests that check every held piece is reported).
#pragma once

#include <string>

namespace stc::test {

inline int pieces_reported(const std::string& message) {
  if (message.find("cut free") == std::string::npos) return 0;
  if (message.rfind("a piece of ", 0) == 0) return 1;
  const size_t space = message.find(" pieces (");
  return space == std::string::npos ? 0 : std::stoi(message.substr(0, space));
}

}  // namespace stc::test
