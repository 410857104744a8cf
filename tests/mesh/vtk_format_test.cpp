// Tests of mesh/vtk_format.h (base64 and DataArray reading and writing) and
// mesh/vtk_cell_types.h (the faces of VTK's linear cells).
#include "mesh/vtk_format.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <pugixml.hpp>

#include "mesh/vtk_cell_types.h"
#include "tests/support/vtu_encodings.h"

namespace polydg::vtk_format {
namespace {

// --- base64 --------------------------------------------------------------------------------

TEST(Base64, MatchesRfc4648Vectors) {
  const std::pair<std::string, std::string> vectors[] = {{"", ""},
                                                         {"f", "Zg=="},
                                                         {"fo", "Zm8="},
                                                         {"foo", "Zm9v"},
                                                         {"foob", "Zm9vYg=="},
                                                         {"fooba", "Zm9vYmE="},
                                                         {"foobar", "Zm9vYmFy"}};
  for (const auto& [plain, encoded] : vectors) {
    EXPECT_EQ(base64Encode(plain), encoded);
    EXPECT_EQ(base64Decode(encoded), plain);
  }
  const std::string binary("\x00\xff\x10\x80\x7f", 5);
  EXPECT_EQ(base64Decode(base64Encode(binary)), binary);
}

TEST(Base64, DecodesConcatenatedPaddedPiecesAndSkipsWhitespace) {
  EXPECT_EQ(base64Decode("Zg==Zm8=\n  Zm9v"), "ffofoo");
  EXPECT_THROW(base64Decode("Zm9v!"), std::runtime_error);
  EXPECT_THROW(base64Decode("Zm9vY"), std::runtime_error);
  EXPECT_THROW(base64Decode("Z==="), std::runtime_error);
}

// --- DataArrays ----------------------------------------------------------------------------

TEST(VtkDataArray, IntegersAreStoredInTheSmallestTypeThatHoldsThem) {
  auto stored = [](std::vector<std::int64_t> values) { return intArray("", "a", values).stored; };
  EXPECT_EQ(stored({}), StoredType::UInt8);
  EXPECT_EQ(stored({0, 255}), StoredType::UInt8);
  EXPECT_EQ(stored({256}), StoredType::Int32);
  EXPECT_EQ(stored({std::numeric_limits<std::int32_t>::max()}), StoredType::Int32);
  EXPECT_EQ(stored({std::int64_t{std::numeric_limits<std::int32_t>::max()} + 1}),
            StoredType::Int64);
  EXPECT_EQ(intArray("", "a", std::vector<std::int64_t>{1, 2, 3}).bytes(), 3u);
  EXPECT_EQ(intArray("", "a", std::vector<std::int64_t>{1, 2, 3}).binaryBytes(), 8u + 3u);
}

/// A VTK file holding `arrays` in `encoding`, as writeVtu lays one out (appended data last).
std::string fileWith(const std::vector<ArrayOut>& arrays, VtuEncoding encoding) {
  std::ostringstream os;
  os << "<VTKFile type=\"UnstructuredGrid\" byte_order=\"LittleEndian\" "
        "header_type=\"UInt64\"><Arrays>\n";
  std::size_t offset = 0;
  for (const ArrayOut& a : arrays) {
    writeDataArray(os, a, encoding, offset);
    offset += a.binaryBytes();
  }
  os << "</Arrays>\n";
  if (encoding == VtuEncoding::Appended) {
    os << "<AppendedData encoding=\"raw\">\n_";
    for (const ArrayOut& a : arrays) writeAppendedBytes(os, a);
    os << "\n</AppendedData>\n";
  }
  os << "</VTKFile>\n";
  return os.str();
}

/// The arrays of a file made by fileWith, read back as doubles and as integers.
struct ReadBack {
  std::map<std::string, std::vector<double>> doubles;
  std::map<std::string, std::vector<std::int64_t>> integers;
};

ReadBack readBack(const std::string& file) {
  const FileParts parts = splitAppendedData(file);
  pugi::xml_document doc;
  const std::string_view xml = parts.xml();
  EXPECT_TRUE(doc.load_buffer(xml.data(), xml.size()));
  const pugi::xml_node root = doc.child("VTKFile");
  const FileLayout layout = readLayout(root, parts.appended);
  ReadBack out;
  for (pugi::xml_node array : root.child("Arrays").children("DataArray")) {
    const std::string name = arrayName(array);
    out.doubles[name] = readArray<double>(array, layout);
    if (std::string_view(array.attribute("type").value()) != "Float64")
      out.integers[name] = readArray<std::int64_t>(array, layout);
  }
  return out;
}

class VtkDataArrayEncoding : public ::testing::TestWithParam<VtuEncoding> {};

TEST_P(VtkDataArrayEncoding, ValuesComeBackBitForBit) {
  const std::vector<double> reals{-0.0,     0.1,      1.0 / 3.0, 1e-300, -1e300,
                                  4.9e-324, 2.5e-310, -7.25,     1e17,   123456.789};
  const std::vector<std::int64_t> small{0, 1, 255}, medium{0, 256, 2147483647},
      large{0, std::int64_t{1} << 40, std::numeric_limits<std::int64_t>::max()};
  const std::vector<ArrayOut> arrays{floatArray("", "reals", 1, reals),
                                     floatArray("", "pairs", 2, reals, /*withTuples=*/true),
                                     intArray("", "small", small), intArray("", "medium", medium),
                                     intArray("", "large", large, /*withTuples=*/true)};
  const std::string file = fileWith(arrays, GetParam());
  const ReadBack back = readBack(file);
  ASSERT_EQ(back.doubles.at("reals").size(), reals.size());
  for (std::size_t i = 0; i < reals.size(); ++i) {
    EXPECT_EQ(std::bit_cast<std::uint64_t>(back.doubles.at("reals")[i]),
              std::bit_cast<std::uint64_t>(reals[i]))
        << "value " << i << " = " << reals[i];
  }
  EXPECT_EQ(back.doubles.at("pairs").size(), reals.size());
  EXPECT_EQ(back.integers.at("small"), small);
  EXPECT_EQ(back.integers.at("medium"), medium);
  EXPECT_EQ(back.integers.at("large"), large);
  EXPECT_NE(file.find("type=\"UInt8\" Name=\"small\""), std::string::npos);
  EXPECT_NE(file.find("type=\"Int32\" Name=\"medium\""), std::string::npos);
  EXPECT_NE(file.find("Name=\"large\" NumberOfTuples=\"3\""), std::string::npos);
  EXPECT_NE(file.find("Name=\"pairs\" NumberOfComponents=\"2\" NumberOfTuples=\"10\""),
            std::string::npos);
}

TEST_P(VtkDataArrayEncoding, GeneratedArraysWriteTheBytesOfTheirValuesHeldWhole) {
  // 30 values (two and a half ascii lines of 12) in each stored type, made in chunks of every
  // size from one value to all of them, so chunk ends fall anywhere in a line and in base64's
  // groups of three bytes.
  for (const std::int64_t largest :
       {std::int64_t{200}, std::int64_t{70000}, std::int64_t{1} << 40}) {
    std::vector<std::int64_t> values(30);
    for (std::size_t i = 0; i < values.size(); ++i)
      values[i] = static_cast<std::int64_t>(i * 7919) % (largest + 1);
    values[17] = largest;
    const GeneratedInts generated{values.size(), largest,
                                  [&](std::size_t begin, std::size_t end, std::int64_t* out) {
                                    std::copy(values.begin() + begin, values.begin() + end, out);
                                  }};
    const ArrayOut held = intArray("  ", "a", values, /*withTuples=*/true);
    const std::string expected = fileWith({held}, GetParam());
    for (std::size_t chunk = 1; chunk <= values.size(); ++chunk) {
      ArrayOut a = generatedIntArray("  ", "a", generated, /*withTuples=*/true);
      a.chunk = chunk;
      EXPECT_EQ(a.stored, held.stored);
      EXPECT_EQ(fileWith({a}, GetParam()), expected)
          << "largest " << largest << ", chunk " << chunk;
    }
  }
}

TEST_P(VtkDataArrayEncoding, GeneratedDoublesWriteTheBytesOfTheirValuesHeldWhole) {
  // 30 doubles as 10 triples, among them -0, a subnormal, the extremes and values without a
  // short decimal form, made in chunks of every size from one value to all of them.
  std::vector<double> values(30);
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] = std::ldexp(1.0 + 0.1 * static_cast<double>(i), static_cast<int>(i) - 15) / 3.0;
  values[3] = -0.0;
  values[7] = std::numeric_limits<double>::denorm_min();
  values[11] = std::numeric_limits<double>::max();
  values[12] = -std::numeric_limits<double>::min();
  const GeneratedDoubles generated{values.size(),
                                   [&](std::size_t begin, std::size_t end, double* out) {
                                     std::copy(values.begin() + begin, values.begin() + end, out);
                                   }};
  const ArrayOut held = floatArray("  ", "a", 3, values, /*withTuples=*/true);
  const std::string expected = fileWith({held}, GetParam());
  for (std::size_t chunk = 1; chunk <= values.size(); ++chunk) {
    ArrayOut a = generatedFloatArray("  ", "a", 3, generated, /*withTuples=*/true);
    a.chunk = chunk;
    EXPECT_EQ(a.stored, StoredType::Float64);
    EXPECT_EQ(a.size(), values.size());
    EXPECT_EQ(a.bytes(), 8 * values.size());
    EXPECT_EQ(fileWith({a}, GetParam()), expected) << "chunk " << chunk;
  }
}

TEST(VtkDataArray, LongGeneratedArraysAreFilledOnAllCoresInOrder) {
  // One chunk of 100,003 values: more than one task fills, so the chunk is made by several
  // ranges, each of which must land where its values belong.
  constexpr std::size_t n = 100003;
  std::vector<double> reals(n);
  std::vector<std::int64_t> integers(n);
  for (std::size_t i = 0; i < n; ++i) {
    reals[i] = 0.5 + static_cast<double>(i);
    integers[i] = static_cast<std::int64_t>(i);
  }
  const ArrayOut realsMade = generatedFloatArray(
      "  ", "r", 1, {n, [&](std::size_t begin, std::size_t end, double* out) {
                       std::copy(reals.begin() + begin, reals.begin() + end, out);
                     }});
  const ArrayOut integersMade = generatedIntArray(
      "  ", "i",
      {n, std::int64_t(n - 1), [&](std::size_t begin, std::size_t end, std::int64_t* out) {
         std::copy(integers.begin() + begin, integers.begin() + end, out);
       }});
  EXPECT_EQ(fileWith({realsMade, integersMade}, VtuEncoding::Appended),
            fileWith({floatArray("  ", "r", 1, reals), intArray("  ", "i", integers)},
                     VtuEncoding::Appended));
}

TEST(VtkDataArray, GeneratedArraysKnowTheirSizeWithoutMakingValues) {
  int calls = 0;
  const ArrayOut a = generatedIntArray(
      "", "a", {1000, 70000, [&](std::size_t, std::size_t, std::int64_t*) { ++calls; }});
  EXPECT_EQ(a.stored, StoredType::Int32);
  EXPECT_EQ(a.size(), 1000u);
  EXPECT_EQ(a.bytes(), 4000u);
  EXPECT_EQ(a.binaryBytes(), 4008u);
  std::ostringstream os;
  writeDataArray(os, a, VtuEncoding::Appended, 0);
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(generatedIntArray("", "a", {0, 0, {}}).stored, StoredType::UInt8);
  EXPECT_EQ(generatedIntArray("", "a", {1, std::int64_t{1} << 31, {}}).stored, StoredType::Int64);
}

INSTANTIATE_TEST_SUITE_P(Encodings, VtkDataArrayEncoding, polydg::testing::allEncodings(),
                         polydg::testing::encodingName);

TEST(VtkDataArray, IdsMustBeIntegers) {
  const std::vector<double> reals{1.0, 2.5};
  const std::string file = fileWith({floatArray("", "ids", 1, reals)}, VtuEncoding::Ascii);
  const FileParts parts = splitAppendedData(file);
  pugi::xml_document doc;
  ASSERT_TRUE(doc.load_buffer(parts.xml().data(), parts.xml().size()));
  const pugi::xml_node array = doc.child("VTKFile").child("Arrays").child("DataArray");
  const FileLayout layout = readLayout(doc.child("VTKFile"), parts.appended);
  EXPECT_EQ(readArray<double>(array, layout), reals);
  EXPECT_THROW(readArray<std::int64_t>(array, layout), FormatError);
}

// --- cell types ----------------------------------------------------------------------------

TEST(VtkCellTypes, LinearCellFacesCloseTheCellConsistently) {
  // Every edge of a closed, consistently oriented cell is used once in each direction, and each
  // point is on at least three faces.
  for (std::int64_t type = 10; type <= 16; ++type) {
    const LinearCellType* cell = linearCellType(type);
    ASSERT_NE(cell, nullptr) << "type " << type;
    EXPECT_EQ(cell->type, type);
    std::map<std::pair<int, int>, int> edges;
    std::vector<int> facesAtPoint(cell->points, 0);
    for (const auto& face : cell->faces) {
      for (std::size_t i = 0; i < face.size(); ++i) {
        ++edges[{face[i], face[(i + 1) % face.size()]}];
        ++facesAtPoint[static_cast<std::size_t>(face[i])];
      }
    }
    for (const auto& [edge, count] : edges) {
      EXPECT_EQ(count, 1) << "type " << type << " edge " << edge.first << "-" << edge.second;
      EXPECT_EQ(edges.count({edge.second, edge.first}), 1u)
          << "type " << type << " edge " << edge.first << "-" << edge.second;
    }
    for (std::size_t p = 0; p < cell->points; ++p)
      EXPECT_GE(facesAtPoint[p], 3) << "type " << type << " point " << p;
  }
  EXPECT_EQ(linearCellType(5), nullptr);  // a triangle
  EXPECT_EQ(linearCellType(kVtkPolyhedron), nullptr);
}

}  // namespace
}  // namespace polydg::vtk_format
