// overdraw/stats.h: the statistics the overdraw benchmark reports beside its raw
// timings: a median with its interquartile range over the interleaved rounds (one noisy
// round on a shared machine moves neither), and the least-squares line of GL time or FPS
// against average overdraw across a run's rows (the thesis's claim, ch. 5, that frame cost
// follows overdraw, checked by its R^2).
#pragma once

#include <cstddef>
#include <vector>

namespace overdraw {

// Quartiles by linear interpolation between order statistics (the "type 7" rule of R and
// NumPy): q(p) = x[floor(h)] + (h - floor(h)) (x[floor(h)+1] - x[floor(h)]), h = (n-1) p.
struct Spread {
  double median = 0, q1 = 0, q3 = 0;
  double iqr() const { return q3 - q1; }
};
// All zero for no values.
Spread spread(std::vector<double> values);

// y = slope x + intercept minimising the squared residuals; r2 = 1 - SS_res / SS_tot.
// Fewer than two distinct x: slope 0, intercept mean(y), r2 0 (no line is determined).
// All y equal (SS_tot = 0) with a determined line: r2 = 1 (the line explains everything).
struct LineFit {
  double slope = 0, intercept = 0, r2 = 0;
  std::size_t points = 0;
  double at(double x) const { return slope * x + intercept; }
};
LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace overdraw
