#include "common/atomic_file.h"
#include "common/hash.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  // One directory per test: CTest runs tests in parallel processes, and these tests count
  // the files in their directory.
  const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  return test_support::scratch("common/" + test, name);
}
using test_support::slurp;

int files_in(const fs::path& dir) {
  int n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

TEST(Hash, Fnv1aKnownValues) {
  // Published FNV-1a 64 test vectors.
  EXPECT_EQ(common::fnv1a("", 0), 0xcbf29ce484222325ULL);
  EXPECT_EQ(common::fnv1a("a", 1), 0xaf63dc4c8601ec8cULL);
  EXPECT_EQ(common::fnv1a("foobar", 6), 0x85944171f73967e8ULL);
  // Continuation equals one pass.
  EXPECT_EQ(common::fnv1a("bar", 3, common::fnv1a("foo", 3)), common::fnv1a("foobar", 6));
}

TEST(AtomicFile, CommitReplacesAndLeavesNoTemporary) {
  const fs::path target = scratch("commit.bin");
  common::write_file_atomically(target, "old", 3);
  common::write_file_atomically(target, "new!", 4);
  EXPECT_EQ(slurp(target), "new!");
  for (const auto& e : fs::directory_iterator(target.parent_path()))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
}

TEST(AtomicFile, AbandonedWriteKeepsOldFile) {
  const fs::path target = scratch("abandon.bin");
  common::write_file_atomically(target, "keep", 4);
  const int before = files_in(target.parent_path());
  {
    common::AtomicFile file(target);
    file.write("partial", 7);
    EXPECT_TRUE(fs::exists(file.temporary()));
  }  // no commit: as if an exception unwound the writer
  EXPECT_EQ(slurp(target), "keep");
  EXPECT_EQ(files_in(target.parent_path()), before);
}

TEST(AtomicFile, MissingDirectoryNamesTarget) {
  try {
    common::AtomicFile file(scratch("no/such/dir/out.bin"));
    FAIL() << "expected IoError";
  } catch (const common::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("out.bin"), std::string::npos) << e.what();
  }
}

}  // namespace
