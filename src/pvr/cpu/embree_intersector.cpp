#include "pvr/cpu/embree_intersector.h"

#include <cstring>
#include <string>

#include "pvr/util/error.h"

namespace pvr {

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
