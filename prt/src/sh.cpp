// Real SH by recurrence. References: Sloan, "Stupid Spherical Harmonics (SH) Tricks"
// (GDC 2008), appendix on the recurrences for P_l^m; the (x + iy)^m trick for the azimuthal
// factor is the usual one for avoiding trigonometry.
#include "prt/sh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace prt {
namespace {

// K_l^m (with sqrt(2) folded in for m > 0) and the recurrence constants for
// Q_l^m = P_l^m / sin^m(theta), computed once in double and stored in the evaluation type so
// the inner loops do no conversions.
template <class T>
struct Tables {
  T k[kMaxOrder][kMaxOrder]{};  // [l][m]
  T a[kMaxOrder][kMaxOrder]{};  // (2l - 1) / (l - m), for l >= m + 2
  T b[kMaxOrder][kMaxOrder]{};  // (l + m - 1) / (l - m), for l >= m + 2
  T diag[kMaxOrder]{};          // Q_m^m = (2m - 1)!!
  T next[kMaxOrder]{};          // Q_{m+1}^m / (z Q_m^m) = 2m + 1

  Tables() {
    for (int l = 0; l < kMaxOrder; ++l) {
      for (int m = 0; m <= l; ++m) {
        // (l - m)! / (l + m)! as a product, exact enough in double for l < 10.
        double ratio = 1.0;
        for (int t = l - m + 1; t <= l + m; ++t) ratio /= t;
        double kk = std::sqrt((2.0 * l + 1.0) / (4.0 * std::numbers::pi) * ratio);
        if (m > 0) kk *= std::numbers::sqrt2;
        k[l][m] = static_cast<T>(kk);
        if (l >= m + 2) {
          a[l][m] = static_cast<T>((2.0 * l - 1.0) / (l - m));
          b[l][m] = static_cast<T>((l + m - 1.0) / (l - m));
        }
      }
    }
    double dd = 1.0;
    for (int m = 0; m < kMaxOrder; ++m) {
      diag[m] = static_cast<T>(dd);
      next[m] = static_cast<T>(2.0 * m + 1.0);
      dd *= 2.0 * m + 1.0;
    }
  }
};

template <class T>
const Tables<T>& tables() {
  static const Tables<T> t;
  return t;
}

// W directions' worth of one quantity: an Eigen array (explicit SIMD; GCC fully unrolls
// small fixed-count loops before its vectoriser sees them) or, for W = 1, a plain scalar.
template <class T, int W>
struct Lanes {
  using V = Eigen::Array<T, W, 1>;
  static V constant(T v) { return V::Constant(v); }
  static V load(const T* p) { return Eigen::Map<const V, Eigen::Unaligned>(p); }
  static void store(T* p, const V& v) {
    Eigen::Map<V, Eigen::Unaligned> dst(p);
    dst = v;
  }
};
template <class T>
struct Lanes<T, 1> {
  using V = T;
  static V constant(T v) { return v; }
  static V load(const T* p) { return *p; }
  static void store(T* p, V v) { *p = v; }
};

// Evaluates W directions at once; value i of direction k goes to out[i * stride + k].
// c, s hold Re and Im of (x + i y)^m = sin^m(theta) (cos m phi, sin m phi), so no
// trigonometry is needed; Q_l^m follows the three-term recurrence in l, stable upward.
template <class T, int W, int order>
void eval_block(const T* __restrict xp, const T* __restrict yp, const T* __restrict zp,
                T* __restrict out, std::ptrdiff_t stride) {
  using L = Lanes<T, W>;
  using V = typename L::V;
  const Tables<T>& tb = tables<T>();
  const V x = L::load(xp), y = L::load(yp), z = L::load(zp);
  auto put = [&](int l, int m, const V& v) {
    L::store(out + std::ptrdiff_t(l * (l + 1) + m) * stride, v);
  };
  V c = L::constant(1), s = L::constant(0);
  // Both loop bounds are compile-time constants; unrolled, every table entry and output
  // address folds to a constant.
#pragma GCC unroll 10
  for (int m = 0; m < order; ++m) {
    V q0 = L::constant(tb.diag[m]);
    // l = m
    if (m == 0) {
      put(0, 0, L::constant(tb.k[0][0] * tb.diag[0]));
    } else {
      const T kmm = tb.k[m][m] * tb.diag[m];
      put(m, m, kmm * c);
      put(m, -m, kmm * s);
    }
    if (m + 1 >= order) break;
    // l = m + 1
    V q1 = tb.next[m] * z * q0;
    if (m == 0) {
      put(1, 0, tb.k[1][0] * q1);
    } else {
      const V kq = tb.k[m + 1][m] * q1;
      put(m + 1, m, kq * c);
      put(m + 1, -m, kq * s);
    }
#pragma GCC unroll 10
    for (int l = m + 2; l < order; ++l) {
      const V q = tb.a[l][m] * z * q1 - tb.b[l][m] * q0;
      q0 = q1;
      q1 = q;
      if (m == 0) {
        put(l, 0, tb.k[l][0] * q);
      } else {
        const V kq = tb.k[l][m] * q;
        put(l, m, kq * c);
        put(l, -m, kq * s);
      }
    }
    const V c_next = x * c - y * s;
    s = x * s + y * c;
    c = c_next;
  }
}

// The order is a template parameter so the recurrence unrolls into straight-line code
// (about 3x fewer instructions than with run-time loop bounds); this picks the instance.
template <class T, int W>
using BlockFn = void (*)(const T*, const T*, const T*, T*, std::ptrdiff_t);

template <class T, int W, int... Orders>
constexpr std::array<BlockFn<T, W>, sizeof...(Orders)> block_table(
    std::integer_sequence<int, Orders...>) {
  return {&eval_block<T, W, Orders + 1>...};
}

template <class T, int W>
void eval_dispatch(int order, const T* x, const T* y, const T* z, T* out, std::ptrdiff_t stride) {
  static_assert(kMinOrder == 1);
  check_order(order, "SH order");
  static constexpr auto kBlocks = block_table<T, W>(std::make_integer_sequence<int, kMaxOrder>());
  kBlocks[order - 1](x, y, z, out, stride);
}

template <class T>
void eval_impl(int order, T x, T y, T z, T* out) {
  eval_dispatch<T, 1>(order, &x, &y, &z, out, 1);
}

// Full blocks of kBlock directions are evaluated in structure-of-arrays form straight into
// the row-major output (row stride = count); a short last block goes through a buffer.
template <class T, class Mat, class Out>
void eval_batch_impl(int order, const Mat& directions, Out& out) {
  check_order(order, "SH order");
  constexpr int kBlock = 16;
  const Eigen::Index n = sh_count(order);
  const Eigen::Index count = directions.cols();
  if (out.rows() != n || out.cols() != count) out.resize(n, count);
  alignas(64) T x[kBlock], y[kBlock], z[kBlock];
  alignas(64) T buffer[kMaxOrder * kMaxOrder * kBlock];
  for (Eigen::Index start = 0; start < count; start += kBlock) {
    const int width = static_cast<int>(std::min<Eigen::Index>(kBlock, count - start));
    for (int k = 0; k < kBlock; ++k) {
      // Pad a short last block by repeating its last direction; those values are dropped.
      const Eigen::Index col = start + std::min(k, width - 1);
      x[k] = directions(0, col);
      y[k] = directions(1, col);
      z[k] = directions(2, col);
    }
    if (width == kBlock) {
      eval_dispatch<T, kBlock>(order, x, y, z, out.data() + start, count);
    } else {
      eval_dispatch<T, kBlock>(order, x, y, z, buffer, kBlock);
      for (Eigen::Index i = 0; i < n; ++i)
        for (int k = 0; k < width; ++k) out(i, start + k) = buffer[i * kBlock + k];
    }
  }
}

}  // namespace

int sh_band(int index) {
  int l = static_cast<int>(std::sqrt(static_cast<double>(index)));
  while (l * l > index) --l;
  while ((l + 1) * (l + 1) <= index) ++l;
  return l;
}

void check_order(int order, const char* what) {
  if (order < kMinOrder || order > kMaxOrder) {
    throw std::invalid_argument(std::string(what) + " must be in [" + std::to_string(kMinOrder) +
                                ", " + std::to_string(kMaxOrder) +
                                "] (order N means bands 0..N-1), got " + std::to_string(order));
  }
}

void sh_eval(int order, double x, double y, double z, double* out) {
  eval_impl(order, x, y, z, out);
}
void sh_eval(int order, float x, float y, float z, float* out) {
  eval_impl(order, x, y, z, out);
}

void sh_eval_batch(int order, const Eigen::Ref<const Eigen::Matrix3Xf>& directions, ShBatchF& out) {
  eval_batch_impl<float>(order, directions, out);
}
void sh_eval_batch(int order, const Eigen::Ref<const Eigen::Matrix3Xd>& directions, ShBatchD& out) {
  eval_batch_impl<double>(order, directions, out);
}

double sh_reference(int l, int m, const Eigen::Vector3d& direction) {
  const Eigen::Vector3d d = direction.normalized();
  const double theta = std::acos(std::clamp(d.z(), -1.0, 1.0));
  const double phi = std::atan2(d.y(), d.x());
  const int am = std::abs(m);
  double fact = 1.0;  // (l - |m|)! / (l + |m|)!
  for (int t = l - am + 1; t <= l + am; ++t) fact /= t;
  const double k = std::sqrt((2.0 * l + 1.0) / (4.0 * std::numbers::pi) * fact);
  // std::assoc_legendre omits the Condon-Shortley phase, as our convention does.
  const double p =
      std::assoc_legendre(static_cast<unsigned>(l), static_cast<unsigned>(am), std::cos(theta));
  if (m > 0) return std::numbers::sqrt2 * k * p * std::cos(am * phi);
  if (m < 0) return std::numbers::sqrt2 * k * p * std::sin(am * phi);
  return k * p;
}

double sh_expand(const Eigen::Ref<const Eigen::VectorXd>& coefficients,
                 const Eigen::Vector3d& direction) {
  const int order = sh_band(static_cast<int>(coefficients.size()) - 1) + 1;
  if (sh_count(order) != coefficients.size()) {
    throw std::invalid_argument("sh_expand: coefficient count " +
                                std::to_string(coefficients.size()) + " is not a square");
  }
  check_order(order, "SH order");
  std::array<double, kMaxOrder * kMaxOrder> y;
  const Eigen::Vector3d d = direction.normalized();
  sh_eval(order, d, y.data());
  return Eigen::Map<const Eigen::VectorXd>(y.data(), coefficients.size()).dot(coefficients);
}

}  // namespace prt
