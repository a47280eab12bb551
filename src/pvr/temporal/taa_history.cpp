#include "pvr/temporal/taa_history.h"

#include <atomic>

#include "pvr/util/error.h"
#include "pvr/util/parallel_for.h"

namespace pvr {

size_t resolveTemporal(const EyeCamera& camera, const TaaParams& params, const Image& current,
                       const std::vector<float>& inverseDepth, const float* sampleSpacing, TaaHistory& history,
                       Image& displayed, const TaaEmitted& emission) {
  const size_t pixels = size_t(camera.width) * camera.height;
  if (current.pixels.size() != pixels || inverseDepth.size() != pixels)
    throw Error("TAA needs the eye's image and its per-pixel depth");
  if (history.valid && (history.camera.width != camera.width || history.camera.height != camera.height))
    history.valid = false;
  TaaView view;
  view.camera = camera;
  view.previousCamera = history.camera;
  view.current = current.pixels.data();
  view.inverseDepth = inverseDepth.data();
  view.sampleSpacing = sampleSpacing;
  view.history = history.valid ? history.image.pixels.data() : nullptr;
  view.historyInverseDepth = history.valid ? history.inverseDepth.data() : nullptr;
  view.emission = emission;
  view.params = params;
  Image resolved(camera.width, camera.height), out(camera.width, camera.height);
  std::atomic<size_t> used{0};
  parallelFor("temporal resolve", size_t(camera.height), 8, [&](size_t begin, size_t end) {
    size_t n = 0;
    for (int y = int(begin); y < int(end); ++y)
      for (int x = 0; x < camera.width; ++x) {
        const TaaPixel p = resolveTemporalPixel(view, x, y);
        const size_t pixel = size_t(y) * camera.width + x;
        resolved.pixels[pixel] = p.history;
        out.pixels[pixel] = p.displayed;
        n += p.usedHistory ? 1 : 0;
      }
    used += n;
  });
  history.image = std::move(resolved);
  history.inverseDepth = inverseDepth;
  history.camera = camera;
  history.valid = true;
  displayed = std::move(out);
  return used;
}

}  // namespace pvr
