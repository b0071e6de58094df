// Keyframes' places (bag of words and direct index) in the store: written with the keyframes,
// read back as they were made, attached on load only for the vocabulary that made them; a store
// of schema version 1 (without them) still opens, and a writer migrates it.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include "place/vocabulary_training.h"
#include "store/map_store.h"
#include "store/map_store_writer.h"
#include "store/store_schema.h"
#include "store/stored_map_loader.h"
#include "store_fixture.h"

namespace edgeslam {
namespace {

using test::freshStoreDir;
using test::SmallMap;

constexpr int kDepth = 1;

Vocabulary vocabularyOf(const SmallMap& small, std::uint64_t seed = 0) {
  std::vector<cv::Mat> descriptors;
  for (const KeyFrame* kf : small.keyframes) descriptors.push_back(kf->features().descriptors);
  VocabularyTrainingOptions options;
  options.branching = 4;
  options.levels = 3;
  options.seed = seed;
  options.weighting = WordWeighting::kTf;  // idf is 0 for words all three views share
  return trainVocabulary(descriptors, options);
}

void writeWhole(const std::shared_ptr<MapStore>& store, StoreSessionId session, SmallMap& small) {
  MapStoreWriter writer(store, session, small.map, nullptr);
  {
    MutexLock lock(small.map.updateMutex());
    writer.onMapChanged(small.map.takeChanges());
  }
  writer.stop();
}

TEST(MapStorePlaces, WrittenWithTheKeyFramesAndAttachedForTheSameVocabularyOnly) {
  const auto dir = freshStoreDir("places");
  SmallMap small;
  const Vocabulary vocabulary = vocabularyOf(small);
  ASSERT_EQ(describeKeyFrames(small.map, vocabulary, kDepth), 3u);
  {
    std::shared_ptr<MapStore> store = openMapStore(dir, MapStoreAccess::kServe);
    writeWhole(store, store->beginSession("m", small.info()), small);
  }
  auto store = openMapStore(dir, MapStoreAccess::kRead);
  const auto stored = store->loadMap("m");
  ASSERT_TRUE(stored);
  const StoredSession& session = stored->sessions.at(0);
  ASSERT_EQ(session.places.size(), 3u);
  {
    MutexLock lock(small.map.updateMutex());
    for (const KeyFramePlaceRecord& p : session.places) {
      const KeyFrame* original = small.map.keyFrame(p.keyframe);
      ASSERT_NE(original, nullptr);
      EXPECT_EQ(p.vocabulary, vocabulary.checksum());
      EXPECT_EQ(p.direct_index_depth, kDepth);
      EXPECT_FALSE(p.bow.empty());
      EXPECT_EQ(p.bow, original->place()->bow);
      EXPECT_EQ(p.features, original->place()->features);
    }
  }

  Map loaded;
  loadStoredSession(session, loaded);
  const AttachedPlaces attached =
      attachStoredPlaces(session, loaded, vocabulary, vocabulary.checksum(), kDepth);
  EXPECT_EQ(attached.attached, 3u);
  EXPECT_TRUE(attached.missing.empty());
  EXPECT_EQ(describeKeyFrames(loaded, vocabulary, kDepth), 0u);  // nothing left to compute
  {
    MutexLock lock(loaded.updateMutex());
    const KeyFrame* first = loaded.keyFrame(small.keyframes[0]->id());
    ASSERT_NE(first, nullptr);
    ASSERT_NE(first->place(), nullptr);
    EXPECT_EQ(first->place()->vocabulary, &vocabulary);
    EXPECT_EQ(first->place()->bow, vocabulary.transform(first->features().descriptors));
  }

  // Another vocabulary (or depth): the stored places are not used, the keyframes are described.
  const Vocabulary other = vocabularyOf(small, 7);
  ASSERT_NE(other.checksum(), vocabulary.checksum());
  Map again;
  loadStoredSession(session, again);
  const AttachedPlaces none = attachStoredPlaces(session, again, other, other.checksum(), kDepth);
  EXPECT_EQ(none.attached, 0u);
  EXPECT_EQ(none.missing.size(), 3u);
  EXPECT_EQ(
      attachStoredPlaces(session, again, vocabulary, vocabulary.checksum(), kDepth + 1).attached,
      0u);
  EXPECT_EQ(describeKeyFrames(again, other, kDepth), 3u);
  std::filesystem::remove_all(dir);
}

TEST(MapStorePlaces, KeyFrameDescribedAfterItWasWrittenGetsItsPlaceLater) {
  const auto dir = freshStoreDir("places_later");
  SmallMap small;
  const Vocabulary vocabulary = vocabularyOf(small);
  std::shared_ptr<MapStore> store = openMapStore(dir, MapStoreAccess::kServe);
  const StoreSessionId session = store->beginSession("m", small.info());
  MapStoreWriter writer(store, session, small.map, nullptr);
  {
    MutexLock lock(small.map.updateMutex());
    writer.onMapChanged(small.map.takeChanges());
  }
  writer.flush();
  EXPECT_TRUE(store->loadMap("m")->sessions.at(0).places.empty());
  describeKeyFrames(small.map, vocabulary, kDepth);  // mapping describes them after the batch
  writer.flush();
  EXPECT_EQ(store->loadMap("m")->sessions.at(0).places.size(), 3u);
  // An erased keyframe takes its place with it.
  {
    MutexLock lock(small.map.updateMutex());
    small.map.eraseKeyFrame(small.keyframes[2]);
    writer.onMapChanged(small.map.takeChanges());
  }
  writer.stop();
  const auto stored = store->loadMap("m");
  EXPECT_EQ(stored->sessions.at(0).keyframes.size(), 2u);
  EXPECT_EQ(stored->sessions.at(0).places.size(), 2u);
  std::filesystem::remove_all(dir);
}

TEST(MapStorePlaces, VersionOneStoreOpensAndAWriterMigratesIt) {
  const auto dir = freshStoreDir("places_v1");
  SmallMap small;
  const Vocabulary vocabulary = vocabularyOf(small);
  describeKeyFrames(small.map, vocabulary, kDepth);
  {
    std::shared_ptr<MapStore> store = openMapStore(dir, MapStoreAccess::kServe);
    writeWhole(store, store->beginSession("m", small.info()), small);
  }
  // What edgeslam wrote before schema version 2.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir / "maps.sqlite").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(
      sqlite3_exec(db, "DROP TABLE keyframe_places; DROP TABLE routes; PRAGMA user_version = 1",
                   nullptr, nullptr, nullptr),
      SQLITE_OK);
  sqlite3_close(db);
  {
    auto reader = openMapStore(dir, MapStoreAccess::kRead);
    const auto stored = reader->loadMap("m");
    ASSERT_TRUE(stored);
    EXPECT_EQ(stored->sessions.at(0).keyframes.size(), 3u);
    EXPECT_TRUE(stored->sessions.at(0).places.empty());
    EXPECT_EQ(reader->mapInfo("m")->keyframes, 3u);
  }
  {
    std::shared_ptr<MapStore> writer = openMapStore(dir, MapStoreAccess::kServe);
    const auto stored = writer->loadMap("m");
    EXPECT_EQ(stored->sessions.at(0).keyframes.size(), 3u);
    MapStoreBatch batch;
    batch.places.push_back({.keyframe = small.keyframes[0]->id(),
                            .vocabulary = vocabulary.checksum(),
                            .direct_index_depth = kDepth,
                            .bow = small.keyframes[0]->place()->bow,
                            .features = small.keyframes[0]->place()->features});
    writer->write(stored->sessions.at(0).id, batch);
    EXPECT_EQ(writer->loadMap("m")->sessions.at(0).places.size(), 1u);
  }
  ASSERT_EQ(sqlite3_open((dir / "maps.sqlite").c_str(), &db), SQLITE_OK);
  sqlite3_stmt* version = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "PRAGMA user_version", -1, &version, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_step(version), SQLITE_ROW);
  EXPECT_EQ(sqlite3_column_int(version, 0), kSchemaVersion);  // migrated through every version
  sqlite3_finalize(version);
  sqlite3_close(db);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace edgeslam
