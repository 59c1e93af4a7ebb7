// The binary Potts labelling solved by a minimum cut against every labelling of small random
// problems (the oracle), plus the cases whose answer is known by hand.
#include "cpca/min_cut.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>

namespace {

TEST(BinaryLabelling, UnaryOnlyTakesEachNodesCheaperLabel) {
  cpca::BinaryLabelling e(3);
  e.add_unary(0, 1.0, 2.0);
  e.add_unary(1, 5.0, -1.0);
  e.add_unary(2, -3.0, 0.5);
  const std::vector<std::uint8_t> l = e.solve();
  EXPECT_EQ(l, (std::vector<std::uint8_t>{0, 1, 0}));
  EXPECT_DOUBLE_EQ(e.energy(l), 1.0 - 1.0 - 3.0);
}

TEST(BinaryLabelling, AStrongPairOverrulesTheWeakerPreference) {
  // Node 0 prefers 0 by 1, node 1 prefers 1 by 3: tied at 2 they both go to 1 (cost 1).
  cpca::BinaryLabelling e(2);
  e.add_unary(0, 0.0, 1.0);
  e.add_unary(1, 3.0, 0.0);
  e.add_potts(0, 1, 2.0);
  const std::vector<std::uint8_t> l = e.solve();
  EXPECT_EQ(l, (std::vector<std::uint8_t>{1, 1}));
  EXPECT_DOUBLE_EQ(e.energy(l), 1.0);
}

TEST(BinaryLabelling, MatchesEveryLabellingOfRandomProblems) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> cost(-2.0, 2.0), weight(0.0, 1.5);
  for (int trial = 0; trial < 300; ++trial) {
    const int n = 1 + int(rng() % 12);
    cpca::BinaryLabelling e(n);
    for (int x = 0; x < n; ++x)
      if (rng() % 4) e.add_unary(x, cost(rng), cost(rng));
    const int pairs = int(rng() % std::uint32_t(3 * n + 1));
    for (int i = 0; i < pairs; ++i)
      e.add_potts(int(rng() % std::uint32_t(n)), int(rng() % std::uint32_t(n)), weight(rng));
    double best = std::numeric_limits<double>::infinity();
    for (std::uint32_t bits = 0; bits < (1u << n); ++bits) {
      std::vector<std::uint8_t> l(static_cast<std::size_t>(n));
      for (int x = 0; x < n; ++x) l[std::size_t(x)] = (bits >> x) & 1;
      best = std::min(best, e.energy(l));
    }
    EXPECT_NEAR(e.energy(e.solve()), best, 1e-9) << "trial " << trial << ", " << n << " nodes";
  }
}

TEST(BinaryLabelling, ChainCutsAtItsWeakestLink) {
  // 0 is pinned to label 0, 5 to label 1; the chain's cheapest edge (2-3) is the cut.
  cpca::BinaryLabelling e(6);
  e.add_unary(0, 0.0, 100.0);
  e.add_unary(5, 100.0, 0.0);
  const double w[] = {4.0, 3.0, 0.5, 2.0, 5.0};
  for (int i = 0; i < 5; ++i) e.add_potts(i, i + 1, w[i]);
  EXPECT_EQ(e.solve(), (std::vector<std::uint8_t>{0, 0, 0, 1, 1, 1}));
}

TEST(BinaryLabelling, RefusesBadInput) {
  cpca::BinaryLabelling e(2);
  EXPECT_THROW(e.add_unary(2, 0, 0), std::invalid_argument);
  EXPECT_THROW(e.add_unary(0, std::numeric_limits<double>::quiet_NaN(), 0), std::invalid_argument);
  EXPECT_THROW(e.add_potts(0, 1, -1.0), std::invalid_argument);
  EXPECT_THROW(e.add_potts(0, 3, 1.0), std::invalid_argument);
  EXPECT_THROW(cpca::BinaryLabelling(-1), std::invalid_argument);
}

}  // namespace
