// Reflectance models and their SH BRDF matrices (thesis ch. 3.1.1 and its glossy
// materials). Models: Lambert; the energy-normalised "modified Phong" of Lafortune & Willems,
// "Using the modified Phong reflectance model for physically based rendering" (1994);
// Cook & Torrance, "A reflectance model for computer graphics" (ACM TOG 1, 1982) with the
// Beckmann distribution and either their V-groove masking term or Smith's height-correlated
// one (Heitz, JCGT 2014); Schlick, "An inexpensive BRDF model for physically-based
// rendering" (1994) for the Fresnel factor.
//
// The BRDF matrix is a product quadrature over view and light hemispheres:
//     B = P F Ys^T,  F(a, b) = f_r(v_a, s_b) s_b.z w_b,
// with P the view fit's projection (prt/view_fit.h; Yv diag(wv) for the thesis's),
// with Gauss-Legendre nodes in cos(theta) on (0, 1) and midpoint nodes in phi. View nodes are
// split into fixed chunks (independent of the thread count) that run in parallel, each with
// its own partial B; the partials are summed in chunk order, so the result is deterministic.
#include "prt/material.h"

#include "prt/sh.h"
#include "prt/zonal.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace prt {
namespace {

constexpr double kPi = std::numbers::pi;

// The one-channel parameters in double, read once so the quadrature's inner loop does no
// conversions and no channel look-ups.
struct Lobe {
  MaterialKind kind;
  double rho_d, rho_s, exponent, m2, f0;
  Masking masking;
};

// Smith's Lambda for Beckmann at a direction with cosine z (0 < z <= 1), roughness^2 m2.
double smith_lambda(double z, double m2) {
  if (z >= 1.0) return 0.0;
  const double a = z / std::sqrt(m2 * (1.0 - z * z));
  // Past a = 8 both terms are below 1e-28 of 1: exp(-64) and erfc(8) ~ 1e-29.
  if (a > 8.0) return 0.0;
  return 0.5 * (std::erf(a) - 1.0) + std::exp(-a * a) / (2.0 * a * std::sqrt(kPi));
}

Lobe make_lobe(const Material& material, int channel) {
  double rho_d = material.albedo.x();
  if (!material.grey()) {
    if (channel < 0 || channel > 2) {
      throw std::invalid_argument("BRDF channel must be 0, 1 or 2 for a coloured material, got " +
                                  std::to_string(channel));
    }
    rho_d = material.albedo[channel];
  }
  const double m = material.roughness;
  return {material.kind,
          rho_d,
          double(material.specular),
          double(material.exponent),
          m * m,
          double(material.f0),
          material.masking};
}

// The header's formulas. v and s are unit vectors in the local frame.
double eval(const Lobe& lobe, const Eigen::Vector3d& v, const Eigen::Vector3d& s) {
  if (v.z() <= 0.0 || s.z() <= 0.0) return 0.0;
  const double diffuse = lobe.rho_d / kPi;
  switch (lobe.kind) {
    case MaterialKind::kLambert:
      return diffuse;
    case MaterialKind::kPhong: {
      // r.v with r = 2 s.z z - s, the mirror direction of s. The lobe is 0 for r.v <= 0 (also
      // for e = 0, where pow(0, 0) would otherwise give 1 behind the mirror direction).
      const double rv = 2.0 * s.z() * v.z() - s.dot(v);
      if (rv <= 0.0 || lobe.rho_s == 0.0) return diffuse;
      return diffuse +
             lobe.rho_s * (lobe.exponent + 2.0) / (2.0 * kPi) * std::pow(rv, lobe.exponent);
    }
    case MaterialKind::kCookTorrance: {
      if (lobe.rho_s == 0.0) return diffuse;
      // v.z, s.z > 0 so (v + s).z > 0: h is well defined and in the upper hemisphere, and
      // v.h = (1 + v.s) / |v + s| > 0.
      const Eigen::Vector3d h = (v + s).normalized();
      const double hz = h.z(), vh = v.dot(h);
      const double hz2 = hz * hz;
      const double tan2 = (1.0 - hz2) / hz2;
      const double d = std::exp(-tan2 / lobe.m2) / (kPi * lobe.m2 * hz2 * hz2);
      const double g =
          lobe.masking == Masking::kSmith
              ? 1.0 / (1.0 + smith_lambda(v.z(), lobe.m2) + smith_lambda(s.z(), lobe.m2))
              : std::min({1.0, 2.0 * hz * v.z() / vh, 2.0 * hz * s.z() / vh});
      const double c = 1.0 - vh, c2 = c * c;
      const double f = lobe.f0 + (1.0 - lobe.f0) * c2 * c2 * c;
      return diffuse + lobe.rho_s * d * g * f / (4.0 * v.z() * s.z());
    }
  }
  return 0.0;  // unreachable for a validated material
}

// The light grid's coordinates as separate arrays, for eval_row.
struct LightArrays {
  Eigen::ArrayXd x, y, z, inv_z;
  Eigen::ArrayXd smith;  // 1 + Lambda(s) (Cook-Torrance with Smith masking), else empty
};

// f_r(v, s_b) for all light nodes s_b at once: the same formulas as eval(), written on Eigen
// arrays so that exp and log run as AVX2 packets. This is the quadrature's hot loop (a
// scalar eval() costs ~60 ns, mostly exp/pow and the divisions); material_test checks
// brdf_matrix against a quadrature built on brdf_eval. Grid nodes are interior
// (Gauss-Legendre), so v.z > 0 and s.z > 0 hold without a test.
void eval_row(const Lobe& lobe, const Eigen::Vector3d& v, const LightArrays& s, double* out) {
  Eigen::Map<Eigen::ArrayXd> row(out, s.z.size());
  const double diffuse = lobe.rho_d / kPi;
  if (lobe.kind == MaterialKind::kLambert || lobe.rho_s == 0.0) {
    row.setConstant(diffuse);
    return;
  }
  const Eigen::ArrayXd vs = v.x() * s.x + v.y() * s.y + v.z() * s.z;
  if (lobe.kind == MaterialKind::kPhong) {
    // r.v = 2 s.z v.z - v.s; x^e = exp(e log x), masked to 0 for x <= 0 as in eval().
    const Eigen::ArrayXd rv = 2.0 * v.z() * s.z - vs;
    const double scale = lobe.rho_s * (lobe.exponent + 2.0) / (2.0 * kPi);
    row = diffuse + scale * (rv > 0.0).select((lobe.exponent * rv.log()).exp(), 0.0);
    return;
  }
  // Cook-Torrance without normalising h: with q = 1 + v.s and p = v.z + s.z, |v + s|^2 = 2q,
  // so v.h = sqrt(q / 2), h.z = p / sqrt(2q), 1 / cos^2(theta_h) = u = 2q / p^2,
  // tan^2(theta_h) = u - 1, and 2 h.z min(v.z, s.z) / v.h = 2 p min(v.z, s.z) / q. Two
  // divisions and one square root per node.
  const Eigen::ArrayXd q = 1.0 + vs;
  const Eigen::ArrayXd p = v.z() + s.z;
  const Eigen::ArrayXd u = 2.0 * q / p.square();
  const Eigen::ArrayXd d = ((1.0 - u) / lobe.m2).exp() * u.square() / (kPi * lobe.m2);
  const Eigen::ArrayXd g = lobe.masking == Masking::kSmith
                               ? (s.smith + smith_lambda(v.z(), lobe.m2)).inverse().eval()
                               : (2.0 * p * s.z.min(v.z()) / q).min(1.0).eval();
  const Eigen::ArrayXd c = 1.0 - (0.5 * q).sqrt();
  const Eigen::ArrayXd f = lobe.f0 + (1.0 - lobe.f0) * c.square().square() * c;
  row = diffuse + (lobe.rho_s / (4.0 * v.z())) * d * g * f * s.inv_z;
}

// Gauss-Legendre nodes and weights on (0, 1): Newton's iteration on P_n from the usual
// Chebyshev-like initial guesses (Numerical Recipes, gauleg), mapped from (-1, 1).
void gauss_legendre(int count, Eigen::VectorXd& nodes, Eigen::VectorXd& weights) {
  nodes.resize(count);
  weights.resize(count);
  for (int i = 0; i < (count + 1) / 2; ++i) {
    double x = std::cos(kPi * (i + 0.75) / (count + 0.5));
    double derivative = 1.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1.0, p1 = 0.0;  // P_k(x), P_{k-1}(x)
      for (int k = 1; k <= count; ++k) {
        const double p2 = p1;
        p1 = p0;
        p0 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p2) / k;
      }
      derivative = count * (x * p0 - p1) / (x * x - 1.0);
      const double step = p0 / derivative;
      x -= step;
      if (std::abs(step) <= 1e-15) break;  // quadratic convergence: x is now exact to rounding
    }
    const double w = 2.0 / ((1.0 - x * x) * derivative * derivative);
    // x and -x on (-1, 1) map to (1 + x) / 2 and (1 - x) / 2 on (0, 1), weights halved.
    nodes[count - 1 - i] = 0.5 * (1.0 + x);
    nodes[i] = 0.5 * (1.0 - x);
    weights[i] = weights[count - 1 - i] = 0.5 * w;
  }
}

struct HemisphereGrid {
  Eigen::Matrix3Xd directions;
  Eigen::VectorXd weights;  // solid-angle weights, summing to 2 pi
};

HemisphereGrid hemisphere_grid(int n_theta, int n_phi) {
  Eigen::VectorXd x, w;
  gauss_legendre(n_theta, x, w);
  HemisphereGrid grid;
  grid.directions.resize(3, Eigen::Index(n_theta) * n_phi);
  grid.weights.resize(grid.directions.cols());
  for (int t = 0; t < n_theta; ++t) {
    const double sin_theta = std::sqrt(std::max(0.0, 1.0 - x[t] * x[t]));
    for (int p = 0; p < n_phi; ++p) {
      const double phi = 2.0 * kPi * (p + 0.5) / n_phi;
      const Eigen::Index k = Eigen::Index(t) * n_phi + p;
      grid.directions.col(k) << sin_theta * std::cos(phi), sin_theta * std::sin(phi), x[t];
      grid.weights[k] = w[t] * 2.0 * kPi / n_phi;
    }
  }
  return grid;
}

std::string range_error(const char* flag, const char* range, double value) {
  std::ostringstream message;
  message << flag << " must be in " << range << ", got " << value;
  return message.str();
}

}  // namespace

void Material::validate() const {
  if (kind != MaterialKind::kLambert && kind != MaterialKind::kPhong &&
      kind != MaterialKind::kCookTorrance) {
    throw std::invalid_argument("--material: unknown material kind " +
                                std::to_string(static_cast<int>(kind)));
  }
  // Written as !(in range) so that NaN fails; the closed ranges reject infinities.
  for (int c = 0; c < 3; ++c) {
    if (!(albedo[c] >= 0.f && albedo[c] <= 1.f)) {
      throw std::invalid_argument(range_error("--albedo", "[0, 1]", albedo[c]) + " (channel " +
                                  std::to_string(c) + ")");
    }
  }
  if (!(specular >= 0.f && specular <= 1.f)) {
    throw std::invalid_argument(range_error("--specular", "[0, 1]", specular));
  }
  if (!(exponent >= 0.f && exponent <= 10000.f)) {
    throw std::invalid_argument(range_error("--exponent", "[0, 10000]", exponent));
  }
  if (!(roughness > 0.f && roughness <= 1.f)) {
    throw std::invalid_argument(range_error("--roughness", "(0, 1]", roughness));
  }
  if (!(f0 >= 0.f && f0 <= 1.f)) {
    throw std::invalid_argument(range_error("--f0", "[0, 1]", f0));
  }
  // A specular lobe on top of the diffuse term must not create energy: rho_d + rho_s <= 1.
  // Lambert has no specular term, so its (unused) --specular does not count. The sum is
  // taken in double with a slack of 1e-6 for values that are 1 in decimal but not in float.
  if (kind != MaterialKind::kLambert) {
    for (int c = 0; c < 3; ++c) {
      if (double(albedo[c]) + double(specular) > 1.0 + 1e-6) {
        std::ostringstream message;
        message << "--albedo + --specular must be <= 1 in every channel (energy conservation), got "
                << albedo[c] << " + " << specular << " in channel " << c;
        throw std::invalid_argument(message.str());
      }
    }
  }
}

double brdf_eval(const Material& material, int channel, const Eigen::Vector3d& v,
                 const Eigen::Vector3d& s) {
  return eval(make_lobe(material, channel), v, s);
}

Eigen::ArrayXd brdf_eval_batch(const Material& material, int channel, const Eigen::Vector3d& v,
                               const Eigen::Matrix3Xd& s) {
  const Lobe lobe = make_lobe(material, channel);
  LightArrays arrays{s.row(0).transpose().array(),
                     s.row(1).transpose().array(),
                     s.row(2).transpose().array(),
                     s.row(2).transpose().array().inverse(),
                     {}};
  if (lobe.kind == MaterialKind::kCookTorrance && lobe.masking == Masking::kSmith)
    arrays.smith = arrays.z.unaryExpr([&](double z) { return 1.0 + smith_lambda(z, lobe.m2); });
  Eigen::ArrayXd out(s.cols());
  eval_row(lobe, v, arrays, out.data());
  return out;
}

BrdfQuadrature resolve_brdf_quadrature(const Material& material, int order,
                                       const BrdfQuadrature& quadrature) {
  check_order(order, "BRDF matrix order");
  for (int value :
       {quadrature.view_theta, quadrature.view_phi, quadrature.light_theta, quadrature.light_phi}) {
    if (value < 0) {
      throw std::invalid_argument("BRDF quadrature node counts must be >= 0 (0 = default), got " +
                                  std::to_string(value));
    }
  }
  // Fields the caller set win; the others get the defaults below.
  auto pick = [](int requested, int fallback) { return requested > 0 ? requested : fallback; };
  BrdfQuadrature q;
  if (material.kind == MaterialKind::kLambert || material.specular == 0.f) {
    // The integrand is separable: y_i(v) against a constant, and y_j(s) s.z. In cos(theta)
    // both are polynomials of degree <= order on the m = 0 entries (Gauss-Legendre with k
    // nodes is exact to degree 2k - 1); in phi they are trigonometric polynomials of degree
    // < order, which midpoint nodes integrate exactly (to 0 for m != 0) from order + 1 nodes
    // on. So this small grid is exact up to rounding.
    q.view_theta = pick(quadrature.view_theta, order);
    q.view_phi = pick(quadrature.view_phi, 2 * order + 1);
    q.light_theta = pick(quadrature.light_theta, order);
    q.light_phi = pick(quadrature.light_phi, 2 * order + 1);
    return q;
  }
  // Glossy lobes. k is the inverse angular width of the lobe in s: cos^e a ~ exp(-e a^2 / 2)
  // gives 1 / sqrt(e) for Phong; Beckmann's exp(-tan^2 / m^2) has width ~m in the half
  // vector, so ~m in s. Measured numbers below are order 6, "2x" = every node count doubled,
  // differences relative in the Frobenius norm, times on 2 shared cores.
  //
  // Phong: the lobe is smooth (C^e at its edge r.v = 0), so the product rule converges like
  // the trapezoid rule on a Gaussian once the node spacing is below the width. Light grid:
  // order + 2.5 k Gauss-Legendre nodes in cos(theta), 2 order + 5 k in phi (spacing ~1.3 / k
  // at the horizon). Measured vs 2x: < 1e-8 for 8 <= e <= 1000, 1e-5 at e = 1, 2e-3 at
  // e = 0 (a discontinuous lobe edge). k >= 8 (the e = 64 grid) below e = 64, where the
  // edge is rough and grids cost nothing anyway. e = 100: 26 x 13 view, 31 x 65 light, ~10 ms.
  //
  // Cook-Torrance converges only algebraically, whatever the grid: for a grazing view the
  // lobe is squeezed against the horizon to an azimuthal width ~m (v.z + s.z), with
  // f s.z ~ D / (2 v.h) large where v.h is small (G's 2 h.z v.z / v.h cancels the 1 / v.z),
  // and the masking term adds kinks (min(v.z, s.z), min(1, .)). The error is dominated by
  // the view nodes nearest the horizon, Gauss-Legendre's first node sitting at ~1 / n^2: more
  // view nodes in theta make it worse, not better, unless the light grid grows with them.
  // Hence few view nodes (order + k; the view integrand is smooth) and many light nodes:
  // order + 12 k in cos(theta), 2 order + 200 k^1.5 in phi (the phi error was measured to go
  // like 1 / (n_phi^2 m^3)). Measured vs 2x: 1e-5 to 4e-5 for 0.125 <= m <= 1, and within
  // 6e-5 of a half-vector brute force; m = 0.3: 10 x 13 view, 46 x 1235 light, ~0.1 s;
  // m = 0.2: ~0.3 s.
  //
  // View phi: y_i(v) g_j(v) has azimuthal degree < 2 order (isotropy), so 2 order + 1
  // midpoint nodes are exact. Phong's view theta (order + 2 k) resolves the horizon layer of
  // width ~1/k where the lobe is clipped by s.z > 0.
  //
  // Isotropy: light_phi is a multiple of view_phi, so both grids are invariant under the
  // dihedral group of rotations by 2 pi / view_phi about z and the mirror y -> -y. B then
  // commutes with that group, and since view_phi > 2 (order - 1) its irreducible pieces on
  // bands < order are those of the full rotation group about z: B commutes with every z
  // rotation up to rounding, however coarse the light grid (Schur's lemma).
  //
  // Caps: k <= 48 for Phong (e ~ 2300) and k <= 8 for Cook-Torrance (m = 0.125) bound the
  // cost at ~0.5 s and ~1.5 s. Sharper lobes are under-resolved: e = 10000 differs from the
  // 2x grid by ~1e-2, m = 0.05 by ~7e-4.
  const bool phong = material.kind == MaterialKind::kPhong;
  const double k = phong ? std::clamp(std::sqrt(double(material.exponent)), 8.0, 48.0)
                         : std::clamp(1.0 / double(material.roughness), 3.0, 8.0);
  const double view_theta_scale = phong ? 2.0 : 1.0;
  const double light_theta_scale = phong ? 2.5 : 12.0;
  const double phi_nodes = phong ? 5.0 * k : 200.0 * k * std::sqrt(k);
  q.view_theta = pick(quadrature.view_theta, order + int(std::ceil(view_theta_scale * k)));
  q.view_phi = pick(quadrature.view_phi, 2 * order + 1);
  q.light_theta = pick(quadrature.light_theta, order + int(std::ceil(light_theta_scale * k)));
  const int light_phi = 2 * order + int(std::ceil(phi_nodes));
  q.light_phi =
      pick(quadrature.light_phi, q.view_phi * ((light_phi + q.view_phi - 1) / q.view_phi));
  return q;
}

Eigen::MatrixXd brdf_matrix(const Material& material, int order, int channel,
                            const BrdfQuadrature& quadrature, ViewFit fit, double view_lambda) {
  material.validate();
  const Lobe lobe = make_lobe(material, channel);
  const BrdfQuadrature q = resolve_brdf_quadrature(material, order, quadrature);
  const int n = sh_count(order);

  const HemisphereGrid view = hemisphere_grid(q.view_theta, q.view_phi);
  const HemisphereGrid light = hemisphere_grid(q.light_theta, q.light_phi);
  const Eigen::Index view_count = view.directions.cols();
  const Eigen::Index light_count = light.directions.cols();

  const Eigen::MatrixXd view_side =
      view_projection(fit, order, view.directions, view.weights, view_lambda);
  ShBatchD y_light;
  sh_eval_batch(order, light.directions, y_light);
  // Ys diag(s.z w)^T, light_count x n: the light side of every product, folded once.
  const Eigen::MatrixXd light_side =
      (y_light.array().rowwise() *
       (light.directions.row(2).transpose().array() * light.weights.array()).transpose())
          .matrix()
          .transpose();
  LightArrays light_arrays{light.directions.row(0).transpose().array(),
                           light.directions.row(1).transpose().array(),
                           light.directions.row(2).transpose().array(),
                           light.directions.row(2).transpose().array().inverse(),
                           {}};
  if (lobe.kind == MaterialKind::kCookTorrance && lobe.masking == Masking::kSmith) {
    light_arrays.smith =
        light_arrays.z.unaryExpr([&](double z) { return 1.0 + smith_lambda(z, lobe.m2); });
  }

  // Work unit: kViewChunk view nodes against all light nodes, in blocks of kLightBlock so
  // that a block of F (256 KB) and of light_side (~600 KB at order 6) stay in cache while
  // the GEMM consumes them. The split depends only on the grid, not on the thread count.
  constexpr Eigen::Index kViewChunk = 16, kLightBlock = 2048;
  const Eigen::Index chunk_count = (view_count + kViewChunk - 1) / kViewChunk;
  std::vector<Eigen::MatrixXd> partial(chunk_count);
  tbb::parallel_for(Eigen::Index(0), chunk_count, [&](Eigen::Index c) {
    const Eigen::Index begin = c * kViewChunk;
    const Eigen::Index size = std::min(kViewChunk, view_count - begin);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> f;
    Eigen::MatrixXd f_light = Eigen::MatrixXd::Zero(size, n);  // F Ys diag(s.z w)^T rows
    LightArrays block;
    for (Eigen::Index b0 = 0; b0 < light_count; b0 += kLightBlock) {
      const Eigen::Index width = std::min(kLightBlock, light_count - b0);
      block.x = light_arrays.x.segment(b0, width);
      block.y = light_arrays.y.segment(b0, width);
      block.z = light_arrays.z.segment(b0, width);
      block.inv_z = light_arrays.inv_z.segment(b0, width);
      if (light_arrays.smith.size()) block.smith = light_arrays.smith.segment(b0, width);
      f.resize(size, width);
      for (Eigen::Index a = 0; a < size; ++a) {
        eval_row(lobe, view.directions.col(begin + a), block, f.row(a).data());
      }
      f_light.noalias() += f * light_side.middleRows(b0, width);
    }
    partial[c] = view_side.middleCols(begin, size) * f_light;
  });
  Eigen::MatrixXd total = Eigen::MatrixXd::Zero(n, n);
  for (const Eigen::MatrixXd& p : partial) total += p;
  return total;
}

Eigen::MatrixXd lambert_brdf_matrix(double albedo, int order, ViewFit fit) {
  check_order(order, "BRDF matrix order");
  if (!(albedo >= 0.0 && albedo <= 1.0)) {
    throw std::invalid_argument(range_error("--albedo", "[0, 1]", albedo));
  }
  // a_l = int_{z>0} y_l^0 (coefficients of the hemisphere indicator, cos^0) and b_l =
  // int_{z>0} z y_l^0 (the clamped cosine): B_ij = (rho / pi) a_i b_j on m = 0 entries.
  const Eigen::VectorXd b = zonal_cosine_power(order, 1.0);
  // The view side: the fit of the constant 1 on the upper hemisphere.
  Eigen::VectorXd a = Eigen::VectorXd::Zero(order);
  switch (fit) {
    case ViewFit::kHemisphere:
      a = zonal_cosine_power(order, 0.0);
      break;
    case ViewFit::kEven:
    case ViewFit::kLeastSquares:
      a[0] = std::sqrt(4.0 * kPi);
      break;
    case ViewFit::kHemisphericalHarmonics:
      a[0] = std::sqrt(2.0 * kPi);
      break;
  }
  const int n = sh_count(order);
  Eigen::MatrixXd result = Eigen::MatrixXd::Zero(n, n);
  for (int li = 0; li < order; ++li) {
    for (int lj = 0; lj < order; ++lj) {
      result(sh_index(li, 0), sh_index(lj, 0)) = albedo / kPi * a[li] * b[lj];
    }
  }
  return result;
}

}  // namespace prt

namespace prt {

double directional_albedo(const Material& material, int channel, const Eigen::Vector3d& v) {
  material.validate();
  const Lobe lobe = make_lobe(material, channel);
  // A dense grid, deliberately unlike brdf_matrix's: midpoints in theta (not Gauss-Legendre
  // in cos theta) around the mirror direction's azimuth. 1024 x 2048 nodes resolve a Phong
  // lobe of exponent ~10^4 or a Beckmann lobe of m = 0.05 with several nodes across.
  constexpr int kTheta = 1024, kPhi = 2048;
  const double phi_v = std::atan2(v.y(), v.x());
  double total = 0.0;
  for (int t = 0; t < kTheta; ++t) {
    const double theta = 0.5 * kPi * (t + 0.5) / kTheta;
    const double z = std::cos(theta), r = std::sin(theta);
    const double weight = (0.5 * kPi / kTheta) * (2.0 * kPi / kPhi) * r * z;  // dOmega s.z
    double ring = 0.0;
    for (int p = 0; p < kPhi; ++p) {
      const double phi = phi_v + kPi + 2.0 * kPi * (p + 0.5) / kPhi;
      ring += eval(lobe, v, Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z));
    }
    total += weight * ring;
  }
  return total;
}

}  // namespace prt
