#pragma once
// Only regular files are opened. A path naming a FIFO blocks open() until a writer appears
// (forever), a directory opens and then reports a nonsense size, a device may never end; so
// every reader of a file named by a user or by another file asks std::filesystem::status,
// which opens nothing, first.
#include <cstdint>
#include <filesystem>
#include <vector>

namespace chorus {

// Throws chorus::Error "<path>: no such file", "… is a directory, not a file" or "… is not a
// regular file (a FIFO, socket or device)".
void requireRegularFile(const std::filesystem::path& path);

// The whole file, after requireRegularFile. Throws chorus::Error naming the file when it is
// larger than maxBytes or cannot be read.
std::vector<unsigned char> readRegularFile(const std::filesystem::path& path, uint64_t maxBytes);

}  // namespace chorus
