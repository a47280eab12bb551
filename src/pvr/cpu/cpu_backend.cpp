#include "pvr/cpu/cpu_backend.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>

namespace pvr {

std::vector<Photon> CpuBackend::tracePhotons(const PhotonTraceParams& params) const {
  SceneView view = scene_.view();
  std::vector<Photon> stored;
  const uint32_t chunk = 1u << 16;  // bounds the scratch memory to chunk * maxDepth photons
  const uint32_t slots = uint32_t(std::max(params.maxDepth, 1));
  std::vector<Photon> scratch(size_t(chunk) * slots);
  std::vector<int> counts(chunk);
  for (uint32_t first = 0; first < params.photonCount; first += chunk) {
    uint32_t n = std::min(chunk, params.photonCount - first);
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, n, 256), [&](const tbb::blocked_range<uint32_t>& r) {
      for (uint32_t i = r.begin(); i < r.end(); ++i)
        counts[i] = tracePhoton(view, intersector_, params, first + i, &scratch[size_t(i) * slots]);
    });
    for (uint32_t i = 0; i < n; ++i)
      stored.insert(stored.end(), scratch.begin() + size_t(i) * slots, scratch.begin() + size_t(i) * slots + counts[i]);
  }
  return stored;
}

template <class Map>
void CpuBackend::renderEyeWith(const EyeCamera& camera, Eye eye, const GatherParams& params, const Map& map,
                               PixelSample* out, const StereoReuseView& reuse, SurfaceRecord* surfaces) const {
  SceneView view = scene_.view();
  // 16x16 tiles: coherent rays per task and good load balance.
  tbb::parallel_for(tbb::blocked_range2d<int>(0, camera.height, 16, 0, camera.width, 16),
                    [&](const tbb::blocked_range2d<int>& r) {
                      for (int y = r.rows().begin(); y < r.rows().end(); ++y)
                        for (int x = r.cols().begin(); x < r.cols().end(); ++x) {
                          size_t pixel = size_t(y) * camera.width + x;
                          out[pixel] = shadePixel(view, intersector_, map, params, camera, eye, x, y, reuse,
                                                  surfaces ? surfaces + pixel : nullptr);
                        }
                    });
}

void CpuBackend::renderEye(const EyeCamera& camera, Eye eye, const GatherParams& params, const HashGridView& map,
                           PixelSample* out, const StereoReuseView& reuse, SurfaceRecord* surfaces) const {
  renderEyeWith(camera, eye, params, map, out, reuse, surfaces);
}

void CpuBackend::renderEye(const EyeCamera& camera, Eye eye, const GatherParams& params, const KdTreeView& map,
                           PixelSample* out, const StereoReuseView& reuse, SurfaceRecord* surfaces) const {
  renderEyeWith(camera, eye, params, map, out, reuse, surfaces);
}

template <class Map>
size_t CpuBackend::renderFoveatedEyeWith(const EyeCamera& camera, Eye eye, const GatherParams& params, const Map& map,
                                         const FoveationMask& mask, int gazeX, int gazeY, EyeResult& out,
                                         const StereoReuseView& reuse, SurfaceRecord* surfaces, size_t* reused) const {
  SceneView view = scene_.view();
  std::vector<uint8_t> used = verticesInUse(mask, gazeX, gazeY);
  std::vector<uint32_t> vertices;
  for (uint32_t i = 0; i < used.size(); ++i)
    if (used[i]) vertices.push_back(i);
  std::vector<Vec3> colours(mask.offsets.size());
  std::vector<float> inverseDepths(mask.offsets.size(), 0.0f);
  std::atomic<size_t> reusedVertices{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, vertices.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    size_t reusedHere = 0;
    for (size_t k = r.begin(); k < r.end(); ++k) {
      const uint32_t v = vertices[k];
      const MaskPoint& o = mask.offsets[v];
      PixelSample sample;
      GatherPoint point = vertexGatherPoint(view, intersector_, params, camera, eye, o.x + float(gazeX) + 0.5f,
                                            o.y + float(gazeY) + 0.5f, reuse, sample, surfaces);
      colours[v] = finishGather(map, point, params.density);
      inverseDepths[v] = sample.inverseDepth;
      reusedHere += sample.reusedFrom != kNotReused ? 1 : 0;
    }
    reusedVertices += reusedHere;
  });
  reconstructFoveatedEye(mask, gazeX, gazeY, colours, inverseDepths, out);
  out.firstPrim.clear();
  if (reused) *reused = reusedVertices;
  return vertices.size();
}

size_t CpuBackend::renderFoveatedEye(const EyeCamera& camera, Eye eye, const GatherParams& params,
                                     const HashGridView& map, const FoveationMask& mask, int gazeX, int gazeY,
                                     EyeResult& out, const StereoReuseView& reuse, SurfaceRecord* surfaces,
                                     size_t* reused) const {
  return renderFoveatedEyeWith(camera, eye, params, map, mask, gazeX, gazeY, out, reuse, surfaces, reused);
}

size_t CpuBackend::renderFoveatedEye(const EyeCamera& camera, Eye eye, const GatherParams& params, const KdTreeView& map,
                                     const FoveationMask& mask, int gazeX, int gazeY, EyeResult& out,
                                     const StereoReuseView& reuse, SurfaceRecord* surfaces, size_t* reused) const {
  return renderFoveatedEyeWith(camera, eye, params, map, mask, gazeX, gazeY, out, reuse, surfaces, reused);
}

void CpuBackend::scatter(const SurfaceRecord* source, size_t sourcePixels, const EyeCamera& target,
                           uint64_t* scattered) const {
  SceneView view = scene_.view();
  std::fill(scattered, scattered + size_t(target.width) * target.height, kNothingScattered);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, sourcePixels, 1024), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      uint32_t pixel;
      uint64_t entry;
      if (!scatterTarget(view, intersector_, source[i], uint32_t(i), target, pixel, entry)) continue;
      std::atomic_ref<uint64_t> slot(scattered[pixel]);  // keep the nearest: an atomic minimum
      uint64_t current = slot.load(std::memory_order_relaxed);
      while (entry < current && !slot.compare_exchange_weak(current, entry, std::memory_order_relaxed)) {
      }
    }
  });
}

}  // namespace pvr
