#include "cli/bench/data_files.h"

#include <stdexcept>
#include <system_error>

namespace polydg::bench {

std::filesystem::path dataDirectory() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec)
    throw std::runtime_error("cannot find the running executable through /proc/self/exe (" +
                             ec.message() + "); pass the data folder with --data");
  return (exe.parent_path() / ".." / "share" / "polydg").lexically_normal();
}

}  // namespace polydg::bench
