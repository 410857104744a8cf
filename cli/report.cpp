#include "cli/report.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

#include <unistd.h>

namespace polydg::cli {

void writeFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write) {
  namespace fs = std::filesystem;
  const fs::path tmp = path.string() + ".tmp-" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out)
      throw UserError("cannot write " + path.string() + ": " + std::strerror(errno) +
                      "; check that the folder exists and is writable");
    write(out);
    out.flush();
    if (!out) {
      std::error_code ignored;
      fs::remove(tmp, ignored);
      throw UserError("cannot write " + path.string() + ": write failed (disk full?)");
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw UserError("cannot write " + path.string() + ": " + ec.message());
  }
}

void writeReport(const std::filesystem::path& path, const nlohmann::json& report) {
  writeFileAtomically(path, [&](std::ostream& out) { out << report.dump(2) << '\n'; });
}

void requireDistinct(const std::filesystem::path& output, const std::filesystem::path& input) {
  std::error_code ec;
  if (std::filesystem::equivalent(output, input, ec))
    throw UserError("refusing to overwrite the input " + input.string() +
                    "; choose another output path");
}

}  // namespace polydg::cli
