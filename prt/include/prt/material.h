// prt/material.h: reflectance models and their SH BRDF matrices.
//
// All BRDFs are isotropic and evaluated in the local frame (z = normal): v points toward the
// viewer, s toward the light, both unit; f_r is zero when v.z <= 0 or s.z <= 0.
//  - Lambert:       f = rho_d / pi
//  - Phong:         f = rho_d / pi + rho_s (e + 2) / (2 pi) max(0, r.v)^e, r = 2 (s.z) z - s
//                   (the energy-normalised "modified Phong" of Lafortune & Willems 1994)
//  - Cook-Torrance: f = rho_d / pi + rho_s D(h) G(v, s) F(v.h) / (4 v.z s.z), h = (v+s)/|v+s|
//                   D Beckmann with roughness m, F Fresnel-Schlick with f0, and G either
//                   - smith (the default): Smith's height-correlated masking-shadowing for
//                     Beckmann, 1 / (1 + Lambda(v) + Lambda(s)), Lambda(w) = (erf(a) - 1) / 2
//                     + exp(-a^2) / (2 a sqrt(pi)), a = w.z / (m sqrt(1 - w.z^2)) (Heitz,
//                     "Understanding the masking-shadowing function", JCGT 2014), or
//                   - v-groove: the original Cook-Torrance term
//                     min(1, 2 h.z v.z / v.h, 2 h.z s.z / v.h) (the thesis's model).
//                   Smith is the default because it follows from the microsurface Beckmann
//                   describes and is what path tracers use, so independent references agree.
// rho_d is RGB; when its three channels are equal the material is grey and transfer needs one
// channel, otherwise three (rho_s, e, m and f0 are the same for all channels).
//
// BRDF matrix (thesis ch. 3.1.1), for one channel: with g_j(v) = int_{s.z>0} f_r(v, s) s.z
// y_j(s) ds, the exit radiance of local lighting y_j, B's column j holds the view-side fit of
// g_j (prt/view_fit.h), so that exit radiance toward local v (v.z >= 0) is y(v)^T B l_local for
// local incident lighting l_local. The thesis's fit is B_ij = int_{v.z>0} y_i g_j.
#pragma once

#include "common/enum_names.h"

#include "prt/view_fit.h"

#include <Eigen/Core>

#include <string>

namespace prt {

enum class MaterialKind { kLambert, kPhong, kCookTorrance };
enum class Masking { kSmith, kVGroove };  // Cook-Torrance's G

struct Material {
  MaterialKind kind = MaterialKind::kPhong;
  Eigen::Vector3f albedo = Eigen::Vector3f::Constant(0.5f);  // rho_d per channel, in [0, 1]
  float specular = 0.3f;   // rho_s in [0, 1]; rho_d + rho_s <= 1 per channel
  float exponent = 32.f;   // Phong e in [0, 10000]
  float roughness = 0.3f;  // Cook-Torrance Beckmann m in (0, 1]
  float f0 = 0.04f;        // Fresnel reflectance at normal incidence, in [0, 1]
  Masking masking = Masking::kSmith;

  bool grey() const { return albedo.x() == albedo.y() && albedo.y() == albedo.z(); }
  int channels() const { return grey() ? 1 : 3; }
  // Throws std::invalid_argument naming the parameter (as its CLI flag, e.g. "--exponent")
  // and the allowed range.
  void validate() const;
};

inline constexpr auto kMaterialNames =
    common::enum_table<MaterialKind>("material", {{MaterialKind::kLambert, "lambert"},
                                                  {MaterialKind::kPhong, "phong"},
                                                  {MaterialKind::kCookTorrance, "cook-torrance"}});
inline constexpr auto kMaskingNames = common::enum_table<Masking>(
    "masking", {{Masking::kSmith, "smith"}, {Masking::kVGroove, "v-groove"}});

// f_r for one channel (0..2; a grey material ignores it). Local frame, unit vectors.
double brdf_eval(const Material& material, int channel, const Eigen::Vector3d& v,
                 const Eigen::Vector3d& s);

// brdf_eval(material, channel, v, s_i) for every column s_i of `s` at once, on Eigen arrays
// so that exp and pow run as packets (equal to brdf_eval to rounding). The caller
// guarantees v.z > 0 and s_i.z > 0 (where brdf_eval would return 0). By reciprocity this is
// also f_r(s_i, v): one light direction against many views.
Eigen::ArrayXd brdf_eval_batch(const Material& material, int channel, const Eigen::Vector3d& v,
                               const Eigen::Matrix3Xd& s);

struct BrdfQuadrature {
  // Gauss-Legendre nodes in cos(theta) x uniform nodes in phi, for the view (v) and light (s)
  // hemispheres. 0 = chosen from the material (sharper lobes get finer s grids).
  int view_theta = 0, view_phi = 0, light_theta = 0, light_phi = 0;
};

// The grid brdf_matrix uses: the non-zero fields of `quadrature`, and for each zero field the
// default chosen from the material and order (the rule and its reasons are in material.cpp).
// Defaults keep light_phi a multiple of view_phi > 2 (order - 1), which makes B commute with
// rotations about the normal up to rounding; explicit grids should do the same.
// Throws std::invalid_argument for a negative field or an unsupported order.
BrdfQuadrature resolve_brdf_quadrature(const Material& material, int order,
                                       const BrdfQuadrature& quadrature = {});

// n x n BRDF matrix (n = order^2) for one channel, by product quadrature. Cost is dominated
// by f_r evaluations (view nodes x light nodes) and runs in parallel; a glossy Phong lobe at
// order 6 takes well under a second.
Eigen::MatrixXd brdf_matrix(const Material& material, int order, int channel,
                            const BrdfQuadrature& quadrature = {}, ViewFit fit = kDefaultViewFit,
                            double view_lambda = kViewFitLambda);

// Directional albedo int_{s.z>0} f_r(v, s) s.z ds of one channel toward the local view v
// (v.z > 0), by a dense product quadrature independent of brdf_matrix's grids (the oracle of
// the white-sky tests and benchmarks).
double directional_albedo(const Material& material, int channel, const Eigen::Vector3d& v);

// Lambert's B in closed form, rank one on the m = 0 entries. Exit radiance is the constant
// (rho / pi) b . l (b_l the clamped-cosine zonal coefficients), which the least-squares and
// even fits represent exactly: sqrt(4 pi) (rho / pi) e_0 b^T. The thesis's fit gives
// (rho / pi) a b^T with a_l = int y_l^0 over the hemisphere; HSH's is that of hemisphere
// with a_l = sqrt(2 pi) on l = 0 only.
Eigen::MatrixXd lambert_brdf_matrix(double albedo, int order, ViewFit fit = kDefaultViewFit);

}  // namespace prt
