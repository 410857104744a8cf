// Numbers in messages and summaries: what a stream prints at a given precision.
#pragma once

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

}  // namespace polydg
