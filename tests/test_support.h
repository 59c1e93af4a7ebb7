// tests/test_support.h: helpers shared by the test suites (scratch files, quadrature).
#pragma once

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace test_support {

// A path in this suite's scratch directory (created on first use).
inline std::filesystem::path scratch(const std::string& suite, const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(PRTR_TEST_TMPDIR) / suite;
  std::filesystem::create_directories(dir);
  return dir / name;
}

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n); exact for polynomials of
// degree < 2n. The oracle quadrature of the SH and bake tests.
inline void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w) {
  x.resize(n);
  w.resize(n);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double dp = 0.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1.0);
      const double dz = p1 / dp;
      z -= dz;
      if (std::abs(dz) < 1e-15) break;
    }
    x[i] = z;
    w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
  }
}

}  // namespace test_support
