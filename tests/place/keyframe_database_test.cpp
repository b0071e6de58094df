// The inverted-index database: queries, exclusion, erase, and concurrent use.
#include "place/keyframe_database.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

namespace edgeslam {
namespace {

BowVector bowOf(std::vector<BowEntry> entries) {
  BowVector b = makeBowVector(std::move(entries));
  normalizeL1(b);
  return b;
}

class KeyFrameDatabaseTest : public ::testing::Test {
 protected:
  void SetUp() override {
    db_.add(10, bowOf({{1, 1}, {2, 1}, {3, 1}, {4, 1}}));
    db_.add(20, bowOf({{3, 1}, {4, 1}, {5, 1}, {6, 1}}));
    db_.add(30, bowOf({{7, 1}, {8, 1}}));
    db_.add(40, bowOf({{1, 1}, {2, 1}, {3, 1}, {9, 1}}));
  }
  KeyFrameDatabase db_;
};

TEST_F(KeyFrameDatabaseTest, QueryReturnsTheSameImageFirstThenBySimilarity) {
  const BowVector q = bowOf({{1, 1}, {2, 1}, {3, 1}, {4, 1}});
  const auto results = db_.query(q, 0);
  ASSERT_EQ(results.size(), 3U);  // 30 shares nothing
  EXPECT_EQ(results[0].id, 10U);
  EXPECT_DOUBLE_EQ(results[0].score, 1.0);
  EXPECT_EQ(results[0].shared_words, 4);
  EXPECT_EQ(results[1].id, 40U);
  EXPECT_NEAR(results[1].score, 0.75, 1e-12);
  EXPECT_EQ(results[2].id, 20U);
  EXPECT_NEAR(results[2].score, 0.5, 1e-12);
  for (const auto& r : results) {
    EXPECT_NEAR(r.score, *db_.score(q, r.id), 1e-12);
    EXPECT_NEAR(r.score, l1Score(q, *db_.bowOf(r.id)), 1e-12);
  }
  EXPECT_EQ(db_.query(q, 1).size(), 1U);
  EXPECT_EQ(db_.query(q, 0, 0.6).size(), 2U);
  EXPECT_FALSE(db_.score(q, 99).has_value());
}

TEST_F(KeyFrameDatabaseTest, CandidatesCountSharedWordsAndHonourExclusion) {
  const BowVector q = bowOf({{1, 1}, {2, 1}, {3, 1}, {4, 1}});
  const auto all = db_.candidatesSharingWords(q);
  ASSERT_EQ(all.size(), 3U);
  EXPECT_EQ(all[0].id, 10U);
  EXPECT_EQ(all[0].shared_words, 4);
  EXPECT_EQ(all[1].id, 40U);
  EXPECT_EQ(all[1].shared_words, 3);
  EXPECT_EQ(all[2].id, 20U);
  EXPECT_EQ(all[2].shared_words, 2);
  const auto excluded = db_.candidatesSharingWords(q, {10, 40});
  ASSERT_EQ(excluded.size(), 1U);
  EXPECT_EQ(excluded[0].id, 20U);
  EXPECT_EQ(db_.query(q, 0, 0.0, {10})[0].id, 40U);
}

TEST_F(KeyFrameDatabaseTest, EraseReplaceAndClear) {
  const BowVector q = bowOf({{1, 1}, {2, 1}});
  db_.erase(10);
  db_.erase(12345);  // unknown: no-op
  EXPECT_FALSE(db_.contains(10));
  EXPECT_EQ(db_.size(), 3U);
  ASSERT_EQ(db_.query(q, 0).size(), 1U);
  EXPECT_EQ(db_.query(q, 0)[0].id, 40U);
  db_.add(40, bowOf({{7, 1}}));  // replaces
  EXPECT_TRUE(db_.query(q, 0).empty());
  EXPECT_EQ(db_.candidatesSharingWords(bowOf({{7, 1}})).size(), 2U);
  db_.clear();
  EXPECT_EQ(db_.size(), 0U);
  EXPECT_TRUE(db_.query(bowOf({{7, 1}}), 0).empty());
}

TEST_F(KeyFrameDatabaseTest, StoresNormalisedVectors) {
  db_.add(50, makeBowVector({{1, 4.0}, {2, 4.0}}));
  EXPECT_NEAR(db_.bowOf(50)->sum(), 1.0, 1e-12);
  EXPECT_NEAR(*db_.score(makeBowVector({{1, 3.0}, {2, 3.0}}), 50), 1.0, 1e-12);
}

TEST(KeyFrameDatabaseConcurrency, AddsAndQueriesFromTwoThreads) {
  KeyFrameDatabase db;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (ImageId id = 0; id < 400; ++id) {
      db.add(id,
             bowOf({{static_cast<WordId>(id % 50), 1}, {static_cast<WordId>(id % 7 + 100), 1}}));
      if (id % 5 == 0 && id > 0) db.erase(id - 1);
    }
    done = true;
  });
  std::size_t queries = 0;
  do {
    const auto results = db.query(bowOf({{3, 1}, {103, 1}}), 5);
    for (const auto& r : results) EXPECT_GT(r.score, 0.0);
    ++queries;
  } while (!done);
  writer.join();
  EXPECT_GT(queries, 0U);
  EXPECT_EQ(db.size(), 400U - 79U);
}

}  // namespace
}  // namespace edgeslam
