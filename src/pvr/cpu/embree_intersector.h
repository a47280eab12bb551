#pragma once
// The CPU backend's ray queries: one Embree 3 scene over the scene's triangles (primitive ids =
// scene triangle indices), with the Intersector interface the shared algorithm code expects.
#include <embree3/rtcore.h>

#include "pvr/scene/scene.h"

namespace pvr {

class EmbreeIntersector {
 public:
  explicit EmbreeIntersector(const Scene& scene);
  ~EmbreeIntersector();
  EmbreeIntersector(const EmbreeIntersector&) = delete;
  EmbreeIntersector& operator=(const EmbreeIntersector&) = delete;

  bool intersect(const Ray& ray, float tMax, Hit& hit) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = ray.origin.x;
    rh.ray.org_y = ray.origin.y;
    rh.ray.org_z = ray.origin.z;
    rh.ray.dir_x = ray.dir.x;
    rh.ray.dir_y = ray.dir.y;
    rh.ray.dir_z = ray.dir.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = tMax;
    rh.ray.mask = ~0u;
    rh.ray.flags = 0;
    rh.ray.time = 0.0f;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit.t = rh.ray.tfar;
    hit.primId = rh.hit.primID;
    hit.u = rh.hit.u;
    hit.v = rh.hit.v;
    return true;
  }

  bool occluded(const Ray& ray, float tMax) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay r;
    r.org_x = ray.origin.x;
    r.org_y = ray.origin.y;
    r.org_z = ray.origin.z;
    r.dir_x = ray.dir.x;
    r.dir_y = ray.dir.y;
    r.dir_z = ray.dir.z;
    r.tnear = 0.0f;
    r.tfar = tMax;
    r.mask = ~0u;
    r.flags = 0;
    r.time = 0.0f;
    rtcOccluded1(scene_, &context, &r);
    return r.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
  }

 private:
  SceneView alphaScene_;  // alpha-tested scenes: the filter functions read the materials through it
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
};

}  // namespace pvr
