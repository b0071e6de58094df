#include "synth/people_motion.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <stdexcept>

namespace edgeslam {
namespace {

MotionSettings kitchenSettings(std::uint64_t seed, int people = 0) {
  MotionSettings settings;
  settings.seed = seed;
  settings.duration_s = 20.0;
  settings.people_count = people;
  settings.image = cv::Size(640, 480);
  settings.fx = settings.fy = 585.0;
  settings.cx = 320.0;
  settings.cy = 240.0;
  settings.base_height_px = 500.0;
  settings.sprite_aspects = {0.35, 0.3, 0.4};
  return settings;
}

bool samePlacements(const std::vector<PersonPlacement>& a, const std::vector<PersonPlacement>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].person != b[i].person || a[i].center_x != b[i].center_x ||
        a[i].foot_y != b[i].foot_y || a[i].height_px != b[i].height_px) {
      return false;
    }
  }
  return true;
}

TEST(PeopleMotion, SameSeedSamePlanOtherSeedOtherPlan) {
  const MotionPlan a = planPeopleMotion(kitchenSettings(5));
  const MotionPlan b = planPeopleMotion(kitchenSettings(5));
  const MotionPlan c = planPeopleMotion(kitchenSettings(6));
  bool differs = false;
  for (double t = 0.0; t < 20.0; t += 0.25) {
    EXPECT_TRUE(samePlacements(a.placementsAt(t), b.placementsAt(t))) << t;
    differs = differs || !samePlacements(a.placementsAt(t), c.placementsAt(t));
  }
  EXPECT_TRUE(differs);
}

TEST(PeopleMotion, OneToThreePeopleAndTheFirstIsOnStageAtTheStart) {
  std::map<std::size_t, int> counts;
  for (std::uint64_t seed = 1; seed <= 30; ++seed) {
    const MotionPlan plan = planPeopleMotion(kitchenSettings(seed));
    ASSERT_GE(plan.people.size(), 1u);
    ASSERT_LE(plan.people.size(), 3u);
    ++counts[plan.people.size()];
    EXPECT_FALSE(plan.placementsAt(0.0).empty()) << "seed " << seed;
  }
  EXPECT_EQ(counts.size(), 3u);  // every count occurs
  EXPECT_EQ(planPeopleMotion(kitchenSettings(1, 3)).people.size(), 3u);
}

TEST(PeopleMotion, WalksEnterAndLeaveThroughTheBordersAndScaleWithDistance) {
  const MotionSettings settings = kitchenSettings(11, 3);
  const MotionPlan plan = planPeopleMotion(settings);
  std::map<WalkKind, int> kinds;
  bool partly_outside = false;
  for (const PersonTrack& track : plan.people) {
    for (const Walk& walk : track.walks) {
      ++kinds[walk.kind];
      const double start_height = settings.fy * 1.7 / walk.from.z_m;
      const double end_height = settings.fy * 1.7 / walk.to.z_m;
      const double change = end_height / start_height;
      if (walk.kind == WalkKind::kApproach) {
        EXPECT_GT(change, 1.9);  // ~0.65x -> ~1.5x of the base height
        EXPECT_LT(change, 2.7);
      } else if (walk.kind == WalkKind::kRecede) {
        EXPECT_LT(change, 1.0 / 1.9);
      } else {
        EXPECT_GT(change, 0.8);
        EXPECT_LT(change, 1.2);
      }
      EXPECT_GT(walk.duration_s, 1.0);
      EXPECT_LT(walk.duration_s, 10.0);
    }
    // Walks of one person never overlap in time.
    for (std::size_t i = 1; i < track.walks.size(); ++i) {
      EXPECT_GT(track.walks[i].start_s, track.walks[i - 1].start_s + track.walks[i - 1].duration_s);
    }
  }
  EXPECT_EQ(kinds.size(), 3u);
  // At a walk's ends the person is outside the image; in between visible, partly cut at times.
  const PersonTrack& track = plan.people.front();
  const Walk& walk = track.walks.front();
  std::size_t visible = 0, samples = 0;
  for (double s = 0.0; s <= 1.0; s += 0.01, ++samples) {
    const auto placements = plan.placementsAt(walk.start_s + s * walk.duration_s);
    const bool shown = std::any_of(placements.begin(), placements.end(),
                                   [](const PersonPlacement& p) { return p.person == 0; });
    if (s < 1e-9 || s > 0.999) {
      EXPECT_FALSE(shown) << s;
      continue;
    }
    if (!shown) continue;
    ++visible;
    for (const PersonPlacement& p : placements) {
      if (p.person != 0) continue;
      const double half_width = 0.5 * p.height_px * track.aspect;
      partly_outside = partly_outside || p.center_x - half_width < 0.0 ||
                       p.center_x + half_width > settings.image.width;
      EXPECT_NEAR(p.height_px * p.depth_m, settings.fy * 1.7, 1e-6);
    }
  }
  EXPECT_GT(visible, samples / 2);
  EXPECT_TRUE(partly_outside);
}

TEST(PeopleMotion, PlacementsAreSortedFarthestFirst) {
  const MotionPlan plan = planPeopleMotion(kitchenSettings(2, 3));
  for (double t = 0.0; t < 20.0; t += 0.1) {
    const auto placements = plan.placementsAt(t);
    for (std::size_t i = 1; i < placements.size(); ++i) {
      EXPECT_GE(placements[i - 1].depth_m, placements[i].depth_m);
    }
  }
}

TEST(PeopleMotion, RejectsBadSettings) {
  MotionSettings settings = kitchenSettings(1);
  settings.sprite_aspects.clear();
  EXPECT_THROW(planPeopleMotion(settings), std::invalid_argument);
  settings = kitchenSettings(1);
  settings.base_height_px = 0.0;
  EXPECT_THROW(planPeopleMotion(settings), std::invalid_argument);
  settings = kitchenSettings(1, 4);
  EXPECT_THROW(planPeopleMotion(settings), std::invalid_argument);
  settings = kitchenSettings(1);
  settings.fx = 0.0;
  EXPECT_THROW(planPeopleMotion(settings), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
