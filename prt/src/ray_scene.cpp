// The only file that includes Embree. Rays go in 16-wide packets (RTCRay16, structure of
// arrays), flagged coherent: all rays of a packet share their origin.
#include "prt/ray_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <limits>
#include <string>

namespace prt {
namespace {

constexpr int kPacket = 16;

void on_embree_error(void* user, RTCError code, const char* message) {
  auto* last = static_cast<std::string*>(user);
  *last = "Embree error " + std::to_string(int(code)) + ": " + (message ? message : "");
}

// Fills a 16-wide packet with rays start .. start+width-1 from one origin; lanes past
// `width` repeat the last ray and are masked off in `valid`.
void fill_packet(RTCRay16& rays, int* valid, const Eigen::Vector3f& origin,
                 const Eigen::Ref<const Eigen::Matrix3Xf>& directions, Eigen::Index start,
                 int width, float tnear) {
  for (int k = 0; k < kPacket; ++k) {
    const Eigen::Index col = start + std::min(k, width - 1);
    valid[k] = k < width ? -1 : 0;
    rays.org_x[k] = origin.x();
    rays.org_y[k] = origin.y();
    rays.org_z[k] = origin.z();
    rays.tnear[k] = tnear;
    rays.dir_x[k] = directions(0, col);
    rays.dir_y[k] = directions(1, col);
    rays.dir_z[k] = directions(2, col);
    rays.time[k] = 0.f;
    rays.tfar[k] = std::numeric_limits<float>::infinity();
    rays.mask[k] = 0xffffffffu;
    rays.id[k] = unsigned(k);
    rays.flags[k] = 0;
  }
}

}  // namespace

struct RayScene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::string last_error;

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
  void check(const char* what) const {
    if (!last_error.empty()) throw RayError(std::string(what) + ": " + last_error);
  }
};

RayScene::RayScene(const meshes::Mesh& mesh) : impl_(std::make_unique<Impl>()) {
  if (mesh.triangles.empty()) throw RayError("ray scene: mesh has no triangles");
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) {
    throw RayError("ray scene: cannot create an Embree device (error " +
                   std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
  }
  rtcSetDeviceErrorFunction(impl_->device, on_embree_error, &impl_->last_error);

  RTCGeometry geometry = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  // Embree allocates the buffers with the padding its SIMD loads need past the last vertex.
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                               RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                               mesh.positions.size()));
  auto* indices = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                              3 * sizeof(unsigned), mesh.triangles.size()));
  impl_->check("ray scene: allocating buffers");
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    vertices[3 * i + 0] = mesh.positions[i].x();
    vertices[3 * i + 1] = mesh.positions[i].y();
    vertices[3 * i + 2] = mesh.positions[i].z();
  }
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    for (int c = 0; c < 3; ++c) indices[3 * i + c] = mesh.triangles[i][c];
  }
  rtcCommitGeometry(geometry);
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  rtcAttachGeometry(impl_->scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(impl_->scene);
  impl_->check("ray scene: building the BVH");
}

RayScene::~RayScene() = default;

void RayScene::occluded(const Eigen::Vector3f& origin,
                        const Eigen::Ref<const Eigen::Matrix3Xf>& directions, float tnear,
                        std::uint8_t* occluded) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  RTCRay16 rays;
  alignas(64) int valid[kPacket];
  const Eigen::Index count = directions.cols();
  for (Eigen::Index start = 0; start < count; start += kPacket) {
    const int width = int(std::min<Eigen::Index>(kPacket, count - start));
    fill_packet(rays, valid, origin, directions, start, width, tnear);
    rtcOccluded16(valid, impl_->scene, &context, &rays);
    // Embree marks an occluded ray by setting tfar to -inf.
    for (int k = 0; k < width; ++k) occluded[start + k] = rays.tfar[k] < 0.f ? 1 : 0;
  }
}

void RayScene::intersect(const Eigen::Vector3f& origin,
                         const Eigen::Ref<const Eigen::Matrix3Xf>& directions, float tnear,
                         RayHit* hits) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  RTCRayHit16 rh;
  alignas(64) int valid[kPacket];
  const Eigen::Index count = directions.cols();
  for (Eigen::Index start = 0; start < count; start += kPacket) {
    const int width = int(std::min<Eigen::Index>(kPacket, count - start));
    fill_packet(rh.ray, valid, origin, directions, start, width, tnear);
    for (int k = 0; k < kPacket; ++k) {
      rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.primID[k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, impl_->scene, &context, &rh);
    for (int k = 0; k < width; ++k) {
      RayHit& h = hits[start + k];
      if (rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) {
        h = RayHit{};
      } else {
        h.triangle = std::int32_t(rh.hit.primID[k]);
        h.u = rh.hit.u[k];
        h.v = rh.hit.v[k];
        h.t = rh.ray.tfar[k];
      }
    }
  }
}

}  // namespace prt
