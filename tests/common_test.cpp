#include "common/atomic_file.h"
#include "common/base64.h"
#include "common/check.h"
#include "common/enum_names.h"
#include "common/hash.h"
#include "common/output_path.h"
#include "common/work_queue.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <sys/stat.h>

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

TEST(OutputPath, SpecialFilesAreRefusedAndKept) {
  // A rename over a FIFO, a symbolic link or a directory would replace it; commit refuses.
  const fs::path fifo = scratch("fifo");
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path link = scratch("link");
  fs::remove(link);
  fs::create_symlink(scratch("elsewhere"), link);
  for (const fs::path& target : {fifo, link}) {
    common::AtomicFile file(target);
    file.write("x", 1);
    EXPECT_THROW(file.commit(), common::IoError) << target;
  }
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link)));
  EXPECT_NE(common::output_target_problem("/dev/null").find("character device"), std::string::npos);
  EXPECT_NE(common::output_target_problem(fifo.parent_path()).find("directory"), std::string::npos);
  EXPECT_EQ(common::output_target_problem(scratch("new.bin")), "");
}

TEST(OutputPath, OutputsNeverNameAnInputOrEachOther) {
  const fs::path in = scratch("in.obj");
  std::ofstream(in) << "v 0 0 0\n";
  // The same file by another spelling.
  const fs::path other = in.parent_path() / "." / in.filename();
  EXPECT_NE(common::outputs_problem({{"-o", other}}, {{"MESH", in}}).find("is the input MESH"),
            std::string::npos);
  EXPECT_NE(common::outputs_problem({{"-o", scratch("a.exr")}, {"--png", scratch("a.exr")}}, {})
                .find("both name"),
            std::string::npos);
  EXPECT_EQ(common::outputs_problem({{"-o", scratch("out.prtx")}, {"--png", ""}}, {{"MESH", in}}),
            "");
}

TEST(Dcheck, ReleaseBuildsDoNotEvaluateTheCondition) {
  int evaluated = 0;
  auto condition = [&] {
    ++evaluated;
    return true;
  };
  PRTR_DCHECK(condition());
#ifdef NDEBUG
  EXPECT_EQ(evaluated, 0);
#else
  EXPECT_EQ(evaluated, 1);
  EXPECT_DEATH(PRTR_DCHECK(evaluated == 0), "internal invariant failed: evaluated == 0");
#endif
}

enum class Colour { kRed, kGreen };
constexpr common::EnumName<Colour> kColours[] = {{Colour::kRed, "red"}, {Colour::kGreen, "green"}};

TEST(EnumNames, NamesParseBackAndUnknownValuesSayUnknown) {
  for (const common::EnumName<Colour>& c : kColours)
    EXPECT_EQ(common::parse_enum<Colour>(kColours, c.name, "colour"), c.value);
  EXPECT_STREQ(common::enum_name<Colour>(kColours, static_cast<Colour>(7)), "unknown");
  try {
    common::parse_enum<Colour>(kColours, "blue", "colour");
    ADD_FAILURE() << "blue parsed";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "unknown colour 'blue'; use red or green");
  }
}

}  // namespace

TEST(WorkQueue, RunsEveryTaskAndHoldsAtMostCapacityWaiting) {
  std::atomic<int> done{0};
  std::atomic<bool> release{false};
  common::WorkQueue queue(2, 3);
  // Two tasks block both workers; then three fit the backlog and a sixth must wait.
  for (int i = 0; i < 2; ++i)
    queue.submit([&] {
      while (!release) std::this_thread::yield();
      ++done;
    });
  // Both blockers have been taken by the workers once the backlog accepts three more.
  for (int i = 0; i < 3; ++i) queue.submit([&] { ++done; });
  std::atomic<bool> sixth_in{false};
  std::thread producer([&] {
    queue.submit([&] { ++done; });
    sixth_in = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(sixth_in) << "the backlog holds at most its capacity";
  release = true;
  producer.join();
  queue.finish();
  EXPECT_EQ(done, 6);
}

TEST(WorkQueue, FirstFailureReachesTheProducer) {
  common::WorkQueue queue(1, 1);
  queue.submit([] { throw std::runtime_error("disk full"); });
  try {
    queue.finish();
    FAIL() << "finish() must rethrow";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "disk full");
  }
  EXPECT_THROW(queue.submit([] {}), std::runtime_error);
  EXPECT_THROW(common::WorkQueue(0, 1), std::invalid_argument);
}

// RFC 4648's test vectors, and a round trip of every byte value at every padding length.
TEST(Base64, MatchesTheRfcVectorsAndRoundTrips) {
  const std::pair<const char*, const char*> vectors[] = {{"", ""},
                                                         {"f", "Zg=="},
                                                         {"fo", "Zm8="},
                                                         {"foo", "Zm9v"},
                                                         {"foob", "Zm9vYg=="},
                                                         {"fooba", "Zm9vYmE="},
                                                         {"foobar", "Zm9vYmFy"}};
  for (const auto& [plain, coded] : vectors) {
    EXPECT_EQ(common::base64_encode(plain), coded);
    EXPECT_EQ(common::base64_decode(coded), plain);
  }
  std::string bytes;
  for (int i = 0; i < 256; ++i) bytes += char(i);
  for (std::size_t n = 253; n <= 256; ++n)
    EXPECT_EQ(common::base64_decode(common::base64_encode(bytes.substr(0, n))), bytes.substr(0, n));
}
