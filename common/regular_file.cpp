#include "common/regular_file.h"

#include <fstream>
#include <string>

#include "common/error.h"

namespace chorus {
namespace fs = std::filesystem;

void requireRegularFile(const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  switch (status.type()) {
    case fs::file_type::regular:
      return;
    case fs::file_type::directory:
      throw fileError(path, "is a directory, not a file");
    case fs::file_type::not_found:
    case fs::file_type::none:
      throw fileError(path, "no such file");
    default:
      throw fileError(path, "is not a regular file (a FIFO, socket or device)");
  }
}

std::vector<unsigned char> readRegularFile(const fs::path& path, uint64_t maxBytes) {
  requireRegularFile(path);
  std::error_code ec;
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) throw fileError(path, "cannot read: " + ec.message());
  if (size > maxBytes)
    throw fileError(path, "is " + std::to_string(size) + " bytes; chorus reads files of at most " +
                              std::to_string(maxBytes) + " bytes here");
  std::vector<unsigned char> bytes(static_cast<size_t>(size));
  std::ifstream in(path, std::ios::binary);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(bytes.size())))
    throw fileError(path, "cannot read");
  return bytes;
}

}  // namespace chorus
