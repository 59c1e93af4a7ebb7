#include "cpca/border_cut.h"

#include "cpca/min_cut.h"

#include <stdexcept>

namespace cpca {

BorderTerms border_terms(const std::vector<TriangleIndices>& triangles,
                         const std::vector<std::uint32_t>& touched, const std::vector<int>& node_of,
                         const std::vector<std::uint32_t>& cluster_of,
                         const std::vector<std::uint32_t>& pass_of, std::uint32_t a,
                         std::uint32_t b, int free_count) {
  if (a == b) throw std::invalid_argument("border_terms: the two passes must differ");
  BorderTerms terms;
  terms.a = a, terms.b = b;
  terms.draws_as_a.assign(std::size_t(free_count), 0.0);
  terms.draws_as_b.assign(std::size_t(free_count), 0.0);
  const auto free = [&](std::uint32_t v) { return node_of[v] >= 0; };
  const auto in_ab = [&](std::uint32_t v) {
    const std::uint32_t p = pass_of[cluster_of[v]];
    return free(v) || p == a || p == b;
  };
  for (std::uint32_t t : touched) {
    const TriangleIndices& tri = triangles[t];
    const int corners = int(in_ab(tri[0])) + int(in_ab(tri[1])) + int(in_ab(tri[2]));
    if (corners < 2) continue;  // one A/B corner: its pass changes nothing
    const double w = corners == 2 ? 1.0 : 0.5;
    for (int j = 0; j < 3; ++j)
      for (int k = j + 1; k < 3; ++k) {
        const std::uint32_t u = tri[std::size_t(j)], v = tri[std::size_t(k)];
        if (u == v || !in_ab(u) || !in_ab(v)) continue;
        if (free(u) && free(v)) {
          terms.pairs.push_back({node_of[u], node_of[v], w});
        } else if (free(u) != free(v)) {
          // A fixed corner in A charges its free partner for taking B, and vice versa.
          const std::uint32_t x = free(u) ? u : v, fixed = free(u) ? v : u;
          (pass_of[cluster_of[fixed]] == a ? terms.draws_as_b
                                           : terms.draws_as_a)[std::size_t(node_of[x])] += w;
        }
      }
  }
  return terms;
}

std::vector<std::uint8_t> cut_border(const BorderTerms& terms, const std::vector<double>& err_a,
                                     const std::vector<double>& err_b, double mu) {
  const std::size_t n = terms.draws_as_a.size();
  if (err_a.size() != n || err_b.size() != n || !(mu >= 0))
    throw std::invalid_argument("cut_border: one error per free vertex and a price >= 0");
  BinaryLabelling energy(static_cast<int>(n));
  for (std::size_t x = 0; x < n; ++x)
    energy.add_unary(int(x), err_a[x] + mu * terms.draws_as_a[x],
                     err_b[x] + mu * terms.draws_as_b[x]);
  for (const BorderTerms::Pair& p : terms.pairs) energy.add_potts(p.x, p.y, mu * p.w);
  return energy.solve();
}

}  // namespace cpca
