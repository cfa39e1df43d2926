// Reading back what a helper program printed (a Python script run on mrcal's side of a test): the
// numbers on the first line that starts with a given word.
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace arpipe::test {

// "key 1.5 2 3e-4" -> {1.5, 2, 3e-4}; empty when no line starts with `key`.
inline std::vector<double> numbers_after(const std::string& text, const std::string& key) {
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string first;
    words >> first;
    if (first != key) continue;
    std::vector<double> out;
    for (double x; words >> x;) out.push_back(x);
    return out;
  }
  return {};
}

}  // namespace arpipe::test
