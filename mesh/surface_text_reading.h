// Reading surface file text line by line and word by word, and the numbers in it, for the
// format checks of mesh/surface_text_check.h; with the wording their messages share.
#pragma once

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <vector>

#include "mesh/surface_text_check.h"

namespace polydg::surface_text {

/// Characters that separate words in every format here (CR included, so CRLF files read like LF).
inline bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// The words of `line`, into `out` (cleared first, so that one buffer serves every line).
inline void splitWords(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  std::size_t i = 0;
  while (true) {
    while (i < line.size() && isSpace(line[i])) ++i;
    if (i == line.size()) return;
    const std::size_t start = i;
    while (i < line.size() && !isSpace(line[i])) ++i;
    out.push_back(line.substr(start, i - start));
  }
}

/// `line` up to its first '#'.
inline std::string_view uncommented(std::string_view line) {
  return line.substr(0, std::min(line.size(), line.find('#')));
}

/// `token` quoted for a message, shortened if long.
inline std::string quoted(std::string_view token) {
  constexpr std::size_t kLongest = 40;
  if (token.size() > kLongest) return "'" + std::string(token.substr(0, kLongest - 3)) + "...'";
  return "'" + std::string(token) + "'";
}

/// The lines of a text from `offset` on, numbered from `firstLine`; a line excludes its '\n'.
class LineReader {
 public:
  LineReader(std::string_view text, std::size_t offset, std::size_t firstLine)
      : text_(text), next_(offset), nextNumber_(firstLine), number_(firstLine) {}

  /// The next line, or false at the end of the text.
  bool next(std::string_view& line) {
    if (next_ >= text_.size()) return false;
    std::size_t end = text_.find('\n', next_);
    if (end == std::string_view::npos) end = text_.size();
    line = text_.substr(next_, end - next_);
    next_ = end + 1;
    number_ = nextNumber_++;
    return true;
  }
  /// The number of the line `next` returned last (the first line's before any).
  std::size_t number() const { return number_; }
  /// Where the line after the last one returned starts.
  std::size_t position() const { return next_; }

 private:
  std::string_view text_;
  std::size_t next_, nextNumber_, number_;
};

/// The words of a text one by one with their line numbers, as a stream reader takes them.
class WordReader {
 public:
  explicit WordReader(std::string_view text) : lines_(text, 0, 1) {}

  bool next(std::string_view& word) {
    while (index_ == words_.size()) {
      std::string_view line;
      if (!lines_.next(line)) return false;
      splitWords(line, words_);
      index_ = 0;
    }
    word = words_[index_++];
    return true;
  }
  /// The words after the last one returned, up to the end of its line; they are skipped.
  std::vector<std::string_view> restOfLine() {
    std::vector<std::string_view> rest(words_.begin() + static_cast<std::ptrdiff_t>(index_),
                                       words_.end());
    index_ = words_.size();
    return rest;
  }
  /// The line of the last word returned.
  std::size_t line() const { return lines_.number(); }

 private:
  LineReader lines_;
  std::vector<std::string_view> words_;
  std::size_t index_ = 0;
};

/// The value of a token isDecimalNumber accepts, correctly rounded to T; +-infinity if it is
/// beyond T's range (a value too small for T is its nearest subnormal or zero, as streams read
/// it).
template <typename T>
T realValue(std::string_view token) {
  if (token.starts_with('+')) token.remove_prefix(1);
  T value{};
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (error == std::errc()) return value;
  // Out of range: from_chars does not say which way.
  const std::string text(token);
  if constexpr (std::is_same_v<T, float>)
    return std::strtof(text.c_str(), nullptr);
  else
    return std::strtod(text.c_str(), nullptr);
}

/// The value of a token isIntegerNumber accepts, or nothing if it is beyond 64 bits.
inline std::optional<long long> integerValue(std::string_view token) {
  if (token.starts_with('+')) token.remove_prefix(1);
  long long value = 0;
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (error != std::errc()) return std::nullopt;
  return value;
}

/// Why `token` is not a finite double, or "" if it is one; then `value` (if given) receives it,
/// correctly rounded (a coordinate is parsed once).
inline std::string coordinateProblem(std::string_view token, double* value = nullptr) {
  if (!isDecimalNumber(token)) return "coordinate " + quoted(token) + " is not a number";
  const double v = realValue<double>(token);
  if (!std::isfinite(v)) return "coordinate " + quoted(token) + " is beyond the range of double";
  if (value) *value = v;
  return "";
}

/// "1 number", "2 numbers".
inline std::string numbers(std::size_t n) {
  return std::to_string(n) + (n == 1 ? " number" : " numbers");
}

}  // namespace polydg::surface_text
