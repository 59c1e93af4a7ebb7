// Tests for prt/path_tracer.h against analytic answers and an independent quadrature: a
// Lambert sphere under a white sky is flat at the albedo, sharp lobes reflect the probe,
// the MIS estimate matches a dense deterministic quadrature of the same integral, a closed
// box is black inside, and results depend only on the keys.
#include "prt/path_tracer.h"
#include "meshes/frames.h"
#include "meshes/procedural.h"
#include "probes/procedural.h"
#include "prt/material.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

namespace {

constexpr double kPi = std::numbers::pi;

prt::Material lambert(float albedo) {
  prt::Material m;
  m.kind = prt::MaterialKind::kLambert;
  m.albedo = Eigen::Vector3f::Constant(albedo);
  return m;
}

// A smooth probe: positive, linear in the direction.
probes::Probe smooth_probe() {
  return probes::make_from_function(256, 128, [](const Eigen::Vector3d& d) {
    return probes::Rgb(float(1.0 + 0.5 * d.x()), float(1.0 + 0.4 * d.y()),
                       float(1.0 - 0.3 * d.z()));
  });
}

// The point at the centroid of triangle t.
prt::SurfacePoint centroid(const prt::PathTracer& tracer, int t) {
  return tracer.surface_point(t, 1.0 / 3, 1.0 / 3);
}

TEST(PathTracer, LambertSphereUnderWhiteSkyIsFlatAtItsAlbedo) {
  const meshes::Mesh sphere = meshes::make_sphere(1.f, 48, 24);
  const probes::Probe sky = probes::make_constant(64, 32, probes::Rgb(1, 1, 1));
  for (int bounces : {0, 1}) {
    prt::PathTracerOptions options;
    options.bounces = bounces;
    const prt::PathTracer tracer(sphere, sky, lambert(0.6f), options);
    double sum = 0;
    int count = 0;
    for (int t = 0; t < int(sphere.triangles.size()); t += 97) {
      const prt::SurfacePoint p = centroid(tracer, t);
      // Views above and below the tangent plane (the latter clamped to the horizon).
      const Eigen::Vector3d views[] = {p.frame.col(2), p.frame.col(0),
                                       (p.frame.col(2) + p.frame.col(1)).normalized(),
                                       -p.frame.col(2)};
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector3d l = tracer.exit_radiance(p, views[k], 1024, std::uint64_t(4 * t + k));
        EXPECT_NEAR(l.x(), 0.6, 0.03) << "triangle " << t;
        EXPECT_EQ(l.x(), l.y());
        EXPECT_EQ(l.x(), l.z());
        sum += l.x();
        ++count;
      }
    }
    EXPECT_NEAR(sum / count, 0.6, 0.004) << "bounces " << bounces;
  }
}

// A sharp specular lobe on a plane (nothing to occlude) reflects the probe: radiance toward
// v is the directional albedo times the probe along the mirror direction, for a probe that
// is linear over the lobe's width.
void expect_mirror(const prt::Material& material) {
  const meshes::Mesh plane = meshes::make_plane(4.f, 2);
  const probes::Probe probe = smooth_probe();
  const prt::PathTracer tracer(plane, probe, material);
  const prt::SurfacePoint p = centroid(tracer, 0);
  ASSERT_NEAR(p.frame.col(2).y(), 1.0, 1e-6);
  for (const Eigen::Vector3d& view : {Eigen::Vector3d(0.3, 0.9, 0.2).normalized(),
                                      Eigen::Vector3d(-0.6, 0.5, 0.1).normalized()}) {
    const Eigen::Vector3d mirror(-view.x(), view.y(), -view.z());
    const Eigen::Vector3d local = p.frame.transpose() * view;
    const double albedo = prt::directional_albedo(material, 0, local);
    const Eigen::Vector3d expected = albedo * probe.lookup(mirror).cast<double>();
    const Eigen::Vector3d l = tracer.exit_radiance(p, view, 512, 11);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(l[c], expected[c], 0.02 * expected[c]) << c;
  }
}

TEST(PathTracer, SharpPhongLobeReflectsTheProbe) {
  prt::Material m;
  m.kind = prt::MaterialKind::kPhong;
  m.albedo.setZero();
  m.specular = 1.f;
  m.exponent = 10000.f;
  expect_mirror(m);
}

TEST(PathTracer, SharpCookTorranceLobeReflectsTheProbe) {
  prt::Material m;
  m.kind = prt::MaterialKind::kCookTorrance;
  m.albedo.setZero();
  m.specular = 1.f;
  m.roughness = 0.02f;
  m.f0 = 1.f;
  expect_mirror(m);
}

TEST(PathTracer, MisEstimateMatchesADenseQuadrature) {
  const meshes::Mesh plane = meshes::make_plane(4.f, 2);
  // A bright, smooth lobe of light plus a dim sky: light sampling matters.
  const Eigen::Vector3d sun = Eigen::Vector3d(0.4, 0.8, -0.3).normalized();
  const probes::Probe probe = probes::make_from_function(128, 64, [&](const Eigen::Vector3d& d) {
    const double lobe = std::exp(40.0 * (d.dot(sun) - 1.0));
    return probes::Rgb(float(0.2 + 8 * lobe), float(0.1 + 6 * lobe), float(0.3 + 4 * lobe));
  });
  prt::Material m;
  m.kind = prt::MaterialKind::kPhong;
  m.albedo = Eigen::Vector3f(0.3f, 0.4f, 0.5f);
  m.specular = 0.4f;
  m.exponent = 30.f;
  prt::PathTracerOptions options;
  options.bounces = 0;
  const prt::PathTracer tracer(plane, probe, m, options);
  const prt::SurfacePoint p = centroid(tracer, 1);
  const Eigen::Vector3d view = Eigen::Vector3d(-0.5, 0.7, 0.4).normalized();
  const Eigen::Vector3d v = p.frame.transpose() * view;
  // The integral the estimator targets, int f(v, s) s.z L(s) ds over the upper hemisphere,
  // by a dense midpoint rule in (cos theta, phi) in the point's own frame: no importance
  // sampling, no random numbers.
  constexpr int kTheta = 300, kPhi = 600;
  Eigen::Vector3d expected = Eigen::Vector3d::Zero();
  for (int i = 0; i < kTheta; ++i) {
    const double z = (i + 0.5) / kTheta, r = std::sqrt(1 - z * z);
    for (int j = 0; j < kPhi; ++j) {
      const double phi = 2 * kPi * (j + 0.5) / kPhi;
      const Eigen::Vector3d s(r * std::cos(phi), r * std::sin(phi), z);
      const Eigen::Vector3d le = probe.lookup(p.frame * s).cast<double>();
      for (int c = 0; c < 3; ++c) expected[c] += prt::brdf_eval(m, c, v, s) * z * le[c];
    }
  }
  expected *= (1.0 / kTheta) * (2 * kPi / kPhi);
  const Eigen::Vector3d l = tracer.exit_radiance(p, view, 8192, 5);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(l[c], expected[c], 0.015 * expected[c]) << c;
}

TEST(ProbeSampler, DensityMatchesItsSamplesAndIntegratesTheProbe) {
  // A bright lobe on a dim sky, and a black cap that must never be drawn.
  const Eigen::Vector3d sun = Eigen::Vector3d(-0.3, 0.5, 0.8).normalized();
  const probes::Probe probe = probes::make_from_function(128, 64, [&](const Eigen::Vector3d& d) {
    if (d.y() < -0.9) return probes::Rgb(0, 0, 0);
    const double lobe = std::exp(60.0 * (d.dot(sun) - 1.0));
    return probes::Rgb(float(0.3 + 20 * lobe), float(0.2 + 10 * lobe), float(0.1 + 5 * lobe));
  });
  const prt::ProbeSampler sampler(probe);
  ASSERT_FALSE(sampler.empty());
  prt::RandomStream rng{42, 0};
  constexpr int kSamples = 200000;
  Eigen::Vector3d integral = Eigen::Vector3d::Zero();
  for (int k = 0; k < kSamples; ++k) {
    double pdf = 0;
    const double u0 = rng.next(), u1 = rng.next(), u2 = rng.next(), u3 = rng.next();
    const Eigen::Vector3d d = sampler.sample(u0, u1, u2, u3, &pdf);
    ASSERT_GT(pdf, 0);
    ASSERT_NEAR(d.norm(), 1, 1e-9);
    ASSERT_NEAR(sampler.pdf(d), pdf, 1e-9 * pdf) << k;
    // Never inside the black cap, but in its rim: texels within one of a lit one (2.8 degrees
    // a row here) have density, since bilinear lookups there are not black.
    ASSERT_GE(d.y(), -0.94);
    integral += probe.lookup(d).cast<double>() / pdf;
  }
  integral /= kSamples;
  // The oracle: the probe's own solid-angle weighted mean, times 4 pi. Bilinear lookups and
  // texel means differ by the interpolation, well under a percent for this smooth map.
  const Eigen::Vector3d expected = 4 * kPi * probe.mean_radiance().cast<double>();
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(integral[c], expected[c], 0.01 * expected[c]) << c;
  EXPECT_TRUE(prt::ProbeSampler(probes::make_constant(8, 4, probes::Rgb(0, 0, 0))).empty());
}

TEST(PathTracer, InsideAClosedBoxIsBlack) {
  meshes::Mesh lid = meshes::make_plane(2.f, 4, 1.f);
  for (meshes::Triangle& t : lid.triangles) std::swap(t[1], t[2]);  // face down, into the box
  const meshes::Mesh box = meshes::merge({meshes::make_open_box(2.f, 4), lid});
  const probes::Probe sky = probes::make_constant(32, 16, probes::Rgb(5, 5, 5));
  for (int bounces : {0, 1, 2}) {
    prt::PathTracerOptions options;
    options.bounces = bounces;
    const prt::PathTracer tracer(box, sky, lambert(0.8f), options);
    for (int t : {0, 5, 17, 40}) {
      const prt::SurfacePoint p = centroid(tracer, t);
      const Eigen::Vector3d l = tracer.exit_radiance(p, p.frame.col(2), 64, 3);
      EXPECT_EQ(l, Eigen::Vector3d::Zero()) << "triangle " << t << ", bounces " << bounces;
    }
  }
  // The same box without its lid lets the sky in, directly and by interreflection.
  const meshes::Mesh open = meshes::make_open_box(2.f, 4);
  prt::PathTracerOptions options;
  options.bounces = 0;
  const prt::PathTracer direct(open, sky, lambert(0.8f), options);
  options.bounces = 1;
  const prt::PathTracer bounced(open, sky, lambert(0.8f), options);
  const prt::SurfacePoint p = centroid(direct, 0);
  const double d = direct.exit_radiance(p, p.frame.col(2), 256, 3).x();
  const double b = bounced.exit_radiance(p, p.frame.col(2), 256, 3).x();
  EXPECT_GT(d, 0.1);
  EXPECT_GT(b, d * 1.05);
}

TEST(PathTracer, ResultsDependOnlyOnTheKeys) {
  const meshes::Mesh sphere = meshes::make_plane_and_sphere();
  const probes::Probe probe = smooth_probe();
  prt::Material m;
  m.kind = prt::MaterialKind::kCookTorrance;
  m.roughness = 0.2f;
  const prt::PathTracer tracer(sphere, probe, m);
  std::vector<prt::ExitQuery> queries;
  for (int t = 0; t < 50; ++t) {
    const prt::SurfacePoint p = centroid(tracer, t * 7);
    queries.push_back({p, p.frame.col(2), std::uint64_t(1000 + t), std::uint32_t(t)});
  }
  std::vector<Eigen::Vector3d> together(50, Eigen::Vector3d::Zero());
  tracer.add_exit_radiance(queries, together.data());
  for (int t = 49; t >= 0; --t) {  // alone and in another order
    Eigen::Vector3d alone = Eigen::Vector3d::Zero();
    prt::ExitQuery q = queries[std::size_t(t)];
    q.slot = 0;
    tracer.add_exit_radiance({q}, &alone);
    EXPECT_EQ(alone, together[std::size_t(t)]) << t;
  }
  Eigen::Vector3d other = Eigen::Vector3d::Zero();
  prt::ExitQuery q = queries[3];
  q.key += 1;
  q.slot = 0;
  tracer.add_exit_radiance({q}, &other);
  EXPECT_NE(other, together[3]);
}

}  // namespace
