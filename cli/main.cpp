// polydg: surface meshes to polyhedral DG simulation meshes, with exact integration and checks.
//
// Sample runs:
//   polydg mesh testdata/torus.obj --cells 16 -o torus.vtu --report mesh.json
//   polydg info testdata/cube.obj --report info.json
//   polydg check mesh.vtu --report check.json
//   polydg solve beam.vtu -o out.vtu --degree 2 --clamp x=0 --traction x=10:0,0,-1
//   polydg bench --suite accuracy --out bench/
//   polydg run testdata/pipeline.json --jobs 2 --out runs/
//   polydg cut mesh.vtu -o half.vtu --plane "0,0,1,0.5" --remove-side + --report cut.json
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>

#include <dlfcn.h>
#include <unistd.h>

#include "cli/blas_threads.h"
#include "cli/commands.h"
#include "physics/solvers/cholmod_loader.h"
#include "polydg/util/error.h"
#include "polydg/util/process.h"

namespace {

/// Debian 12's OpenBLAS (0.3.21, DYNAMIC_ARCH) does not know recent Intel CPUs (family 6,
/// model 207, say) and falls back to its Prescott (SSE3) kernels: CHOLMOD's supernodal
/// factorizations, which the patch tests and rigid-mode checks of many commands run, were then
/// 1.5-2x slower. OpenBLAS reads OPENBLAS_CORETYPE only when it is loaded; so on an Intel CPU
/// with AVX2 polydg loads CHOLMOD, and with it OpenBLAS, at its start (elsewhere on the first
/// factorization, cholmod_loader.h), and if OpenBLAS reports Prescott on a CPU with AVX-512
/// (or AVX2 and FMA), polydg starts itself again, once, with OPENBLAS_CORETYPE set to the
/// matching kernels (SkylakeX, Haswell). A user's own OPENBLAS_CORETYPE is respected; another
/// BLAS (no openblas_get_corename) is left alone; if the restart fails, polydg carries on as
/// it is.
void useMatchingBlasKernels(char** argv) {
#if defined(__x86_64__) && defined(__GNUC__)
  if (std::getenv("OPENBLAS_CORETYPE") != nullptr) return;
  __builtin_cpu_init();
  if (!__builtin_cpu_is("intel") || !__builtin_cpu_supports("avx2")) return;
  try {
    polydg::loadCholmod();
  } catch (const std::exception&) {
    return;  // said again, with the advice, where a command needs it
  }
  using CoreName = const char* (*)();
  const auto corename = reinterpret_cast<CoreName>(dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  if (corename == nullptr || std::strcmp(corename(), "Prescott") != 0) return;
  const char* kernels = nullptr;
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl"))
    kernels = "SkylakeX";
  else if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
    kernels = "Haswell";
  if (kernels == nullptr) return;
  setenv("OPENBLAS_CORETYPE", kernels, 1);
  execv("/proc/self/exe", argv);
  unsetenv("OPENBLAS_CORETYPE");  // exec failed: go on with the kernels loaded
#else
  (void)argv;
#endif
}

/// The first argument that is not an option: the subcommand a user asked for.
const char* requestedCommand(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (argv[i][0] != '-') return argv[i];
  return nullptr;
}

}  // namespace

int main(int argc, char** argv) {
  useMatchingBlasKernels(argv);
  polydg::cli::stopIdleBlasThreads();
  polydg::keepFreedMemory();
  CLI::App app{"polydg: turn surface meshes into polyhedral DG simulation meshes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "polydg 0.1.0");
  polydg::cli::CommonOptions common;
  int exitCode = 0;
  app.add_flag("-q,--quiet", common.quiet, "print nothing but errors");
  app.fallthrough();  // --quiet may follow the subcommand
  polydg::cli::addInfoCommand(app, common, exitCode);
  polydg::cli::addMeshCommand(app, common, exitCode);
  polydg::cli::addCheckCommand(app, common, exitCode);
  polydg::cli::addSolveCommand(app, common, exitCode);
  polydg::cli::addSimulateCommand(app, common, exitCode);
  polydg::cli::addCutCommand(app, common, exitCode);
  polydg::cli::addRunCommand(app, common, exitCode);
  polydg::cli::addExportCommand(app, common, exitCode);
  polydg::cli::addBenchCommand(app, common, exitCode);
  // CLI11 would answer an unknown command with "A subcommand is required".
  if (const char* command = requestedCommand(argc, argv)) {
    std::string known;
    for (const CLI::App* sub : app.get_subcommands({})) {
      if (sub->get_name() == command) {
        known.clear();
        break;
      }
      known += (known.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known.empty()) {
      std::cerr << "polydg: error: unknown command '" << command << "'; the commands are " << known
                << " (see polydg --help)\n";
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, like every other error; CLI11's own would add a second.
    std::cerr << "polydg: error: " << e.what() << " (see polydg --help)\n";
    return 2;
  } catch (const polydg::CheckFailure& e) {
    std::cerr << "polydg: error: " << e.what() << '\n';
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "polydg: error: " << e.what() << '\n';
    return 2;
  }
  return exitCode;
}
