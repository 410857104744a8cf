#include "cli/bench/mesh_cell_count.h"

#include <array>
#include <cctype>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string_view>

#include "polydg/util/error.h"

namespace polydg::bench {

namespace {

/// `line` without the spaces, tabs and carriage return around it.
std::string_view trimmed(std::string_view line) {
  const std::size_t begin = line.find_first_not_of(" \t\r");
  if (begin == std::string_view::npos) return {};
  return line.substr(begin, line.find_last_not_of(" \t\r") - begin + 1);
}

/// The whole number `text` (digits only), or nothing.
std::optional<std::size_t> wholeNumber(std::string_view text) {
  if (text.empty() || text.size() > 19) return std::nullopt;
  std::size_t value = 0;
  for (char c : text) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return std::nullopt;
    value = 10 * value + static_cast<std::size_t>(c - '0');
  }
  return value;
}

/// `count` whole numbers from `line`, or nothing if it does not start with as many.
template <std::size_t count>
std::optional<std::array<std::size_t, count>> wholeNumbers(const std::string& line) {
  std::istringstream words(line);
  std::array<std::size_t, count> values{};
  std::string word;
  for (std::size_t& value : values) {
    if (!(words >> word)) return std::nullopt;
    const std::optional<std::size_t> v = wholeNumber(word);
    if (!v) return std::nullopt;
    value = *v;
  }
  return values;
}

/// Whether the tag text `tag` (what follows '<') is an element named `name`.
bool isElement(std::string_view tag, std::string_view name) {
  if (tag.substr(0, name.size()) != name) return false;
  return tag.size() == name.size() || std::isspace(static_cast<unsigned char>(tag[name.size()])) ||
         tag[name.size()] == '/';
}

/// The value of attribute `name` in the tag text `tag`, or nothing if it has none.
std::optional<std::string_view> attribute(std::string_view tag, std::string_view name) {
  for (std::size_t at = tag.find(name); at != std::string_view::npos; at = tag.find(name, at + 1)) {
    if (at == 0 || !std::isspace(static_cast<unsigned char>(tag[at - 1]))) continue;
    std::string_view rest = trimmed(tag.substr(at + name.size()));
    if (rest.empty() || rest[0] != '=') continue;
    rest = trimmed(rest.substr(1));
    if (rest.empty() || (rest[0] != '"' && rest[0] != '\'')) continue;
    const std::size_t close = rest.find(rest[0], 1);
    if (close == std::string_view::npos) return std::nullopt;
    return rest.substr(1, close - 1);
  }
  return std::nullopt;
}

std::ifstream openFile(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError("cannot open " + file.string());
  return in;
}

}  // namespace

std::size_t mshTetrahedra(std::istream& in, const std::string& name) {
  auto fail = [&](const std::string& what) { throw InputError(name + ": " + what); };
  std::string line;
  if (!std::getline(in, line) || trimmed(line) != "$MeshFormat")
    fail("not a Gmsh MSH file (it does not start with $MeshFormat)");
  std::string version;
  int fileType = -1;
  if (!std::getline(in, line)) line.clear();
  std::istringstream format(line);
  if (!(format >> version >> fileType)) fail("no version line after $MeshFormat");
  if (version != "4.1") fail("MSH version " + version + "; only MSH 4.1 ASCII is read");
  if (fileType != 0) fail("a binary MSH file; only MSH 4.1 ASCII is read");
  while (std::getline(in, line) && trimmed(line) != "$Elements") continue;
  if (!in) fail("no $Elements section");
  if (!std::getline(in, line)) line.clear();
  const auto header = wholeNumbers<4>(line);
  if (!header) fail("$Elements does not start with 'numEntityBlocks numElements minTag maxTag'");
  const std::size_t blocks = (*header)[0], elements = (*header)[1];
  std::size_t total = 0, tetrahedra = 0;
  for (std::size_t b = 0; b < blocks; ++b) {
    if (!std::getline(in, line)) line.clear();
    const auto block = wholeNumbers<4>(line);
    if (!block)
      fail("element block " + std::to_string(b + 1) + " of " + std::to_string(blocks) +
           " does not start with 'entityDim entityTag elementType numElementsInBlock'");
    const std::size_t type = (*block)[2], count = (*block)[3];
    for (std::size_t e = 0; e < count && in; ++e)
      in.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
    if (!in) fail("$Elements ends inside element block " + std::to_string(b + 1));
    total += count;
    if (type == 4) tetrahedra += count;
  }
  if (total != elements)
    fail("the element blocks hold " + std::to_string(total) + " elements, $Elements says " +
         std::to_string(elements));
  if (!std::getline(in, line) || trimmed(line) != "$EndElements")
    fail("no $EndElements after the element blocks");
  return tetrahedra;
}

std::size_t mshTetrahedra(const std::filesystem::path& file) {
  std::ifstream in = openFile(file);
  return mshTetrahedra(in, file.string());
}

std::size_t vtuCells(std::istream& in, const std::string& name) {
  std::size_t cells = 0, pieces = 0;
  std::string text;
  // Each piece of text up to a '>' ends with one tag; its '<' is the last one in it.
  while (std::getline(in, text, '>')) {
    const std::size_t open = text.rfind('<');
    if (open == std::string::npos) continue;
    const std::string_view tag = std::string_view(text).substr(open + 1);
    if (isElement(tag, "AppendedData")) break;
    if (!isElement(tag, "Piece")) continue;
    ++pieces;
    const std::optional<std::string_view> value = attribute(tag, "NumberOfCells");
    const std::optional<std::size_t> count = value ? wholeNumber(trimmed(*value)) : std::nullopt;
    if (!count)
      throw InputError(name + ": Piece " + std::to_string(pieces) +
                       " has no NumberOfCells that is a whole number");
    cells += *count;
  }
  if (pieces == 0) throw InputError(name + ": no <Piece> (not a VTK XML UnstructuredGrid)");
  return cells;
}

std::size_t vtuCells(const std::filesystem::path& file) {
  std::ifstream in = openFile(file);
  return vtuCells(in, file.string());
}

}  // namespace polydg::bench
