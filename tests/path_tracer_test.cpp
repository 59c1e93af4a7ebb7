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

// A plane lit by a bright, smooth lobe of light plus a dim sky (light sampling matters), a
// point on it and a view, and the integral the estimators target, int f(v, s) s.z L(s) ds
// over the upper hemisphere, by a dense midpoint rule in (cos theta, phi) in the point's own
// frame: no importance sampling, no random numbers.
struct QuadratureCase {
  meshes::Mesh plane = meshes::make_plane(4.f, 2);
  Eigen::Vector3d sun = Eigen::Vector3d(0.4, 0.8, -0.3).normalized();
  probes::Probe probe = probes::make_from_function(128, 64, [this](const Eigen::Vector3d& d) {
    const double lobe = std::exp(40.0 * (d.dot(sun) - 1.0));
    return probes::Rgb(float(0.2 + 8 * lobe), float(0.1 + 6 * lobe), float(0.3 + 4 * lobe));
  });
  Eigen::Vector3d view = Eigen::Vector3d(-0.5, 0.7, 0.4).normalized();

  Eigen::Vector3d expected(const prt::Material& m, const prt::SurfacePoint& p) const {
    const Eigen::Vector3d v = p.frame.transpose() * view;
    constexpr int kTheta = 300, kPhi = 600;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int i = 0; i < kTheta; ++i) {
      const double z = (i + 0.5) / kTheta, r = std::sqrt(1 - z * z);
      for (int j = 0; j < kPhi; ++j) {
        const double phi = 2 * kPi * (j + 0.5) / kPhi;
        const Eigen::Vector3d s(r * std::cos(phi), r * std::sin(phi), z);
        const Eigen::Vector3d le = probe.lookup(p.frame * s).cast<double>();
        for (int c = 0; c < 3; ++c) sum[c] += prt::brdf_eval(m, c, v, s) * z * le[c];
      }
    }
    return sum * (1.0 / kTheta) * (2 * kPi / kPhi);
  }
};

// A glossy material of either kind: Phong of exponent 30 or Cook-Torrance of roughness 0.15.
prt::Material glossy(prt::MaterialKind kind) {
  prt::Material m;
  m.kind = kind;
  m.albedo = Eigen::Vector3f(0.3f, 0.4f, 0.5f);
  m.specular = kind == prt::MaterialKind::kPhong ? 0.4f : 0.5f;
  m.exponent = 30.f;
  m.roughness = 0.15f;
  return m;
}

TEST(PathTracer, MisEstimateMatchesADenseQuadrature) {
  const QuadratureCase q;
  const prt::Material m = glossy(prt::MaterialKind::kPhong);
  prt::PathTracerOptions options;
  options.bounces = 0;
  const prt::PathTracer tracer(q.plane, q.probe, m, options);
  const prt::SurfacePoint p = centroid(tracer, 1);
  const Eigen::Vector3d expected = q.expected(m, p);
  const Eigen::Vector3d l = tracer.exit_radiance(p, q.view, 8192, 5);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(l[c], expected[c], 0.015 * expected[c]) << c;
}

// The surface light field's estimator: the light technique from samples shared by many
// views (add_shared_light) and the paths' BRDF technique weighted for them (ExitQuery's
// shared_light_ratio) together estimate the same integral, for several sharing ratios.
TEST(PathTracer, SharedLightSamplesMatchADenseQuadrature) {
  const QuadratureCase q;
  for (const prt::Material& m :
       {glossy(prt::MaterialKind::kPhong), glossy(prt::MaterialKind::kCookTorrance)}) {
    prt::PathTracerOptions options;
    options.bounces = 0;
    const prt::PathTracer tracer(q.plane, q.probe, m, options);
    const prt::SurfacePoint p = centroid(tracer, 1);
    const Eigen::Vector3d expected = q.expected(m, p);
    constexpr int kPaths = 4096;
    for (int ratio : {1, 4}) {
      const prt::SharedLights lights = tracer.sample_lights(p, kPaths * ratio, 77);
      ASSERT_EQ(lights.size(), std::size_t(kPaths * ratio));
      Eigen::Vector3d light_part = Eigen::Vector3d::Zero();
      for (std::size_t j = 0; j < lights.size(); ++j)
        tracer.add_shared_light(p, lights, j, q.view, double(ratio), &light_part);
      light_part /= double(lights.size());
      std::vector<prt::ExitQuery> queries;
      for (int k = 0; k < kPaths; ++k) {
        prt::ExitQuery e{p, q.view, std::uint64_t(k), 0};
        e.shared_light_ratio = ratio;
        queries.push_back(e);
      }
      Eigen::Vector3d brdf_part = Eigen::Vector3d::Zero();
      tracer.add_exit_radiance(queries, &brdf_part);
      const Eigen::Vector3d l = light_part + brdf_part / kPaths;
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(l[c], expected[c], 0.02 * expected[c]) << int(m.kind) << " " << ratio << c;
      // Each technique alone is biased (each covers only its share of the weights).
      EXPECT_GT(light_part.minCoeff(), 0.0);
      EXPECT_GT(brdf_part.minCoeff(), 0.0);
    }
  }
}

TEST(PathTracer, SharedLightSamplesAreShadowed) {
  // A point under a much larger plane (its back face toward the point): every direction
  // more than a few degrees above the horizon is blocked, the ones below are never lit.
  meshes::Mesh two =
      meshes::merge({meshes::make_plane(4.f, 2, 0.f), meshes::make_plane(40.f, 2, 1.f)});
  meshes::compute_frames(two);
  const probes::Probe sky = probes::make_constant(64, 32, probes::Rgb(1, 1, 1));
  const prt::PathTracer covered(two, sky, glossy(prt::MaterialKind::kPhong));
  const prt::SurfacePoint p = centroid(covered, 1);
  const prt::SharedLights lights = covered.sample_lights(p, 256, 9);
  ASSERT_EQ(lights.size(), 256u);
  int lit = 0;
  for (std::size_t j = 0; j < lights.size(); ++j) {
    EXPECT_GT(lights.pdf[j], 0.0);
    if (lights.direction[j].z() > 0.1 || lights.direction[j].z() <= 0) {
      EXPECT_EQ(lights.radiance[j].maxCoeff(), 0.0) << j;
    }
    lit += lights.radiance[j].maxCoeff() > 0 ? 1 : 0;
  }
  EXPECT_LT(lit, 16);
  // Without the upper plane every sample above the horizon sees the sky, about half.
  const meshes::Mesh one = meshes::make_plane(4.f, 2, 0.f);
  const prt::PathTracer open(one, sky, glossy(prt::MaterialKind::kPhong));
  const prt::SharedLights seen = open.sample_lights(centroid(open, 1), 256, 9);
  int above = 0;
  for (std::size_t j = 0; j < seen.size(); ++j) {
    const bool up = seen.direction[j].z() > 0;
    above += up ? 1 : 0;
    EXPECT_EQ(seen.radiance[j].maxCoeff(), up ? 1.0 : 0.0) << j;
  }
  EXPECT_NEAR(above, 128, 24);
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

// An image traced in bands, each keyed from its first ray's index in the whole image, is the
// image traced at once; a ray that misses shows the probe.
TEST(PathTracer, ImageInBandsIsTheImageAtOnce) {
  const meshes::Mesh sphere = meshes::make_sphere(1.f, 24, 12);
  const probes::Probe probe = smooth_probe();
  prt::Material m;
  m.kind = prt::MaterialKind::kCookTorrance;
  m.roughness = 0.2f;
  const prt::PathTracer tracer(sphere, probe, m);
  // A fan of rays from (0, 0, 4) toward the -z axis, the outer ones past the sphere.
  constexpr int kRays = 200;
  Eigen::Matrix3Xf origins(3, kRays), directions(3, kRays);
  for (int i = 0; i < kRays; ++i) {
    origins.col(i) = Eigen::Vector3f(0, 0, 4);
    const float a = 0.6f * float(i) / kRays;
    directions.col(i) =
        Eigen::Vector3f(std::sin(a), 0.1f * std::cos(3.f * a), -std::cos(a)).normalized();
  }
  std::vector<std::uint8_t> hit(kRays, 2);
  const Eigen::Matrix3Xf whole =
      prt::path_trace_image(tracer, origins, directions, 8, {}, 0, hit.data());
  // The coverage it reports is the scene's own intersection of the same rays.
  std::vector<prt::RayHit> hits(kRays);
  tracer.scene().intersect_from(origins, directions, 0.f, hits.data());
  for (int i = 0; i < kRays; ++i)
    EXPECT_EQ(hit[std::size_t(i)], hits[std::size_t(i)].triangle >= 0 ? 1 : 0) << i;
  EXPECT_EQ(hit.front(), 1);
  EXPECT_EQ(hit.back(), 0);
  const int split = 77;
  const Eigen::Matrix3Xf first =
      prt::path_trace_image(tracer, origins.leftCols(split), directions.leftCols(split), 8, {}, 0);
  const Eigen::Matrix3Xf second =
      prt::path_trace_image(tracer, origins.rightCols(kRays - split),
                            directions.rightCols(kRays - split), 8, {}, std::uint64_t(split));
  EXPECT_EQ(first, whole.leftCols(split));
  EXPECT_EQ(second, whole.rightCols(kRays - split));
  // Keyed from 0 instead, the second band's paths are other paths.
  const Eigen::Matrix3Xf unkeyed = prt::path_trace_image(tracer, origins.rightCols(kRays - split),
                                                         directions.rightCols(kRays - split), 8);
  EXPECT_NE(unkeyed, whole.rightCols(kRays - split));
  const Eigen::Vector3f last = directions.col(kRays - 1);
  EXPECT_EQ(whole.col(kRays - 1), probe.lookup(last.cast<double>()).cast<float>());
}

}  // namespace
