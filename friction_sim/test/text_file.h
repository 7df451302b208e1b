// A whole text file as one string, for the tests that compare files written by a run.
#pragma once

#include <fstream>
#include <sstream>
#include <string>

namespace friction::testing {

/// The whole text of the file at `path` ("" if it cannot be read).
inline std::string readFile(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

}  // namespace friction::testing
