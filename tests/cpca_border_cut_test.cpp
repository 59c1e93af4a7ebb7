// One border between two passes relabelled by a minimum cut, against every labelling of the
// free vertices (the oracle): the Potts decomposition of a triangle's pass count must be exact
// for any mix of free corners, fixed corners in the two passes and corners in other passes.
#include "cpca/border_cut.h"

#include "cpca_test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>

namespace {

int passes_met(const cpca::TriangleIndices& t, const std::vector<std::uint32_t>& pass) {
  return int(std::set<std::uint32_t>{pass[t[0]], pass[t[1]], pass[t[2]]}.size());
}

struct Problem {
  cpca::Geometry g;
  std::vector<std::uint32_t> pass;  // per vertex; here a vertex's cluster is its pass
  std::vector<std::uint32_t> identity{0, 1, 2, 3};
  std::vector<std::uint32_t> free, touched;
  std::vector<int> node_of;
  std::vector<double> err_a, err_b;
};

// A grid with random passes 0-3 (0 and 1 the border's), up to `most` free vertices among
// those in 0 or 1, random errors.
Problem random_problem(std::mt19937& rng, int most) {
  Problem p;
  p.g = cpca_test::grid(6);
  const std::size_t v = p.g.positions.size();
  p.pass.resize(v);
  for (std::uint32_t& q : p.pass) q = rng() % 5 < 4 ? rng() % 2 : 2 + rng() % 2;
  p.node_of.assign(v, -1);
  std::uniform_real_distribution<double> err(0.0, 2.0);
  for (std::uint32_t x = 0; x < v && int(p.free.size()) < most; ++x)
    if (p.pass[x] < 2 && rng() % 3 == 0) {
      p.node_of[x] = int(p.free.size());
      p.free.push_back(x);
      p.err_a.push_back(err(rng));
      p.err_b.push_back(err(rng));
    }
  for (std::uint32_t t = 0; t < p.g.triangles.size(); ++t)
    if (std::any_of(p.g.triangles[t].begin(), p.g.triangles[t].end(),
                    [&](std::uint32_t x) { return p.node_of[x] >= 0; }))
      p.touched.push_back(t);
  return p;
}

// E of a labelling, counted directly: the errors plus mu times the passes every touched
// triangle meets.
double energy(Problem p, const std::vector<std::uint8_t>& label, double mu) {
  double e = 0;
  for (std::size_t n = 0; n < p.free.size(); ++n) {
    p.pass[p.free[n]] = label[n];
    e += label[n] ? p.err_b[n] : p.err_a[n];
  }
  for (std::uint32_t t : p.touched) e += mu * passes_met(p.g.triangles[t], p.pass);
  return e;
}

TEST(BorderCut, MatchesEveryLabellingOfRandomBorders) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 200; ++trial) {
    const Problem p = random_problem(rng, 12);
    const double mu = std::uniform_real_distribution<double>(0.0, 1.5)(rng);
    const cpca::BorderTerms terms = cpca::border_terms(p.g.triangles, p.touched, p.node_of, p.pass,
                                                       p.identity, 0, 1, int(p.free.size()));
    const std::vector<std::uint8_t> cut = cpca::cut_border(terms, p.err_a, p.err_b, mu);
    double best = std::numeric_limits<double>::infinity();
    const std::size_t n = p.free.size();
    for (std::uint32_t bits = 0; bits < (1u << n); ++bits) {
      std::vector<std::uint8_t> label(n);
      for (std::size_t x = 0; x < n; ++x) label[x] = (bits >> x) & 1;
      best = std::min(best, energy(p, label, mu));
    }
    EXPECT_NEAR(energy(p, cut, mu), best, 1e-9) << "trial " << trial << ", " << n << " free";
  }
}

TEST(BorderCut, AtAHighPriceStraightensAJaggedBorder) {
  // Columns x < 3 in pass 0, the rest in 1, but with the middle column's vertices alternating:
  // with equal errors the cut puts that column wholly on one side (a straight border).
  cpca::Geometry g = cpca_test::grid(6);
  std::vector<std::uint32_t> pass(g.positions.size()), free;
  std::vector<int> node_of(pass.size(), -1);
  for (std::uint32_t x = 0; x < pass.size(); ++x) {
    const int column = int(x % 6), row = int(x / 6);
    pass[x] = column < 3 ? 0 : 1;
    if (column == 3) {
      pass[x] = std::uint32_t(row % 2);
      node_of[x] = int(free.size());
      free.push_back(x);
    }
  }
  std::vector<std::uint32_t> touched;
  for (std::uint32_t t = 0; t < g.triangles.size(); ++t)
    for (std::uint32_t x : g.triangles[t])
      if (node_of[x] >= 0) {
        touched.push_back(t);
        break;
      }
  const std::vector<std::uint32_t> identity{0, 1};
  const cpca::BorderTerms terms =
      cpca::border_terms(g.triangles, touched, node_of, pass, identity, 0, 1, int(free.size()));
  const std::vector<double> zero(free.size(), 0.0);
  const std::vector<std::uint8_t> label = cpca::cut_border(terms, zero, zero, 1.0);
  for (std::uint8_t l : label) EXPECT_EQ(l, label[0]);
}

TEST(BorderCut, RefusesBadInput) {
  const cpca::Geometry g = cpca_test::grid(3);
  const std::vector<std::uint32_t> pass(g.positions.size(), 0), identity{0, 1};
  const std::vector<int> node_of(pass.size(), -1);
  EXPECT_THROW(cpca::border_terms(g.triangles, {}, node_of, pass, identity, 1, 1, 0),
               std::invalid_argument);
  const cpca::BorderTerms terms =
      cpca::border_terms(g.triangles, {}, node_of, pass, identity, 0, 1, 0);
  EXPECT_THROW(cpca::cut_border(terms, {1.0}, {}, 1.0), std::invalid_argument);
  EXPECT_THROW(cpca::cut_border(terms, {}, {}, -1.0), std::invalid_argument);
}

}  // namespace
