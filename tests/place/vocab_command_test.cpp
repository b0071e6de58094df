// `edgeslam vocab train|info` as a user runs them.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "place/vocabulary.h"
#include "support/edgeslam_command.h"

namespace edgeslam {
namespace {

namespace fs = std::filesystem;

TEST(VocabCommand, TrainsFromAFolderAndAListThenInfoChecksTheFile) {
  EDGESLAM_REQUIRE_SHARED("datasets/tum-fr2desk-20/rgb.txt");
  const fs::path dir =
      fs::temp_directory_path() / ("edgeslam_vocab_cli_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const fs::path out = dir / "sub" / "tum.vocab";
  const auto tum = test::sharedPath("datasets/tum-fr2desk-20");
  const auto train = test::runEdgeslam(
      "vocab train --images " + (tum / "rgb.txt").string() + " --out " + out.string() +
      " --k 4 --levels 2 --features 300 --threads 2 --max-images 8");
  ASSERT_EQ(train.exit_code, 0) << train.output;
  EXPECT_NE(train.output.find("images       8"), std::string::npos) << train.output;
  EXPECT_NE(train.output.find("words"), std::string::npos) << train.output;
  const Vocabulary v = Vocabulary::load(out);
  EXPECT_EQ(v.branching(), 4);
  EXPECT_EQ(v.levels(), 2);
  EXPECT_EQ(v.tree().training_images, 8U);

  // The same images from the folder give the same vocabulary (same order, same seed).
  const fs::path from_folder = dir / "folder.vocab";
  const auto again = test::runEdgeslam(
      "vocab train --images " + (tum / "rgb").string() + " --out " + from_folder.string() +
      " --k 4 --levels 2 --features 300 --threads 1 --max-images 8");
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(Vocabulary::load(from_folder).tree(), v.tree());

  const auto info = test::runEdgeslam("vocab info " + out.string(), false);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("words        " + std::to_string(v.wordCount())), std::string::npos)
      << info.output;
  EXPECT_NE(info.output.find("checksum     ok"), std::string::npos) << info.output;

  const auto json = test::runEdgeslam("vocab info --json " + out.string(), false);
  ASSERT_EQ(json.exit_code, 0) << json.output;
  EXPECT_NE(json.output.find("\"checksum_ok\": true"), std::string::npos) << json.output;

  {
    std::fstream f(out, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(100);
    f.put('\x7f');
  }
  const auto corrupt = test::runEdgeslam("vocab info " + out.string());
  EXPECT_EQ(corrupt.exit_code, 1);
  EXPECT_NE(corrupt.output.find("checksum mismatch"), std::string::npos) << corrupt.output;
  fs::remove_all(dir);
}

TEST(VocabCommand, BadImageArgumentsAreNamed) {
  const auto missing = test::runEdgeslam("vocab train --images /no/such/folder --out /tmp/x.vocab");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("/no/such/folder"), std::string::npos) << missing.output;
  const auto absent = test::runEdgeslam("vocab info /no/such/file.vocab");
  EXPECT_EQ(absent.exit_code, 1);
  EXPECT_NE(absent.output.find("cannot open"), std::string::npos) << absent.output;
}

}  // namespace
}  // namespace edgeslam
