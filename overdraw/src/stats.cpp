#include "overdraw/stats.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace overdraw {
namespace {

double quantile(const std::vector<double>& sorted, double p) {
  const double h = double(sorted.size() - 1) * p;
  const std::size_t lo = std::size_t(std::floor(h));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (h - double(lo)) * (sorted[hi] - sorted[lo]);
}

}  // namespace

Spread spread(std::vector<double> values) {
  if (values.empty()) return {};
  std::sort(values.begin(), values.end());
  return {quantile(values, 0.5), quantile(values, 0.25), quantile(values, 0.75)};
}

LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size()) throw std::logic_error("fit_line: x and y differ in length");
  LineFit fit;
  fit.points = x.size();
  if (x.empty()) return fit;
  const double n = double(x.size());
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= n;
  my /= n;
  // Centred sums: the raw-moment formula loses every digit when x clusters near 1.3.
  double sxx = 0, sxy = 0, syy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
    syy += (y[i] - my) * (y[i] - my);
  }
  fit.intercept = my;
  if (sxx <= 0) return fit;
  fit.slope = sxy / sxx;
  fit.intercept = my - fit.slope * mx;
  double residual = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double d = y[i] - fit.at(x[i]);
    residual += d * d;
  }
  fit.r2 = syy > 0 ? std::max(0.0, 1.0 - residual / syy) : 1.0;
  return fit;
}

}  // namespace overdraw
