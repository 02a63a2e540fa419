// The random source of every stage: splitmix64's and the 64-bit Mersenne Twister's published
// sequences, and the same bits to numbers for both, so that every bake keeps its draws.
#include <gtest/gtest.h>

#include <random>

#include "common/random.h"

namespace treeanim {
namespace {

TEST(RandomStream, IsSplitMix64) {
  // splitmix64's reference outputs from state 0 (Vigna's splitmix64.c).
  RandomStream random{0};
  EXPECT_EQ(random.next_u64(), 0xe220a8397b1dcdafULL);
  EXPECT_EQ(random.next_u64(), 0x6e789e6aa1b965f4ULL);
  EXPECT_EQ(random.next_u64(), 0x06c45d188009454fULL);
}

TEST(RandomStream, AKeyIsItsStream) {
  RandomStream a = RandomStream::keyed(7, 1, 2, 3), b = RandomStream::keyed(7, 1, 2, 3);
  const RandomStream other = RandomStream::keyed(7, 1, 2, 4);
  EXPECT_EQ(a.state, b.state);
  EXPECT_NE(a.state, other.state);
  for (int k = 0; k < 100; ++k) {
    const double u = a.uniform();
    EXPECT_EQ(u, b.uniform());
    EXPECT_GE(u, 0.0);
    EXPECT_LT(u, 1.0);
  }
}

TEST(RandomSequence, IsTheMersenneTwisterWithTheTop53Bits) {
  std::mt19937_64 engine(42);
  RandomSequence random(42);
  for (int k = 0; k < 1000; ++k) EXPECT_EQ(random.uniform(), uniform_from_bits(engine()));
  EXPECT_EQ(uniform_from_bits(0), 0.0);
  EXPECT_EQ(uniform_from_bits(~0ULL), 1.0 - 0x1.0p-53);
}

}  // namespace
}  // namespace treeanim
