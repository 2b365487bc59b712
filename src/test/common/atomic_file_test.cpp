#include "palcas_core/common/atomic_file.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace fs = std::filesystem;

namespace {

std::string readAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("palcas_atomic_file_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(AtomicFileTest, WritesNewFileAndReplacesOldOneWhole) {
  const std::string path = (dir_ / "a.bin").string();
  const std::string binary("x\0y\n\xff", 5);
  palcas::writeFileAtomically(path, binary);
  EXPECT_EQ(readAll(path), binary);
  palcas::writeFileAtomically(path, "second");
  EXPECT_EQ(readAll(path), "second");
  EXPECT_FALSE(fs::exists(path + ".tmp"));
}

TEST_F(AtomicFileTest, MissingFolderThrowsNamingTheFile) {
  const std::string path = (dir_ / "no_such_folder" / "a.txt").string();
  palcas_test::expectThrowNaming<std::runtime_error>(
      [&] { palcas::writeFileAtomically(path, "text"); }, path + ".tmp");
}

TEST_F(AtomicFileTest, FailedRenameKeepsOldContentAndRemovesTmp) {
  // A folder where the file should be: rename(2) of a file over a folder fails.
  const fs::path path = dir_ / "target";
  fs::create_directories(path / "inside");
  palcas_test::expectThrowNaming<std::runtime_error>(
      [&] { palcas::writeFileAtomically(path.string(), "text"); }, path.string());
  EXPECT_TRUE(fs::is_directory(path / "inside"));
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
}

}  // namespace
