#include "pvr/cpu/cpu_backend.h"

#include <algorithm>
#include <atomic>

#include "pvr/util/parallel_for.h"

namespace pvr {

std::vector<Photon> CpuBackend::tracePhotons(const PhotonTraceParams& params) const {
  SceneView view = scene_.view();
  std::vector<Photon> stored;
  const uint32_t chunk = 1u << 16;  // bounds the scratch memory to chunk * maxDepth photons
  const uint32_t slots = uint32_t(std::max(params.maxDepth, 1));
  std::vector<Photon> scratch(size_t(chunk) * slots);
  std::vector<int> counts(chunk);
  const uint32_t last = params.lastPhoton();
  for (uint32_t first = params.firstPhoton; first < last; first += chunk) {
    uint32_t n = std::min(chunk, last - first);
    parallelFor("photon trace", n, 256, [&](size_t begin, size_t end) {
      for (uint32_t i = uint32_t(begin); i < uint32_t(end); ++i)
        counts[i] = tracePhoton(view, intersector_, params, first + i, &scratch[size_t(i) * slots]);
    });
    for (uint32_t i = 0; i < n; ++i)
      stored.insert(stored.end(), scratch.begin() + size_t(i) * slots, scratch.begin() + size_t(i) * slots + counts[i]);
  }
  return stored;
}

template <class Map>
void CpuBackend::renderEyeWith(const EyeCamera& camera, Eye eye, const GatherParams& params, const Map& map,
                               PixelSample* out, const StereoReuseView& reuse, SurfaceRecord* surfaces,
                               PixelGuide* guides) const {
  SceneView view = scene_.view();
  // 16x16 tiles: coherent rays per task and good load balance.
  parallelForTiles("eye pass", camera.height, camera.width, 16, [&](int y0, int y1, int x0, int x1) {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        size_t pixel = size_t(y) * camera.width + x;
        out[pixel] = shadePixel(view, intersector_, map, params, camera, eye, x, y, reuse,
                                surfaces ? surfaces + pixel : nullptr, guides ? guides + pixel : nullptr);
      }
  });
}

void CpuBackend::renderEye(const EyeCamera& camera, Eye eye, const GatherParams& params, const HashGridView& map,
                           PixelSample* out, const StereoReuseView& reuse, SurfaceRecord* surfaces,
                           PixelGuide* guides) const {
  renderEyeWith(camera, eye, params, map, out, reuse, surfaces, guides);
}

void CpuBackend::renderEye(const EyeCamera& camera, Eye eye, const GatherParams& params, const KdTreeView& map,
                           PixelSample* out, const StereoReuseView& reuse, SurfaceRecord* surfaces,
                           PixelGuide* guides) const {
  renderEyeWith(camera, eye, params, map, out, reuse, surfaces, guides);
}

// shadePixel's sample loop split at the gather points, so that a sample's points of the whole
// image enter the cache before any of them is finished.
template <class Map>
void CpuBackend::renderEyeCachedWith(const EyeCamera& camera, Eye eye, const GatherParams& params, const Map& map,
                                     HostSurfaceCache& cache, PixelSample* out, const StereoReuseView& reuse,
                                     SurfaceRecord* surfaces, PixelGuide* guides) const {
  SceneView view = scene_.view();
  const size_t pixels = size_t(camera.width) * camera.height;
  std::vector<GatherPoint> points(pixels);
  std::vector<Vec3> radiance(pixels, Vec3(0.0f));
  for (int s = 0; s < params.samplesPerPixel; ++s) {
    parallelForTiles("eye rays", camera.height, camera.width, 16, [&](int y0, int y1, int x0, int x1) {
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          const size_t pixel = size_t(y) * camera.width + x;
          if (s == 0) out[pixel] = PixelSample();
          points[pixel] = pixelGatherPoint(view, intersector_, params, camera, eye, x, y, s, reuse, out[pixel],
                                           s == 0 && surfaces ? surfaces + pixel : nullptr);
          if (!guides) continue;
          const GatherPoint& p = points[pixel];
          PixelGuide& g = guides[pixel];
          if (s == 0) g = PixelGuide(), g.albedo = p.reflectance, g.normal = p.normal;
          g.direct += p.radiance;
          g.emitted += p.emitted;
        }
    });
    cache.insert(points.data(), pixels);
    cache.estimateCreated(map, params.density);
    const SurfaceCacheView cached = cache.view();
    parallelFor("cached estimates", pixels, 4096, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) radiance[i] += finishGatherCached(cached, map, points[i], params.density);
    });
  }
  const float inverseSamples = 1.0f / float(params.samplesPerPixel);
  parallelFor("cached pixels", pixels, 4096, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      if (out[i].reusedFrom != kNotReused) {  // the other eye's finished colour, as shadePixel gives it
        out[i].radiance = points[i].radiance;
        if (guides) guides[i].direct = points[i].radiance, guides[i].emitted = Vec3(0.0f);
        continue;
      }
      out[i].radiance = radiance[i] * inverseSamples;
      if (guides) guides[i].direct *= inverseSamples, guides[i].emitted *= inverseSamples;
    }
  });
}

void CpuBackend::renderEyeCached(const EyeCamera& camera, Eye eye, const GatherParams& params, const HashGridView& map,
                                 HostSurfaceCache& cache, PixelSample* out, const StereoReuseView& reuse,
                                 SurfaceRecord* surfaces, PixelGuide* guides) const {
  renderEyeCachedWith(camera, eye, params, map, cache, out, reuse, surfaces, guides);
}

void CpuBackend::renderEyeCached(const EyeCamera& camera, Eye eye, const GatherParams& params, const KdTreeView& map,
                                 HostSurfaceCache& cache, PixelSample* out, const StereoReuseView& reuse,
                                 SurfaceRecord* surfaces, PixelGuide* guides) const {
  renderEyeCachedWith(camera, eye, params, map, cache, out, reuse, surfaces, guides);
}

template <class Map>
size_t CpuBackend::shadeMaskVerticesWith(const EyeCamera& camera, Eye eye, const GatherParams& params, const Map& map,
                                         const FoveationMask& mask, int gazeX, int gazeY, std::vector<Vec3>& colours,
                                         std::vector<float>& inverseDepths, const StereoReuseView& reuse,
                                         SurfaceRecord* surfaces, size_t* reused) const {
  SceneView view = scene_.view();
  std::vector<uint8_t> used = verticesInUse(mask, gazeX, gazeY);
  std::vector<uint32_t> vertices;
  for (uint32_t i = 0; i < used.size(); ++i)
    if (used[i]) vertices.push_back(i);
  colours.resize(mask.offsets.size());
  inverseDepths.assign(mask.offsets.size(), 0.0f);
  std::atomic<size_t> reusedVertices{0};
  parallelFor("foveated vertices", vertices.size(), 256, [&](size_t begin, size_t end) {
    size_t reusedHere = 0;
    for (size_t k = begin; k < end; ++k) {
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
  if (reused) *reused = reusedVertices;
  return vertices.size();
}

size_t CpuBackend::shadeMaskVertices(const EyeCamera& camera, Eye eye, const GatherParams& params,
                                     const HashGridView& map, const FoveationMask& mask, int gazeX, int gazeY,
                                     std::vector<Vec3>& colours, std::vector<float>& inverseDepths,
                                     const StereoReuseView& reuse, SurfaceRecord* surfaces, size_t* reused) const {
  return shadeMaskVerticesWith(camera, eye, params, map, mask, gazeX, gazeY, colours, inverseDepths, reuse, surfaces,
                               reused);
}

size_t CpuBackend::shadeMaskVertices(const EyeCamera& camera, Eye eye, const GatherParams& params, const KdTreeView& map,
                                     const FoveationMask& mask, int gazeX, int gazeY, std::vector<Vec3>& colours,
                                     std::vector<float>& inverseDepths, const StereoReuseView& reuse,
                                     SurfaceRecord* surfaces, size_t* reused) const {
  return shadeMaskVerticesWith(camera, eye, params, map, mask, gazeX, gazeY, colours, inverseDepths, reuse, surfaces,
                               reused);
}

void CpuBackend::scatter(const SurfaceRecord* source, size_t sourcePixels, const EyeCamera& target,
                           uint64_t* scattered) const {
  SceneView view = scene_.view();
  std::fill(scattered, scattered + size_t(target.width) * target.height, kNothingScattered);
  parallelFor("stereo scatter", sourcePixels, 1024, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
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
