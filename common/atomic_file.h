#pragma once
// Writes that never leave a half-written file behind: the writer fills a temporary file in the
// target directory, which is renamed over the target only when the writer succeeded.
#include <filesystem>
#include <functional>
#include <string>

namespace chorus {

// Calls write(temporaryPath); on success renames it to `target`, otherwise removes it and
// rethrows. Throws chorus::Error naming `target` when the directory is not writable.
void writeAtomically(const std::filesystem::path& target,
                     const std::function<void(const std::filesystem::path&)>& write);

// Whether `name` is one of writeAtomically's temporary files ("<target>.tmp<pid>_<n>").
bool isTemporaryFileName(const std::string& name);

// Removes the temporary files a killed writer left in `dir` (and, if `recursive`, below it);
// only for a directory no other process writes (owned_directory.h). Returns how many.
int removeTemporaryFiles(const std::filesystem::path& dir, bool recursive);

// Convenience for text outputs (JSON, CSV, HTML).
void writeTextAtomically(const std::filesystem::path& target, const std::string& text);

// The whole file's bytes; throws chorus::Error naming it when it cannot be read.
std::string readFileBytes(const std::filesystem::path& file);

// Creates `dir` (and parents); throws chorus::Error naming it when that fails.
void ensureDirectory(const std::filesystem::path& dir);

}  // namespace chorus
