// OwnedDirectory: one run at a time per output directory, stale temporary files removed, and a
// run's files never mixed with the previous run's (common/owned_directory.h).
#include <gtest/gtest.h>

#include <sys/file.h>
#include <unistd.h>

#include <fstream>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/owned_directory.h"
#include "tests/support/test_support.h"

namespace chorus {
namespace {

namespace fs = std::filesystem;

void touch(const fs::path& file) {
  std::ofstream(file) << "x";
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// Above Linux's largest pid_max (2^22): no process can have it.
constexpr const char* kDeadPid = "4194305";

TEST(OwnedDirectory, TemporaryFileNamesAreExactlyWriteAtomicallysPattern) {
  EXPECT_TRUE(isTemporaryFileName("render.exr.tmp123_0"));
  EXPECT_TRUE(isTemporaryFileName("stats.json.tmp4194305_17"));
  EXPECT_FALSE(isTemporaryFileName("render.exr"));
  EXPECT_FALSE(isTemporaryFileName("notes.tmp"));
  EXPECT_FALSE(isTemporaryFileName("a.tmp12"));
  EXPECT_FALSE(isTemporaryFileName("a.tmp12_"));
  EXPECT_FALSE(isTemporaryFileName("a.tmpx_1"));
  EXPECT_FALSE(isTemporaryFileName(".tmp1_2"));
  // The name writeAtomically really uses: a failing write leaves its temporary file visible.
  test::TempDir dir;
  std::string seen;
  const std::string error = errorOf([&] {
    writeAtomically(dir / "out.exr", [&](const fs::path& tmp) {
      seen = tmp.filename().string();
      throw Error("stop");
    });
  });
  EXPECT_EQ(error, "stop");
  EXPECT_TRUE(isTemporaryFileName(seen)) << seen;
}

TEST(OwnedDirectory, SecondOwnerIsRefusedNamingTheFirstsPid) {
  test::TempDir dir;
  const fs::path out = dir / "out";
  {
    const OwnedDirectory first(out);
    EXPECT_TRUE(fs::is_directory(out));
    const std::string error = errorOf([&] { OwnedDirectory second(out); });
    EXPECT_EQ(error, out.string() + ": is in use by another chorus run (pid " +
                         std::to_string(::getpid()) + ")");
  }
  // Released: the directory this owner created and left empty is gone, and it can be owned again.
  EXPECT_FALSE(fs::exists(out));
  const OwnedDirectory again(out);
  EXPECT_TRUE(fs::is_directory(out));
}

TEST(OwnedDirectory, AnExistingDirectoryKeepsItsFilesAndLosesOnlyTheLock) {
  test::TempDir dir;
  touch(dir / "mine.txt");
  { const OwnedDirectory owned(dir.path()); }
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir.path()))
    names.push_back(entry.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"mine.txt"});
}

TEST(OwnedDirectory, AFileInTheWayIsAnError) {
  test::TempDir dir;
  touch(dir / "file");
  EXPECT_NE(errorOf([&] { OwnedDirectory owned(dir / "file"); }).find("it is a file"),
            std::string::npos);
}

// A lock file left by a killed run (its pid dead, the kernel's flock gone with it) does not
// block the next run.
TEST(OwnedDirectory, ALockFileOfAKilledRunIsTakenOver) {
  test::TempDir dir;
  std::ofstream(dir / ".chorus.lock") << kDeadPid << "\n";
  const OwnedDirectory owned(dir.path());
  std::ifstream lock(dir / ".chorus.lock");
  std::string pid;
  lock >> pid;
  EXPECT_EQ(pid, std::to_string(::getpid()));
}

TEST(OwnedDirectory, StaleTemporaryFilesAreRemovedInDirAndTheListedSubdirectories) {
  test::TempDir dir;
  fs::create_directories(dir / "cases" / "room_spp4");
  fs::create_directories(dir / "other");
  const std::string stale = std::string(".tmp") + kDeadPid + "_0";
  for (const fs::path& file : {dir / ("render.exr" + stale), dir / ("stats.json" + stale),
                               dir / "cases" / ("room_spp4.csv" + stale),
                               dir / "cases" / "room_spp4" / ("image0.png" + stale),
                               dir / "other" / ("x.exr" + stale), dir / "notes.tmp"})
    touch(file);
  { const OwnedDirectory owned(dir.path(), {"cases"}); }
  EXPECT_FALSE(fs::exists(dir / ("render.exr" + stale)));
  EXPECT_FALSE(fs::exists(dir / ("stats.json" + stale)));
  EXPECT_FALSE(fs::exists(dir / "cases" / ("room_spp4.csv" + stale)));
  EXPECT_FALSE(fs::exists(dir / "cases" / "room_spp4" / ("image0.png" + stale)));
  EXPECT_TRUE(fs::exists(dir / "other" / ("x.exr" + stale)));  // not a listed subdirectory
  EXPECT_TRUE(fs::exists(dir / "notes.tmp"));                  // not a temporary file's name
}

std::vector<std::string> filesIn(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().filename().string()[0] != '.')
      names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// Run 1 writes a, b and stats.json; run 2 declares a, c and stats.json and is killed after
// writing c (no stats.json yet); run 3 declares d and stats.json. At every point the directory
// holds no file of an earlier run beside a later run's stats.json.
TEST(OwnedDirectory, EachRunRemovesThePreviousRunsFilesEvenAfterAKill) {
  test::TempDir dir;
  touch(dir / "user.txt");
  {
    OwnedDirectory run1(dir.path());
    run1.replacePreviousRun({"a.exr", "b.exr", "stats.json"});
    for (const char* f : {"a.exr", "b.exr", "stats.json"}) touch(dir / f);
  }
  {
    OwnedDirectory run2(dir.path());
    run2.replacePreviousRun({"a.exr", "c.exr", "stats.json"});
    EXPECT_EQ(filesIn(dir.path()), std::vector<std::string>{"user.txt"});
    touch(dir / "c.exr");  // then killed: no a.exr, no stats.json
  }
  {
    OwnedDirectory run3(dir.path());
    run3.replacePreviousRun({"d.exr", "stats.json"});
    EXPECT_EQ(filesIn(dir.path()), std::vector<std::string>{"user.txt"});
  }
}

TEST(OwnedDirectory, NamesOutsideTheDirectoryAreNeverRemoved) {
  test::TempDir dir;
  fs::create_directories(dir / "out");
  touch(dir / "precious.exr");
  std::ofstream(dir / "out" / ".chorus-files") << "../precious.exr\n..\n/etc/passwd\n";
  OwnedDirectory owned(dir / "out");
  owned.replacePreviousRun({"stats.json"});
  EXPECT_TRUE(fs::exists(dir / "precious.exr"));
  EXPECT_NE(errorOf([&] { owned.replacePreviousRun({"../x"}); }).find("not a file name"),
            std::string::npos);
}

}  // namespace
}  // namespace chorus
