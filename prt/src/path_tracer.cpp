// Path tracing under a probe (prt/path_tracer.h). Paths advance together, one depth at a
// time: each depth traces all its light samples' shadow rays as one Embree stream and all its
// BRDF samples as another (streams run ~1.75x the rate of single rays, ray_scene.cpp), and
// the BRDF samples that hit a front face become the next depth's paths.
#include "prt/path_tracer.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <string>

namespace prt {
namespace {

constexpr double kTracerPi = std::numbers::pi;

std::uint64_t finalise(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

double power_weight(double a, double b) {
  const double a2 = a * a;
  return a2 / (a2 + b * b);
}

// Any unit vector perpendicular to n.
Eigen::Vector3d perpendicular(const Eigen::Vector3d& n) {
  const Eigen::Vector3d axis =
      std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return (axis - axis.dot(n) * n).normalized();
}

// The local view the BRDF is evaluated at: below kGrazingZ, the horizon's direction under
// or over v (clamp_to_horizon of its tangent part) lifted to kGrazingZ, a unit vector. (Lifting
// v itself where 0 <= v.z < kGrazingZ left it up to 5e-7 short of unit, which the batched
// BRDF, taking |v + s|^2 = 2 (1 + v.s), turns into percent errors for a light opposite v.)
Eigen::Vector3d shading_view(const Eigen::Vector3d& v) {
  if (v.z() >= kGrazingZ) return v;
  const Eigen::Vector3d h = clamp_to_horizon(Eigen::Vector3d(v.x(), v.y(), -1.0));
  const double t = std::sqrt(1 - kGrazingZ * kGrazingZ);
  return Eigen::Vector3d(t * h.x(), t * h.y(), kGrazingZ);
}

// The BRDF's sampling: the cosine lobe with probability 1 - p_spec, the specular lobe with
// p_spec = rho_s / (mean rho_d + rho_s).
struct Lobes {
  Material material;
  double p_spec = 0;
  bool black = false;
  double m2 = 0;

  explicit Lobes(const Material& m) : material(m) {
    const double diffuse = m.albedo.cast<double>().mean();
    const double specular = m.kind == MaterialKind::kLambert ? 0.0 : double(m.specular);
    black = diffuse + specular <= 0;
    p_spec = black ? 0 : specular / (diffuse + specular);
    m2 = double(m.roughness) * double(m.roughness);
  }

  // f_r per channel, as brdf_eval: the channels differ only in the diffuse term rho_d / pi.
  Eigen::Vector3d eval(const Eigen::Vector3d& v, const Eigen::Vector3d& s) const {
    if (v.z() <= 0 || s.z() <= 0) return Eigen::Vector3d::Zero();
    const double f0 = brdf_eval(material, 0, v, s);
    if (material.grey()) return Eigen::Vector3d::Constant(f0);
    const Eigen::Vector3d rho = material.albedo.cast<double>();
    return Eigen::Vector3d::Constant(f0) + (rho - Eigen::Vector3d::Constant(rho.x())) / kTracerPi;
  }

  double specular_pdf(const Eigen::Vector3d& v, const Eigen::Vector3d& s) const {
    if (material.kind == MaterialKind::kPhong) {
      const Eigen::Vector3d r(-v.x(), -v.y(), v.z());  // v mirrored about the normal
      const double c = r.dot(s);
      if (c <= 0) return 0;
      const double e = material.exponent;
      return (e + 1) / (2 * kTracerPi) * std::pow(c, e);
    }
    const Eigen::Vector3d sum = v + s;
    const double norm = sum.norm();
    if (!(norm > 0)) return 0;
    const Eigen::Vector3d h = sum / norm;
    const double vh = v.dot(h);
    if (h.z() <= 0 || vh <= 0) return 0;
    const double c2 = h.z() * h.z();
    const double d = std::exp(-(1 - c2) / (c2 * m2)) / (kTracerPi * m2 * c2 * c2);
    return d * h.z() / (4 * vh);
  }

  double pdf(const Eigen::Vector3d& v, const Eigen::Vector3d& s) const {
    double p = (1 - p_spec) * std::max(0.0, s.z()) / kTracerPi;
    if (p_spec > 0) p += p_spec * specular_pdf(v, s);
    return p;
  }

  // pdf(v_i, s) for the views v_i (columns, v_i.z > 0) against one s with s.z > 0, on
  // arrays. Cook-Torrance without normalising h, as brdf_eval_batch: with q = 1 + v.s and
  // p = v.z + s.z, v.h = sqrt(q / 2), h.z = p / sqrt(2q) and 1 / h.z^2 = u = 2q / p^2, so
  // D h.z / (4 v.h) = D p / (4q); both of h.z and v.h are positive here.
  Eigen::ArrayXd pdf_batch(const Eigen::Matrix3Xd& views, const Eigen::Vector3d& s) const {
    const Eigen::ArrayXd vz = views.row(2).transpose().array();
    Eigen::ArrayXd p = Eigen::ArrayXd::Constant(views.cols(), (1 - p_spec) * s.z() / kTracerPi);
    if (!(p_spec > 0)) return p;
    const Eigen::ArrayXd vs = (views.transpose() * s).array();
    if (material.kind == MaterialKind::kPhong) {
      // The mirror image of v against s: r.s = 2 v.z s.z - v.s.
      const Eigen::ArrayXd c = 2 * s.z() * vz - vs;
      const double e = material.exponent;
      return p + p_spec * (e + 1) / (2 * kTracerPi) *
                     (c > 0).select((e * c.max(1e-300).log()).exp(), 0.0);
    }
    const Eigen::ArrayXd q = 1 + vs, sum_z = vz + s.z();
    const Eigen::ArrayXd u = 2 * q / sum_z.square();
    const Eigen::ArrayXd d = ((1 - u) / m2).exp() * u.square() / (kTracerPi * m2);
    return p + p_spec * d * sum_z / (4 * q);
  }

  // A direction (over the whole sphere; those below the horizon carry nothing) and its
  // density, from three uniform numbers.
  Eigen::Vector3d sample(const Eigen::Vector3d& v, double u0, double u1, double u2,
                         double* density) const {
    Eigen::Vector3d s;
    const double phi = 2 * kTracerPi * u2;
    if (u0 >= p_spec) {
      const double r = std::sqrt(u1);
      s = Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1 - u1)));
    } else if (material.kind == MaterialKind::kPhong) {
      const Eigen::Vector3d axis(-v.x(), -v.y(), v.z());
      const double c = std::pow(1 - u1, 1.0 / (double(material.exponent) + 1));
      const double sn = std::sqrt(std::max(0.0, 1 - c * c));
      const Eigen::Vector3d t = perpendicular(axis), b = axis.cross(t);
      s = c * axis + sn * (std::cos(phi) * t + std::sin(phi) * b);
    } else {
      const double tan2 = -m2 * std::log(1 - u1);
      const double c = 1 / std::sqrt(1 + tan2), sn = std::sqrt(std::max(0.0, 1 - c * c));
      const Eigen::Vector3d h(sn * std::cos(phi), sn * std::sin(phi), c);
      s = 2 * v.dot(h) * h - v;
    }
    *density = pdf(v, s);
    return s;
  }
};

}  // namespace

std::uint64_t mix_key(std::uint64_t a, std::uint64_t b) {
  return finalise(a * 0x9E3779B97F4A7C15ULL + finalise(b + 0x632BE59BD9B4E019ULL));
}

double RandomStream::next() {
  const std::uint64_t z = finalise(key + (++counter) * 0x9E3779B97F4A7C15ULL);
  return double(z >> 11) * 0x1.0p-53;
}

void PathTracerOptions::validate() const {
  if (bounces < 0 || bounces > 16) {
    throw std::invalid_argument("--bounces must be in [0, 16], got " + std::to_string(bounces));
  }
  if (!(ray_offset > 0 && ray_offset <= 0.1)) {
    throw std::invalid_argument("--ray-offset must be in (0, 0.1], got " +
                                std::to_string(ray_offset));
  }
}

// --- ProbeSampler ------------------------------------------------------------------------------

ProbeSampler::ProbeSampler(const probes::Probe& probe)
    : width_(probe.width()), height_(probe.height()) {
  if (width_ <= 0 || height_ <= 0) return;
  const auto value = [&](int x, int y) {
    const probes::Rgb& c = probe.texel((x % width_ + width_) % width_, y);
    return std::max(0.0, double(c.maxCoeff()));
  };
  std::vector<double> weight(std::size_t(width_) * height_);
  for (int y = 0; y < height_; ++y) {
    const double solid_angle = probe.pixel_solid_angle(y);
    for (int x = 0; x < width_; ++x) {
      double w = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= height_) continue;
        for (int dx = -1; dx <= 1; ++dx) w = std::max(w, value(x + dx, yy));
      }
      weight[std::size_t(y) * width_ + x] = w * solid_angle;
    }
  }
  // Vose's alias method ("A linear algorithm for generating random numbers with a given
  // distribution", 1991): one table look-up per sample instead of two binary searches over
  // megabytes of CDF (a 1024 x 512 probe's searches were a sixth of the bake's time).
  const std::size_t n = weight.size();
  for (double w : weight) total_ += w;
  texel_pdf_.assign(n, 0.0);
  alias_prob_.assign(n, 1.f);
  alias_.resize(n);
  for (std::size_t i = 0; i < n; ++i) alias_[i] = std::uint32_t(i);
  if (total_ <= 0) return;
  std::vector<double> scaled(n);
  std::vector<std::uint32_t> small, large;
  for (std::size_t i = 0; i < n; ++i) {
    scaled[i] = weight[i] / total_ * double(n);
    (scaled[i] < 1 ? small : large).push_back(std::uint32_t(i));
  }
  while (!small.empty() && !large.empty()) {
    const std::uint32_t s = small.back(), l = large.back();
    small.pop_back();
    alias_prob_[s] = float(scaled[s]);
    alias_[s] = l;
    scaled[l] -= 1 - scaled[s];
    if (scaled[l] < 1) {
      large.pop_back();
      small.push_back(l);
    }
  }
  // What is left holds probability 1 of itself up to rounding, which can also leave texels
  // of zero weight behind: those send every draw to the brightest texel instead.
  const auto brightest =
      std::uint32_t(std::max_element(weight.begin(), weight.end()) - weight.begin());
  for (std::uint32_t s : small) {
    if (weight[s] > 0) continue;
    alias_prob_[s] = 0.f;
    alias_[s] = brightest;
  }
  for (int y = 0; y < height_; ++y) {
    const double solid_angle = probe.pixel_solid_angle(y);
    for (int x = 0; x < width_; ++x) {
      const std::size_t i = std::size_t(y) * width_ + x;
      texel_pdf_[i] = weight[i] / total_ / solid_angle;
    }
  }
}

Eigen::Vector3d ProbeSampler::sample(double u0, double u1, double u2, double u3,
                                     double* pdf) const {
  const std::size_t n = alias_.size();
  std::size_t i = std::min(n - 1, std::size_t(u0 * double(n)));
  if (!(u1 < double(alias_prob_[i]))) i = alias_[i];
  const int y = int(i / std::size_t(width_)), x = int(i % std::size_t(width_));
  // Uniform in solid angle inside the texel: cos(theta) uniform between the row's edges.
  const double top = std::cos(kTracerPi * y / height_),
               bottom = std::cos(kTracerPi * (y + 1) / height_);
  const double cos_theta = top + u2 * (bottom - top);
  const double theta = std::acos(std::clamp(cos_theta, -1.0, 1.0));
  *pdf = texel_pdf_[std::size_t(y) * width_ + x];
  return probes::latlong_direction((x + u3) / width_, theta / kTracerPi);
}

double ProbeSampler::pdf(const Eigen::Vector3d& direction) const {
  if (total_ <= 0) return 0;
  return pdf_uv(probes::latlong_uv(direction));
}

double ProbeSampler::pdf_uv(const Eigen::Vector2d& uv) const {
  if (total_ <= 0) return 0;
  const int x = std::clamp(int(uv.x() * width_), 0, width_ - 1);
  const int y = std::clamp(int(uv.y() * height_), 0, height_ - 1);
  return texel_pdf_[std::size_t(y) * width_ + x];
}

namespace {

// A secondary ray's origin: off the surface along the face normal, on the side it leaves by.
Eigen::Vector3f ray_origin(const SurfacePoint& p, const Eigen::Vector3d& d, double offset) {
  const double side = d.dot(p.face_normal) >= 0 ? 1.0 : -1.0;
  return (p.position + side * offset * p.face_normal).cast<float>();
}

// A probe sample's share of the light technique, f L cos w / p (view v and sample s in the
// shading frame, s above it), weighted by the power heuristic against the BRDF technique
// with `count` light samples per BRDF sample. Zero where the BRDF is.
Eigen::Vector3d light_sample_value(const Lobes& lobes, const Eigen::Vector3d& v,
                                   const Eigen::Vector3d& s, const Eigen::Vector3d& radiance,
                                   double pdf, double count) {
  const Eigen::Vector3d f = lobes.eval(v, s);
  if (!(f.maxCoeff() > 0)) return Eigen::Vector3d::Zero();
  const double w = power_weight(count * pdf, lobes.pdf(v, s));
  return f.cwiseProduct(radiance) * (s.z() * w / pdf);
}

}  // namespace

// --- PathTracer --------------------------------------------------------------------------------

struct PathTracer::Path {
  SurfacePoint point;
  Eigen::Vector3d view;  // local, shading_view applied
  Eigen::Vector3d throughput;
  std::uint64_t key;
  std::uint32_t slot;
  double shared_light_ratio;  // first vertex only: ExitQuery's
};

PathTracer::PathTracer(const meshes::Mesh& mesh, const probes::Probe& probe,
                       const Material& material, const PathTracerOptions& options)
    : mesh_(mesh), probe_(probe), material_(material), options_(options), sampler_(probe) {
  options.validate();
  material.validate();
  if (!mesh.has_frames()) {
    throw std::invalid_argument("path tracer: the mesh has no frames (meshes::compute_frames)");
  }
  if (probe.texels().empty()) throw std::invalid_argument("path tracer: the probe is empty");
  scene_ = std::make_unique<RayScene>(mesh);
  offset_ = options.ray_offset * std::max(1e-30, double(meshes::bounds(mesh).diagonal()));
}

PathTracer::~PathTracer() = default;

SurfacePoint PathTracer::surface_point(std::int32_t triangle, double u, double v) const {
  const meshes::Triangle& t = mesh_.triangles[std::size_t(triangle)];
  const double w0 = 1 - u - v;
  auto lerp = [&](const std::vector<meshes::Vec3>& a) {
    return Eigen::Vector3d(w0 * a[t[0]].cast<double>() + u * a[t[1]].cast<double>() +
                           v * a[t[2]].cast<double>());
  };
  SurfacePoint p;
  p.position = lerp(mesh_.positions);
  const Eigen::Vector3d p0 = mesh_.positions[t[0]].cast<double>();
  const Eigen::Vector3d face =
      (mesh_.positions[t[1]].cast<double>() - p0).cross(mesh_.positions[t[2]].cast<double>() - p0);
  const double face_norm = face.norm();
  p.face_normal = face_norm > 0 ? Eigen::Vector3d(face / face_norm) : Eigen::Vector3d::UnitY();
  Eigen::Vector3d n = lerp(mesh_.normals);
  n = n.norm() > 1e-12 ? Eigen::Vector3d(n.normalized()) : p.face_normal;
  Eigen::Vector3d tangent = lerp(mesh_.tangents);
  tangent -= tangent.dot(n) * n;
  tangent = tangent.norm() > 1e-6 ? Eigen::Vector3d(tangent.normalized()) : perpendicular(n);
  p.frame.col(0) = tangent;
  p.frame.col(1) = n.cross(tangent);
  p.frame.col(2) = n;
  return p;
}

void PathTracer::trace(std::vector<Path>& paths, Eigen::Vector3d* out) const {
  const Lobes lobes(material_);
  if (lobes.black) return;
  const bool lights = !sampler_.empty();
  std::vector<Path> next;
  Eigen::Matrix3Xf light_origins, light_dirs, brdf_origins, brdf_dirs;
  std::vector<Eigen::Vector3d> light_value, brdf_value, brdf_through;
  std::vector<Eigen::Vector3d> brdf_world;
  std::vector<Eigen::Vector2d> brdf_uv;
  std::vector<std::uint32_t> light_path, brdf_path;
  std::vector<std::uint8_t> blocked;
  std::vector<RayHit> hits;
  for (int depth = 0; depth <= options_.bounces && !paths.empty(); ++depth) {
    const bool last = depth == options_.bounces;
    const std::size_t n = paths.size();
    light_origins.resize(3, Eigen::Index(n));
    light_dirs.resize(3, Eigen::Index(n));
    brdf_origins.resize(3, Eigen::Index(n));
    brdf_dirs.resize(3, Eigen::Index(n));
    light_value.clear();
    brdf_value.clear();
    brdf_through.clear();
    brdf_world.clear();
    brdf_uv.clear();
    light_path.clear();
    brdf_path.clear();
    for (std::uint32_t i = 0; i < n; ++i) {
      const Path& path = paths[i];
      RandomStream rng{mix_key(path.key, std::uint64_t(depth)), 0};
      const Eigen::Matrix3d& frame = path.point.frame;
      const Eigen::Vector3d& v = path.view;
      // Light sample; its numbers are drawn even when the probe is black, so the BRDF
      // sample's numbers stay the same.
      const double l0 = rng.next(), l1 = rng.next(), l2 = rng.next(), l3 = rng.next();
      // The light technique's samples per BRDF sample, for the BRDF sample's weight.
      const double light_n = path.shared_light_ratio > 0 ? path.shared_light_ratio : 1.0;
      if (lights && !(path.shared_light_ratio > 0)) {
        double p_light = 0;
        const Eigen::Vector3d s_world = sampler_.sample(l0, l1, l2, l3, &p_light);
        const Eigen::Vector3d s = frame.transpose() * s_world;
        if (p_light > 0 && s.z() > 0) {
          const Eigen::Vector3d value =
              light_sample_value(lobes, v, s, probe_.lookup(s_world).cast<double>(), p_light, 1.0);
          if (value.maxCoeff() > 0) {
            const Eigen::Index k = Eigen::Index(light_path.size());
            light_value.push_back(path.throughput.cwiseProduct(value));
            light_dirs.col(k) = s_world.cast<float>();
            light_origins.col(k) = ray_origin(path.point, s_world, offset_);
            light_path.push_back(i);
          }
        }
      }
      // BRDF sample.
      const double b0 = rng.next(), b1 = rng.next(), b2 = rng.next();
      double p_brdf = 0;
      const Eigen::Vector3d s = lobes.sample(v, b0, b1, b2, &p_brdf);
      if (!(p_brdf > 0) || s.z() <= 0) continue;
      const Eigen::Vector3d f = lobes.eval(v, s);
      if (!(f.maxCoeff() > 0)) continue;
      const Eigen::Vector3d s_world = (frame * s).normalized();
      const Eigen::Index k = Eigen::Index(brdf_path.size());
      brdf_through.push_back(path.throughput.cwiseProduct(f) * (s.z() / p_brdf));
      // Its probe coordinates serve the light technique's density here and the probe's
      // radiance if it escapes.
      const Eigen::Vector2d uv = probes::latlong_uv(s_world);
      const double w = lights ? power_weight(p_brdf, light_n * sampler_.pdf_uv(uv)) : 1.0;
      brdf_value.push_back(brdf_through.back() * w);
      brdf_world.push_back(s_world);
      brdf_uv.push_back(uv);
      brdf_dirs.col(k) = s_world.cast<float>();
      brdf_origins.col(k) = ray_origin(path.point, s_world, offset_);
      brdf_path.push_back(i);
    }
    // Shadow rays of the light samples.
    const Eigen::Index lights_n = Eigen::Index(light_path.size());
    if (lights_n > 0) {
      blocked.resize(std::size_t(lights_n));
      scene_->occluded_from(light_origins.leftCols(lights_n), light_dirs.leftCols(lights_n), 0.f,
                            blocked.data());
      for (Eigen::Index k = 0; k < lights_n; ++k) {
        if (!blocked[std::size_t(k)])
          out[paths[light_path[std::size_t(k)]].slot] += light_value[std::size_t(k)];
      }
    }
    // BRDF rays: a miss sees the probe; a front hit continues the path while bounces remain.
    const Eigen::Index brdf_n = Eigen::Index(brdf_path.size());
    next.clear();
    if (brdf_n > 0 && last) {
      blocked.resize(std::size_t(brdf_n));
      scene_->occluded_from(brdf_origins.leftCols(brdf_n), brdf_dirs.leftCols(brdf_n), 0.f,
                            blocked.data());
      for (Eigen::Index k = 0; k < brdf_n; ++k) {
        if (blocked[std::size_t(k)]) continue;
        const Eigen::Vector3d le = probe_.lookup_uv(brdf_uv[std::size_t(k)]).cast<double>();
        out[paths[brdf_path[std::size_t(k)]].slot] += brdf_value[std::size_t(k)].cwiseProduct(le);
      }
    } else if (brdf_n > 0) {
      hits.resize(std::size_t(brdf_n));
      scene_->intersect_from(brdf_origins.leftCols(brdf_n), brdf_dirs.leftCols(brdf_n), 0.f,
                             hits.data());
      for (Eigen::Index k = 0; k < brdf_n; ++k) {
        const RayHit& h = hits[std::size_t(k)];
        const Path& from = paths[brdf_path[std::size_t(k)]];
        const Eigen::Vector3d& d = brdf_world[std::size_t(k)];
        if (h.triangle < 0) {
          const Eigen::Vector3d le = probe_.lookup_uv(brdf_uv[std::size_t(k)]).cast<double>();
          out[from.slot] += brdf_value[std::size_t(k)].cwiseProduct(le);
          continue;
        }
        Path p;
        p.point = surface_point(h.triangle, h.u, h.v);
        if (p.point.face_normal.dot(d) >= 0) continue;  // a back face: blocks, sends nothing
        p.view = shading_view(p.point.frame.transpose() * (-d));
        p.throughput = brdf_through[std::size_t(k)];
        p.key = mix_key(from.key, 0x5EED0000ULL + std::uint64_t(depth));
        p.slot = from.slot;
        p.shared_light_ratio = 0;
        next.push_back(p);
      }
    }
    paths.swap(next);
  }
}

SharedLights PathTracer::sample_lights(const SurfacePoint& point, int count,
                                       std::uint64_t key) const {
  SharedLights lights;
  if (sampler_.empty() || count <= 0) return lights;
  const std::size_t n = std::size_t(count);
  lights.direction.resize(n);
  lights.pdf.resize(n);
  lights.radiance.assign(n, Eigen::Vector3d::Zero());
  Eigen::Matrix3Xf origins(3, Eigen::Index(n)), dirs(3, Eigen::Index(n));
  std::vector<std::uint32_t> traced;
  const std::uint64_t stream = mix_key(options_.seed, key);
  for (std::size_t j = 0; j < n; ++j) {
    RandomStream rng{mix_key(stream, std::uint64_t(j)), 0};
    const double u0 = (double(j) + rng.next()) / double(n);
    const double u1 = rng.next(), u2 = rng.next(), u3 = rng.next();
    double pdf = 0;
    const Eigen::Vector3d world = sampler_.sample(u0, u1, u2, u3, &pdf);
    lights.pdf[j] = pdf;
    lights.direction[j] = point.frame.transpose() * world;
    if (!(pdf > 0) || lights.direction[j].z() <= 0) continue;
    const Eigen::Index k = Eigen::Index(traced.size());
    origins.col(k) = ray_origin(point, world, offset_);
    dirs.col(k) = world.cast<float>();
    lights.radiance[j] = probe_.lookup(world).cast<double>();
    traced.push_back(std::uint32_t(j));
  }
  const Eigen::Index m = Eigen::Index(traced.size());
  if (m == 0) return lights;
  std::vector<std::uint8_t> blocked(traced.size());
  scene_->occluded_from(origins.leftCols(m), dirs.leftCols(m), 0.f, blocked.data());
  for (std::size_t k = 0; k < traced.size(); ++k)
    if (blocked[k]) lights.radiance[traced[k]] = Eigen::Vector3d::Zero();
  return lights;
}

void PathTracer::add_shared_light(const SurfacePoint& point, const SharedLights& lights,
                                  std::size_t j, const Eigen::Matrix3Xd& views, double ratio,
                                  Eigen::Vector3d* out) const {
  const Lobes lobes(material_);
  if (lobes.black || !lights.lit(j) || views.cols() == 0) return;
  const Eigen::Vector3d& s = lights.direction[j];
  Eigen::Matrix3Xd local = point.frame.transpose() * views;
  for (Eigen::Index i = 0; i < local.cols(); ++i) local.col(i) = shading_view(local.col(i));
  // f(v_i, s) as f(s, v_i), and the BRDF technique's density of s from each view.
  const Eigen::ArrayXd f = brdf_eval_batch(material_, 0, s, local);
  const Eigen::ArrayXd p_brdf = lobes.pdf_batch(local, s);
  const double p_light = ratio * lights.pdf[j];
  const Eigen::ArrayXd w = p_light * p_light / (p_light * p_light + p_brdf.square());
  const Eigen::ArrayXd scale = w * (s.z() / lights.pdf[j]);
  const Eigen::Vector3d& radiance = lights.radiance[j];
  // A coloured material differs from channel 0 in its diffuse term only (Lobes::eval).
  const Eigen::Vector3d diffuse_offset =
      material_.grey() ? Eigen::Vector3d::Zero()
                       : Eigen::Vector3d((material_.albedo.cast<double>().array() -
                                          double(material_.albedo.x())) /
                                         kTracerPi);
  for (Eigen::Index i = 0; i < local.cols(); ++i) {
    const Eigen::Vector3d fi = Eigen::Vector3d::Constant(f[i]) + diffuse_offset;
    if (!(fi.maxCoeff() > 0)) continue;  // where the BRDF is zero, as light_sample_value
    out[i] += fi.cwiseProduct(radiance) * scale[i];
  }
}

void PathTracer::add_exit_radiance(const std::vector<ExitQuery>& queries,
                                   Eigen::Vector3d* out) const {
  std::vector<Path> paths;
  paths.reserve(queries.size());
  for (const ExitQuery& q : queries) {
    Path p;
    p.point = q.point;
    p.view = shading_view(q.point.frame.transpose() * q.view);
    p.throughput = Eigen::Vector3d::Ones();
    p.key = mix_key(options_.seed, q.key);
    p.slot = q.slot;
    p.shared_light_ratio = q.shared_light_ratio;
    paths.push_back(p);
  }
  trace(paths, out);
}

Eigen::Vector3d PathTracer::exit_radiance(const SurfacePoint& point, const Eigen::Vector3d& view,
                                          int spp, std::uint64_t key) const {
  std::vector<ExitQuery> queries(std::size_t(std::max(spp, 0)));
  for (int k = 0; k < spp; ++k) {
    queries[std::size_t(k)] = ExitQuery{point, view, mix_key(key, std::uint64_t(k)), 0};
  }
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  add_exit_radiance(queries, &sum);
  return spp > 0 ? Eigen::Vector3d(sum / spp) : sum;
}

Eigen::Matrix3Xf path_trace_image(const PathTracer& tracer, const Eigen::Matrix3Xf& origins,
                                  const Eigen::Matrix3Xf& directions, int spp,
                                  const std::function<void(std::uint64_t, std::uint64_t)>& progress,
                                  std::uint64_t first_key, std::uint8_t* hit) {
  if (origins.cols() != directions.cols()) {
    throw std::invalid_argument("path_trace_image: " + std::to_string(origins.cols()) +
                                " origins for " + std::to_string(directions.cols()) +
                                " directions");
  }
  if (spp < 1) throw std::invalid_argument("--spp must be >= 1, got " + std::to_string(spp));
  const Eigen::Index count = origins.cols();
  Eigen::Matrix3Xf image(3, count);
  constexpr Eigen::Index kTile = 64;
  const Eigen::Index tiles = (count + kTile - 1) / kTile;
  std::atomic<std::uint64_t> done{0};
  std::mutex progress_mutex;
  const RayScene& scene = tracer.scene();
  tbb::parallel_for(Eigen::Index(0), tiles, [&](Eigen::Index tile) {
    const Eigen::Index begin = tile * kTile, size = std::min(kTile, count - begin);
    std::vector<RayHit> hits(static_cast<std::size_t>(size));
    scene.intersect_from(origins.middleCols(begin, size), directions.middleCols(begin, size), 0.f,
                         hits.data());
    std::vector<Eigen::Vector3d> sums(std::size_t(size), Eigen::Vector3d::Zero());
    std::vector<ExitQuery> queries;
    for (Eigen::Index i = 0; i < size; ++i) {
      const Eigen::Vector3d d = directions.col(begin + i).cast<double>().normalized();
      const RayHit& h = hits[std::size_t(i)];
      if (hit) hit[begin + i] = h.triangle >= 0 ? 1 : 0;
      if (h.triangle < 0) {
        sums[std::size_t(i)] = tracer.probe().lookup(d).cast<double>() * spp;
        continue;
      }
      const SurfacePoint p = tracer.surface_point(h.triangle, h.u, h.v);
      if (p.face_normal.dot(d) >= 0) continue;  // back face
      for (int k = 0; k < spp; ++k) {
        queries.push_back(ExitQuery{p, -d,
                                    mix_key(first_key + std::uint64_t(begin + i), std::uint64_t(k)),
                                    std::uint32_t(i)});
      }
    }
    tracer.add_exit_radiance(queries, sums.data());
    for (Eigen::Index i = 0; i < size; ++i) {
      image.col(begin + i) = (sums[std::size_t(i)] / spp).cast<float>();
    }
    const std::uint64_t now = done.fetch_add(std::uint64_t(size)) + std::uint64_t(size);
    if (progress) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      progress(now, std::uint64_t(count));
    }
  });
  return image;
}

}  // namespace prt
