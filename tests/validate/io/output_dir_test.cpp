// Output safety: what rdyn did not write is never deleted or replaced; rdyn's own outputs
// are replaced whole; an unfinished output leaves nothing behind.
#include "validate/io/output_dir.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

class Outputs : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("rdyn_out_" + std::to_string(getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  static std::string read(const fs::path& p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  }
  // Names in the test folder that are rdyn temporaries.
  long temporaries() const {
    long n = 0;
    for (const auto& e : fs::recursive_directory_iterator(dir_))
      n += e.path().filename().string().find("rdyn-tmp") != std::string::npos;
    return n;
  }
  fs::path dir_;
};

TEST_F(Outputs, NewFolderGetsTheResultsAndAManifestOfThem) {
  {
    OutputDir out((dir_ / "a/b/res").string());
    write_text_file(out.file("x.csv"), "1\n");
    out.make_subfolder("sub");
    write_text_file(out.file("sub/y.csv"), "2\n");
    out.commit();
  }
  EXPECT_EQ(read(dir_ / "a/b/res/x.csv"), "1\n");
  EXPECT_EQ(read(dir_ / "a/b/res/.rdyn-output"), "rdyn output v1\nsub/\nsub/y.csv\nx.csv\n");
  EXPECT_EQ(temporaries(), 0);
}

TEST_F(Outputs, UnfinishedOutputLeavesNothingNotEvenTheParentsItCreated) {
  {
    OutputDir out((dir_ / "new/deeper/res").string());
    write_text_file(out.file("x.csv"), "1\n");
  }  // no commit: a failed run
  EXPECT_FALSE(fs::exists(dir_ / "new"));
  EXPECT_EQ(temporaries(), 0);
}

TEST_F(Outputs, RdynOutputIsReplacedWhole) {
  for (const char* name : {"first.csv", "second.csv"}) {
    OutputDir out((dir_ / "res").string());
    write_text_file(out.file(name), name);
    out.commit();
  }
  EXPECT_FALSE(fs::exists(dir_ / "res/first.csv"));
  EXPECT_EQ(read(dir_ / "res/second.csv"), "second.csv");
  EXPECT_EQ(temporaries(), 0);
}

TEST_F(Outputs, ForeignFolderIsRefusedUntouchedAndForceMergesIntoIt) {
  fs::create_directories(dir_ / "proj");
  std::ofstream(dir_ / "proj/scene.yaml") << "mine";
  std::ofstream(dir_ / "proj/x.csv") << "old";
  EXPECT_THROW(OutputDir((dir_ / "proj").string()), OutputError);
  EXPECT_EQ(read(dir_ / "proj/scene.yaml"), "mine");
  {
    OutputDir out((dir_ / "proj").string(), /*force=*/true);
    write_text_file(out.file("x.csv"), "new");
    out.commit();
  }
  EXPECT_EQ(read(dir_ / "proj/scene.yaml"), "mine");  // kept
  EXPECT_EQ(read(dir_ / "proj/x.csv"), "new");        // same name: replaced, as --force says
  EXPECT_EQ(read(dir_ / "proj/.rdyn-output"), "rdyn output v1\nx.csv\n");
  EXPECT_THROW(OutputDir((dir_ / "proj").string()), OutputError);  // scene.yaml is still not rdyn's
}

TEST_F(Outputs, ForcedMergeChecksEveryDestinationBeforeMovingAnything) {
  // A user folder where rdyn writes a file (or a file where it writes a folder) is refused at
  // commit before the first move: run.json stays the user's and no manifest appears (issue #23).
  for (const bool folder_for_file : {true, false}) {
    fs::remove_all(dir_ / "proj");
    fs::create_directories(dir_ / "proj");
    std::ofstream(dir_ / "proj/run.json") << "the user's";
    if (folder_for_file) {
      fs::create_directories(dir_ / "proj/timeseries.csv");
    } else {
      std::ofstream(dir_ / "proj/figures") << "a file";
    }
    {
      OutputDir out((dir_ / "proj").string(), /*force=*/true);
      write_text_file(out.file("run.json"), "rdyn's");
      write_text_file(out.file("timeseries.csv"), "t\n");
      out.make_subfolder("figures");
      write_text_file(out.file("figures/a.svg"), "<svg/>");
      try {
        out.commit();
        ADD_FAILURE() << "committed";
      } catch (const OutputError& e) {
        EXPECT_NE(std::string(e.what()).find(folder_for_file ? "proj/timeseries.csv: is a folder"
                                                             : "proj/figures: exists and is not a folder"),
                  std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("Nothing was written"), std::string::npos) << e.what();
      }
    }
    EXPECT_EQ(read(dir_ / "proj/run.json"), "the user's");
    EXPECT_FALSE(fs::exists(dir_ / "proj/.rdyn-output"));
    EXPECT_EQ(temporaries(), 0);
  }
}

TEST_F(Outputs, AFileAddedDuringTheRunStopsTheReplacement) {
  {
    OutputDir first((dir_ / "res").string());
    write_text_file(first.file("a.csv"), "a");
    first.commit();
  }
  OutputDir second((dir_ / "res").string());
  write_text_file(second.file("b.csv"), "b");
  std::ofstream(dir_ / "res/notes.txt") << "written by the user meanwhile";
  EXPECT_THROW(second.commit(), OutputError);
  EXPECT_EQ(read(dir_ / "res/notes.txt"), "written by the user meanwhile");
  EXPECT_EQ(read(dir_ / "res/a.csv"), "a");
}

TEST_F(Outputs, AUserFolderInsideAnRdynOutputIsForeign) {
  {
    OutputDir first((dir_ / "res").string());
    write_text_file(first.file("a.csv"), "a");
    first.commit();
  }
  fs::create_directories(dir_ / "res/my_notes/sub");
  EXPECT_THROW(OutputDir((dir_ / "res").string()), OutputError);
  EXPECT_TRUE(fs::exists(dir_ / "res/my_notes/sub"));
}

TEST_F(Outputs, SymlinkedFolderIsFollowed) {
  fs::create_directories(dir_ / "real");
  fs::create_directory_symlink("real", dir_ / "link");
  OutputDir out((dir_ / "link").string());
  write_text_file(out.file("x.csv"), "1");
  out.commit();
  EXPECT_TRUE(fs::is_symlink(dir_ / "link"));
  EXPECT_EQ(read(dir_ / "real/x.csv"), "1");
}

TEST_F(Outputs, FilesAreReplacedOnlyWhenRecognisedOrForced) {
  const auto ours = [](const std::string& head) { return head.rfind("# rdyn", 0) == 0; };
  const std::string path = (dir_ / "t.csv").string();
  std::ofstream(path) << "user data";
  EXPECT_THROW(OutputFile(path, false, ours), OutputError);
  EXPECT_EQ(read(path), "user data");
  {
    OutputFile f(path, /*force=*/true, ours);
    write_text_file(f.write_path(), "# rdyn 1");
    f.commit();
  }
  {
    OutputFile f(path, false, ours);  // now recognisably rdyn's
    write_text_file(f.write_path(), "# rdyn 2");
    f.commit();
  }
  EXPECT_EQ(read(path), "# rdyn 2");
  {
    OutputFile f(path, false, ours);
    write_text_file(f.write_path(), "# rdyn 3 unfinished");
  }  // no commit
  EXPECT_EQ(read(path), "# rdyn 2");
  EXPECT_EQ(temporaries(), 0);
}

TEST_F(Outputs, DevicesAreWrittenThroughAndAFullOneFailsWithItsReason) {
  OutputFile null_out("/dev/null", false, nullptr);
  EXPECT_EQ(null_out.write_path(), "/dev/null");
  write_text_file(null_out.write_path(), "discarded");
  null_out.commit();
  OutputFile full("/dev/full", false, nullptr);
  try {
    write_text_file(full.write_path(), "x");
    FAIL() << "a full device accepted a write";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("No space left"), std::string::npos) << e.what();
  }
}

TEST_F(Outputs, FifoIsRefusedWithoutAReaderAndWrittenThroughWithOne) {
  const std::string fifo = (dir_ / "pipe").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  EXPECT_THROW(OutputFile(fifo, false, nullptr), OutputError);
  const int reader = open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  {
    OutputFile f(fifo, false, nullptr);
    write_text_file(f.write_path(), "through the pipe");
    f.commit();
  }
  char buf[64] = {};
  EXPECT_EQ(::read(reader, buf, sizeof buf - 1), 16);
  EXPECT_STREQ(buf, "through the pipe");
  close(reader);
}

TEST_F(Outputs, FolderWhereAFileIsExpectedAndTheReverseAreRefused) {
  fs::create_directories(dir_ / "d");
  EXPECT_THROW(OutputFile((dir_ / "d").string(), true, nullptr), OutputError);
  std::ofstream(dir_ / "f") << "x";
  EXPECT_THROW(OutputDir((dir_ / "f").string(), true), OutputError);
  EXPECT_THROW(OutputDir("/"), OutputError);
  EXPECT_EQ(read(dir_ / "f"), "x");
}

}  // namespace
}  // namespace rdyn::validate
