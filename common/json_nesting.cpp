#include "common/json_nesting.h"

namespace chorus {

bool jsonNestsDeeperThan(std::span<const unsigned char> text, int limit) {
  int depth = 0;
  bool inString = false, escaped = false;
  for (const unsigned char c : text) {
    if (inString) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      if (++depth > limit) return true;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return false;
}

}  // namespace chorus
