#include "render/shading.h"

#include "prt/sh.h"
#include "prt/view_fit.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace render {

namespace {

using RowMatrixXf = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

int rows_of(int order, bool glossy) {
  return glossy ? order * order : 1;
}

// y(local view) for glossy transfer, or the constant 1 that makes diffuse view independent.
void basis_at(int order, bool glossy, const Eigen::Vector3d& local, float* y) {
  if (glossy)
    prt::sh_eval(order, float(local.x()), float(local.y()), float(local.z()), y);
  else
    y[0] = 1.f;
}

}  // namespace

ConstantLayout constant_layout(int order, bool glossy, int components) {
  ConstantLayout l;
  l.glossy = glossy;
  l.order = glossy ? order : 1;
  l.rows = rows_of(order, glossy);
  l.terms = components + 1;
  return l;
}

ConstantLayout constant_layout(const cpca::CompressedSet& set) {
  return constant_layout(set.order, set.glossy(), set.component_count);
}

ShadingConstants::ShadingConstants(const cpca::CompressedSet& set)
    : layout_(constant_layout(set)),
      cluster_count_(set.cluster_count),
      channels_(set.channels),
      order_(set.order) {
  const int n = set.coefficient_count();
  const int rows_per_term = channels_ * layout_.rows;
  packed_.resize(std::size_t(cluster_count_));
  for (int k = 0; k < cluster_count_; ++k) {
    RowMatrixXf& m = packed_[std::size_t(k)];
    m.resize(Eigen::Index(layout_.terms) * rows_per_term, n);
    // x reshaped row-major to (channels * rows) x n is exactly the stack of transfer rows.
    m.topRows(rows_per_term) = Eigen::Map<const RowMatrixXf>(set.mean(k).data(), rows_per_term, n);
    const auto basis = set.basis(k);
    for (int j = 0; j < set.component_count; ++j)
      m.middleRows(Eigen::Index(j + 1) * rows_per_term, rows_per_term) =
          Eigen::Map<const RowMatrixXf>(basis.row(j).data(), rows_per_term, n);
  }
}

void ShadingConstants::compute(const Eigen::Ref<const prt::ShLighting>& lighting,
                               const std::vector<std::uint32_t>& slot_of, float* out) const {
  const int n = order_ * order_;
  if (lighting.rows() != n)
    throw std::invalid_argument("lighting has " + std::to_string(lighting.rows()) +
                                " SH rows but the compressed set is order " +
                                std::to_string(order_) + " (" + std::to_string(n) +
                                "); project the probe at the set's order");
  if (slot_of.size() != std::size_t(cluster_count_))
    throw std::invalid_argument(
        "ShadingConstants::compute: slot_of must have one entry per cluster");
  const Eigen::Matrix<float, Eigen::Dynamic, 3> l = lighting.cast<float>();
  const ConstantLayout lay = layout_;
  tbb::parallel_for(
      tbb::blocked_range<int>(0, cluster_count_, 4), [&](const tbb::blocked_range<int>& range) {
        Eigen::Matrix<float, Eigen::Dynamic, 3> product;
        for (int k = range.begin(); k < range.end(); ++k) {
          product.noalias() = packed_[std::size_t(k)] * l;
          float* dst = out + std::size_t(slot_of[std::size_t(k)]) * lay.floats_stride();
          for (int t = 0; t < lay.terms; ++t)
            for (int c = 0; c < 3; ++c)
              for (int i = 0; i < lay.rows; ++i)
                dst[lay.offset(t, c, i)] = product(row(t, c, i), c);
          std::fill(dst + lay.floats_per_cluster(), dst + lay.floats_stride(), 0.f);
        }
      });
}

Eigen::Vector3d local_view(const meshes::Mesh& mesh, std::size_t p, const Eigen::Vector3d& eye) {
  const Eigen::Vector3d v = (eye - mesh.positions[p].cast<double>()).normalized();
  return prt::clamp_to_horizon(Eigen::Vector3d(mesh.tangents[p].cast<double>().dot(v),
                                               mesh.bitangents[p].cast<double>().dot(v),
                                               mesh.normals[p].cast<double>().dot(v)));
}

void shade_vertices(const cpca::CompressedSet& set, const ConstantLayout& layout,
                    const float* constants, const meshes::Mesh& mesh, const Eigen::Vector3d& eye,
                    std::vector<Rgb>& radiance) {
  const std::size_t vertex_count = mesh.vertex_count();
  radiance.resize(vertex_count);
  const int N = layout.terms - 1;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, vertex_count, 256),
      [&](const tbb::blocked_range<std::size_t>& range) {
        Eigen::VectorXf y(layout.rows);
        Eigen::VectorXf s(layout.terms * 3);
        for (std::size_t p = range.begin(); p < range.end(); ++p) {
          const Eigen::Vector3d local = local_view(mesh, p, eye);
          basis_at(layout.order, layout.glossy, local, y.data());
          const float* k = constants + std::size_t(set.cluster_of[p]) * layout.floats_stride();
          // (terms * 3) x rows, row-major: one row per (term, colour).
          s.noalias() = Eigen::Map<const RowMatrixXf>(k, layout.terms * 3, layout.rows) * y;
          Rgb r = s.head<3>();
          const float* w = set.weights.data() + p * std::size_t(N);
          for (int j = 0; j < N; ++j) r += w[j] * s.segment<3>(3 * (j + 1));
          radiance[p] = r;
        }
      });
}

std::vector<Rgb> reference_vertex_radiance(const cpca::CompressedSet& set, const meshes::Mesh& mesh,
                                           const Eigen::Ref<const prt::ShLighting>& lighting,
                                           const Eigen::Vector3d& eye) {
  if (!mesh.has_frames() || mesh.vertex_count() != set.vertex_count)
    throw std::invalid_argument("reference_vertex_radiance: the mesh needs frames and " +
                                std::to_string(set.vertex_count) + " vertices");
  const int n = set.coefficient_count();
  const bool glossy = set.glossy();
  const int rows = rows_of(set.order, glossy);
  std::vector<Rgb> out(mesh.vertex_count());
  std::vector<float> x(set.dimension());
  std::vector<double> y(std::size_t(std::max(rows, 1)));
  for (std::size_t p = 0; p < mesh.vertex_count(); ++p) {
    cpca::reconstruct_vertex(set, p, x.data());
    const Eigen::Vector3d local = local_view(mesh, p, eye);
    if (glossy)
      prt::sh_eval(set.order, local, y.data());
    else
      y[0] = 1.0;
    for (int c = 0; c < 3; ++c) {
      const int channel = set.channels == 1 ? 0 : c;
      double r = 0.0;
      for (int i = 0; i < rows; ++i) {
        double e = 0.0;
        for (int j = 0; j < n; ++j)
          e += double(x[(std::size_t(channel) * rows + i) * n + j]) * lighting(j, c);
        r += y[std::size_t(i)] * e;
      }
      out[p][c] = float(r);
    }
  }
  return out;
}

void exit_vectors(const prt::TransferSet& transfer,
                  const Eigen::Ref<const prt::ShLighting>& lighting, std::vector<float>& out) {
  const int n = transfer.coefficient_count();
  if (lighting.rows() != n)
    throw std::invalid_argument("lighting has " + std::to_string(lighting.rows()) +
                                " SH rows but the transfer is order " +
                                std::to_string(transfer.order));
  const bool glossy = transfer.kind == prt::TransferKind::kGlossy;
  const int rows = rows_of(transfer.order, glossy);
  const int channels = transfer.channels;
  const std::size_t vertex_count = transfer.vertex_count;
  out.resize(vertex_count * 3 * std::size_t(rows));
  const Eigen::Matrix<float, Eigen::Dynamic, 3> l = lighting.cast<float>();
  const Eigen::Index rows_per_vertex = Eigen::Index(channels) * rows;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, vertex_count, 512),
      [&](const tbb::blocked_range<std::size_t>& range) {
        const Eigen::Index count = Eigen::Index(range.size());
        const Eigen::Map<const RowMatrixXf> m(
            transfer.data.data() + range.begin() * rows_per_vertex * n, count * rows_per_vertex, n);
        const Eigen::Matrix<float, Eigen::Dynamic, 3> product = m * l;
        for (Eigen::Index v = 0; v < count; ++v) {
          float* dst = out.data() + (range.begin() + std::size_t(v)) * 3 * std::size_t(rows);
          for (int c = 0; c < 3; ++c) {
            const Eigen::Index base =
                v * rows_per_vertex + Eigen::Index(channels == 1 ? 0 : c) * rows;
            for (int i = 0; i < rows; ++i) dst[c * rows + i] = product(base + i, c);
          }
        }
      });
}

}  // namespace render
