// The team's size under other work (bake/thread_governor.h): the policy on made-up windows.
// Two real bakes sharing two cores: tests/hardening/contention.py.
#include "bake/thread_governor.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace treeanim {
namespace {

using Change = TeamPolicy::Change;

// A window of `seconds` in which other work kept `threads` threads waiting `share` of the time,
// beside helpers that ran `helpers` s and waited as long on the team's cores.
TeamWindow window(int threads, double share, double seconds = 0.25, double helpers = 0) {
  return {.threads = threads, .seconds = seconds, .team_wait = share * threads * seconds + helpers,
          .helpers_cpu = helpers};
}

TEST(TeamPolicy, KeepsItsTeamWhileNoOtherWorkWaits) {
  TeamPolicy policy(4, 4);
  for (int k = 0; k < 1000; ++k) {
    // The bake's own writers may keep the team waiting as long as they run: that is not other work.
    ASSERT_EQ(policy.next(window(4, 0.02, 0.25, 0.2)), Change::kNone);
    ASSERT_EQ(policy.threads(), 4);
  }
}

TEST(TeamPolicy, DropsAThreadAWindowWhileOtherWorkKeepsItWaiting) {
  TeamPolicy policy(3, 4);
  EXPECT_EQ(policy.next(window(3, 0.5)), Change::kShrunk);
  EXPECT_EQ(policy.threads(), 2);
  EXPECT_DOUBLE_EQ(policy.last_share(), 0.5);
  EXPECT_EQ(policy.next(window(2, 0.3)), Change::kShrunk);
  EXPECT_EQ(policy.threads(), 1);
  EXPECT_EQ(policy.next(window(1, 0.3)), Change::kNone);  // one thread is the least
  EXPECT_EQ(policy.threads(), 1);
}

TEST(TeamPolicy, DropsToTheThreadsThatRanAndNoMoreThanTheCores) {
  TeamPolicy many(8, 2);  // more threads than cores: they waited 31 % of the time, asleep the rest
  EXPECT_EQ(many.next(window(8, 0.31)), Change::kShrunk);
  EXPECT_EQ(many.threads(), 2);
  TeamPolicy shared(8, 8);  // other work on half the cores
  EXPECT_EQ(shared.next(window(8, 0.5)), Change::kShrunk);
  EXPECT_EQ(shared.threads(), 4);
  TeamPolicy crowded(4, 4);  // all but nothing left
  EXPECT_EQ(crowded.next(window(4, 0.95)), Change::kShrunk);
  EXPECT_EQ(crowded.threads(), 1);
}

TEST(TeamPolicy, TriesAThreadMoreLaterAndWaitsTwiceAsLongEachTimeItFails) {
  TeamPolicy policy(2, 2);
  ASSERT_EQ(policy.next(window(2, 0.5)), Change::kShrunk);
  double wait = TeamPolicy::kFirstWait;
  for (int attempt = 0; attempt < 8; ++attempt) {
    // Quiet windows of one thread until the wait is over, then a window of two on trial.
    double quiet = 0;
    Change change = Change::kNone;
    while ((change = policy.next(window(1, 0))) == Change::kNone) quiet += 0.25;
    ASSERT_EQ(change, Change::kTrying);
    EXPECT_NEAR(quiet + 0.25, wait, 1e-9);
    ASSERT_EQ(policy.threads(), 2);
    ASSERT_EQ(policy.next(window(2, 0.4)), Change::kTryFailed);  // the other work is still there
    ASSERT_EQ(policy.threads(), 1);
    wait = std::min(2 * wait, TeamPolicy::kLongestWait);
  }
  EXPECT_EQ(wait, TeamPolicy::kLongestWait);
}

TEST(TeamPolicy, KeepsTheThreadItTriedWhenNoOneWaits) {
  TeamPolicy policy(3, 4);
  ASSERT_EQ(policy.next(window(3, 0.5)), Change::kShrunk);
  ASSERT_EQ(policy.next(window(2, 0.5)), Change::kShrunk);
  Change change = Change::kNone;
  while ((change = policy.next(window(1, 0))) == Change::kNone) {
  }
  ASSERT_EQ(change, Change::kTrying);
  EXPECT_EQ(policy.next(window(2, 0.01)), Change::kGrown);
  EXPECT_EQ(policy.threads(), 2);
  // The next thread after the first wait again, not the longer one of a failed try.
  double quiet = 0;
  while ((change = policy.next(window(2, 0))) == Change::kNone) quiet += 0.25;
  EXPECT_EQ(change, Change::kTrying);
  EXPECT_NEAR(quiet + 0.25, TeamPolicy::kFirstWait, 1e-9);
  EXPECT_EQ(policy.next(window(3, 0)), Change::kGrown);
  EXPECT_EQ(policy.threads(), 3);
  EXPECT_EQ(policy.next(window(3, 0)), Change::kNone);  // never past the team it was given
}

}  // namespace
}  // namespace treeanim
