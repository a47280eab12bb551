#pragma once
// The CPU reference backend's work: the shared photon-tracing and gathering code over Embree, in
// labelled parallel loops (TBB). Every result is independent of thread count and scheduling.
// CpuFrameBackend (cpu_frame_backend.h) runs these as the frame pipeline's stages.
#include <vector>

#include "pvr/cpu/embree_intersector.h"
#include "pvr/foveation/mask.h"
#include "pvr/photon/gather.h"
#include "pvr/photon/hash_grid.h"
#include "pvr/photon/host_surface_cache.h"
#include "pvr/photon/kd_tree.h"
#include "pvr/photon/photon_trace.h"

namespace pvr {

class CpuBackend {
 public:
  explicit CpuBackend(const Scene& scene) : scene_(scene), intersector_(scene) {}

  // Traces params.photonCount photons; stored photons come out in photon-index order.
  std::vector<Photon> tracePhotons(const PhotonTraceParams& params) const;

  // Shades every pixel of one eye into `out` (width * height entries, row-major, top row first),
  // taking the other eye's shading where `reuse` allows, and recording each pixel's surface in
  // `surfaces` if given (the eye the other one reuses), and what the denoiser needs in `guides`
  // if given.
  void renderEye(const EyeCamera& camera, Eye eye, const GatherParams& params, const HashGridView& map,
                 PixelSample* out, const StereoReuseView& reuse = StereoReuseView(),
                 SurfaceRecord* surfaces = nullptr, PixelGuide* guides = nullptr) const;
  void renderEye(const EyeCamera& camera, Eye eye, const GatherParams& params, const KdTreeView& map,
                 PixelSample* out, const StereoReuseView& reuse = StereoReuseView(),
                 SurfaceRecord* surfaces = nullptr, PixelGuide* guides = nullptr) const;

  // renderEye with the surface cache (DensityScheme::SurfaceCache): each sample's gather points
  // go into `cache` as a pass of their own, its new cells are estimated, and the Lambertian points
  // take their estimates from it (the cache keeps the cells of earlier passes and eyes).
  void renderEyeCached(const EyeCamera& camera, Eye eye, const GatherParams& params, const HashGridView& map,
                       HostSurfaceCache& cache, PixelSample* out, const StereoReuseView& reuse = StereoReuseView(),
                       SurfaceRecord* surfaces = nullptr, PixelGuide* guides = nullptr) const;
  void renderEyeCached(const EyeCamera& camera, Eye eye, const GatherParams& params, const KdTreeView& map,
                       HostSurfaceCache& cache, PixelSample* out, const StereoReuseView& reuse = StereoReuseView(),
                       SurfaceRecord* surfaces = nullptr, PixelGuide* guides = nullptr) const;

  // Foveated: shades the mask's vertices in use for the gaze pixel (gazeX, gazeY) into
  // `colours` and `inverseDepths` (one per mask vertex; unused ones untouched); returns the
  // vertices shaded. Vertices on pixel centres take the other eye's shading where `reuse` allows
  // (counted in `reused`) and record their surfaces in `surfaces` (per pixel) if given.
  size_t shadeMaskVertices(const EyeCamera& camera, Eye eye, const GatherParams& params, const HashGridView& map,
                           const FoveationMask& mask, int gazeX, int gazeY, std::vector<Vec3>& colours,
                           std::vector<float>& inverseDepths, const StereoReuseView& reuse = StereoReuseView(),
                           SurfaceRecord* surfaces = nullptr, size_t* reused = nullptr) const;
  size_t shadeMaskVertices(const EyeCamera& camera, Eye eye, const GatherParams& params, const KdTreeView& map,
                           const FoveationMask& mask, int gazeX, int gazeY, std::vector<Vec3>& colours,
                           std::vector<float>& inverseDepths, const StereoReuseView& reuse = StereoReuseView(),
                           SurfaceRecord* surfaces = nullptr, size_t* reused = nullptr) const;

  // Scatter: projects every reusable source pixel's surface into `target`'s image, keeping the
  // nearest per target pixel in `scattered` (width * height entries, filled with kNothingScattered
  // here).
  void scatter(const SurfaceRecord* source, size_t sourcePixels, const EyeCamera& target, uint64_t* scattered) const;

  const Scene& scene() const { return scene_; }
  const EmbreeIntersector& intersector() const { return intersector_; }

 private:
  template <class Map>
  size_t shadeMaskVerticesWith(const EyeCamera& camera, Eye eye, const GatherParams& params, const Map& map,
                               const FoveationMask& mask, int gazeX, int gazeY, std::vector<Vec3>& colours,
                               std::vector<float>& inverseDepths, const StereoReuseView& reuse,
                               SurfaceRecord* surfaces, size_t* reused) const;
  template <class Map>
  void renderEyeCachedWith(const EyeCamera& camera, Eye eye, const GatherParams& params, const Map& map,
                           HostSurfaceCache& cache, PixelSample* out, const StereoReuseView& reuse,
                           SurfaceRecord* surfaces, PixelGuide* guides) const;
  template <class Map>
  void renderEyeWith(const EyeCamera& camera, Eye eye, const GatherParams& params, const Map& map,
                     PixelSample* out, const StereoReuseView& reuse, SurfaceRecord* surfaces,
                     PixelGuide* guides) const;
  const Scene& scene_;
  EmbreeIntersector intersector_;
};

}  // namespace pvr
