// Glossy exit radiance against exact integrals: how much of the error is the view side's
// representation (prt/view_fit.h), per fit, SH order, material and view angle.
//
// Every number comes from the engine's own bake (prt::bake of an unoccluded UV sphere, 4096
// samples, no bounces: M_p = B T_p D(F_p^T)) and the engine's SH lighting (prt::project),
// evaluated as the renderers do (view clamped to the horizon). The references share nothing
// with that path:
//  - white sky: the BRDF's directional albedo by dense quadrature (prt::directional_albedo);
//  - a probe: the exact per-pixel integral sum_pixels f_r(v, s) L(s) max(0, n.s) dOmega over
//    every texel of the same probe, for a subset of the sphere's vertices and views at
//    0-75 degrees from the normal with azimuths spread by the golden angle.
// Errors: relative RMSE sqrt(sum (x - r)^2 / sum r^2) and bias sum (x - r) / sum r over R, G, B.
//
// Usage: glossy_fidelity_bench [--quick] [--fit FIT] [--lambda L] [PROBE.exr ...]
//   default probes: Blender's forest and city studio lights; --quick: orders 2, 6, 10 only.
#include "meshes/procedural.h"
#include "probes/load.h"
#include "prt/bake.h"
#include "prt/material.h"
#include "prt/projection.h"
#include "prt/sh.h"
#include "prt/view_fit.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kPi = std::numbers::pi;
constexpr int kSamples = 4096;

struct NamedMaterial {
  std::string name;
  prt::Material material;
};

std::vector<NamedMaterial> materials() {
  std::vector<NamedMaterial> out;
  prt::Material m;
  m.kind = prt::MaterialKind::kLambert;
  m.albedo.setConstant(0.5f);
  m.specular = 0.f;
  out.push_back({"lambert 0.5", m});
  m = {};
  m.kind = prt::MaterialKind::kCookTorrance;
  m.albedo.setZero();
  m.specular = 1.f;
  m.f0 = 1.f;
  for (float roughness : {0.5f, 0.3f}) {
    m.roughness = roughness;
    char name[64];
    std::snprintf(name, sizeof name, "cook-torrance m %.1f", roughness);
    out.push_back({name, m});
  }
  m = {};  // the default: Phong, exponent 32, rho_d 0.5, rho_s 0.3
  out.push_back({"phong e 32 (default)", m});
  return out;
}

const prt::ViewFit kFits[] = {prt::ViewFit::kHemisphere, prt::ViewFit::kEven,
                              prt::ViewFit::kHemisphericalHarmonics, prt::ViewFit::kLeastSquares};

// The sphere's transfer for one material, order and fit (HSH through the BRDF override,
// since the bake only takes fits the renderers evaluate).
prt::TransferSet bake_sphere(const meshes::Mesh& sphere, const prt::Material& material, int order,
                             prt::ViewFit fit, double lambda) {
  prt::BakeOptions o;
  o.kind = prt::TransferKind::kGlossy;
  o.order = order;
  o.samples = kSamples;
  o.bounces = 0;
  o.material = material;
  o.brdf_override = prt::brdf_matrix(material, order, 0, {}, fit, lambda);
  return prt::bake(sphere, o);
}

// Radiance (grey transfer) toward world direction w at vertex p.
Eigen::Vector3d radiance(const prt::TransferSet& t, const meshes::Mesh& mesh, std::size_t p,
                         prt::ViewFit fit, const prt::ShLighting& lighting,
                         const Eigen::Vector3d& w) {
  const Eigen::Vector3d local = prt::clamp_to_horizon(Eigen::Vector3d(
      mesh.tangents[p].cast<double>().dot(w), mesh.bitangents[p].cast<double>().dot(w),
      mesh.normals[p].cast<double>().dot(w)));
  const int n = t.coefficient_count();
  std::vector<double> y(n);
  prt::view_basis_eval(fit, t.order, local, y.data());
  const Eigen::MatrixXd m = t.transfer(p, 0).cast<double>();
  const Eigen::RowVectorXd row = Eigen::Map<const Eigen::RowVectorXd>(y.data(), n) * m;
  return (row * lighting).transpose();
}

struct View {
  std::size_t vertex;
  int angle;  // degrees from the normal
  Eigen::Vector3d w;
};

std::vector<View> probe_views(const meshes::Mesh& sphere, const std::vector<int>& angles) {
  std::vector<View> views;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  int k = 0;
  // Every 5th vertex: 60-odd vertices over the whole sphere, so every part of the probe is
  // above some of them.
  for (std::size_t p = 0; p < sphere.vertex_count(); p += 5) {
    const Eigen::Vector3d n = sphere.normals[p].cast<double>();
    const Eigen::Vector3d t = sphere.tangents[p].cast<double>();
    const Eigen::Vector3d b = sphere.bitangents[p].cast<double>();
    for (int a : angles) {
      const double theta = a * kPi / 180.0, phi = golden * k++;
      const Eigen::Vector3d w =
          std::cos(theta) * n + std::sin(theta) * (std::cos(phi) * t + std::sin(phi) * b);
      views.push_back({p, a, w.normalized()});
    }
  }
  return views;
}

// sum_pixels f_r(F^T w, F^T s) L(s) max(0, n.s) dOmega for every view.
std::vector<Eigen::Vector3d> exact_probe(const probes::Probe& probe, const meshes::Mesh& sphere,
                                         const prt::Material& material,
                                         const std::vector<View>& views) {
  const int width = probe.width(), height = probe.height();
  std::vector<Eigen::Vector3d> dirs(std::size_t(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) dirs[std::size_t(y) * width + x] = probe.pixel_direction(x, y);
  std::vector<Eigen::Vector3d> out(views.size());
  tbb::parallel_for(std::size_t(0), views.size(), [&](std::size_t i) {
    const View& v = views[i];
    const Eigen::Vector3d n = sphere.normals[v.vertex].cast<double>();
    const Eigen::Vector3d t = sphere.tangents[v.vertex].cast<double>();
    const Eigen::Vector3d b = sphere.bitangents[v.vertex].cast<double>();
    const Eigen::Vector3d local_v(t.dot(v.w), b.dot(v.w), n.dot(v.w));
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int y = 0; y < height; ++y) {
      const double d_omega = probe.pixel_solid_angle(y);
      Eigen::Vector3d row = Eigen::Vector3d::Zero();
      for (int x = 0; x < width; ++x) {
        const Eigen::Vector3d& s = dirs[std::size_t(y) * width + x];
        const double cosine = n.dot(s);
        if (cosine <= 0.0) continue;
        const double f =
            prt::brdf_eval(material, 0, local_v, Eigen::Vector3d(t.dot(s), b.dot(s), cosine));
        row += f * cosine * probe.texel(x, y).cast<double>();
      }
      sum += d_omega * row;
    }
    out[i] = sum;
  });
  return out;
}

// The light side alone: the view side evaluated exactly. g_j(v) = int f_r(v, s) s.z y_j(s) ds
// by a dense midpoint grid (128 x 1024 over the light hemisphere, SH values computed once),
// applied to T_p D(F_p^T) l, read from a bake with the identity as its BRDF matrix. What
// remains is the light side's truncation, which no view fit can remove.
class ExactViewSide {
 public:
  ExactViewSide(int order) : order_(order) {
    constexpr int kTheta = 128, kPhi = 1024;
    dirs_.resize(3, kTheta * kPhi);
    weights_.resize(kTheta * kPhi);
    for (int t = 0; t < kTheta; ++t) {
      const double theta = 0.5 * kPi * (t + 0.5) / kTheta;
      for (int p = 0; p < kPhi; ++p) {
        const double phi = 2 * kPi * (p + 0.5) / kPhi;
        const int k = t * kPhi + p;
        dirs_.col(k) << std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
            std::cos(theta);
        weights_[k] = std::sin(theta) * std::cos(theta) * (0.5 * kPi / kTheta) * (2 * kPi / kPhi);
      }
    }
    prt::ShBatchD y;
    prt::sh_eval_batch(order, dirs_, y);
    y_ = y;
  }
  Eigen::VectorXd g(const prt::Material& material, const Eigen::Vector3d& v) const {
    Eigen::VectorXd f(dirs_.cols());
    for (Eigen::Index k = 0; k < dirs_.cols(); ++k)
      f[k] = prt::brdf_eval(material, 0, v, dirs_.col(k)) * weights_[k];
    return y_ * f;
  }
  int order() const { return order_; }

 private:
  int order_;
  Eigen::Matrix3Xd dirs_;
  Eigen::VectorXd weights_;
  Eigen::MatrixXd y_;
};

std::vector<Eigen::Vector3d> light_side_only(const ExactViewSide& exact,
                                             const prt::TransferSet& light_transfer,
                                             const meshes::Mesh& sphere,
                                             const prt::Material& material,
                                             const prt::ShLighting& lighting,
                                             const std::vector<View>& views) {
  std::vector<Eigen::Vector3d> out(views.size());
  tbb::parallel_for(std::size_t(0), views.size(), [&](std::size_t i) {
    const std::size_t p = views[i].vertex;
    const Eigen::Vector3d& w = views[i].w;
    const Eigen::Vector3d local(sphere.tangents[p].cast<double>().dot(w),
                                sphere.bitangents[p].cast<double>().dot(w),
                                sphere.normals[p].cast<double>().dot(w));
    const Eigen::MatrixXd k = light_transfer.transfer(p, 0).cast<double>();
    out[i] = (exact.g(material, local).transpose() * k * lighting).transpose();
  });
  return out;
}

struct Error {
  double rmse = 0, bias = 0;
};

Error error_of(const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& ref,
               const std::vector<View>& views, int angle = -1) {
  double se = 0, sr = 0, d = 0, r = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (angle >= 0 && views[i].angle != angle) continue;
    se += (x[i] - ref[i]).squaredNorm();
    sr += ref[i].squaredNorm();
    d += (x[i] - ref[i]).sum();
    r += ref[i].sum();
  }
  return {std::sqrt(se / sr), d / r};
}

// The probe columns of one table row: relative RMSE and bias per probe, then the first
// probe's RMSE by view angle. `evaluate` gives the radiance of every view under lighting l.
template <class Evaluate>
void print_probe_errors(const std::vector<probes::Probe>& probes_in, int order,
                        const std::vector<std::vector<Eigen::Vector3d>>& exact,
                        const std::vector<View>& views, const std::vector<int>& angles,
                        const Evaluate& evaluate) {
  std::vector<Error> by_angle;
  for (std::size_t q = 0; q < probes_in.size(); ++q) {
    const std::vector<Eigen::Vector3d> x = evaluate(prt::project(probes_in[q], order));
    const Error e = error_of(x, exact[q], views);
    std::printf(" %.2f%% | %+.2f%% |", 100 * e.rmse, 100 * e.bias);
    if (q == 0)
      for (int a : angles) by_angle.push_back(error_of(x, exact[q], views, a));
  }
  std::printf(" ");
  for (std::size_t a = 0; a < by_angle.size(); ++a)
    std::printf("%s%.1f", a ? "/" : "", 100 * by_angle[a].rmse);
  std::printf(" |\n");
  std::fflush(stdout);
}

// The row that keeps SH only on the light side (the view side exact): what the method's view
// projection costs, apart from its light-side truncation.
void print_exact_view_side(const meshes::Mesh& sphere, const prt::Material& material, int order,
                           const std::vector<probes::Probe>& probes_in,
                           const std::vector<std::vector<Eigen::Vector3d>>& exact,
                           const std::vector<View>& views, const std::vector<int>& angles) {
  prt::BakeOptions o;
  o.order = order;
  o.samples = kSamples;
  o.bounces = 0;
  o.material = material;
  o.brdf_override = Eigen::MatrixXd::Identity(order * order, order * order);
  const prt::TransferSet light = prt::bake(sphere, o);
  const ExactViewSide exact_view(order);
  std::printf("| exact view side | %d | | | |", order);
  print_probe_errors(probes_in, order, exact, views, angles, [&](const prt::ShLighting& l) {
    return light_side_only(exact_view, light, sphere, material, l, views);
  });
}

void print_table_header(const std::string& material, const std::vector<probes::Probe>& probes_in) {
  std::printf("## %s\n\n", material.c_str());
  std::printf("| fit | order | white sky: at 0 deg | p99 abs 0-70 deg | max abs |");
  for (std::size_t q = 0; q < probes_in.size(); ++q)
    std::printf(" %s rel. RMSE | bias |", probes_in[q].name().c_str());
  std::printf(" rel. RMSE by angle %s (0/15/30/45/60/75) |\n", probes_in[0].name().c_str());
  std::printf("| --- | ---: | ---: | ---: | ---: |");
  for (std::size_t q = 0; q < probes_in.size(); ++q) std::printf(" ---: | ---: |");
  std::printf(" --- |\n");
}

// A row's white-sky columns: the error of the radiance toward each angle from the sphere's
// pole vertex (any vertex would do: the sky is uniform) against the directional albedo.
void print_white_sky(const prt::TransferSet& t, const meshes::Mesh& sphere, prt::ViewFit fit,
                     const std::vector<int>& sky_angles, const std::vector<double>& albedo) {
  // White sky: l = sqrt(4 pi) e_0 in every channel.
  prt::ShLighting white = prt::ShLighting::Zero(t.order * t.order, 3);
  white.row(0).setConstant(std::sqrt(4.0 * kPi));
  std::vector<double> sky_err;
  const std::size_t pole = 0;
  const Eigen::Vector3d n = sphere.normals[pole].cast<double>();
  const Eigen::Vector3d tan = sphere.tangents[pole].cast<double>();
  for (std::size_t i = 0; i < sky_angles.size(); ++i) {
    const double th = sky_angles[i] * kPi / 180.0;
    const Eigen::Vector3d w = std::cos(th) * n + std::sin(th) * tan;
    const double x = radiance(t, sphere, pole, fit, white, w.normalized())[0];
    sky_err.push_back((x - albedo[i]) / albedo[i]);
  }
  std::vector<double> abs_err;
  for (double e : sky_err) abs_err.push_back(std::abs(e));
  std::sort(abs_err.begin(), abs_err.end());
  const double p99 = abs_err[std::size_t(std::floor(0.99 * double(abs_err.size() - 1)))];
  std::printf("| %s | %d | %+.2f%% | %.2f%% | %.2f%% |", prt::kViewFitNames.name(fit), t.order,
              100 * sky_err[0], 100 * p99, 100 * abs_err.back());
}

struct Args {
  bool quick = false;
  double lambda = prt::kViewFitLambda;
  std::vector<std::string> probe_paths;
  std::vector<prt::ViewFit> fits{std::begin(kFits), std::end(kFits)};
};

// nullopt on a usage error (printed).
std::optional<Args> parse_args(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--quick") {
      a.quick = true;
    } else if (arg == "--fit" && i + 1 < argc) {
      a.fits = {prt::kViewFitNames.parse(argv[++i])};
    } else if (arg == "--lambda" && i + 1 < argc) {
      a.lambda = std::atof(argv[++i]);
    } else if (!arg.empty() && arg[0] == '-') {
      std::fprintf(stderr,
                   "usage: glossy_fidelity_bench [--quick] [--fit FIT] [--lambda L] [PROBE ...]\n");
      return std::nullopt;
    } else {
      a.probe_paths.push_back(arg);
    }
  }
  if (a.probe_paths.empty()) {
    const std::string dir = "/usr/share/blender/datafiles/studiolights/world/";
    a.probe_paths = {dir + "forest.exr", dir + "city.exr"};
  }
  return a;
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Args> args = parse_args(argc, argv);
  if (!args) return 2;
  const bool quick = args->quick;
  const double lambda = args->lambda;
  const std::vector<std::string>& probe_paths = args->probe_paths;
  const std::vector<prt::ViewFit>& fits = args->fits;
  const std::vector<int> orders =
      quick ? std::vector<int>{2, 6, 10} : std::vector<int>{2, 4, 6, 8, 10};
  const auto start = Clock::now();
  const meshes::Mesh sphere = meshes::make_sphere(1.f, 24, 14);
  std::printf("# glossy fidelity: unoccluded sphere (%zu vertices), %d samples, lambda %g\n\n",
              sphere.vertex_count(), kSamples, lambda);

  std::vector<probes::Probe> probes_in;
  for (const std::string& path : probe_paths) probes_in.push_back(probes::load_probe(path));
  const std::vector<int> angles = {0, 15, 30, 45, 60, 75};
  const std::vector<View> views = probe_views(sphere, angles);

  // White sky: the sphere's pole vertex (index 0 is as good as any: the sky is uniform).
  std::vector<int> sky_angles;
  for (int a = 0; a <= 70; a += 2) sky_angles.push_back(a);

  for (const NamedMaterial& nm : materials()) {
    std::vector<double> albedo;
    for (int a : sky_angles) {
      const double th = a * kPi / 180.0;
      albedo.push_back(prt::directional_albedo(nm.material, 0,
                                               Eigen::Vector3d(std::sin(th), 0.0, std::cos(th))));
    }
    std::vector<std::vector<Eigen::Vector3d>> exact;
    for (const probes::Probe& probe : probes_in)
      exact.push_back(exact_probe(probe, sphere, nm.material, views));

    print_table_header(nm.name, probes_in);
    for (int order : orders)
      if (order == 6 || order == 10)
        print_exact_view_side(sphere, nm.material, order, probes_in, exact, views, angles);
    for (prt::ViewFit fit : fits) {
      for (int order : orders) {
        const prt::TransferSet t = bake_sphere(sphere, nm.material, order, fit, lambda);
        print_white_sky(t, sphere, fit, sky_angles, albedo);
        print_probe_errors(probes_in, order, exact, views, angles, [&](const prt::ShLighting& l) {
          std::vector<Eigen::Vector3d> x(views.size());
          for (std::size_t i = 0; i < views.size(); ++i)
            x[i] = radiance(t, sphere, views[i].vertex, fit, l, views[i].w);
          return x;
        });
      }
    }
    std::printf("\n");
  }
  std::printf("total %.1f s\n", std::chrono::duration<double>(Clock::now() - start).count());
  return 0;
}
