#pragma once
// The CPU code's parallel loops (TBB underneath), each labelled with the work it does: an
// pvr::Error thrown by the body comes out prefixed with the label, so a failure names its stage.
// Results never depend on the thread count: bodies write disjoint outputs.
#include <cstddef>
#include <functional>

namespace pvr {

// body(begin, end) over [0, n) in chunks of about `grain` items.
void parallelFor(const char* label, size_t n, size_t grain, const std::function<void(size_t begin, size_t end)>& body);

// body(y0, y1, x0, x1) over a rows x cols image in tiles of about tile x tile pixels.
void parallelForTiles(const char* label, int rows, int cols, int tile,
                      const std::function<void(int y0, int y1, int x0, int x1)>& body);

// a() and b() at the same time (a recursive build's two halves); returns when both have.
void parallelInvoke(const std::function<void()>& a, const std::function<void()>& b);

// The threads a library with a pool of its own (Embree's BVH builder, which calls photonvr's
// callbacks on its TBB workers) should use: 0 for its default; 1 in the ThreadSanitizer build,
// which cannot see that pool's synchronisation.
int libraryThreadLimit();

}  // namespace pvr
