#include "pvr/temporal/taa_history.h"

#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include "pvr/util/error.h"

namespace pvr {

size_t resolveTemporal(const EyeCamera& camera, const TaaParams& params, EyeResult& eye, TaaHistory& history) {
  const size_t pixels = size_t(camera.width) * camera.height;
  if (eye.image.pixels.size() != pixels || eye.inverseDepth.size() != pixels)
    throw Error("TAA needs the eye's image and its per-pixel depth");
  if (history.valid && (history.camera.width != camera.width || history.camera.height != camera.height))
    history.valid = false;
  TaaView view;
  view.camera = camera;
  view.previousCamera = history.camera;
  view.current = eye.image.pixels.data();
  view.inverseDepth = eye.inverseDepth.data();
  view.sampleSpacing = eye.sampleSpacing.empty() ? nullptr : eye.sampleSpacing.data();
  view.history = history.valid ? history.image.pixels.data() : nullptr;
  view.historyInverseDepth = history.valid ? history.inverseDepth.data() : nullptr;
  view.params = params;
  Image out(camera.width, camera.height);
  tbb::combinable<size_t> used;
  tbb::parallel_for(tbb::blocked_range<int>(0, camera.height, 8), [&](const tbb::blocked_range<int>& rows) {
    size_t n = 0;
    for (int y = rows.begin(); y < rows.end(); ++y)
      for (int x = 0; x < camera.width; ++x) {
        bool usedHistory;
        out.pixels[size_t(y) * camera.width + x] = resolveTemporalPixel(view, x, y, usedHistory);
        n += usedHistory ? 1 : 0;
      }
    used.local() += n;
  });
  history.image = out;
  history.inverseDepth = eye.inverseDepth;
  history.camera = camera;
  history.valid = true;
  eye.image = std::move(out);
  return used.combine(std::plus<size_t>());
}

}  // namespace pvr
