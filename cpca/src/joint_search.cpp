#include "cpca/joint_search.h"

#include "common/check.h"
#include "cpca/assignment.h"
#include "cpca/border_cut.h"
#include "cpca/cluster_gram.h"
#include "cpca/cluster_pca.h"
#include "cpca/compress.h"
#include "cpca/patch_first.h"
#include "cpca/supercluster_incidence.h"
#include "cpca/supercluster_refine.h"
#include "cpca/supercluster_strategy.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace cpca {
namespace {

double total_of(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0);
}

int distinct(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  return 1 + int(a != b) + int(c != a && c != b);
}

// Triangles of each vertex, CSR.
struct VertexTriangles {
  std::vector<std::uint32_t> offset, triangle;
  VertexTriangles(std::size_t vertices, const std::vector<TriangleIndices>& triangles)
      : offset(vertices + 1, 0) {
    for (const TriangleIndices& t : triangles)
      for (std::uint32_t v : t) ++offset[v + 1];
    for (std::size_t v = 0; v < vertices; ++v) offset[v + 1] += offset[v];
    triangle.resize(offset.back());
    std::vector<std::uint32_t> fill(offset.begin(), offset.end() - 1);
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      for (std::uint32_t v : triangles[t]) triangle[fill[v]++] = t;
  }
};

// What the vertex sweep reads and changes.
struct SweepState {
  const std::vector<TriangleIndices>& triangles;
  const VertexTriangles& incident;
  const std::vector<std::uint32_t>& pass_of;  // per cluster
  std::vector<std::uint32_t>& cluster_of;
  std::vector<std::uint32_t>& size;  // members per cluster
  double mu;                         // weight of one drawn triangle, in squared-error units
  std::uint64_t drawn, cap;          // triangles drawn now; no move may take them above cap
  // Error the moves that the epsilon search's cap refused would have added: above zero, the
  // price of a draw is above the one that spends the allowance exactly.
  double wanted = 0;

  std::uint32_t pass(std::uint32_t v) const { return pass_of[cluster_of[v]]; }
  // Draws of p's triangles if p's pass were q (a vertex listed twice in a triangle moves
  // with itself).
  std::int64_t draws(std::uint32_t p, std::uint32_t q) const {
    std::int64_t n = 0;
    for (std::uint32_t i = incident.offset[p]; i < incident.offset[p + 1]; ++i) {
      const TriangleIndices& t = triangles[incident.triangle[i]];
      const auto at = [&](std::uint32_t v) { return v == p ? q : pass(v); };
      n += distinct(at(t[0]), at(t[1]), at(t[2]));
    }
    return n;
  }
};

// Gauss-Seidel vertex moves with fixed bases; returns the triangles drawn it saved (may be
// negative when error gains pay for more draws).
std::int64_t sweep_vertices(const Eigen::Ref<const DataMatrix>& data, const DataMatrix& d2,
                            const CompressedSet& fitted, SweepState& s, std::uint64_t& moves) {
  std::int64_t saved = 0;
  std::vector<std::uint32_t> extra;
  for (std::uint32_t p = 0; p < s.cluster_of.size(); ++p) {
    const std::uint32_t a = s.cluster_of[p];
    if (s.size[a] <= 1) continue;
    const std::int64_t here = s.draws(p, s.pass_of[a]);
    double best = 0;
    std::uint32_t best_c = a;
    std::int64_t best_draws = here;
    const auto consider = [&](std::uint32_t c, double err) {
      const std::int64_t n = s.pass_of[c] == s.pass_of[a] ? here : s.draws(p, s.pass_of[c]);
      if (n > here && s.drawn + std::uint64_t(n - here) > s.cap) return;
      const double delta = err - double(d2(p, a)) + s.mu * double(n - here);
      if (delta < best) best = delta, best_c = c, best_draws = n;
    };
    for (Eigen::Index c = 0; c < d2.cols(); ++c)
      if (std::uint32_t(c) != a && std::isfinite(d2(p, c))) consider(std::uint32_t(c), d2(p, c));
    // Neighbours' clusters the nearest-mean candidates missed: the moves that cut draws.
    extra.clear();
    for (std::uint32_t i = s.incident.offset[p]; i < s.incident.offset[p + 1]; ++i)
      for (std::uint32_t v : s.triangles[s.incident.triangle[i]]) {
        const std::uint32_t c = s.cluster_of[v];
        if (c != a && !std::isfinite(d2(p, c)) &&
            std::find(extra.begin(), extra.end(), c) == extra.end())
          extra.push_back(c);
      }
    for (std::uint32_t c : extra) consider(c, subspace_distance(data.row(p), fitted, int(c)));
    if (best_c == a) continue;
    --s.size[a], ++s.size[best_c];
    s.cluster_of[p] = best_c;
    saved += here - best_draws;
    s.drawn = std::uint64_t(std::int64_t(s.drawn) + best_draws - here);
    ++moves;
  }
  return saved;
}

// Best-improvement swaps between a cluster and the members of its neighbours' passes until
// none lowers the draws. Returns the triangles drawn.
std::uint64_t swap_descent(const ClusterIncidence& inc, int per_pass,
                           std::vector<std::uint32_t>& pass_of, std::uint64_t& swaps) {
  const int passes = int(*std::max_element(pass_of.begin(), pass_of.end())) + 1;
  GroupingLocalSearch search(inc, per_pass, pass_of, passes);
  std::vector<std::int64_t> correction(std::size_t(inc.cluster_count), 0);
  for (bool changed = true; changed;) {
    changed = false;
    for (std::uint32_t c = 0; c < std::uint32_t(inc.cluster_count); ++c) {
      std::int64_t best = 0;
      std::uint32_t partner = c;
      const std::uint32_t p = search.pass_of()[c];
      search.shared_corrections(c, correction);
      for (std::uint32_t i = inc.neighbor_offset[c]; i < inc.neighbor_offset[c + 1]; ++i) {
        const std::uint32_t q = search.pass_of()[inc.neighbor[i]];
        if (q == p) continue;
        // delta_swap(c, d), with the shared part taken from one walk over c's hyperedges.
        const std::int64_t c_part = search.delta_move(c, q);
        for (std::uint32_t d : search.members(q)) {
          const std::int64_t delta = c_part + search.delta_move(d, p) + correction[d];
          if (delta < best) best = delta, partner = d;
        }
      }
      for (std::uint32_t i = inc.neighbor_offset[c]; i < inc.neighbor_offset[c + 1]; ++i)
        correction[inc.neighbor[i]] = 0;
      if (partner == c) continue;
      search.swap(c, partner);
      ++swaps;
      changed = true;
    }
  }
  pass_of = search.pass_of();
  return search.drawn();
}

// PCA refit of the clusters whose membership differs from `before`'s; the others keep their
// means, bases, weights and errors. A cluster's fit depends only on its member rows in
// ascending order and the seed (cluster_pca.h), so this equals a refit of every cluster bit
// for bit, at the cost of the clusters that changed (late steps move few vertices).
std::vector<double> refit_changed(const Eigen::Ref<const DataMatrix>& data,
                                  const CompressedSet& before, const std::vector<double>& error,
                                  CompressedSet& next, const JointSearchOptions& o,
                                  ClusterGrams* grams = nullptr) {
  std::vector<char> changed(std::size_t(next.cluster_count), 0);
  for (std::size_t p = 0; p < next.cluster_of.size(); ++p)
    if (next.cluster_of[p] != before.cluster_of[p])
      changed[before.cluster_of[p]] = changed[next.cluster_of[p]] = 1;
  std::vector<double> next_error = error;
  PowerIterationOptions power;
  power.seed = o.seed;
  if (grams && o.solver == PcaSolver::kPowerIteration) {
    // In place over all rows: the changed clusters' rows are not copied out, and the others
    // keep their numbers.
    if (std::find(changed.begin(), changed.end(), 1) == changed.end()) return next_error;
    power.tolerance = o.refit_tolerance;
    grams->sync(data, next.cluster_of, next.cluster_count);
    std::vector<const Eigen::MatrixXd*> all(changed.size());
    for (std::uint32_t c = 0; c < changed.size(); ++c) all[c] = grams->gram(c);
    const std::vector<double> fitted =
        fit_cluster_pca_warm(data, next, before.bases, power, all, changed);
    for (std::size_t p = 0; p < next.cluster_of.size(); ++p)
      if (changed[next.cluster_of[p]]) next_error[p] = fitted[p];
    return next_error;
  }
  std::vector<std::uint32_t> local(changed.size(), ~0u), ids;
  for (std::uint32_t c = 0; c < changed.size(); ++c)
    if (changed[c]) local[c] = std::uint32_t(ids.size()), ids.push_back(c);
  if (ids.empty()) return next_error;
  std::vector<std::uint32_t> rows;
  CompressedSet part;
  part.cluster_count = int(ids.size());
  part.component_count = next.component_count;
  for (std::uint32_t p = 0; p < next.cluster_of.size(); ++p)
    if (changed[next.cluster_of[p]])
      rows.push_back(p), part.cluster_of.push_back(local[next.cluster_of[p]]);
  DataMatrix x(Eigen::Index(rows.size()), data.cols());
  for (std::size_t i = 0; i < rows.size(); ++i) x.row(Eigen::Index(i)) = data.row(rows[i]);
  const std::size_t d = next.dimension(), n = std::size_t(next.component_count);
  const std::vector<double> part_error = fit_cluster_pca(x, part, o.solver, power);
  for (std::size_t j = 0; j < ids.size(); ++j) {
    std::copy_n(part.means.begin() + std::ptrdiff_t(j * d), d,
                next.means.begin() + std::ptrdiff_t(ids[j] * d));
    std::copy_n(part.bases.begin() + std::ptrdiff_t(j * n * d), n * d,
                next.bases.begin() + std::ptrdiff_t(ids[j] * n * d));
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    next_error[rows[i]] = part_error[i];
    std::copy_n(part.weights.begin() + std::ptrdiff_t(i * n), n,
                next.weights.begin() + std::ptrdiff_t(std::size_t(rows[i]) * n));
  }
  return next_error;
}

ClusterIncidence incidence_of(const CompressedSet& set, const Geometry& g, int per_pass) {
  SuperClusterInput input;
  input.cluster_of = set.cluster_of;
  input.triangles = g.triangles;
  input.cluster_count = set.cluster_count;
  input.per_pass = per_pass;
  return cluster_incidence(input);
}

// Each vertex's squared error under its cluster's stored mean, basis and weights, as
// fit_cluster_pca reports it.
std::vector<double> reconstruction_errors(const Eigen::Ref<const DataMatrix>& data,
                                          const CompressedSet& set) {
  std::vector<double> error(set.cluster_of.size());
  const Eigen::Index n = set.component_count;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, error.size(), 256), [&](const auto& range) {
    for (std::size_t p = range.begin(); p < range.end(); ++p) {
      const int c = int(set.cluster_of[p]);
      Eigen::RowVectorXd r = (data.row(Eigen::Index(p)) - set.mean(c)).template cast<double>();
      if (n > 0)
        r -= Eigen::Map<const Eigen::RowVectorXf>(set.weights.data() + p * std::size_t(n), n)
                 .cast<double>() *
             set.basis(c).template cast<double>();
      error[p] = r.squaredNorm();
    }
  });
  return error;
}

// Makes a kept proposal the search's state and records the step.
void keep_step(CompressedSet&& next, std::vector<double>&& next_error,
               std::vector<std::uint32_t>&& next_pass, std::uint64_t drawn, std::uint64_t moves,
               std::uint64_t swaps, double objective, CompressedSet& set,
               std::vector<double>& error, std::vector<std::uint32_t>& pass_of,
               JointSearchResult& r) {
  set = std::move(next);
  error = std::move(next_error);
  pass_of = std::move(next_pass);
  r.triangles_drawn = drawn;
  r.vertex_moves += moves;
  r.pass_swaps += swaps;
  r.objective.push_back(objective);
  ++r.steps;
}

// One step from (set, error, pass_of); returns false (and leaves them) unless J fell.
bool step(const Eigen::Ref<const DataMatrix>& data, const Geometry& g, const VertexTriangles& vt,
          const Eigen::VectorXf& norms, const JointSearchOptions& o, double mu, CompressedSet& set,
          std::vector<double>& error, std::vector<std::uint32_t>& pass_of, JointSearchResult& r) {
  const DataMatrix d2 = subspace_distances(data, norms, set, o.candidates);
  CompressedSet next = set;
  std::vector<std::uint32_t> next_pass = pass_of;
  std::uint64_t moves = 0, swaps = 0;
  std::uint64_t drawn = r.triangles_drawn;
  if (mu == 0) {
    // Iterative CPCA's own step (compress.cpp), so that lambda = 0 is that method.
    next.cluster_of = argmin_rows(d2);
    split_empty_clusters(data, next.cluster_of, set.cluster_count);
  } else {
    std::vector<std::uint32_t> size(std::size_t(set.cluster_count), 0);
    for (std::uint32_t c : set.cluster_of) ++size[c];
    const double cap = o.overdraw_cap * double(g.triangles.size());
    SweepState s{g.triangles,
                 vt,
                 next_pass,
                 next.cluster_of,
                 size,
                 mu,
                 drawn,
                 o.overdraw_cap > 0 ? std::uint64_t(std::floor(cap))
                                    : std::numeric_limits<std::uint64_t>::max()};
    drawn -= std::uint64_t(sweep_vertices(data, d2, set, s, moves));
  }
  std::vector<double> next_error = refit_changed(data, set, error, next, o);
  if (mu != 0) {
    const ClusterIncidence inc = incidence_of(next, g, o.per_pass);
    PRTR_DCHECK(triangles_drawn(inc, next_pass) == drawn);
    drawn = swap_descent(inc, o.per_pass, next_pass, swaps);
  }
  const double before = total_of(error) + mu * double(r.triangles_drawn);
  const double after = total_of(next_error) + mu * double(drawn);
  if (!(after < before)) return false;
  keep_step(std::move(next), std::move(next_error), std::move(next_pass), drawn, moves, swaps,
            after / double(data.rows()), set, error, pass_of, r);
  return (before - after) / before >= o.threshold;
}

// The epsilon search's candidates: for every vertex its own cluster (first), the other
// clusters of its pass (a move among them costs no draws), the clusters of its 1-ring (the
// only moves that can change draws) and, when `closures` is not empty, its cluster's closure
// (cluster_pca.h), each with its squared distance to that cluster's affine subspace under the
// step's bases. Without closures a step costs O(V (per_pass + ring)) distances instead of
// iterative CPCA's V x K mean products.
struct Candidates {
  std::vector<std::uint32_t> offset, cluster;
  std::vector<double> error;
  // The fit each distance was taken under (FitGenerations), so the next step can reuse it.
  std::vector<std::uint32_t> generation;
};

// How many times each cluster's mean and basis have changed in a search. A step refits only
// the clusters whose members changed (refit_changed), so a vertex's distance to any other
// cluster is the one an earlier step computed: late steps on the horse (K = 128) refit 25-80
// clusters and leave 40-70% of the candidate distances known.
struct FitGenerations {
  std::vector<std::uint32_t> of;  // per cluster
  // After a kept step from `before` to `after`.
  void advance(const CompressedSet& before, const CompressedSet& after) {
    std::vector<char> changed(of.size(), 0);
    for (std::size_t p = 0; p < after.cluster_of.size(); ++p)
      if (after.cluster_of[p] != before.cluster_of[p])
        changed[before.cluster_of[p]] = changed[after.cluster_of[p]] = 1;
    for (std::size_t c = 0; c < of.size(); ++c) of[c] += std::uint32_t(changed[c]);
  }
};

Candidates bounded_candidates(const Eigen::Ref<const DataMatrix>& data, const CompressedSet& set,
                              const Geometry& g, const VertexTriangles& vt,
                              const std::vector<std::uint32_t>& pass_of,
                              std::vector<std::vector<std::uint32_t>> closures,
                              const FitGenerations& fits, const Candidates& previous) {
  const std::size_t vertices = set.cluster_of.size();
  std::vector<std::vector<std::uint32_t>> in_pass(
      std::size_t(*std::max_element(pass_of.begin(), pass_of.end())) + 1);
  for (std::uint32_t c = 0; c < pass_of.size(); ++c) in_pass[pass_of[c]].push_back(c);
  // The closure in id order, as the candidates' order breaks the sweep's ties.
  for (auto& ids : closures) std::sort(ids.begin(), ids.end());
  const auto list = [&](std::uint32_t p, std::vector<std::uint32_t>& out) {
    const std::uint32_t a = set.cluster_of[p];
    out.assign(1, a);
    for (std::uint32_t c : in_pass[pass_of[a]])
      if (c != a) out.push_back(c);
    for (std::uint32_t i = vt.offset[p]; i < vt.offset[p + 1]; ++i)
      for (std::uint32_t v : g.triangles[vt.triangle[i]]) {
        const std::uint32_t c = set.cluster_of[v];
        if (std::find(out.begin(), out.end(), c) == out.end()) out.push_back(c);
      }
    if (closures.empty()) return;
    for (std::uint32_t c : closures[a])
      if (std::find(out.begin(), out.end(), c) == out.end()) out.push_back(c);
  };
  std::vector<std::vector<std::uint32_t>> lists(vertices);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, vertices, 512), [&](const auto& range) {
    for (std::size_t p = range.begin(); p < range.end(); ++p) list(std::uint32_t(p), lists[p]);
  });
  Candidates r;
  r.offset.assign(vertices + 1, 0);
  for (std::size_t p = 0; p < vertices; ++p)
    r.offset[p + 1] = r.offset[p] + std::uint32_t(lists[p].size());
  r.cluster.resize(r.offset.back());
  r.error.resize(r.offset.back());
  r.generation.resize(r.offset.back());
  // p's distance to c from the previous step, when c's fit has not changed since.
  const auto reuse = [&](std::uint32_t p, std::uint32_t c, double& error) {
    if (previous.offset.size() != vertices + 1) return false;
    for (std::uint32_t j = previous.offset[p]; j < previous.offset[p + 1]; ++j)
      if (previous.cluster[j] == c && previous.generation[j] == fits.of[c])
        return error = previous.error[j], true;
    return false;
  };
  // The distances not known from the previous step, each cluster's candidate points in one
  // matrix product (as subspace_distances does): one (point, cluster) pair at a time cost half
  // the search's time.
  std::vector<std::vector<std::uint32_t>> entries(std::size_t(set.cluster_count));
  std::vector<std::uint32_t> point_of(r.offset.back());
  for (std::uint32_t p = 0; p < vertices; ++p)
    for (std::uint32_t i = 0; i < lists[p].size(); ++i) {
      const std::uint32_t c = lists[p][i], e = r.offset[p] + i;
      r.cluster[e] = c;
      r.generation[e] = fits.of[c];
      point_of[e] = p;
      if (!reuse(p, c, r.error[e])) entries[c].push_back(e);
    }
  tbb::parallel_for(0, set.cluster_count, [&](int c) {
    const std::vector<std::uint32_t>& e = entries[std::size_t(c)];
    if (e.empty()) return;
    std::vector<std::uint32_t> points(e.size());
    for (std::size_t i = 0; i < e.size(); ++i) points[i] = point_of[e[i]];
    const std::vector<float> residual = subspace_residuals(data, set, c, points);
    for (std::size_t i = 0; i < e.size(); ++i) r.error[e[i]] = double(residual[i]);
  });
  return r;
}

// Gauss-Seidel moves minimising err + mu * draws among the bounded candidates, with the
// step's bases fixed, under the error constraint: the running total of the members' errors
// (under those bases) never exceeds the cap, and while it is above the cap only moves that
// lower the error are taken. The refit that follows can only lower each cluster's error for
// its new members, so a step that ends within the cap stays within it.
std::int64_t sweep_epsilon(const Candidates& cand, SweepState& s, double cap, double& total,
                           std::uint64_t& moves) {
  const std::uint32_t vertices = std::uint32_t(s.cluster_of.size());
  // Vertices in order of their best move's gain (err + mu * draws) at the sweep's start, so
  // the error allowance goes to the cheapest draws first instead of to the lowest indices.
  std::vector<double> gain(vertices, 0.0);
  tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, vertices, 512), [&](const auto& range) {
    for (std::uint32_t p = range.begin(); p < range.end(); ++p) {
      const std::uint32_t a = s.cluster_of[p];
      const std::int64_t here = s.draws(p, s.pass_of[a]);
      for (std::uint32_t i = cand.offset[p] + 1; i < cand.offset[p + 1]; ++i) {
        const std::uint32_t c = cand.cluster[i];
        const std::int64_t n = s.pass_of[c] == s.pass_of[a] ? here : s.draws(p, s.pass_of[c]);
        gain[p] =
            std::min(gain[p], cand.error[i] - cand.error[cand.offset[p]] + s.mu * double(n - here));
      }
    }
  });
  std::vector<std::uint32_t> order;
  for (std::uint32_t p = 0; p < vertices; ++p)
    if (gain[p] < 0) order.push_back(p);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return gain[a] < gain[b]; });
  std::int64_t saved = 0;
  for (const std::uint32_t p : order) {
    const std::uint32_t a = s.cluster_of[p];
    if (s.size[a] <= 1) continue;
    const std::int64_t here = s.draws(p, s.pass_of[a]);
    const double own = cand.error[cand.offset[p]];
    // Above the cap every move must lower the error (draws are then only the tie-breaker the
    // price makes them); within it no move may take the running total above it.
    const bool above = total > cap;
    double best = 0, best_de = 0;
    std::uint32_t best_c = a;
    std::int64_t best_draws = here;
    double blocked = 0;  // the error the best move the cap refused would have added
    for (std::uint32_t i = cand.offset[p] + 1; i < cand.offset[p + 1]; ++i) {
      const std::uint32_t c = cand.cluster[i];
      const double de = cand.error[i] - own;
      if (above && !(de < 0)) continue;
      const std::int64_t n = s.pass_of[c] == s.pass_of[a] ? here : s.draws(p, s.pass_of[c]);
      const double delta = de + s.mu * double(n - here);
      if (!above && total + de > cap) {
        if (delta < best) blocked = std::max(blocked, de);
        continue;
      }
      if (delta < best) best = delta, best_c = c, best_draws = n, best_de = de;
    }
    s.wanted += blocked;
    if (best_c == a) continue;
    --s.size[a], ++s.size[best_c];
    s.cluster_of[p] = best_c;
    total += best_de;
    saved += here - best_draws;
    s.drawn = std::uint64_t(std::int64_t(s.drawn) + best_draws - here);
    ++moves;
  }
  return saved;
}

// The error of p's candidate cluster c under the step's bases (c must be a candidate).
double candidate_error(const Candidates& cand, std::uint32_t p, std::uint32_t c) {
  for (std::uint32_t i = cand.offset[p]; i < cand.offset[p + 1]; ++i)
    if (cand.cluster[i] == c) return cand.error[i];
  return std::numeric_limits<double>::infinity();
}

// Border cuts (border_cut.h): for every two passes A and B that meet, the vertices with a
// candidate cluster in each are relabelled at once by a minimum cut of the sweep's energy,
// err + mu * draws, each at its best candidate's error in the pass it takes. A cut is kept
// when it lowers that energy, keeps every cluster non-empty and keeps the running error
// within the cap (or lowers it while above), as the sweep's moves do.
std::int64_t cut_borders(const Candidates& cand, SweepState& s, double cap, double& total,
                         std::uint64_t& moves) {
  const std::uint32_t vertices = std::uint32_t(s.cluster_of.size());
  const double average_cap = cap / double(vertices);
  // (A, B), A < B, with the border vertices that can take either.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> listed;
  for (std::uint32_t p = 0; p < vertices; ++p) {
    const std::uint32_t own = s.pass(p);
    for (std::uint32_t i = cand.offset[p]; i < cand.offset[p + 1]; ++i) {
      const std::uint32_t q = s.pass_of[cand.cluster[i]];
      if (q != own) listed.push_back({std::uint64_t(std::min(own, q)) << 32 | std::max(own, q), p});
    }
  }
  std::sort(listed.begin(), listed.end());
  listed.erase(std::unique(listed.begin(), listed.end()), listed.end());
  std::vector<int> node_of(vertices, -1);
  std::vector<std::uint32_t> stamp(s.triangles.size(), ~0u);
  std::vector<std::uint32_t> free, touched, best_a, best_b, old_cluster;
  std::vector<double> err_a, err_b, own_err;
  // Passes the touched triangles meet, summed; and free vertex n into cluster c.
  const auto draws_of = [&s](const std::vector<std::uint32_t>& ts) {
    std::int64_t n = 0;
    for (std::uint32_t t : ts)
      n +=
          distinct(s.pass(s.triangles[t][0]), s.pass(s.triangles[t][1]), s.pass(s.triangles[t][2]));
    return n;
  };
  const auto relabel = [&s, &free](std::size_t n, std::uint32_t c) {
    --s.size[s.cluster_of[free[n]]], ++s.size[c];
    s.cluster_of[free[n]] = c;
  };
  std::int64_t saved = 0;
  std::uint32_t pair_id = 0;
  for (std::size_t i = 0; i < listed.size(); ++pair_id) {
    const std::uint64_t key = listed[i].first;
    const std::uint32_t a = std::uint32_t(key >> 32), b = std::uint32_t(key);
    free.clear(), err_a.clear(), err_b.clear(), best_a.clear(), best_b.clear(), own_err.clear();
    for (; i < listed.size() && listed[i].first == key; ++i) {
      const std::uint32_t p = listed[i].second, own = s.pass(p);
      if (own != a && own != b) continue;  // an earlier cut moved it away
      double ea = std::numeric_limits<double>::infinity(), eb = ea;
      std::uint32_t ca = 0, cb = 0;
      for (std::uint32_t k = cand.offset[p]; k < cand.offset[p + 1]; ++k) {
        const std::uint32_t c = cand.cluster[k], q = s.pass_of[c];
        if (q == a && cand.error[k] < ea) ea = cand.error[k], ca = c;
        if (q == b && cand.error[k] < eb) eb = cand.error[k], cb = c;
      }
      // A cut may not put a vertex above the average error the cap allows (unless it is
      // there already): segments moved into a neighbour's clusters carry errors alike along
      // the border, which images see more than Average SE does (held-out cat, K = 128: SE
      // 0.92 x the original's but image RMSE 1.08 x without this bound, 0.86 x with it).
      const double now = candidate_error(cand, p, s.cluster_of[p]);
      if (!std::isfinite(ea) || !std::isfinite(eb) || std::max(ea, eb) > std::max(average_cap, now))
        continue;
      node_of[p] = int(free.size());
      free.push_back(p), err_a.push_back(ea), err_b.push_back(eb);
      best_a.push_back(ca), best_b.push_back(cb);
      own_err.push_back(now);
    }
    if (free.size() < 2) {
      for (std::uint32_t p : free) node_of[p] = -1;
      continue;
    }
    touched.clear();
    for (std::uint32_t p : free)
      for (std::uint32_t k = s.incident.offset[p]; k < s.incident.offset[p + 1]; ++k)
        if (const std::uint32_t t = s.incident.triangle[k]; stamp[t] != pair_id)
          stamp[t] = pair_id, touched.push_back(t);
    const std::int64_t drawn_before = draws_of(touched);
    const BorderTerms terms = border_terms(s.triangles, touched, node_of, s.cluster_of, s.pass_of,
                                           a, b, int(free.size()));
    old_cluster.resize(free.size());
    for (std::size_t n = 0; n < free.size(); ++n) old_cluster[n] = s.cluster_of[free[n]];
    // At the step's price first; when that cut would overspend the allowance, at a quarter of
    // it, and so on: the pair's own dual, so the last of the allowance is still spent.
    double mu = s.mu;
    for (int tries = 0; tries < 6; mu *= 0.25, ++tries) {
      const std::vector<std::uint8_t> label = cut_border(terms, err_a, err_b, mu);
      double de = 0;
      std::uint64_t changed = 0;
      for (std::size_t n = 0; n < free.size(); ++n) {
        const std::uint32_t c = label[n] ? best_b[n] : best_a[n];
        de += (label[n] ? err_b[n] : err_a[n]) - own_err[n];
        changed += c != old_cluster[n];
        relabel(n, c);
      }
      const std::int64_t drawn_after = draws_of(touched);
      bool emptied = false;
      for (std::size_t n = 0; n < free.size() && !emptied; ++n)
        emptied = s.size[old_cluster[n]] == 0;
      // Judged at the step's price, as every move of the step is.
      const double gain = de + s.mu * double(drawn_after - drawn_before);
      const bool within = total > cap ? de < 0 : total + de <= cap;
      if (!emptied && within && changed > 0 && gain < -1e-12 * std::max(1.0, std::abs(total))) {
        total += de;
        saved += drawn_before - drawn_after;
        s.drawn = std::uint64_t(std::int64_t(s.drawn) + drawn_after - drawn_before);
        moves += changed;
        break;
      }
      for (std::size_t n = 0; n < free.size(); ++n) relabel(n, old_cluster[n]);
      if (tries == 0 && !within) s.wanted += de;
      if (within || changed == 0) break;  // a lower price only buys less
    }
    for (std::uint32_t p : free) node_of[p] = -1;
  }
  return saved;
}

// One epsilon step: bounded sweep at price mu, border cuts, warm refit, pass swaps. The proposal is
// kept when it lowers (violation of the error cap, triangles drawn, error) lexicographically.
// Returns whether it was kept; `feasible` tells whether the proposal met the cap, and
// `overpriced` whether the moves the cap refused would have overspent it by more than 1%.
bool epsilon_step(const Eigen::Ref<const DataMatrix>& data, const Geometry& g,
                  const VertexTriangles& vt, const JointSearchOptions& o, double mu,
                  double cap_total, CompressedSet& set, std::vector<double>& error,
                  std::vector<std::uint32_t>& pass_of, ClusterGrams& grams, Candidates& memo,
                  FitGenerations& fits, JointSearchResult& r, bool& feasible, bool& overpriced) {
  // Above the cap the search needs error-lowering moves, which the clusters near a vertex's
  // own offer (its cluster's closure, cluster_pca.h); within it only moves that change draws
  // matter, and those are bounded to the 1-ring, so no such distances are computed.
  const bool above = total_of(error) > cap_total;
  if (!o.reuse_distances) memo = Candidates();
  memo = bounded_candidates(
      data, set, g, vt, pass_of,
      above ? cluster_closures(set, o.candidates) : std::vector<std::vector<std::uint32_t>>(), fits,
      memo);
  const Candidates& cand = memo;
  CompressedSet next = set;
  std::vector<std::uint32_t> next_pass = pass_of;
  std::uint64_t moves = 0, swaps = 0;
  std::vector<std::uint32_t> size(std::size_t(set.cluster_count), 0);
  for (std::uint32_t c : set.cluster_of) ++size[c];
  const double before_error = total_of(error);
  SweepState s{g.triangles, vt, next_pass,         next.cluster_of,
               size,        mu, r.triangles_drawn, std::numeric_limits<std::uint64_t>::max()};
  std::uint64_t drawn = r.triangles_drawn;
  double total = 0;
  for (std::uint32_t p = 0; p < set.cluster_of.size(); ++p) total += cand.error[cand.offset[p]];
  drawn -= std::uint64_t(sweep_epsilon(cand, s, cap_total, total, moves));
  drawn -= std::uint64_t(cut_borders(cand, s, cap_total, total, moves));
  std::vector<double> next_error = refit_changed(data, set, error, next, o, &grams);
  const ClusterIncidence inc = incidence_of(next, g, o.per_pass);
  PRTR_DCHECK(triangles_drawn(inc, next_pass) == drawn);
  drawn = swap_descent(inc, o.per_pass, next_pass, swaps);
  const double after_error = total_of(next_error);
  const double violation_before = std::max(0.0, before_error - cap_total);
  const double violation_after = std::max(0.0, after_error - cap_total);
  feasible = violation_after == 0;
  overpriced = s.wanted > 0.01 * cap_total;
  const bool better = violation_before > 0
                          ? violation_after < violation_before
                          : feasible && (drawn < r.triangles_drawn || (drawn == r.triangles_drawn &&
                                                                       after_error < before_error));
  if (!better) return false;
  fits.advance(set, next);
  keep_step(std::move(next), std::move(next_error), std::move(next_pass), drawn, moves, swaps,
            after_error / double(data.rows()), set, error, pass_of, r);
  return true;
}

// Clusters renumbered so that pass p holds [p * per_pass, ...): the order grouping.
void renumber_by_pass(CompressedSet& set, const std::vector<std::uint32_t>& pass_of, int per_pass) {
  std::vector<std::uint32_t> id(pass_of.size());
  std::vector<std::uint32_t> used(pass_of.size(), 0);
  for (std::uint32_t c = 0; c < pass_of.size(); ++c)
    id[c] = pass_of[c] * std::uint32_t(per_pass) + used[pass_of[c]]++;
  const std::size_t d = set.dimension(), n = std::size_t(set.component_count);
  std::vector<float> means(set.means.size()), bases(set.bases.size());
  for (std::uint32_t c = 0; c < pass_of.size(); ++c) {
    std::copy_n(set.means.begin() + std::ptrdiff_t(c * d), d,
                means.begin() + std::ptrdiff_t(id[c] * d));
    std::copy_n(set.bases.begin() + std::ptrdiff_t(c * n * d), n * d,
                bases.begin() + std::ptrdiff_t(id[c] * n * d));
  }
  set.means = std::move(means);
  set.bases = std::move(bases);
  for (std::uint32_t& c : set.cluster_of) c = id[c];
}

// The search's start: LBG + PCA as compress() fits them, with the METIS super-clusters
// brought to the order profile (joint); or patch-first's set and passes (patch-joint).
CompressedSet joint_start(const Eigen::Ref<const DataMatrix>& data, const CompressOptions& options,
                          const Geometry& geometry, CompressReport& rep, std::vector<double>& error,
                          std::vector<std::uint32_t>& pass_of) {
  const bool patches = options.method == ClusterMethod::kPatchJoint ||
                       options.method == ClusterMethod::kPatchEpsilon;
  CompressOptions start = options;
  start.method = ClusterMethod::kLbg;
  CompressedSet set = patches ? compress_patch_first(data, options, geometry, &rep)
                              : compress(data, start, nullptr, &rep);
  // compress() does not hand back its per-vertex errors; the same fit again gives them (for
  // patch-first, a fit of the same clusters over the whole data).
  PowerIterationOptions power;
  power.seed = options.seed;
  if (options.method == ClusterMethod::kPatchEpsilon)
    // The stitched patches already hold each cluster's fit of its members: only the errors
    // are missing, and a second fit of every cluster would cost as much as the start.
    error = reconstruction_errors(data, set);
  else
    error = fit_cluster_pca(data, set, options.solver, power);
  if (patches) {
    pass_of.resize(std::size_t(set.cluster_count));
    for (std::uint32_t c = 0; c < pass_of.size(); ++c)
      pass_of[c] = c / std::uint32_t(options.clusters_per_pass);
    return set;
  }
  SuperClusterInput input;
  input.cluster_of = set.cluster_of;
  input.triangles = geometry.triangles;
  input.cluster_count = set.cluster_count;
  input.per_pass = options.clusters_per_pass;
  pass_of = order_profile(set.cluster_of, geometry.triangles, group_clusters("metis", input),
                          set.cluster_count, options.clusters_per_pass);
  return set;
}

}  // namespace

std::vector<std::uint32_t> order_profile(const std::vector<std::uint32_t>& cluster_of,
                                         const std::vector<TriangleIndices>& triangles,
                                         const SuperClusters& groups, int cluster_count,
                                         int per_pass) {
  SuperClusterInput input;
  input.cluster_of = cluster_of;
  input.triangles = triangles;
  input.cluster_count = cluster_count;
  input.per_pass = per_pass;
  const int passes = int(groups.passes.size());
  if (passes != pass_count(input))
    throw std::invalid_argument("order_profile: the grouping has " + std::to_string(passes) +
                                " passes, not the minimum " + std::to_string(pass_count(input)));
  const ClusterIncidence inc = cluster_incidence(input);
  GroupingLocalSearch search(inc, per_pass, pass_of_clusters(groups, cluster_count), passes);
  std::uint32_t last = 0;
  for (std::uint32_t p = 1; p < std::uint32_t(passes); ++p)
    if (search.members(p).size() < search.members(last).size()) last = p;
  for (std::uint32_t p = 0; p < std::uint32_t(passes); ++p)
    while (p != last && int(search.members(p).size()) < per_pass) {
      std::int64_t best = std::numeric_limits<std::int64_t>::max();
      std::uint32_t pick = 0;
      for (std::uint32_t c : search.members(last))
        if (const std::int64_t d = search.delta_move(c, p); d < best) best = d, pick = c;
      search.move(pick, p);
    }
  std::vector<std::uint32_t> pass_of = search.pass_of();
  for (std::uint32_t& p : pass_of)
    p = p == last ? std::uint32_t(passes - 1) : p - std::uint32_t(p > last);
  return pass_of;
}

JointSearchResult joint_search(const Eigen::Ref<const DataMatrix>& data, const Geometry& geometry,
                               CompressedSet& set, std::vector<double>& vertex_error,
                               std::vector<std::uint32_t> pass_of,
                               const JointSearchOptions& options) {
  if (!(options.lambda >= 0) || !std::isfinite(options.lambda))
    throw std::invalid_argument("joint search: lambda must be finite and >= 0, got " +
                                std::to_string(options.lambda));
  if (!(options.overdraw_cap == 0 || options.overdraw_cap >= 1))
    throw std::invalid_argument("joint search: the overdraw cap must be 0 (none) or >= 1, got " +
                                std::to_string(options.overdraw_cap));
  JointSearchResult r;
  const double total = total_of(vertex_error);
  r.error_scale = total / double(data.rows());
  const ClusterIncidence inc = incidence_of(set, geometry, options.per_pass);
  r.triangles_drawn = triangles_drawn(inc, pass_of);
  const double t = double(std::max<std::size_t>(geometry.triangles.size(), 1));
  const double mu = options.lambda * total / t;
  r.objective.push_back((total + mu * double(r.triangles_drawn)) / double(data.rows()));
  if (mu > 0) {
    r.triangles_drawn = swap_descent(inc, options.per_pass, pass_of, r.pass_swaps);
    r.objective.push_back((total + mu * double(r.triangles_drawn)) / double(data.rows()));
  }
  const VertexTriangles vt(std::size_t(data.rows()), geometry.triangles);
  if (options.error_target > 0) {
    // The epsilon-constraint search: the price of a drawn triangle is a Lagrange multiplier
    // found by the search itself (below), so no weight needs setting per mesh or K.
    const double cap_total = options.error_target * double(data.rows());
    double price = 2 * total / t;
    r.triangles_drawn = swap_descent(inc, options.per_pass, pass_of, r.pass_swaps);
    ClusterGrams grams;
    Candidates memo;
    FitGenerations fits{std::vector<std::uint32_t>(std::size_t(set.cluster_count), 0)};
    for (int i = 1, rejected = 0; i <= options.max_steps && rejected < 3; ++i) {
      r.tried = i;
      bool feasible = false, overpriced = false;
      const double error_before = total_of(vertex_error);
      const std::uint64_t drawn_before = r.triangles_drawn;
      const bool kept =
          epsilon_step(data, geometry, vt, options, price, cap_total, set, vertex_error, pass_of,
                       grams, memo, fits, r, feasible, overpriced);
      // A kept step that moved neither the extra draws (those above one a triangle, what the
      // search can change) nor, from above the cap, the error by the threshold counts as a
      // stall. Within the cap the objective is the draws alone: a falling error only widens an
      // allowance the search is not spending (the cat, 19% of its allowance unspent, ran 8
      // more steps for the same overdraw to three places while its refits lowered the error).
      const bool above = error_before > cap_total;
      const bool moved =
          kept &&
          (double(drawn_before) - double(r.triangles_drawn) >=
               options.threshold * (double(drawn_before) - t) ||
           (above && error_before - total_of(vertex_error) >= options.threshold * error_before));
      rejected = moved ? 0 : rejected + 1;
      // Dual ascent on the constraint: a draw gets cheaper while the error is above the cap,
      // or while the moves the cap refused would have overspent the allowance by more than 1%
      // (the price is then above the one that spends it exactly, and spends it on the first
      // moves met instead of the cheapest draws); it gets dearer (faster: the allowance is
      // spent in few steps) while more than 1% of the allowance is left unspent.
      if (!feasible || overpriced)
        price *= 0.5;
      else if (total_of(vertex_error) < 0.99 * cap_total || !kept)
        price *= 4;
      // Above the cap, a search whose excess would not reach zero in the steps left even at
      // this step's rate gives up: the rate only slows (each step's error-lowering moves are
      // those the last one left), and the caller's fallback (compress_joint) then starts
      // sooner. On the horse the patches' excess fell 0.77, 0.57, ..., 0.18 of the cap and
      // stalled at 0.14 after 20 steps; on the asteroid it fell 0.25 to 0 in 6.
      const double excess_before = error_before - cap_total,
                   excess = total_of(vertex_error) - cap_total;
      if (kept && excess_before > 0 && excess > 0 &&
          excess > (options.max_steps - i) * (excess_before - excess)) {
        r.gave_up = true;
        break;
      }
    }
    r.pass_of = std::move(pass_of);
    return r;
  }
  const Eigen::VectorXf norms = data.rowwise().squaredNorm();
  for (int i = 1; i <= options.max_steps && total_of(vertex_error) > 0; ++i) {
    r.tried = i;
    if (!step(data, geometry, vt, norms, options, mu, set, vertex_error, pass_of, r)) break;
  }
  r.pass_of = std::move(pass_of);
  return r;
}

CompressedSet compress_joint(const Eigen::Ref<const DataMatrix>& data,
                             const CompressOptions& options, const Geometry& geometry,
                             CompressReport* report, JointSearchResult* search) {
  if (options.alpha != 0 || options.overdraw_reduction)
    throw std::invalid_argument(
        "the joint search takes neither geometry coherence (alpha) nor the overdraw reduction: "
        "it weighs overdraw itself (lambda)");
  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  CompressReport local;
  CompressReport& rep = report ? *report : local;
  rep = CompressReport{};
  auto t = Clock::now();
  double target = 0;
  double reference_seconds = 0;
  CompressOptions start_options = options;
  if (options.method == ClusterMethod::kPatchEpsilon) {
    if (!(options.error_slack >= 0) || !std::isfinite(options.error_slack))
      throw std::invalid_argument(
          "patch-eps: the error slack (epsilon) must be finite and >= 0, "
          "got " +
          std::to_string(options.error_slack));
    double reference = options.error_target;
    if (!(reference > 0)) {
      CompressOptions original = options;
      original.method = ClusterMethod::kLbg;
      original.reference_clusters.clear();
      CompressReport original_report;
      start_options.reference_clusters =
          compress(data, original, nullptr, &original_report).cluster_of;
      reference = original_report.error.average_squared_error;
      reference_seconds = seconds(t);
    } else if (options.reference_clusters.size() != std::size_t(data.rows())) {
      throw std::invalid_argument(
          "patch-eps: a given reference (error target) needs its clusters, one per vertex; got " +
          std::to_string(options.reference_clusters.size()) + " for " +
          std::to_string(data.rows()) + " vertices");
    }
    target = (1 + options.error_slack) * reference;
    // An exact reference (zero error) leaves no room: any positive cap below float rounding.
    if (!(target > 0)) target = std::numeric_limits<double>::min();
  }
  std::vector<double> error;
  std::vector<std::uint32_t> pass_of;
  CompressedSet set = joint_start(data, start_options, geometry, rep, error, pass_of);
  rep.lbg_seconds += reference_seconds;
  const double start_seconds = seconds(t);
  t = Clock::now();
  const JointSearchOptions jo{.lambda = options.lambda,
                              .per_pass = options.clusters_per_pass,
                              .max_steps = options.cpca_max_iterations,
                              .threshold = options.cpca_threshold,
                              .candidates = options.cpca_candidates,
                              .solver = options.solver,
                              .seed = options.seed,
                              .overdraw_cap = options.overdraw_cap,
                              .error_target = target};
  JointSearchResult r = joint_search(data, geometry, set, error, std::move(pass_of), jo);
  if (options.method == ClusterMethod::kPatchEpsilon &&
      total_of(error) > target * double(data.rows()) * (1 + 1e-9)) {
    // Patches too small for their clusters (a small mesh at a large K) can leave the search
    // above the constraint. Original CPCA meets it by definition, so the search then starts
    // from its clusters, grouped by ILS and brought to the order profile, and only cuts draws.
    // The reference's clusters (given, or made above), fitted again rather than clustered.
    CompressedSet from = fit_clustering(data, options, start_options.reference_clusters);
    std::vector<double> from_error = reconstruction_errors(data, from);
    SuperClusterInput input;
    input.cluster_of = from.cluster_of;
    input.triangles = geometry.triangles;
    input.cluster_count = from.cluster_count;
    input.per_pass = options.clusters_per_pass;
    std::vector<std::uint32_t> from_pass =
        order_profile(from.cluster_of, geometry.triangles, group_clusters("ils", input),
                      from.cluster_count, options.clusters_per_pass);
    JointSearchResult fr = joint_search(data, geometry, from, from_error, std::move(from_pass), jo);
    if (total_of(from_error) < total_of(error)) {
      fr.tried += r.tried;
      set = std::move(from);
      error = std::move(from_error);
      r = std::move(fr);
    }
  }
  renumber_by_pass(set, r.pass_of, options.clusters_per_pass);
  set.method = options.method;
  set.iterations += r.tried;
  rep.cpca_seconds = seconds(t);
  rep.cpca_iterations = r.tried;
  rep.pca_seconds = start_seconds - rep.lbg_seconds;
  if (options.method == ClusterMethod::kPatchEpsilon) {
    // Its clustering time is all of it: the reference, the start and its fit, the search.
    rep.lbg_seconds = start_seconds;
    rep.pca_seconds = 0;
  }
  rep.error = error_metrics(data, set);
  rep.has_geometry = true;
  rep.span = triangle_span(set.cluster_of, geometry.triangles);
  rep.total_seconds = start_seconds + rep.cpca_seconds;
  if (search) *search = std::move(r);
  return set;
}

}  // namespace cpca
