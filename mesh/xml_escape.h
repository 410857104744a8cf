// XML text escaping, shared by the VTU writer (array names) and the SVG plots (labels).
#pragma once

#include <string>
#include <string_view>

namespace polydg {

/// `text` with the five XML special characters replaced by their entities, safe inside
/// element content and inside single- or double-quoted attribute values.
inline std::string xmlEscape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace polydg
