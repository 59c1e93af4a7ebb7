#include "cpca/cluster_gram.h"

#include "cpca/lbg.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>

namespace cpca {

void ClusterGrams::sync(const Eigen::Ref<const DataMatrix>& data,
                        const std::vector<std::uint32_t>& cluster_of, int clusters) {
  std::vector<std::vector<std::uint32_t>> target = cluster_members(cluster_of, clusters);
  if (members_.size() != std::size_t(clusters)) {
    members_.assign(std::size_t(clusters), {});
    grams_.assign(std::size_t(clusters), Eigen::MatrixXd());
    kept_.assign(std::size_t(clusters), 0);
  }
  // Which clusters keep a matrix: those below the dimension, in id order until the budget is
  // spent.
  std::size_t bytes = 0;
  std::vector<char> keep(std::size_t(clusters), 0);
  for (std::size_t c = 0; c < target.size(); ++c) {
    const std::size_t m = target[c].size();
    if (m == 0 || Eigen::Index(m) >= data.cols()) continue;
    if (bytes + m * m * sizeof(double) > max_bytes_) continue;
    bytes += m * m * sizeof(double);
    keep[c] = 1;
  }
  std::atomic<std::uint64_t> computed{0};
  tbb::parallel_for(0, clusters, [&](int ci) {
    const std::size_t c = std::size_t(ci);
    if (!keep[c]) {
      kept_[c] = 0;
      grams_[c] = Eigen::MatrixXd();
      members_[c].clear();
      return;
    }
    const std::vector<std::uint32_t>& now = target[c];
    const std::vector<std::uint32_t>& before = members_[c];
    if (kept_[c] && now == before) return;
    // Old index of every member that stays; -1 for those that joined.
    const Eigen::Index m = Eigen::Index(now.size());
    std::vector<Eigen::Index> old(now.size(), -1);
    std::vector<Eigen::Index> joined;
    for (std::size_t i = 0, j = 0; i < now.size(); ++i) {
      if (kept_[c]) {
        while (j < before.size() && before[j] < now[i]) ++j;
        if (j < before.size() && before[j] == now[i]) old[i] = Eigen::Index(j);
      }
      if (old[i] < 0) joined.push_back(Eigen::Index(i));
    }
    Eigen::MatrixXd g(m, m);
    for (Eigen::Index i = 0; i < m; ++i)
      if (old[std::size_t(i)] >= 0)
        for (Eigen::Index j = 0; j <= i; ++j)
          if (old[std::size_t(j)] >= 0)
            g(i, j) = g(j, i) = grams_[c](old[std::size_t(i)], old[std::size_t(j)]);
    if (!joined.empty()) {
      Eigen::MatrixXd rows(m, data.cols());
      for (Eigen::Index i = 0; i < m; ++i)
        rows.row(i) = data.row(now[std::size_t(i)]).cast<double>();
      computed += joined.size();
      if (Eigen::Index(joined.size()) == m) {  // all new: the symmetric product costs half
        g.setZero();
        g.selfadjointView<Eigen::Lower>().rankUpdate(rows);
        g = g.selfadjointView<Eigen::Lower>();
      } else {
        Eigen::MatrixXd fresh(Eigen::Index(joined.size()), data.cols());
        for (std::size_t a = 0; a < joined.size(); ++a)
          fresh.row(Eigen::Index(a)) = rows.row(joined[a]);
        const Eigen::MatrixXd dots = fresh * rows.transpose();  // joined x m
        for (std::size_t a = 0; a < joined.size(); ++a)
          for (Eigen::Index j = 0; j < m; ++j)
            g(joined[a], j) = g(j, joined[a]) = dots(Eigen::Index(a), j);
      }
    }
    grams_[c] = std::move(g);
    members_[c] = now;
    kept_[c] = 1;
  });
  rows_computed_ += computed;
}

const Eigen::MatrixXd* ClusterGrams::gram(std::uint32_t c) const {
  return c < kept_.size() && kept_[c] ? &grams_[c] : nullptr;
}

}  // namespace cpca
