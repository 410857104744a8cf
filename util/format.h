// Numbers and other libraries' words in messages and summaries.
#pragma once

#include <cctype>
#include <sstream>
#include <string>

namespace polydg {

/// x with `precision` significant digits, as std::ostream prints it ("3.47222", "1.27e+30").
inline std::string formatNumber(double x, int precision = 6) {
  std::ostringstream s;
  s.precision(precision);
  s << x;
  return s.str();
}

/// `text` (another library's message) on one line: line breaks and runs of white space become
/// one space, the ends trimmed; "unknown error" if nothing is left.
inline std::string oneLine(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (std::isspace(static_cast<unsigned char>(c))) {
      if (!out.empty() && out.back() != ' ') out += ' ';
    } else {
      out += c;
    }
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out.empty() ? "unknown error" : out;
}

}  // namespace polydg
