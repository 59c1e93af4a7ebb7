// cpca/min_cut.h: exact minimisation of a binary labelling energy with Potts pairwise terms,
//   E(l) = sum_x D_x(l_x) + sum_{x,y} w_xy [l_x != l_y],   l_x in {0, 1}, w_xy >= 0,
// by a minimum s-t cut (Greig, Porteous & Seheult 1989; Kolmogorov & Zabih 2004: such
// energies are graph-representable because Potts terms are submodular). Label 0 is the source
// side. The maximum flow is Dinic's (1970) blocking flows on level graphs; the graphs it is
// made for (the border of two render passes, some hundreds of nodes) are small, so clarity
// wins over Boykov-Kolmogorov's tree reuse.
#pragma once

#include <cstdint>
#include <vector>

namespace cpca {

class BinaryLabelling {
 public:
  explicit BinaryLabelling(int nodes);

  // Adds cost0 to E when x takes label 0 and cost1 when it takes 1 (any finite values).
  void add_unary(int x, double cost0, double cost1);
  // Adds w (>= 0) to E when x and y take different labels.
  void add_potts(int x, int y, double w);

  // A labelling of least E (where several tie, the one with the fewest 0s), and E of any.
  std::vector<std::uint8_t> solve();
  double energy(const std::vector<std::uint8_t>& labels) const;

 private:
  struct Arc {
    int to;
    double residual;
  };
  void add_arc_pair(int a, int b, double forward, double backward);
  bool levels(int s, int t);
  double push(int x, int t, double limit);

  int nodes_;
  std::vector<double> cost0_, cost1_;
  struct Pair {
    int x, y;
    double w;
  };
  std::vector<Pair> pairs_;
  // The flow network, built by solve().
  std::vector<Arc> arcs_;
  std::vector<std::vector<int>> out_;
  std::vector<int> level_, next_;
};

}  // namespace cpca
