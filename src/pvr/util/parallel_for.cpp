#include "pvr/util/parallel_for.h"

#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <string>

#include "pvr/util/error.h"

namespace pvr {

void parallelFor(const char* label, size_t n, size_t grain, const std::function<void(size_t, size_t)>& body) {
  try {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain > 0 ? grain : 1),
                      [&](const tbb::blocked_range<size_t>& r) { body(r.begin(), r.end()); });
  } catch (const Error& e) {
    throw Error(std::string(label) + ": " + e.what());
  }
}

void parallelForTiles(const char* label, int rows, int cols, int tile,
                      const std::function<void(int, int, int, int)>& body) {
  const size_t grain = size_t(tile > 0 ? tile : 1);
  try {
    tbb::parallel_for(tbb::blocked_range2d<int>(0, rows, grain, 0, cols, grain), [&](const tbb::blocked_range2d<int>& r) {
      body(r.rows().begin(), r.rows().end(), r.cols().begin(), r.cols().end());
    });
  } catch (const Error& e) {
    throw Error(std::string(label) + ": " + e.what());
  }
}

}  // namespace pvr
