// The baker against closed forms and independent brute-force integrals. Brute force here
// never uses the baker's code paths: its own rays (Moller-Trumbore over the triangles, or an
// analytic box), its own Monte Carlo sampling, and no projection of visibility to SH.
#include "prt/bake.h"

#include "ray_oracle.h"

#include "meshes/procedural.h"
#include "prt/sampling.h"
#include "prt/sh.h"
#include "prt/sh_rotation.h"
#include "prt/zonal.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

namespace {

using Vec3d = Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

prt::Material lambert(float albedo) {
  prt::Material m;
  m.kind = prt::MaterialKind::kLambert;
  m.albedo = Eigen::Vector3f::Constant(albedo);
  m.specular = 0.f;
  return m;
}

// Positive, band-limited lighting (order 3): a dominant DC term plus random higher bands,
// so radiance stays positive everywhere (checked by the caller through its use).
Eigen::VectorXd band_limited_lighting(std::uint64_t seed) {
  prt::Pcg32 rng(seed);
  Eigen::VectorXd l(9);
  for (int i = 0; i < 9; ++i) l[i] = 0.35 * (2 * rng.next_double() - 1);
  l[0] = 3.0;  // 3 / sqrt(4 pi) ~ 0.85 mean radiance; the rest swings at most ~0.8
  return l;
}
double radiance(const Eigen::VectorXd& l, const Vec3d& d) {
  return prt::sh_expand(l, d);
}

// Lighting vector padded to the bake's order.
Eigen::VectorXf padded(const Eigen::VectorXd& l, int order) {
  Eigen::VectorXf out = Eigen::VectorXf::Zero(prt::sh_count(order));
  out.head(l.size()) = l.cast<float>();
  return out;
}

Eigen::Matrix3d frame(const meshes::Mesh& m, std::size_t p) {
  Eigen::Matrix3d f;
  f.col(0) = m.tangents[p].cast<double>();
  f.col(1) = m.bitangents[p].cast<double>();
  f.col(2) = m.normals[p].cast<double>();
  return f;
}

// Tangent-frame basis around n for the brute-force samplers (independent of mesh frames).
Eigen::Matrix3d basis_around(const Vec3d& n) {
  const Vec3d a = std::abs(n.x()) < 0.9 ? Vec3d::UnitX() : Vec3d::UnitY();
  const Vec3d t = (a - a.dot(n) * n).normalized();
  Eigen::Matrix3d b;
  b.col(0) = t;
  b.col(1) = n.cross(t);
  b.col(2) = n;
  return b;
}

// Moller-Trumbore against triangles [first_tri, last_tri), which lie inside the sphere
// (centre, radius): rays that miss that sphere are rejected without testing triangles.
bool ray_hits(const meshes::Mesh& m, std::size_t first_tri, std::size_t last_tri, const Vec3d& o,
              const Vec3d& d, const Vec3d& centre = Vec3d(0, 1.5, 0), double radius = 0.51) {
  const Vec3d oc = o - centre;
  const double b = oc.dot(d), c = oc.squaredNorm() - radius * radius;
  if (c > 0 && (b > 0 || b * b < c)) return false;
  for (std::size_t t = first_tri; t < last_tri; ++t)
    if (test_support::ray_hits_triangle(m, t, o, d, 1e-9)) return true;
  return false;
}

// Exact hemisphere product matrix H = int_{z>0} y y^T: Gauss-Legendre on z in (0, 1) with 32
// nodes and 64 phi nodes integrates the degree <= 18 polynomial integrand exactly.
Eigen::MatrixXd hemisphere_product(int order) {
  const int nz = 32, nphi = 64, n = prt::sh_count(order);
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(n, n);
  std::vector<double> y(n);
  std::vector<double> gx, gw;
  test_support::gauss_legendre(nz, gx, gw);
  for (int i = 0; i < nz; ++i) {
    // Node mapped from [-1, 1] to (0, 1).
    const double w = 0.5 * gw[i], z = 0.5 * (gx[i] + 1), r = std::sqrt(1 - z * z);
    for (int k = 0; k < nphi; ++k) {
      const double phi = 2 * kPi * (k + 0.5) / nphi;
      prt::sh_eval(order, Vec3d(r * std::cos(phi), r * std::sin(phi), z), y.data());
      const Eigen::Map<Eigen::VectorXd> v(y.data(), n);
      h += w * (2 * kPi / nphi) * v * v.transpose();
    }
  }
  return h;
}

TEST(Bake, DiffuseUnoccludedSphereIsTheClampedCosine) {
  const meshes::Mesh sphere = meshes::make_sphere(1.f, 32, 16);
  prt::BakeOptions o;
  o.kind = prt::TransferKind::kDiffuse;
  o.material = lambert(0.8f);
  o.bounces = 0;
  o.samples = 1024;
  prt::BakeStats stats;
  const prt::TransferSet t = prt::bake(sphere, o, &stats);
  EXPECT_EQ(stats.occluded_fraction, 0.0);  // convex: no ray may hit the sphere itself
  const Eigen::VectorXd h = prt::zonal_clamped_cosine(6);
  double worst = 0;
  for (std::size_t p = 0; p < sphere.vertex_count(); ++p) {
    double y[36];
    prt::sh_eval(6, Vec3d(sphere.normals[p].cast<double>()), y);
    for (int l = 0; l < 6; ++l)
      for (int m = -l; m <= l; ++m) {
        const int i = prt::sh_index(l, m);
        const double expected = 0.8 / kPi * std::sqrt(4 * kPi / (2 * l + 1)) * h[l] * y[i];
        worst = std::max(worst, std::abs(t.transfer(p, 0)(i, 0) - expected));
      }
  }
  // Entries are O(0.5); the Fibonacci lattice integrates this continuous integrand with an
  // error of ~1e-3 at 1024 samples (measured 4e-4).
  EXPECT_LT(worst, 2e-3);
}

TEST(Bake, GlossyUnoccludedSphereIsTheHemisphereProduct) {
  const meshes::Mesh sphere = meshes::make_sphere(1.f, 16, 8);
  const Eigen::MatrixXd h = hemisphere_product(6);
  double worst[2];
  for (int k = 0; k < 2; ++k) {
    prt::BakeOptions o;
    o.material = lambert(0.5f);
    o.bounces = 0;
    o.samples = 1024 << (2 * k);                          // 1024, then 16384
    o.brdf_override = Eigen::MatrixXd::Identity(36, 36);  // M = T D(F^T), so T = M D(F)
    const prt::TransferSet t = prt::bake(sphere, o);
    worst[k] = 0;
    for (std::size_t p = 0; p < sphere.vertex_count(); p += 7) {
      const Eigen::MatrixXd m = t.transfer(p, 0).cast<double>();
      const Eigen::MatrixXd local = m * prt::ShRotation(6, frame(sphere, p)).dense();
      worst[k] = std::max(worst[k], (local - h).cwiseAbs().maxCoeff());
    }
  }
  // H has entries up to 0.5; the lattice error falls with the sample count.
  EXPECT_LT(worst[0], 1e-2);
  EXPECT_LT(worst[1], worst[0] / 3);
}

// Plane + sphere: plane vertices near, under and beside the shadow.
struct Occluder {
  meshes::Mesh mesh;
  std::size_t plane_triangles = 0;  // triangles [0, plane) are the plane
  std::vector<std::size_t> probes;  // chosen plane vertices
};

Occluder occluder_scene() {
  Occluder s;
  s.mesh = meshes::make_plane_and_sphere(6.f, 24, 0.5f, 1.5f, 48, 24);
  // The plane comes first in the merged mesh; its vertices are the ones at y = 0 (the sphere
  // spans y in [1, 2]).
  auto on_plane = [&](std::uint32_t v) { return s.mesh.positions[v].y() == 0.f; };
  while (s.plane_triangles < s.mesh.triangle_count()) {
    const meshes::Triangle& t = s.mesh.triangles[s.plane_triangles];
    if (!(on_plane(t[0]) && on_plane(t[1]) && on_plane(t[2]))) break;
    ++s.plane_triangles;
  }
  EXPECT_EQ(s.plane_triangles, std::size_t(24 * 24 * 2));  // the whole 24 x 24 plane grid
  for (const Vec3d& target : {Vec3d(0, 0, 0), Vec3d(0.5, 0, 0), Vec3d(1.0, 0, 0.5)}) {
    std::size_t best = 0;
    double dist = 1e30;
    for (std::uint32_t v = 0; v < s.mesh.vertex_count(); ++v) {
      const double d = (s.mesh.positions[v].cast<double>() - target).norm();
      if (on_plane(v) && d < dist) dist = d, best = v;
    }
    s.probes.push_back(best);
  }
  return s;
}

TEST(Bake, DiffuseShadowMatchesBruteForce) {
  const Occluder scene = occluder_scene();
  const Eigen::VectorXd light = band_limited_lighting(3);
  prt::BakeOptions o;
  o.kind = prt::TransferKind::kDiffuse;
  o.material = lambert(0.7f);
  o.bounces = 0;  // the plane cannot see itself and the sphere's bounce is tested elsewhere
  o.samples = 4096;
  const prt::TransferSet t = prt::bake(scene.mesh, o);
  const Eigen::VectorXf l = padded(light, 6);

  for (std::size_t p : scene.probes) {
    const Vec3d origin = scene.mesh.positions[p].cast<double>() + Vec3d(0, 1e-6, 0);
    const Eigen::Matrix3d b = basis_around(Vec3d::UnitY());
    // E[rho L V] under cosine-weighted sampling = rho/pi int L V cos.
    prt::Pcg32 rng(100 + p);
    const int n = 100000;
    double sum = 0;
    for (int k = 0; k < n; ++k) {
      const Vec3d d = b * prt::sample_cosine_hemisphere(rng.next_double(), rng.next_double());
      if (!ray_hits(scene.mesh, scene.plane_triangles, scene.mesh.triangle_count(), origin, d))
        sum += radiance(light, d);
    }
    const double brute = 0.7 * sum / n;
    const double prt_value = t.transfer(p, 0).col(0).dot(l);
    // 1%: Monte Carlo sigma/sqrt(n) ~ 0.1%, PRT's lattice error at 4096 samples ~0.3%.
    EXPECT_NEAR(prt_value, brute, 0.01 * brute) << "vertex " << p;
  }
}

TEST(Bake, GlossyShadowMatchesBruteForceWithBrdfMatrix) {
  const Occluder scene = occluder_scene();
  const Eigen::VectorXd light = band_limited_lighting(5);
  prt::BakeOptions o;
  o.material.kind = prt::MaterialKind::kPhong;
  o.material.albedo = Eigen::Vector3f::Constant(0.5f);
  o.material.specular = 0.3f;
  o.material.exponent = 8.f;
  o.bounces = 0;
  o.samples = 4096;
  const prt::TransferSet t = prt::bake(scene.mesh, o);
  const Eigen::MatrixXd brdf = prt::brdf_matrix(o.material, 6, 0);
  const Eigen::VectorXf l = padded(light, 6);

  for (std::size_t p : scene.probes) {
    const Eigen::Matrix3d f = frame(scene.mesh, p);
    const Vec3d origin = scene.mesh.positions[p].cast<double>() + Vec3d(0, 1e-6, 0);
    // Local SH coefficients of the visible band-limited lighting, by uniform hemisphere MC.
    prt::Pcg32 rng(200 + p);
    const int n = 100000;
    Eigen::VectorXd c = Eigen::VectorXd::Zero(36);
    double y[36];
    for (int k = 0; k < n; ++k) {
      Vec3d local = prt::sample_uniform_sphere(rng.next_double(), rng.next_double());
      local.z() = std::abs(local.z());
      const Vec3d d = f * local;
      if (ray_hits(scene.mesh, scene.plane_triangles, scene.mesh.triangle_count(), origin, d))
        continue;
      prt::sh_eval(6, local, y);
      c += (2 * kPi / n) * radiance(light, d) * Eigen::Map<Eigen::VectorXd>(y, 36);
    }
    const Eigen::VectorXd exit_brute = brdf * c;
    const Eigen::VectorXd exit_prt = (t.transfer(p, 0) * l).cast<double>();
    for (const Vec3d& view : {Vec3d(0, 1, 0), Vec3d(0.5, 0.8, 0.3).normalized()}) {
      prt::sh_eval(6, Vec3d(f.transpose() * view), y);
      const Eigen::Map<Eigen::VectorXd> yv(y, 36);
      const double brute = yv.dot(exit_brute), value = yv.dot(exit_prt);
      EXPECT_NEAR(value, brute, 0.01 * std::abs(brute)) << "vertex " << p;
    }
  }
}

// ---- Interreflection in the open box ---------------------------------------------------

// Analytic ray cast inside the open box [-h, h]^3 (top open): the face hit first, or -1 when
// the ray escapes through the opening. Faces: 0 floor, 1 -x, 2 +x, 3 -z, 4 +z.
int box_cast(double h, const Vec3d& o, const Vec3d& d, Vec3d* hit, Vec3d* normal) {
  double best = 1e30;
  int face = -1;
  auto consider = [&](int f, int axis, double plane, const Vec3d& n) {
    if (std::abs(d[axis]) < 1e-15) return;
    const double t = (plane - o[axis]) / d[axis];
    if (t <= 1e-12 || t >= best) return;
    best = t;
    face = f;
    *normal = n;
  };
  consider(0, 1, -h, Vec3d(0, 1, 0));
  consider(1, 0, -h, Vec3d(1, 0, 0));
  consider(2, 0, h, Vec3d(-1, 0, 0));
  consider(3, 2, -h, Vec3d(0, 0, 1));
  consider(4, 2, h, Vec3d(0, 0, -1));
  const double t_top = d.y() > 0 ? (h - o.y()) / d.y() : 1e30;
  if (t_top < best) return -1;  // leaves through the opening first
  *hit = o + best * d;
  return face;
}

TEST(Bake, InterreflectionInOpenBoxIsBoundedAndConverges) {
  const meshes::Mesh box = meshes::make_open_box(2.f, 8);
  const float rho = 0.5f;
  Eigen::VectorXf white = Eigen::VectorXf::Zero(36);
  white[0] = float(std::sqrt(4 * kPi));  // constant radiance 1
  std::vector<std::vector<double>> radiance_by_bounce;
  for (int b = 0; b <= 3; ++b) {
    prt::BakeOptions o;
    o.kind = prt::TransferKind::kDiffuse;
    o.material = lambert(rho);
    o.bounces = b;
    o.samples = 1024;
    const prt::TransferSet t = prt::bake(box, o);
    std::vector<double> r(box.vertex_count());
    for (std::size_t p = 0; p < r.size(); ++p) r[p] = t.transfer(p, 0).col(0).dot(white);
    radiance_by_bounce.push_back(r);
  }
  // Every vertex, rim and corner ones included, sees some sky through the opening, and none
  // sees more than a full hemisphere of it (split vertices along the edges must neither go
  // dark nor leak light through the crease).
  for (std::size_t p = 0; p < box.vertex_count(); ++p) {
    EXPECT_GT(radiance_by_bounce[0][p], 0.02 * rho) << "vertex " << p << " is dark";
    EXPECT_LE(radiance_by_bounce[0][p], rho + 1e-3) << "vertex " << p;
  }
  double increment[4] = {0, 0, 0, 0};
  for (int b = 1; b <= 3; ++b) {
    for (std::size_t p = 0; p < box.vertex_count(); ++p) {
      const double delta = radiance_by_bounce[b][p] - radiance_by_bounce[b - 1][p];
      // Each bounce adds light (float rounding of O(1) sums ~1e-6).
      EXPECT_GE(delta, -1e-5) << "bounce " << b << " vertex " << p;
      increment[b] += delta;
    }
  }
  // Increments shrink by about rho per bounce: at most rho (a wall sees other walls over
  // less than its whole hemisphere) and not vanishing.
  for (int b = 2; b <= 3; ++b) {
    const double ratio = increment[b] / increment[b - 1];
    EXPECT_LE(ratio, rho * 1.02) << "bounce " << b;
    EXPECT_GE(ratio, rho * 0.25) << "bounce " << b;
  }
  // Energy bound: never above rho L / (1 - rho).
  for (double r : radiance_by_bounce[3]) EXPECT_LE(r, rho / (1 - rho) + 1e-5);
}

TEST(Bake, OneBounceInOpenBoxMatchesBruteForce) {
  const float size = 2.f, rho = 0.6f;
  const double h = size / 2;
  const meshes::Mesh box = meshes::make_open_box(size, 8);
  const Eigen::VectorXd light = band_limited_lighting(9);
  prt::BakeOptions o;
  o.kind = prt::TransferKind::kDiffuse;
  o.material = lambert(rho);
  o.bounces = 1;
  o.samples = 4096;
  const prt::TransferSet t = prt::bake(box, o);
  const Eigen::VectorXf l = padded(light, 6);

  // Floor centre and a wall centre (interior vertices, away from the unwelded edges).
  for (const Vec3d& target : {Vec3d(0, -h, 0), Vec3d(-h, 0, 0)}) {
    std::size_t p = 0;
    double dist = 1e30;
    for (std::size_t v = 0; v < box.vertex_count(); ++v) {
      const double d = (box.positions[v].cast<double>() - target).norm();
      if (d < dist) dist = d, p = v;
    }
    const Vec3d n = box.normals[p].cast<double>();
    const Vec3d origin = box.positions[p].cast<double>();
    prt::Pcg32 rng(300 + p);
    // Direct + one bounce, both rho/pi-weighted cosine integrals, by cosine-weighted sampling.
    auto irradiance_ratio = [&](const Vec3d& at, const Vec3d& normal, int samples) {
      const Eigen::Matrix3d b = basis_around(normal);
      double sum = 0;
      Vec3d hit, hit_n;
      for (int k = 0; k < samples; ++k) {
        const Vec3d d = b * prt::sample_cosine_hemisphere(rng.next_double(), rng.next_double());
        if (box_cast(h, at, d, &hit, &hit_n) < 0) sum += radiance(light, d);
      }
      return rho * sum / samples;  // radiance leaving a Lambert point lit directly
    };
    const int outer = 40000, inner = 400;
    const Eigen::Matrix3d b = basis_around(n);
    double direct = 0, bounce = 0;
    Vec3d hit, hit_n;
    for (int k = 0; k < outer; ++k) {
      const Vec3d d = b * prt::sample_cosine_hemisphere(rng.next_double(), rng.next_double());
      if (box_cast(h, origin, d, &hit, &hit_n) < 0) {
        direct += radiance(light, d);
      } else {
        bounce += irradiance_ratio(hit, hit_n, inner);
      }
    }
    const double brute = rho * (direct + bounce) / outer;
    const double value = t.transfer(p, 0).col(0).dot(l);
    // 2%: Monte Carlo error ~0.3%; PRT interpolates bounce light linearly over the 8 x 8
    // wall grid, which smooths the corners' darkening.
    EXPECT_NEAR(value, brute, 0.02 * brute) << "vertex " << p;
  }
}

// Glossy one-bounce exit radiance of the open box's floor centre toward off-normal views,
// against nested Monte Carlo over the same model: the outer estimate projects the light that
// hit points send back onto the receiver's local SH basis, and each hit point's exit
// radiance is its own Monte Carlo projection of the sky it sees, passed through the BRDF
// matrix B (order-n BRDFs are what PRT represents, so B is part of the model, as in the
// shadow test above). No baker code path: analytic box rays, uniform hemisphere samples,
// frames from basis_around (B commutes with turns about the normal, so any tangent works).
void expect_glossy_bounce_matches_nested_mc(const prt::Material& material) {
  const int order = 4, n = prt::sh_count(order);
  const double h = 1.0;
  const meshes::Mesh box = meshes::make_open_box(2.f * float(h), 8);
  const Eigen::VectorXd light = band_limited_lighting(13);
  const Eigen::MatrixXd brdf = prt::brdf_matrix(material, order, 0);
  prt::BakeOptions o;
  o.kind = prt::TransferKind::kGlossy;
  o.order = order;
  o.material = material;
  o.samples = 2048;
  o.bounces = 1;
  const prt::TransferSet with_bounce = prt::bake(box, o);
  o.bounces = 0;
  const prt::TransferSet direct = prt::bake(box, o);
  const Eigen::VectorXf l = padded(light, order);

  std::size_t p = 0;
  double dist = 1e30;
  for (std::size_t v = 0; v < box.vertex_count(); ++v) {
    const double d = (box.positions[v].cast<double>() - Vec3d(0, -h, 0)).norm();
    if (d < dist) dist = d, p = v;
  }
  const Eigen::MatrixXf bounce = with_bounce.transfer(p, 0) - direct.transfer(p, 0);

  std::vector<double> y(n);
  auto sh = [&](const Vec3d& local) {
    prt::sh_eval(order, local, y.data());
    return Eigen::Map<const Eigen::VectorXd>(y.data(), n).eval();
  };
  prt::Pcg32 rng(400 + p);
  // Radiance a hit point q (normal nq) sends toward world direction w, lit directly.
  auto exit_direct = [&](const Vec3d& q, const Vec3d& nq, const Vec3d& w, int samples) {
    const Eigen::Matrix3d b = basis_around(nq);
    Eigen::VectorXd c = Eigen::VectorXd::Zero(n);
    Vec3d hit, hit_n;
    for (int k = 0; k < samples; ++k) {
      Vec3d local = prt::sample_uniform_sphere(rng.next_double(), rng.next_double());
      local.z() = std::abs(local.z());
      const Vec3d d = b * local;
      if (box_cast(h, q, d, &hit, &hit_n) < 0)
        c += (2 * kPi / samples) * radiance(light, d) * sh(local);
    }
    return sh(b.transpose() * w).dot(brdf * c);
  };

  const Vec3d np = box.normals[p].cast<double>();
  const Eigen::Matrix3d bp = basis_around(np);
  const Eigen::Matrix3d fp = frame(box, p);
  for (const Vec3d& view :
       {Vec3d(0.6, 0.7, -0.4).normalized(), Vec3d(-0.3, 0.5, 0.8).normalized()}) {
    const Eigen::RowVectorXd yb = sh(bp.transpose() * view).transpose() * brdf;
    const int outer = 6000, inner = 256;
    double sum = 0, sum2 = 0;
    Vec3d hit, hit_n;
    for (int k = 0; k < outer; ++k) {
      Vec3d local = prt::sample_uniform_sphere(rng.next_double(), rng.next_double());
      local.z() = std::abs(local.z());
      const Vec3d s = bp * local;
      double x = 0;
      if (box_cast(h, box.positions[p].cast<double>(), s, &hit, &hit_n) >= 0) {
        x = 2 * kPi * yb.dot(sh(local)) * exit_direct(hit, hit_n, -s, inner);
      }
      sum += x;
      sum2 += x * x;
    }
    const double brute = sum / outer;
    const double sigma = std::sqrt(std::max(0.0, sum2 / outer - brute * brute) / outer);
    prt::sh_eval(order, Vec3d(fp.transpose() * view), y.data());
    const double value =
        Eigen::Map<const Eigen::VectorXd>(y.data(), n).dot((bounce * l).cast<double>());
    // 4 sigma of the nested estimate (1.4-2.3% of the value), plus 1% for the bake's linear
    // interpolation of hit radiance across the 8 x 8 wall grid. Measured: 0.9-2.1 sigma.
    EXPECT_NEAR(value, brute, 4 * sigma + 0.01 * std::abs(brute))
        << prt::kMaterialNames.name(material.kind) << " view " << view.transpose() << " sigma "
        << sigma;
    EXPECT_GT(std::abs(brute), 10 * sigma);  // the bounce is a measurable signal here
  }
}

TEST(Bake, PhongBounceMatchesNestedMonteCarloOffNormal) {
  prt::Material m = lambert(0.4f);
  m.kind = prt::MaterialKind::kPhong;
  m.specular = 0.5f;
  m.exponent = 8.f;
  expect_glossy_bounce_matches_nested_mc(m);
}

TEST(Bake, CookTorranceBounceMatchesNestedMonteCarloOffNormal) {
  prt::Material m = lambert(0.4f);
  m.kind = prt::MaterialKind::kCookTorrance;
  m.specular = 0.5f;
  m.roughness = 0.4f;
  m.f0 = 0.5f;
  expect_glossy_bounce_matches_nested_mc(m);
}

TEST(Bake, GlossyLambertBounceAgreesWithDiffuseBounce) {
  // A second code path as the oracle. With a Lambert material the glossy exit radiance at
  // view = normal is (y(n)^T a) (rho/pi) (b^T T l): the receiver factor y(n)^T a is common
  // to the shadow and bounce passes, so the ratio bounce / direct must match the diffuse
  // path's, up to the order-6 truncation of the hemisphere indicator with which glossy
  // corners emit (a few percent; the bound is 10%). Catches frame, transpose and grouping
  // errors in the glossy bounce.
  const meshes::Mesh box = meshes::make_open_box(2.f, 6);
  Eigen::VectorXf white = Eigen::VectorXf::Zero(16);
  white[0] = float(std::sqrt(4 * kPi));
  auto ratios = [&](prt::TransferKind kind) {
    std::vector<double> r;
    double value[2][2000];
    for (int b = 0; b <= 1; ++b) {
      prt::BakeOptions o;
      o.kind = kind;
      o.order = 4;
      o.material = lambert(0.5f);
      o.bounces = b;
      o.samples = 1024;
      const prt::TransferSet t = prt::bake(box, o);
      for (std::size_t p = 0; p < box.vertex_count(); ++p) {
        if (kind == prt::TransferKind::kDiffuse) {
          value[b][p] = t.transfer(p, 0).col(0).dot(white);
        } else {
          double y[16];
          prt::sh_eval(4, Vec3d(0, 0, 1), y);  // view along the normal, in the local frame
          value[b][p] =
              Eigen::Map<Eigen::VectorXd>(y, 16).dot((t.transfer(p, 0) * white).cast<double>());
        }
      }
    }
    for (std::size_t p = 0; p < box.vertex_count(); ++p) r.push_back(value[1][p] / value[0][p] - 1);
    return r;
  };
  const std::vector<double> diffuse = ratios(prt::TransferKind::kDiffuse);
  const std::vector<double> glossy = ratios(prt::TransferKind::kGlossy);
  double mean_diffuse = 0, mean_glossy = 0;
  for (std::size_t p = 0; p < diffuse.size(); ++p) {
    mean_diffuse += diffuse[p] / diffuse.size();
    mean_glossy += glossy[p] / glossy.size();
    EXPECT_NEAR(glossy[p], diffuse[p], 0.1 * diffuse[p] + 1e-3) << "vertex " << p;
  }
  EXPECT_GT(mean_diffuse, 0.1);  // the bounce is a real share of the light in this box
  EXPECT_NEAR(mean_glossy, mean_diffuse, 0.05 * mean_diffuse);
}

TEST(Bake, SameSeedGivesIdenticalBytesForAnyThreadCount) {
  const meshes::Mesh box = meshes::make_open_box(2.f, 6);
  prt::BakeOptions o;
  o.material = lambert(0.5f);
  o.material.kind = prt::MaterialKind::kPhong;
  o.material.specular = 0.2f;
  o.order = 4;
  o.samples = 256;
  o.bounces = 2;
  const prt::TransferSet a = prt::bake(box, o);
  const prt::TransferSet b = prt::bake(box, o);
  ASSERT_EQ(a.data.size(), b.data.size());
  EXPECT_EQ(0, std::memcmp(a.data.data(), b.data.data(), a.data.size() * sizeof(float)));
  {
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    const prt::TransferSet c = prt::bake(box, o);
    EXPECT_EQ(0, std::memcmp(a.data.data(), c.data.data(), a.data.size() * sizeof(float)));
  }
  o.seed = 2;
  const prt::TransferSet d = prt::bake(box, o);
  EXPECT_NE(0, std::memcmp(a.data.data(), d.data.data(), a.data.size() * sizeof(float)));
}

TEST(Bake, RecordsItsParameters) {
  const meshes::Mesh sphere = meshes::make_sphere(1.f, 8, 4);
  prt::BakeOptions o;
  o.order = 3;
  o.samples = 64;
  o.bounces = 0;
  o.seed = 77;
  o.material.albedo = Eigen::Vector3f(0.5f, 0.4f, 0.3f);
  const prt::TransferSet t = prt::bake(sphere, o);
  EXPECT_EQ(t.channels, 3);
  EXPECT_EQ(t.order, 3);
  EXPECT_EQ(t.samples, 64);
  EXPECT_EQ(t.seed, 77u);
  EXPECT_EQ(t.vertex_count, sphere.vertex_count());
  EXPECT_EQ(t.mesh_hash, meshes::content_hash(sphere));
  EXPECT_EQ(t.data.size(), sphere.vertex_count() * 3 * 81);
}

TEST(Bake, RejectsBadOptions) {
  const meshes::Mesh sphere = meshes::make_sphere(1.f, 8, 4);
  auto expect_flag = [&](prt::BakeOptions o, const char* flag) {
    try {
      prt::bake(sphere, o);
      ADD_FAILURE() << "expected an error naming " << flag;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(flag), std::string::npos) << e.what();
    }
  };
  prt::BakeOptions o;
  o.order = 11;
  expect_flag(o, "--order");
  o = {};
  o.samples = 0;
  expect_flag(o, "--samples");
  o = {};
  o.bounces = 17;
  expect_flag(o, "--bounces");
  o = {};
  o.material.exponent = -1.f;
  expect_flag(o, "--exponent");
}

}  // namespace
