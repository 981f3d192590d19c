#pragma once
// How deeply JSON text nests arrays and objects, found by scanning the bytes (strings skipped)
// instead of parsing: code that walks parsed JSON recursively (tinygltf's conversion of
// `extras` into its own values) overflows the stack on 100 000 nested arrays, so untrusted JSON
// is checked with this before any parser sees it.
#include <span>

namespace chorus {

// Whether some array or object in `text` lies more than `limit` levels deep (the outermost
// level is 1). Malformed text is the parser's business: only the depth is judged here.
bool jsonNestsDeeperThan(std::span<const unsigned char> text, int limit);

}  // namespace chorus
