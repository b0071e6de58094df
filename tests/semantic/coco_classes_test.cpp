#include "semantic/coco_classes.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace edgeslam {
namespace {

TEST(CocoClasses, NamesFollowTheUsualOrder) {
  EXPECT_EQ(cocoClassName(0), "person");
  EXPECT_EQ(cocoClassName(2), "car");
  EXPECT_EQ(cocoClassName(5), "bus");
  EXPECT_EQ(cocoClassName(7), "truck");
  EXPECT_EQ(cocoClassName(16), "dog");
  EXPECT_EQ(cocoClassName(79), "toothbrush");
  EXPECT_THROW(cocoClassName(80), std::out_of_range);
  EXPECT_THROW(cocoClassName(-1), std::out_of_range);
}

TEST(CocoClasses, LooksUpNamesLeniently) {
  EXPECT_EQ(cocoClassId("person"), 0);
  EXPECT_EQ(cocoClassId(" Traffic_Light "), 9);
  EXPECT_EQ(cocoClassId("unicorn"), -1);
}

TEST(CocoClasses, DefaultMovableClassesAreVehiclesPeopleAndAnimals) {
  const auto ids = defaultMovableClasses();
  EXPECT_EQ(classListToString(ids),
            "person,bicycle,car,motorcycle,bus,truck,bird,cat,dog,horse,sheep,cow,elephant,bear,"
            "zebra,giraffe");
}

TEST(CocoClasses, ParsesCommaSeparatedLists) {
  EXPECT_EQ(parseClassList("dog, person,car,person"), (std::vector<int>{0, 2, 16}));
  EXPECT_EQ(parseClassList("default"), defaultMovableClasses());
  EXPECT_EQ(parseClassList("default,chair").back(), 56);
}

TEST(CocoClasses, RejectsUnknownOrEmptyLists) {
  try {
    parseClassList("person,unicorn");
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unicorn"), std::string::npos);
  }
  EXPECT_THROW(parseClassList(" , "), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
