// The vocabulary file: round trip and rejection of damaged files.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <random>

#include "place/vocabulary_training.h"
#include "synthetic_descriptors.h"

namespace edgeslam {
namespace {

namespace fs = std::filesystem;

class VocabularyFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("edgeslam_vocab_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    const auto s = test::makeScenes(6, 30, 24, 50, 8, 4);
    images_ = s.images;
    VocabularyTrainingOptions o;
    o.branching = 5;
    o.levels = 3;
    vocabulary_ = trainVocabulary(images_, o);
    path_ = dir_ / "small.vocab";
    vocabulary_.save(path_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::vector<char> bytes() const {
    std::ifstream in(path_, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
  }
  void write(const fs::path& path, const std::vector<char>& data) const {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(data.data(), static_cast<std::streamsize>(data.size()));
  }
  // The message of the exception loading `path` throws ("" when none).
  static std::string loadError(const fs::path& path) {
    try {
      Vocabulary::load(path);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
  fs::path path_;
  std::vector<cv::Mat> images_;
  Vocabulary vocabulary_;
};

TEST_F(VocabularyFile, RoundTripKeepsTreeWeightsAndTransform) {
  const Vocabulary loaded = Vocabulary::load(path_);
  EXPECT_EQ(loaded.tree(), vocabulary_.tree());
  EXPECT_EQ(loaded.wordCount(), vocabulary_.wordCount());
  for (WordId w = 0; w < loaded.wordCount(); ++w) {
    EXPECT_EQ(loaded.wordWeight(w), vocabulary_.wordWeight(w));
  }
  for (const cv::Mat& image : images_) {
    EXPECT_EQ(loaded.transform(image), vocabulary_.transform(image));
    BowVector b1, b2;
    FeatureVector f1, f2;
    loaded.transform(image, 1, b1, f1);
    vocabulary_.transform(image, 1, b2, f2);
    EXPECT_EQ(f1, f2);
  }
  EXPECT_EQ(loaded.checksum(), vocabulary_.checksum());
  EXPECT_FALSE(fs::exists(fs::path(path_.string() + ".partial")));
}

TEST_F(VocabularyFile, FlippedByteIsACorruptChecksum) {
  std::vector<char> data = bytes();
  data[data.size() / 2] ^= 0x10;
  const fs::path bad = dir_ / "flipped.vocab";
  write(bad, data);
  const std::string error = loadError(bad);
  EXPECT_NE(error.find("checksum mismatch"), std::string::npos) << error;
  EXPECT_NE(error.find(bad.string()), std::string::npos) << error;
}

TEST_F(VocabularyFile, TruncatedFileIsNamedTruncated) {
  std::vector<char> data = bytes();
  for (const std::size_t keep : {data.size() - 1, data.size() / 2, std::size_t{20}}) {
    const fs::path bad = dir_ / "truncated.vocab";
    write(bad, std::vector<char>(data.begin(), data.begin() + static_cast<long>(keep)));
    const std::string error = loadError(bad);
    EXPECT_NE(error.find("truncated"), std::string::npos) << keep << ": " << error;
    EXPECT_NE(error.find(bad.string()), std::string::npos) << error;
  }
  data.push_back('x');
  write(dir_ / "long.vocab", data);
  EXPECT_NE(loadError(dir_ / "long.vocab").find("unexpected bytes"), std::string::npos);
}

TEST_F(VocabularyFile, WrongMagicOrVersionOrMissingFileIsRejected) {
  std::vector<char> data = bytes();
  std::vector<char> magic = data;
  magic[0] = 'X';
  write(dir_ / "magic.vocab", magic);
  EXPECT_NE(loadError(dir_ / "magic.vocab").find("bad magic"), std::string::npos);

  std::vector<char> version = data;
  version[8] = 7;  // the format version follows the 8-byte magic
  write(dir_ / "version.vocab", version);
  const std::string version_error = loadError(dir_ / "version.vocab");
  EXPECT_NE(version_error.find("unsupported format version 7"), std::string::npos) << version_error;

  write(dir_ / "text.vocab", std::vector<char>{'h', 'e', 'l', 'l', 'o'});
  EXPECT_NE(loadError(dir_ / "text.vocab").find("bad magic"), std::string::npos);

  const std::string missing = loadError(dir_ / "absent.vocab");
  EXPECT_NE(missing.find("cannot open"), std::string::npos) << missing;
  EXPECT_NE(missing.find("absent.vocab"), std::string::npos) << missing;
}

TEST_F(VocabularyFile, SaveIntoAMissingFolderFailsClearly) {
  try {
    vocabulary_.save(dir_ / "no" / "such" / "folder" / "v.vocab");
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot create"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace edgeslam
