// OrderedWorker (common/ordered_worker.h): every item in order on its thread behind a bounded
// queue, the handler's first exception given back to the producer with nothing handled after it.
#include "common/ordered_worker.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

namespace treeanim {
namespace {

using namespace std::chrono_literals;

TEST(OrderedWorker, HandlesEveryItemInOrderOnItsOwnThreadAfterItsStart) {
  std::vector<int> handled;  // written by the worker alone until drain()
  std::thread::id started, ran;
  OrderedWorker<int> worker(
      3, [&] { started = std::this_thread::get_id(); },
      [&](int& item) {
        ran = std::this_thread::get_id();
        handled.push_back(item);
      });
  for (int i = 0; i < 100; ++i) worker.push(i);
  worker.drain();
  ASSERT_EQ(handled.size(), 100u);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(handled[size_t(i)], i);
  EXPECT_EQ(started, ran);
  EXPECT_NE(ran, std::this_thread::get_id());
  for (int i = 100; i < 110; ++i) worker.push(i);
  worker.close();  // handles what is queued before the thread ends
  EXPECT_EQ(handled.size(), 110u);
}

TEST(OrderedWorker, KeepsAtMostItsCapacityWaiting) {
  std::atomic<int> taken = 0, pushed = 0;
  std::atomic<bool> release = false;
  OrderedWorker<int> worker(2, nullptr, [&](int&) {
    ++taken;
    while (!release) std::this_thread::sleep_for(1ms);
  });
  std::thread producer([&] {
    for (int i = 0; i < 5; ++i, ++pushed) worker.push(i);
  });
  // One item in hand and two waiting: the fourth push waits for room, however long.
  while (taken < 1 || pushed < 3) std::this_thread::sleep_for(1ms);
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(taken, 1);
  EXPECT_EQ(pushed, 3);
  release = true;
  producer.join();
  worker.drain();
  EXPECT_EQ(taken, 5);
}

TEST(OrderedWorker, GivesBackTheFirstErrorAndHandlesNothingAfterIt) {
  std::vector<int> handled;
  OrderedWorker<int> worker(4, nullptr, [&](int& item) {
    handled.push_back(item);
    if (item == 3) throw std::runtime_error("disk full at 3");
    if (item == 4) throw std::runtime_error("a second failure");
  });
  bool thrown = false;
  try {
    for (int i = 1; i <= 10; ++i) worker.push(i);
    worker.drain();
  } catch (const std::runtime_error& e) {
    thrown = true;
    EXPECT_STREQ(e.what(), "disk full at 3");
  }
  EXPECT_TRUE(thrown);
  EXPECT_THROW(worker.push(11), std::runtime_error);
  EXPECT_THROW(worker.drain(), std::runtime_error);
  EXPECT_THROW(worker.close(), std::runtime_error);
  EXPECT_EQ(handled, (std::vector<int>{1, 2, 3}));  // items queued behind the failed one are dropped
}

TEST(OrderedWorker, StoppedItEndsTheItemInHandAndDropsTheRest) {
  std::atomic<int> begun = 0, handled = 0;
  {
    OrderedWorker<int> worker(4, nullptr, [&](int&) {
      ++begun;
      std::this_thread::sleep_for(20ms);
      ++handled;
    });
    for (int i = 0; i < 4; ++i) worker.push(i);
    while (begun < 1) std::this_thread::sleep_for(1ms);
  }  // destroyed, as by a producer unwinding from an error: it stops
  EXPECT_EQ(handled, begun);  // the item in hand ended
  EXPECT_LE(handled, 2);      // the rest, but perhaps one taken meanwhile, dropped
}

TEST(OrderedWorker, AStartThatFailsIsItsFirstError) {
  OrderedWorker<int> worker(
      1, [] { throw std::runtime_error("no such priority"); }, [](int&) { FAIL() << "handled"; });
  EXPECT_THROW(
      {
        worker.push(1);  // queued if the thread has not started yet, and then dropped
        worker.drain();
      },
      std::runtime_error);
  EXPECT_THROW(worker.push(2), std::runtime_error);
}

TEST(OrderedWorker, RefusesAnItemAfterItIsClosed) {
  OrderedWorker<int> worker(1, nullptr, [](int&) {});
  worker.close();
  EXPECT_THROW(worker.push(1), std::logic_error);
  EXPECT_THROW(OrderedWorker<int>(0, nullptr, [](int&) {}), std::logic_error);
}

}  // namespace
}  // namespace treeanim
