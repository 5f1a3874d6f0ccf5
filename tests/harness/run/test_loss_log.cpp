// run.log's lines for a loss stretch (LossLog): each failed relocalisation
// attempt with its reason, repeats folded, a summary when it ends.
#include <gtest/gtest.h>

#include "pvb/run/loss_log.hpp"

namespace pvb::run {
namespace {

std::vector<std::string> feed(LossLog& log, int index, bool lost, const std::string& reason = {},
                              const std::string& kind = {}) {
  return log.frame(index, index / 30.0, lost, reason, kind);
}

TEST(LossLog, ExplainsEveryLostFrameAndSummarisesTheStretch) {
  LossLog log("pe-slam");
  EXPECT_TRUE(feed(log, 9, false).empty());
  // The loss itself has its own line elsewhere.
  EXPECT_TRUE(feed(log, 10, true, "local map: only 21 inliers", "none").empty());
  const std::string none = "relocalisation: 0 candidates from place recognition";
  const std::string few = "relocalisation: 3 candidates, best 9 descriptor matches (need 15)";
  EXPECT_TRUE(feed(log, 11, true, none, "no candidates").empty());
  EXPECT_TRUE(feed(log, 12, true, none, "no candidates").empty());
  EXPECT_TRUE(feed(log, 13, true, none, "no candidates").empty());
  std::vector<std::string> l = feed(log, 14, true, few, "too few descriptor matches");
  ASSERT_EQ(l.size(), 1u);
  EXPECT_EQ(l[0], "frames 11-13 (t = 0.367-0.433 s): pe-slam still lost, 3 frames: " + none);
  l = feed(log, 15, false);
  ASSERT_EQ(l.size(), 2u);
  EXPECT_EQ(l[0], "frame 14 (t = 0.467 s): pe-slam still lost: " + few);
  EXPECT_EQ(l[1],
            "frames 10-14: pe-slam lost for 5 frames, 4 relocalisation attempts failed (3 no candidates, "
            "1 too few descriptor matches); tracked again at frame 15");
  EXPECT_TRUE(feed(log, 16, false).empty());
  EXPECT_TRUE(log.finish().empty());
}

TEST(LossLog, ALossToTheEndIsSummarisedAtTheEnd) {
  LossLog log("baseline");
  EXPECT_TRUE(feed(log, 0, false).empty());
  EXPECT_TRUE(feed(log, 1, true, "motion model: only 3 matches", "none").empty());
  EXPECT_TRUE(feed(log, 2, true, "relocalisation: ambiguous (keyframes 3 and 40 both matched, at places 4.10 m apart)",
                   "ambiguous")
                  .empty());
  const std::vector<std::string> l = log.finish();
  ASSERT_EQ(l.size(), 2u);
  EXPECT_EQ(l[0], "frame 2 (t = 0.067 s): baseline still lost: relocalisation: ambiguous (keyframes 3 and 40 both "
                  "matched, at places 4.10 m apart)");
  EXPECT_EQ(l[1], "frames 1-2: baseline lost for 2 frames, 1 relocalisation attempt failed (1 ambiguous); not "
                  "relocalised by the end of the run");
  EXPECT_TRUE(log.finish().empty());
}

// Started in a loaded map: lost from the first frame, every frame an attempt.
TEST(LossLog, StartingLostCountsTheFirstFrameAsAnAttempt) {
  LossLog log("pe-slam", true);
  EXPECT_TRUE(feed(log, 0, true, "relocalisation: 0 candidates from place recognition", "no candidates").empty());
  const std::vector<std::string> l = feed(log, 1, false);
  ASSERT_EQ(l.size(), 2u);
  EXPECT_EQ(l[1], "frames 0-0: pe-slam lost for 1 frame, 1 relocalisation attempt failed (1 no candidates); "
                  "tracked again at frame 1");
}

}  // namespace
}  // namespace pvb::run
