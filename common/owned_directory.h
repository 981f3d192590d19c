#pragma once
// An output directory owned by one run at a time, whose files always belong to one run:
//  - DIR/.chorus.lock is flock(2)-ed while the run lasts (the kernel drops the lock when the
//    process dies, kill -9 included), so a second run into DIR fails at once with one line
//    naming the first run's pid instead of mixing its files with the first run's;
//  - the temporary files that killed writers left behind (atomic_file.h) are removed;
//  - replacePreviousRun() removes the previous run's files (listed in DIR/.chorus-files) before
//    this run writes any, so that DIR never holds one run's stats.json beside another's outputs.
// docs/hardening-cli.md has the design and its failure cases.
#include <filesystem>
#include <string>
#include <vector>

namespace chorus {

class OwnedDirectory {
 public:
  // Creates DIR (and parents) and locks it; removes stale temporary files in DIR and everywhere
  // below the listed subdirectories. Throws chorus::Error "DIR is in use by another chorus run
  // (pid N)", or naming DIR when it cannot be created or locked.
  explicit OwnedDirectory(std::filesystem::path dir,
                          const std::vector<std::string>& cleanSubdirectories = {});
  // Unlocks. Removes the lock file, and DIR itself when this run created it and left it empty
  // (a run that failed before writing leaves nothing behind).
  ~OwnedDirectory();
  OwnedDirectory(const OwnedDirectory&) = delete;
  OwnedDirectory& operator=(const OwnedDirectory&) = delete;

  const std::filesystem::path& path() const { return dir_; }

  // Declares the files (names relative to DIR) this run may write and removes them and those of
  // the previous run, stats.json first, keeping the list of both in DIR/.chorus-files until
  // they are gone: a run killed at any point leaves only files the next run removes.
  void replacePreviousRun(const std::vector<std::string>& files);

 private:
  std::filesystem::path dir_;
  int fd_ = -1;
  bool createdDir_ = false;
};

}  // namespace chorus
