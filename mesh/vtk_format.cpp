#include "mesh/vtk_format.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <type_traits>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <zlib.h>
#include <pugixml.hpp>

#include "mesh/xml_escape.h"
#include "util/uninitialized.h"

namespace polydg::vtk_format {

// ============================================================================================
// Base64
// ============================================================================================

namespace {

constexpr char kBase64Alphabet[] =
    "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

int base64Value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

}  // namespace

void Base64Writer::write(const void* data, std::size_t size) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    group_[count_++] = bytes[i];
    if (count_ == 3) emit();
  }
}

void Base64Writer::finish() {
  if (count_ > 0) emit();
}

void Base64Writer::emit() {
  const std::uint32_t bits = (std::uint32_t{group_[0]} << 16) |
                             (count_ > 1 ? std::uint32_t{group_[1]} << 8 : 0) |
                             (count_ > 2 ? std::uint32_t{group_[2]} : 0);
  char out[4] = {kBase64Alphabet[(bits >> 18) & 63], kBase64Alphabet[(bits >> 12) & 63],
                 count_ > 1 ? kBase64Alphabet[(bits >> 6) & 63] : '=',
                 count_ > 2 ? kBase64Alphabet[bits & 63] : '='};
  os_.write(out, 4);
  count_ = 0;
}

bool isXmlSpace(char c) { return c == ' ' || c == '\n' || c == '\r' || c == '\t'; }

bool ByteReader::read(std::size_t n, std::string& out) {
  if (!base64_) {
    if (n > data_.size() - pos_) return false;
    out.append(data_.substr(pos_, n));
    pos_ += n;
    return true;
  }
  while (pending_.size() - pendingPos_ < n) {
    if (!decodeGroup()) return false;
  }
  out.append(pending_, pendingPos_, n);
  pendingPos_ += n;
  if (pendingPos_ == pending_.size()) {
    pending_.clear();
    pendingPos_ = 0;
  }
  return true;
}

std::size_t ByteReader::maxRemaining() const {
  const std::size_t left = data_.size() - pos_;
  return base64_ ? left / 4 * 3 + 3 + (pending_.size() - pendingPos_) : left;
}

/// Decodes the next group into pending_; false at the end of the text.
bool ByteReader::decodeGroup() {
  int values[4];
  int count = 0;
  int padding = 0;
  while (count < 4) {
    while (pos_ < data_.size() && isXmlSpace(data_[pos_])) ++pos_;
    if (pos_ == data_.size()) {
      if (count == 0) return false;
      throw FormatError("base64 data ends inside a group of four characters");
    }
    const char c = data_[pos_++];
    if (c == '=' && count >= 2) {
      ++padding;
      values[count++] = 0;
    } else {
      const int v = base64Value(c);
      if (v < 0 || padding > 0)
        throw FormatError(std::string("invalid character '") + c + "' in base64 data");
      values[count++] = v;
    }
  }
  const std::uint32_t bits = (std::uint32_t(values[0]) << 18) | (std::uint32_t(values[1]) << 12) |
                             (std::uint32_t(values[2]) << 6) | std::uint32_t(values[3]);
  pending_.push_back(static_cast<char>((bits >> 16) & 0xff));
  if (padding < 2) pending_.push_back(static_cast<char>((bits >> 8) & 0xff));
  if (padding < 1) pending_.push_back(static_cast<char>(bits & 0xff));
  return true;
}

std::string base64Encode(std::string_view bytes) {
  std::ostringstream os;
  Base64Writer out(os);
  out.write(bytes.data(), bytes.size());
  out.finish();
  return os.str();
}

std::string base64Decode(std::string_view text) {
  ByteReader in(text, /*base64=*/true);
  std::string out;
  while (in.read(1, out)) {
  }
  return out;
}

// ============================================================================================
// Writing
// ============================================================================================

namespace {

std::string_view vtkTypeName(StoredType t) {
  switch (t) {
    case StoredType::Float64: return "Float64";
    case StoredType::UInt8: return "UInt8";
    case StoredType::Int32: return "Int32";
    case StoredType::Int64: return "Int64";
  }
  return "Int64";
}

std::size_t storedSize(StoredType t) {
  switch (t) {
    case StoredType::UInt8: return 1;
    case StoredType::Int32: return 4;
    default: return 8;
  }
}

/// Appends `values`, stored as `stored` (little-endian), to `out`.
template <class T>
void storeValues(StoredType stored, std::span<const T> values, std::vector<char>& out) {
  const std::size_t at = out.size();
  out.resize(at + values.size() * storedSize(stored));
  char* p = out.data() + at;
  auto put = [&](auto value) {
    auto bytes = std::bit_cast<std::array<char, sizeof value>>(value);
    if constexpr (std::endian::native == std::endian::big) std::reverse(bytes.begin(), bytes.end());
    std::memcpy(p, bytes.data(), bytes.size());
    p += bytes.size();
  };
  for (const T value : values) {
    if constexpr (std::is_same_v<T, double>) {
      put(value);
    } else {
      switch (stored) {
        case StoredType::UInt8: put(static_cast<std::uint8_t>(value)); break;
        case StoredType::Int32: put(static_cast<std::int32_t>(value)); break;
        default: put(value); break;
      }
    }
  }
}

/// Values of a generated array that one task makes: a chunk is split into ranges of this many.
constexpr std::size_t kFillGrain = 1 << 14;

/// Hands a generated array's values to f(first, values) chunk by chunk, each chunk filled by
/// ranges on all cores (every position gets its value whatever the range, so the bytes never
/// depend on the schedule).
template <class T, class Fill, class F>
void forEachChunk(const ArrayOut& a, const Fill& fill, F&& f) {
  const std::size_t chunk = std::max<std::size_t>(a.chunk, 1);
  UninitializedVector<T> run(std::min(a.size(), chunk));  // every value is filled below
  for (std::size_t begin = 0; begin < a.size(); begin += chunk) {
    const std::size_t end = std::min(a.size(), begin + chunk);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, kFillGrain),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        fill(r.begin(), r.end(), run.data() + (r.begin() - begin));
                      });
    f(begin, std::span<const T>(run.data(), end - begin));
  }
}

/// Hands the values of `a` to f(first, values), values[i] being value first + i: a held array
/// in one run, a generated one chunk by chunk (forEachChunk).
template <class F>
void forEachRun(const ArrayOut& a, F&& f) {
  const bool real = a.stored == StoredType::Float64;
  if (!a.isGenerated()) {
    if (real)
      f(std::size_t{0}, a.doubles);
    else
      f(std::size_t{0}, a.integers);
  } else if (real) {
    forEachChunk<double>(a, a.generatedDoubles.fill, f);
  } else {
    forEachChunk<std::int64_t>(a, a.generated.fill, f);
  }
}

/// Writes the UInt64 byte count and the values of `a` as raw bytes to `sink`.
template <class Sink>
void writeBinary(const ArrayOut& a, Sink&& sink) {
  constexpr std::size_t kPiece = 1 << 16;
  std::vector<char> buffer;
  auto count = std::bit_cast<std::array<char, 8>>(std::uint64_t{a.bytes()});
  if constexpr (std::endian::native == std::endian::big) std::reverse(count.begin(), count.end());
  sink(count.data(), count.size());
  forEachRun(a, [&](std::size_t, auto values) {
    for (std::size_t begin = 0; begin < values.size(); begin += kPiece) {
      buffer.clear();
      storeValues(a.stored, values.subspan(begin, std::min(kPiece, values.size() - begin)), buffer);
      sink(buffer.data(), buffer.size());
    }
  });
}

/// The smallest of UInt8, Int32 and Int64 that holds non-negative values up to `largest`.
StoredType intType(std::int64_t largest) {
  return largest < 256                                         ? StoredType::UInt8
         : largest <= std::numeric_limits<std::int32_t>::max() ? StoredType::Int32
                                                               : StoredType::Int64;
}

/// An array with no values yet: its place, name and whether it has NumberOfTuples.
ArrayOut namedArray(std::string_view indent, std::string_view name, bool withTuples) {
  ArrayOut a;
  a.indent = indent;
  a.name = name;
  a.withTuples = withTuples;
  return a;
}

}  // namespace

std::size_t ArrayOut::bytes() const { return size() * storedSize(stored); }

ArrayOut floatArray(std::string_view indent, std::string_view name, int components,
                    std::span<const double> values, bool withTuples) {
  ArrayOut a = namedArray(indent, name, withTuples);
  a.components = components;
  a.doubles = values;
  return a;
}

ArrayOut intArray(std::string_view indent, std::string_view name,
                  std::span<const std::int64_t> values, bool withTuples) {
  const std::int64_t largest = values.empty() ? 0 : *std::max_element(values.begin(), values.end());
  ArrayOut a = namedArray(indent, name, withTuples);
  a.integers = values;
  a.stored = intType(largest);
  return a;
}

ArrayOut generatedFloatArray(std::string_view indent, std::string_view name, int components,
                             GeneratedDoubles values, bool withTuples) {
  ArrayOut a = namedArray(indent, name, withTuples);
  a.components = components;
  a.generatedDoubles = std::move(values);
  return a;
}

ArrayOut generatedIntArray(std::string_view indent, std::string_view name, GeneratedInts values,
                           bool withTuples) {
  ArrayOut a = namedArray(indent, name, withTuples);
  a.stored = intType(values.largest);
  a.generated = std::move(values);
  return a;
}

void writeDataArray(std::ostream& os, const ArrayOut& a, VtuEncoding encoding, std::size_t offset) {
  os << a.indent << "<DataArray type=\"" << vtkTypeName(a.stored) << "\" Name=\""
     << xmlEscape(a.name) << '"';
  // Like VTK, only for several components: meshio 5 turns any array that has the attribute
  // into a 2D one, which its polyhedron reader cannot take for 'faces'.
  if (a.components != 1) os << " NumberOfComponents=\"" << a.components << '"';
  if (a.withTuples) os << " NumberOfTuples=\"" << a.size() << '"';
  if (encoding == VtuEncoding::Appended) {
    os << " format=\"appended\" offset=\"" << offset << "\"/>\n";
    return;
  }
  os << " format=\"" << (encoding == VtuEncoding::Ascii ? "ascii" : "binary") << "\">\n"
     << a.indent << "  ";
  if (encoding == VtuEncoding::Ascii) {
    char buffer[64];
    forEachRun(a, [&](std::size_t first, auto values) {
      for (std::size_t j = 0; j < values.size(); ++j) {
        const std::size_t i = first + j;
        if (i > 0 && i % 12 == 0)
          os << '\n' << a.indent << "  ";
        else if (i > 0)
          os << ' ';
        const auto result = std::to_chars(buffer, buffer + sizeof buffer, values[j]);
        os.write(buffer, result.ptr - buffer);
      }
    });
  } else {
    Base64Writer out(os);
    writeBinary(a, [&](const char* data, std::size_t n) { out.write(data, n); });
    out.finish();
  }
  os << '\n' << a.indent << "</DataArray>\n";
}

void writeReplacing(const std::string& path, const std::function<void(std::ostream&)>& contents) {
  const std::string tmp = path + ".tmp";
  auto fail = [&](int error) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot write " + path + ": " +
                             (error != 0 ? std::strerror(error) : "I/O error"));
  };
  {
    std::ofstream os(tmp, std::ios::binary | std::ios::trunc);
    if (!os) fail(errno);
    errno = 0;
    try {
      contents(os);
    } catch (...) {
      os.close();
      std::remove(tmp.c_str());
      throw;
    }
    os.flush();
    if (!os) fail(errno);
    os.close();
    if (os.fail()) fail(errno);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) fail(errno);
}

void writeAppendedBytes(std::ostream& os, const ArrayOut& a) {
  writeBinary(
      a, [&](const char* data, std::size_t n) { os.write(data, static_cast<std::streamsize>(n)); });
}

// ============================================================================================
// Reading
// ============================================================================================

namespace {

enum class Scalar { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };

/// The scalar of a DataArray `type` (VTK's names and their legacy aliases), if numeric.
std::optional<Scalar> scalarOf(std::string_view type) {
  static const std::pair<std::string_view, Scalar> kTypes[] = {
      {"Int8", Scalar::Int8},       {"UInt8", Scalar::UInt8},   {"Int16", Scalar::Int16},
      {"UInt16", Scalar::UInt16},   {"Int32", Scalar::Int32},   {"UInt32", Scalar::UInt32},
      {"Int64", Scalar::Int64},     {"UInt64", Scalar::UInt64}, {"Float32", Scalar::Float32},
      {"Float64", Scalar::Float64}, {"Char", Scalar::Int8},     {"UChar", Scalar::UInt8},
      {"Short", Scalar::Int16},     {"UShort", Scalar::UInt16}, {"Int", Scalar::Int32},
      {"UInt", Scalar::UInt32},     {"Long", Scalar::Int64},    {"ULong", Scalar::UInt64},
      {"Float", Scalar::Float32},   {"Double", Scalar::Float64}};
  for (const auto& [name, scalar] : kTypes)
    if (name == type) return scalar;
  return std::nullopt;
}

Scalar parseScalar(std::string_view type, std::string_view array) {
  if (const std::optional<Scalar> scalar = scalarOf(type)) return *scalar;
  throw FormatError("array '" + std::string(array) + "' has unknown type '" + std::string(type) +
                    "'");
}

std::size_t scalarSize(Scalar s) {
  switch (s) {
    case Scalar::Int8:
    case Scalar::UInt8: return 1;
    case Scalar::Int16:
    case Scalar::UInt16: return 2;
    case Scalar::Int32:
    case Scalar::UInt32:
    case Scalar::Float32: return 4;
    case Scalar::Int64:
    case Scalar::UInt64:
    case Scalar::Float64: return 8;
  }
  return 1;
}

bool isFloat(Scalar s) { return s == Scalar::Float32 || s == Scalar::Float64; }

/// Converts one value to the requested kind: any value to double; integers (or floats holding
/// integers) to int64.
template <class Out, class In>
Out convertValue(In v, std::string_view array) {
  if constexpr (std::is_same_v<Out, double>) {
    return static_cast<double>(v);
  } else if constexpr (std::is_floating_point_v<In>) {
    if (!(v == std::floor(v) && std::abs(v) < 9.0e18))
      throw FormatError("array '" + std::string(array) +
                        "' holds a non-integer value where ids are expected");
    return static_cast<std::int64_t>(v);
  } else if constexpr (std::is_same_v<In, std::uint64_t>) {
    if (v > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
      throw FormatError("array '" + std::string(array) + "' holds a value too large for an id");
    return static_cast<std::int64_t>(v);
  } else {
    return static_cast<std::int64_t>(v);
  }
}

template <class T>
T loadScalar(const char* p, bool swap) {
  std::array<char, sizeof(T)> bytes;
  std::memcpy(bytes.data(), p, sizeof(T));
  if (swap) std::reverse(bytes.begin(), bytes.end());
  return std::bit_cast<T>(bytes);
}

template <class Out, class In>
void appendConverted(const std::string& bytes, bool swap, std::string_view array,
                     std::vector<Out>& out) {
  const std::size_t n = bytes.size() / sizeof(In);
  out.reserve(out.size() + n);
  for (std::size_t i = 0; i < n; ++i)
    out.push_back(convertValue<Out>(loadScalar<In>(bytes.data() + i * sizeof(In), swap), array));
}

template <class Out>
void convertBytes(const std::string& bytes, Scalar s, bool swap, std::string_view array,
                  std::vector<Out>& out) {
  switch (s) {
    case Scalar::Int8: return appendConverted<Out, std::int8_t>(bytes, swap, array, out);
    case Scalar::UInt8: return appendConverted<Out, std::uint8_t>(bytes, swap, array, out);
    case Scalar::Int16: return appendConverted<Out, std::int16_t>(bytes, swap, array, out);
    case Scalar::UInt16: return appendConverted<Out, std::uint16_t>(bytes, swap, array, out);
    case Scalar::Int32: return appendConverted<Out, std::int32_t>(bytes, swap, array, out);
    case Scalar::UInt32: return appendConverted<Out, std::uint32_t>(bytes, swap, array, out);
    case Scalar::Int64: return appendConverted<Out, std::int64_t>(bytes, swap, array, out);
    case Scalar::UInt64: return appendConverted<Out, std::uint64_t>(bytes, swap, array, out);
    case Scalar::Float32: return appendConverted<Out, float>(bytes, swap, array, out);
    case Scalar::Float64: return appendConverted<Out, double>(bytes, swap, array, out);
  }
}

std::uint64_t readHeaderWord(ByteReader& in, const FileLayout& layout, const std::string& what) {
  std::string bytes;
  if (!in.read(layout.headerSize, bytes)) throw FormatError("truncated " + what);
  return layout.headerSize == 4 ? loadScalar<std::uint32_t>(bytes.data(), layout.swapBytes)
                                : loadScalar<std::uint64_t>(bytes.data(), layout.swapBytes);
}

/// The raw bytes of one binary array: a header, then the data, possibly in zlib blocks.
std::string readBinaryBytes(ByteReader& in, const FileLayout& layout, const std::string& what) {
  std::string data;
  if (!layout.compressed) {
    const std::uint64_t size = readHeaderWord(in, layout, what);
    if (size > in.maxRemaining() || !in.read(size, data)) throw FormatError("truncated " + what);
    return data;
  }
  const std::uint64_t blocks = readHeaderWord(in, layout, what);
  const std::uint64_t blockSize = readHeaderWord(in, layout, what);
  const std::uint64_t lastSize = readHeaderWord(in, layout, what);
  if (blocks > in.maxRemaining() / layout.headerSize) throw FormatError("truncated " + what);
  std::vector<std::uint64_t> compressedSizes(blocks);
  std::uint64_t totalCompressed = 0;
  for (auto& c : compressedSizes) {
    c = readHeaderWord(in, layout, what);
    totalCompressed += c;
  }
  if (totalCompressed > in.maxRemaining()) throw FormatError("truncated " + what);
  std::string block;
  for (std::uint64_t b = 0; b < blocks; ++b) {
    const std::uint64_t expected = (b + 1 == blocks && lastSize != 0) ? lastSize : blockSize;
    block.clear();
    if (!in.read(compressedSizes[b], block)) throw FormatError("truncated " + what);
    // zlib cannot expand data by more than about 1032:1; larger claims are corrupt headers.
    if (expected > 1100 * compressedSizes[b] + 1024)
      throw FormatError("corrupt compression header in " + what);
    const std::size_t at = data.size();
    data.resize(at + expected);
    uLongf produced = static_cast<uLongf>(expected);
    const int status =
        uncompress(reinterpret_cast<Bytef*>(data.data() + at), &produced,
                   reinterpret_cast<const Bytef*>(block.data()), static_cast<uLong>(block.size()));
    if (status != Z_OK || produced != expected)
      throw FormatError("cannot decompress " + what +
                        " (zlib: " + (status == Z_OK ? "wrong block size" : zError(status)) + ")");
  }
  return data;
}

}  // namespace

std::string arrayName(pugi::xml_node array) {
  const char* name = array.attribute("Name").value();
  return *name ? name : array.parent().name();
}

namespace {

/// Calls f(first, last) for each whitespace-separated token of `text`.
template <class F>
void forEachToken(std::string_view text, F&& f) {
  std::size_t pos = 0;
  while (true) {
    while (pos < text.size() && isXmlSpace(text[pos])) ++pos;
    if (pos == text.size()) return;
    std::size_t end = pos;
    while (end < text.size() && !isXmlSpace(text[end])) ++end;
    f(text.data() + pos, text.data() + end);
    pos = end;
  }
}

FormatError invalidNumber(const std::string& name, const char* first, const char* last) {
  return FormatError("array '" + name + "' has an invalid number '" +
                     std::string(first, std::min<std::ptrdiff_t>(last - first, 32)) + "'");
}

bool isAscii(std::string_view format) { return format == "ascii" || format.empty(); }

/// The bytes of a binary or appended array, after its header (decompressed).
std::string binaryPayload(pugi::xml_node array, const FileLayout& layout, const std::string& name,
                          std::string_view format) {
  if (format == "binary") {
    ByteReader in(array.child_value(), /*base64=*/true);
    return readBinaryBytes(in, layout, "data in array '" + name + "'");
  }
  if (format == "appended") {
    const pugi::xml_attribute offsetAttr = array.attribute("offset");
    const unsigned long long offset = offsetAttr.as_ullong(~0ull);
    if (!offsetAttr || offset == ~0ull)
      throw FormatError("array '" + name + "' has no valid offset into the appended data");
    if (offset > layout.appended.size())
      throw FormatError("truncated appended data (array '" + name + "')");
    ByteReader in(layout.appended.substr(offset), layout.appendedBase64);
    return readBinaryBytes(in, layout, "appended data (array '" + name + "')");
  }
  throw FormatError("array '" + name + "' has unknown format '" + std::string(format) + "'");
}

}  // namespace

template <class Out>
std::vector<Out> readArray(pugi::xml_node array, const FileLayout& layout) {
  const std::string name = arrayName(array);
  const Scalar scalar = parseScalar(array.attribute("type").value(), name);
  const std::string_view format = array.attribute("format").value();
  std::vector<Out> out;
  if (isAscii(format)) {
    forEachToken(array.child_value(), [&](const char* first, const char* last) {
      std::from_chars_result result{};
      if (isFloat(scalar)) {
        double v = 0.0;
        result = std::from_chars(first, last, v);
        if (result.ec == std::errc()) out.push_back(convertValue<Out>(v, name));
      } else if (scalar == Scalar::UInt64) {
        std::uint64_t v = 0;
        result = std::from_chars(first, last, v);
        if (result.ec == std::errc()) out.push_back(convertValue<Out>(v, name));
      } else {
        std::int64_t v = 0;
        result = std::from_chars(first, last, v);
        if (result.ec == std::errc()) out.push_back(convertValue<Out>(v, name));
      }
      if (result.ec != std::errc() || result.ptr != last) throw invalidNumber(name, first, last);
    });
    return out;
  }
  const std::string bytes = binaryPayload(array, layout, name, format);
  if (bytes.size() % scalarSize(scalar) != 0)
    throw FormatError("array '" + name +
                      "' has a byte count that is not a multiple of its type size");
  convertBytes(bytes, scalar, layout.swapBytes, name, out);
  return out;
}

template std::vector<double> readArray<double>(pugi::xml_node, const FileLayout&);
template std::vector<std::int64_t> readArray<std::int64_t>(pugi::xml_node, const FileLayout&);

bool isNumericType(std::string_view type) { return scalarOf(type).has_value(); }

std::string readBytes(pugi::xml_node array, const FileLayout& layout) {
  const std::string name = arrayName(array);
  const std::string_view type = array.attribute("type").value();
  if (type != "String" && type != "Int8" && type != "UInt8" && type != "Char" && type != "UChar")
    throw FormatError("array '" + name + "' has type '" + std::string(type) +
                      "', which does not hold bytes");
  const std::string_view format = array.attribute("format").value();
  if (!isAscii(format)) return binaryPayload(array, layout, name, format);
  std::string out;
  forEachToken(array.child_value(), [&](const char* first, const char* last) {
    int v = 0;
    const auto result = std::from_chars(first, last, v);
    if (result.ec != std::errc() || result.ptr != last) throw invalidNumber(name, first, last);
    if (v < -128 || v > 255)
      throw FormatError("array '" + name + "' holds " + std::to_string(v) +
                        ", which is not a byte");
    out.push_back(static_cast<char>(v));
  });
  return out;
}

pugi::xml_node findArray(pugi::xml_node parent, std::string_view name) {
  for (pugi::xml_node a : parent.children("DataArray"))
    if (name == a.attribute("Name").value()) return a;
  return {};
}

std::uint64_t readCount(pugi::xml_node node, const char* attribute) {
  const pugi::xml_attribute a = node.attribute(attribute);
  std::uint64_t value = 0;
  const std::string_view text = a.value();
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (!a || result.ec != std::errc() || result.ptr != text.data() + text.size())
    throw FormatError(std::string(node.name()) + " has no valid " + attribute);
  return value;
}

FileParts splitAppendedData(std::string_view bytes) {
  FileParts parts;
  parts.whole = bytes;
  const std::size_t appendedTag = bytes.find("<AppendedData");
  if (appendedTag == std::string_view::npos) return parts;
  const std::size_t tagEnd = bytes.find('>', appendedTag);
  if (tagEnd == std::string_view::npos) throw FormatError("truncated AppendedData element");
  std::size_t underscore = tagEnd + 1;
  while (underscore < bytes.size() && isXmlSpace(bytes[underscore])) ++underscore;
  if (underscore == bytes.size() || bytes[underscore] != '_')
    throw FormatError("AppendedData does not start with '_'");
  const std::size_t begin = underscore + 1;
  const std::size_t close = bytes.rfind("</AppendedData>");
  const std::size_t end = close != std::string_view::npos && close >= begin ? close : bytes.size();
  parts.appended = bytes.substr(begin, end - begin);
  parts.closedXml = std::string(bytes.substr(0, tagEnd + 1)) + "</AppendedData></VTKFile>";
  parts.hasAppended = true;
  return parts;
}

FileLayout readLayout(pugi::xml_node root, std::string_view appended) {
  FileLayout layout;
  layout.appended = appended;
  const std::string_view byteOrder = root.attribute("byte_order").as_string("LittleEndian");
  if (byteOrder != "LittleEndian" && byteOrder != "BigEndian")
    throw FormatError("unknown byte_order '" + std::string(byteOrder) + "'");
  layout.swapBytes = (byteOrder == "BigEndian") != (std::endian::native == std::endian::big);
  const std::string_view headerType = root.attribute("header_type").as_string("UInt32");
  if (headerType != "UInt32" && headerType != "UInt64")
    throw FormatError("unknown header_type '" + std::string(headerType) + "'");
  layout.headerSize = headerType == "UInt64" ? 8 : 4;
  const std::string_view compressor = root.attribute("compressor").value();
  if (!compressor.empty() && compressor != "vtkZLibDataCompressor")
    throw FormatError("compressor " + std::string(compressor) +
                      " is not supported (only vtkZLibDataCompressor)");
  layout.compressed = !compressor.empty();
  if (const pugi::xml_node appendedNode = root.child("AppendedData")) {
    const std::string_view encoding = appendedNode.attribute("encoding").as_string("raw");
    if (encoding != "raw" && encoding != "base64")
      throw FormatError("unknown AppendedData encoding '" + std::string(encoding) + "'");
    layout.appendedBase64 = encoding == "base64";
  }
  return layout;
}

}  // namespace polydg::vtk_format
