#include "pvr/cpu/embree_intersector.h"

#include <cstring>
#include <string>

#include "pvr/util/error.h"

namespace pvr {
namespace {

// Any-hit filter for alpha masking: a hit on a cut-out texel is rejected and the ray goes on.
void alphaFilter(const RTCFilterFunctionNArguments* args) {
  const SceneView* scene = static_cast<const SceneView*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    if (!scene->alphaPasses(prim, RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i))) args->valid[i] = 0;
  }
}

}  // namespace

EmbreeIntersector::EmbreeIntersector(const Scene& scene) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw Error("cannot create an Embree device (error " + std::to_string(rtcGetDeviceError(nullptr)) + ")");
  scene_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  const auto& vertices = scene.vertices();
  const auto& indices = scene.indices();
  // Embree's buffers are over-allocated by 16 bytes: it may read past the last vertex with SSE.
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                         3 * sizeof(float), vertices.size()));
  auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                            3 * sizeof(uint32_t), indices.size() / 3));
  if (!vb || !ib) throw Error("out of memory while building the Embree scene");
  std::memcpy(vb, vertices.data(), vertices.size() * sizeof(Vec3));
  std::memcpy(ib, indices.data(), indices.size() * sizeof(uint32_t));
  if (scene.hasAlphaTestedMaterial()) {
    alphaScene_ = scene.view();
    rtcSetGeometryUserData(geom, &alphaScene_);
    rtcSetGeometryIntersectFilterFunction(geom, alphaFilter);
    rtcSetGeometryOccludedFilterFunction(geom, alphaFilter);
  }
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene_, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene_);
  if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw Error("Embree failed to build the scene's BVH");
}

EmbreeIntersector::~EmbreeIntersector() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

}  // namespace pvr
