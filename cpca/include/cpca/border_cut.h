// cpca/border_cut.h: the border between two render passes A and B relabelled at once by a
// minimum cut (docs/ARCHITECTURE.md, "The epsilon constraint"). Some vertices are free to
// take A or B, each at its own error cost; all others keep their pass. The energy
//   sum_free err(x, l_x) + mu * sum_triangles passes(triangle)
// is minimised exactly over the free labels: with its other corners fixed, a triangle's pass
// count over labels in {A, B} is a constant plus Potts terms -- weight 1 between two A/B
// corners when the third lies in another pass, 1/2 on each pair when all three are A or B
// (when they do not all agree exactly two pairs differ) -- and a binary Potts energy is a
// minimum cut (min_cut.h). Single-vertex moves stall where no one vertex can gain alone; a
// cut moves whole border segments.
#pragma once

#include "cpca/geometry.h"

#include <cstdint>
#include <vector>

namespace cpca {

// The draws part of one border's energy, per unit price.
struct BorderTerms {
  std::uint32_t a = 0, b = 0;                  // the passes; label 0 is a, 1 is b
  std::vector<double> draws_as_a, draws_as_b;  // per free vertex: what its fixed partners charge
  struct Pair {
    int x, y;
    double w;
  };
  std::vector<Pair> pairs;  // Potts terms between free vertices
};

// `touched`: the triangles with at least one free corner, each once. node_of[v] >= 0 numbers
// the free vertices 0..free-1, -1 elsewhere. A fixed vertex v lies in pass
// pass_of[cluster_of[v]].
BorderTerms border_terms(const std::vector<TriangleIndices>& triangles,
                         const std::vector<std::uint32_t>& touched, const std::vector<int>& node_of,
                         const std::vector<std::uint32_t>& cluster_of,
                         const std::vector<std::uint32_t>& pass_of, std::uint32_t a,
                         std::uint32_t b, int free_count);

// The labels (0: a, 1: b) of least  sum err + mu * draws, err_a / err_b per free vertex.
std::vector<std::uint8_t> cut_border(const BorderTerms& terms, const std::vector<double>& err_a,
                                     const std::vector<double>& err_b, double mu);

}  // namespace cpca
