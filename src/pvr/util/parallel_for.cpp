#include "pvr/util/parallel_for.h"

#include <string>

#include "pvr/util/error.h"

#ifdef PVR_PARALLEL_STD_THREADS
#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include <tbb/global_control.h>
#else
#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#endif

namespace pvr {

#ifdef PVR_PARALLEL_STD_THREADS
// The ThreadSanitizer build (scripts/test-tsan.sh): the same loops on plain std::threads, whose
// start and join TSan sees. TBB's scheduler synchronises inside a library TSan did not instrument,
// so under TSan every hand-over of work would be reported as a race (google/sanitizers#1004);
// this way TSan checks photonvr's loop bodies and the data they share.
namespace {

constexpr unsigned kWorkers = 4;  // more than this machine's cores: chunks run on different threads

// chunk(c) for c in [0, chunks), on kWorkers threads; the first exception is rethrown after all join.
void runChunks(size_t chunks, const std::function<void(size_t)>& chunk) {
  std::atomic<size_t> next{0};
  std::exception_ptr error;
  std::mutex errorMutex;
  auto work = [&] {
    for (size_t c; (c = next.fetch_add(1)) < chunks;) {
      try {
        chunk(c);
      } catch (...) {
        std::lock_guard<std::mutex> lock(errorMutex);
        if (!error) error = std::current_exception();
      }
    }
  };
  // A tbb::global_control limit still applies (a test compares one thread with many).
  const size_t workers = std::min<size_t>({kWorkers, chunks, tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)});
  std::vector<std::thread> threads;
  try {
    for (size_t t = 1; t < workers; ++t) threads.emplace_back(work);
  } catch (...) {  // no thread to start: the ones started and this one do the work
  }
  work();
  for (std::thread& t : threads) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace
#endif

void parallelFor(const char* label, size_t n, size_t grain, const std::function<void(size_t, size_t)>& body) {
  if (grain == 0) grain = 1;
  try {
#ifdef PVR_PARALLEL_STD_THREADS
    runChunks((n + grain - 1) / grain, [&](size_t c) { body(c * grain, std::min(n, (c + 1) * grain)); });
#else
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain),
                      [&](const tbb::blocked_range<size_t>& r) { body(r.begin(), r.end()); });
#endif
  } catch (const Error& e) {
    throw Error(std::string(label) + ": " + e.what());
  }
}

void parallelForTiles(const char* label, int rows, int cols, int tile,
                      const std::function<void(int, int, int, int)>& body) {
  const int grain = tile > 0 ? tile : 1;
  try {
#ifdef PVR_PARALLEL_STD_THREADS
    const size_t tilesX = size_t((cols + grain - 1) / grain), tilesY = size_t((rows + grain - 1) / grain);
    runChunks(tilesX * tilesY, [&](size_t c) {
      const int y0 = int(c / tilesX) * grain, x0 = int(c % tilesX) * grain;
      body(y0, std::min(rows, y0 + grain), x0, std::min(cols, x0 + grain));
    });
#else
    tbb::parallel_for(tbb::blocked_range2d<int>(0, rows, size_t(grain), 0, cols, size_t(grain)),
                      [&](const tbb::blocked_range2d<int>& r) {
                        body(r.rows().begin(), r.rows().end(), r.cols().begin(), r.cols().end());
                      });
#endif
  } catch (const Error& e) {
    throw Error(std::string(label) + ": " + e.what());
  }
}

int libraryThreadLimit() {
#ifdef PVR_PARALLEL_STD_THREADS
  return 1;
#else
  return 0;
#endif
}

void parallelInvoke(const std::function<void()>& a, const std::function<void()>& b) {
#ifdef PVR_PARALLEL_STD_THREADS
  runChunks(2, [&](size_t c) { c == 0 ? a() : b(); });
#else
  tbb::parallel_invoke(a, b);
#endif
}

}  // namespace pvr
