#include "polydg/version.h"

namespace polydg {

const char* libraryVersion() { return kVersion; }

}  // namespace polydg
