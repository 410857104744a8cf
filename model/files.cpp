#include "model/files.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

#include <unistd.h>

#include "polydg/util/error.h"

namespace polydg {

namespace fs = std::filesystem;

void writeFileAtomically(const fs::path& path, const std::function<void(std::ostream&)>& write) {
  const fs::path tmp = path.string() + ".tmp-" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out)
      throw OutputError("cannot write " + path.string() + ": " + std::strerror(errno) +
                        "; check that the folder exists and is writable");
    write(out);
    out.flush();
    if (!out) {
      std::error_code ignored;
      fs::remove(tmp, ignored);
      throw OutputError("cannot write " + path.string() + ": write failed (disk full?)");
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw OutputError("cannot write " + path.string() + ": " + ec.message());
  }
}

void writeJsonFile(const fs::path& path, const nlohmann::json& document) {
  writeFileAtomically(path, [&](std::ostream& out) { out << document.dump(2) << '\n'; });
}

void requireWritable(const fs::path& output) {
  const fs::path folder = output.parent_path().empty() ? fs::path(".") : output.parent_path();
  std::error_code ec;
  if (!fs::is_directory(folder, ec))
    throw OutputError("cannot write " + output.string() + ": the folder " + folder.string() +
                      " does not exist; create it or choose another output path");
  if (::access(folder.c_str(), W_OK) != 0)
    throw OutputError("cannot write " + output.string() + ": the folder " + folder.string() +
                      " is not writable; choose another output path");
  if (fs::is_directory(output, ec))
    throw OutputError("cannot write " + output.string() + ": it is a folder; give a file name");
}

void requireOutput(const fs::path& output, std::initializer_list<fs::path> inputs) {
  for (const fs::path& input : inputs) {
    std::error_code ec;
    if (fs::equivalent(output, input, ec))
      throw InputError("refusing to overwrite the input " + input.string() +
                       "; choose another output path");
  }
  requireWritable(output);
}

}  // namespace polydg
