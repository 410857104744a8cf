// How VTK XML files store arrays: base64, <DataArray> elements in ascii, inline binary or
// appended form (raw or base64, uncompressed or zlib-compressed, UInt32 or UInt64 headers, either
// byte order), and the choice of integer types; the helpers behind mesh/vtu_io.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <ostream>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "polydg/mesh/vtu_io.h"

namespace pugi {
class xml_node;
}

namespace polydg::vtk_format {

/// A problem with a file's contents, described without the file's name (readVtu adds it).
class FormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// --- base64 ---------------------------------------------------------------------------------

/// Base64 (RFC 4648, with '=' padding), as used for binary data in VTK XML files.
std::string base64Encode(std::string_view bytes);

/// Decodes groups of four characters, ignoring whitespace; a group may end in padding
/// anywhere, so separately encoded pieces that were concatenated (as VTK writes headers and
/// data) decode to the concatenated bytes. Throws FormatError on any other character or an
/// incomplete final group.
std::string base64Decode(std::string_view text);

/// Streams bytes out as base64 text; finish() writes the last, padded group.
class Base64Writer {
 public:
  explicit Base64Writer(std::ostream& os) : os_(os) {}
  void write(const void* data, std::size_t size);
  void finish();

 private:
  void emit();

  std::ostream& os_;
  unsigned char group_[3] = {0, 0, 0};
  int count_ = 0;
};

/// Reads consecutive bytes from a region of a file, either raw or base64 text decoded one
/// group of four characters at a time (so separately encoded pieces decode seamlessly).
class ByteReader {
 public:
  ByteReader(std::string_view data, bool base64) : data_(data), base64_(base64) {}

  /// Appends the next `n` bytes to `out`; returns false if the data ends first. Throws
  /// FormatError on invalid base64.
  bool read(std::size_t n, std::string& out);

  /// An upper bound on the bytes left, to reject absurd sizes before allocating.
  std::size_t maxRemaining() const;

 private:
  bool decodeGroup();

  std::string_view data_;
  bool base64_;
  std::size_t pos_ = 0;
  std::string pending_;
  std::size_t pendingPos_ = 0;
};

/// True for the four characters XML counts as white space (space, tab, CR, LF), which separate
/// ascii values and may appear anywhere in base64 text.
bool isXmlSpace(char c);

// --- writing --------------------------------------------------------------------------------

/// The type an array is stored as: doubles as Float64; integers (all non-negative here) in the
/// smallest of UInt8, Int32 and Int64 that holds them (VTK and meshio convert on reading).
enum class StoredType { Float64, UInt8, Int32, Int64 };

/// Produces values [begin, end) of a generated array into out[0 .. end - begin).
using FillValues = std::function<void(std::size_t begin, std::size_t end, std::int64_t* out)>;

/// Non-negative integers made on demand instead of held: how many, the largest (which picks the
/// stored type before any value is made) and `fill`, which the writer calls from several
/// threads at once for disjoint ranges, so it must give each position the same value whatever
/// the range it falls in.
struct GeneratedInts {
  std::size_t size = 0;
  std::int64_t largest = 0;
  FillValues fill;
};

/// Doubles made on demand instead of held, under GeneratedInts' rules: how many, and `fill`,
/// which writes values [begin, end) to out[0 .. end - begin).
struct GeneratedDoubles {
  std::size_t size = 0;
  std::function<void(std::size_t begin, std::size_t end, double* out)> fill;
};

/// How many values of a generated array are made and written at a time (8 MB as Int64).
inline constexpr std::size_t kChunkValues = std::size_t{1} << 20;

/// One <DataArray> to write: its values (doubles or integers, entity by entity with
/// `components` values each) and how to store them. The spans, and what a generated array's
/// fill refers to, must outlive the writing.
struct ArrayOut {
  std::string_view indent, name;
  int components = 1;
  bool withTuples = false;  ///< field data needs NumberOfTuples
  std::span<const double> doubles;
  std::span<const std::int64_t> integers;
  StoredType stored = StoredType::Float64;
  /// Integers generated `chunk` values at a time (then `integers` is unused), if its fill is set.
  GeneratedInts generated;
  /// Doubles generated the same way (then `doubles` is unused), if its fill is set.
  GeneratedDoubles generatedDoubles;
  std::size_t chunk = kChunkValues;  ///< at least 1

  bool isGenerated() const {
    return static_cast<bool>(generated.fill) || static_cast<bool>(generatedDoubles.fill);
  }
  std::size_t size() const {
    if (stored == StoredType::Float64)
      return generatedDoubles.fill ? generatedDoubles.size : doubles.size();
    return generated.fill ? generated.size : integers.size();
  }
  /// Bytes of the stored values, without the header.
  std::size_t bytes() const;
  /// Bytes of the array in binary form: the UInt64 byte count, then the values.
  std::size_t binaryBytes() const { return 8 + bytes(); }
};

/// `values` stored as Float64; `withTuples` writes NumberOfTuples (field data needs it).
ArrayOut floatArray(std::string_view indent, std::string_view name, int components,
                    std::span<const double> values, bool withTuples = false);

/// Non-negative `values` stored as the smallest of UInt8, Int32 and Int64 that holds them.
ArrayOut intArray(std::string_view indent, std::string_view name,
                  std::span<const std::int64_t> values, bool withTuples = false);

/// `values` generated when written, stored as floatArray stores them.
ArrayOut generatedFloatArray(std::string_view indent, std::string_view name, int components,
                             GeneratedDoubles values, bool withTuples = false);

/// `values` generated when written, stored as intArray would store them all.
ArrayOut generatedIntArray(std::string_view indent, std::string_view name, GeneratedInts values,
                           bool withTuples = false);

/// Writes one <DataArray> (header_type UInt64, little-endian, uncompressed): ascii text (12
/// values a line, shortest round-trip form), inline base64 of the binary form, or, for
/// VtuEncoding::Appended, only the tag with `offset` (bytes into the appended data; see
/// writeAppendedBytes). A generated array is made chunk by chunk, each chunk on all cores; the
/// bytes are those of its values held whole.
void writeDataArray(std::ostream& os, const ArrayOut& a, VtuEncoding encoding, std::size_t offset);

/// Writes the binary form of `a` (binaryBytes() bytes) raw, for the AppendedData section.
void writeAppendedBytes(std::ostream& os, const ArrayOut& a);

/// Writes a file through `contents` to `path + ".tmp"`, then renames it over `path`, so `path`
/// is never left half-written; on any failure the temporary file is removed. Throws
/// std::runtime_error("cannot write PATH: reason") for an I/O error, and lets what `contents`
/// throws through.
void writeReplacing(const std::string& path, const std::function<void(std::ostream&)>& contents);

// --- reading --------------------------------------------------------------------------------

/// What every array read needs to know about its file.
struct FileLayout {
  bool swapBytes = false;      ///< the file's byte order differs from this machine's
  std::size_t headerSize = 4;  ///< UInt32 or UInt64 headers
  bool compressed = false;     ///< vtkZLibDataCompressor
  std::string_view appended;   ///< the bytes after AppendedData's '_'
  bool appendedBase64 = true;
};

/// A VTK XML file split where its data stops being XML: appended data may be raw binary, so the
/// text up to AppendedData's opening tag, closed off, is parsed alone.
struct FileParts {
  std::string_view whole;  ///< the file
  std::string closedXml;   ///< the text before the appended data, closed; empty if none
  std::string_view appended;
  bool hasAppended = false;

  std::string_view xml() const { return hasAppended ? std::string_view(closedXml) : whole; }
};

/// Splits `bytes` (which must outlive the result). Throws FormatError if AppendedData is
/// truncated or does not start with '_'.
FileParts splitAppendedData(std::string_view bytes);

/// The layout of the file whose <VTKFile> element is `root`: byte_order, header_type,
/// compressor, AppendedData encoding; `appended` from splitAppendedData. Throws FormatError
/// for values it does not know.
FileLayout readLayout(pugi::xml_node root, std::string_view appended);

/// The array's Name, or its parent element's name if it has none (e.g. "Points").
std::string arrayName(pugi::xml_node array);

/// Reads a DataArray's values as `Out` (double or std::int64_t), whatever its stored numeric
/// type and format, in file order (components interleaved). Integers read as int64 must be
/// integers (floats holding integers are accepted) and fit int64. Throws FormatError.
template <class Out>
std::vector<Out> readArray(pugi::xml_node array, const FileLayout& layout);

/// True for the numeric types readArray reads: Int8 .. UInt64, Float32, Float64 and their legacy
/// names (Char, UChar, Short, UShort, Int, UInt, Long, ULong, Float, Double).
bool isNumericType(std::string_view type);

/// The bytes of a one-byte array (type String, Int8, UInt8, Char or UChar) in any format; in
/// ascii each number, from -128 to 255, is one byte. (VTK writes a String array, in an <Array>
/// element, as its values each followed by a NUL byte.) Throws FormatError.
std::string readBytes(pugi::xml_node array, const FileLayout& layout);

/// The first <DataArray> child of `parent` with Name `name`, or a null node.
pugi::xml_node findArray(pugi::xml_node parent, std::string_view name);

/// The non-negative integer attribute `attribute` of `node`; throws FormatError if it is
/// missing or invalid.
std::uint64_t readCount(pugi::xml_node node, const char* attribute);

}  // namespace polydg::vtk_format
