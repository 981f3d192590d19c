// The driver's own AddressSanitizer defaults (see kAsanOptions), read before main() so that
// they also hold in every forked child.
#include "tools/fuzz/sandbox.h"

#if defined(__SANITIZE_ADDRESS__)
extern "C" const char* __asan_default_options() {
  return chorus::fuzz::kAsanOptions;
}
#endif
