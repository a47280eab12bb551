#include "pvr/cuda/denoise.cuh"

#include <algorithm>
#include <map>
#include <mutex>
#include <utility>

#include "pvr/util/error.h"

namespace pvr::cuda {
namespace {

constexpr int kBlock = 16;
constexpr unsigned kListThreads = 256;

__device__ inline bool blockPixel(const EyeCamera& c, int& x, int& y) {
  x = int(blockIdx.x) * kBlock + int(threadIdx.x);
  y = int(blockIdx.y) * kBlock + int(threadIdx.y);
  return x < c.width && y < c.height;
}

// At most 64 registers (four blocks an SM): at 80, once the history's taps could refer to the left
// eye's, the kernel went 199 -> 236 us an eye on Sponza (H100).
// Under quarter photon passes (`even` set) the filtered pixels are also listed apart by parity.
__global__ void __launch_bounds__(kBlock * kBlock, 4) accumulateKernel(DenoiseFrameView v, uint32_t* filtered,
                                                                        unsigned* counts, uint32_t* even, uint32_t* odd) {
  int x, y;
  const bool inside = blockPixel(v.camera, x, y);
  const size_t pixel = inside ? denoisePixel(v.camera, x, y) : 0;
  if (inside) accumulateDenoisePixel(v, x, y);
  const bool filters = inside && filtersPixel(v, pixel);
  appendInBlock<kBlock * kBlock>(filtered, counts, filters, uint32_t(pixel));
  if (!even) return;  // the same for the whole grid
  // Each append's shared sums are read to its end: the next may write them only after a barrier.
  __syncthreads();
  appendInBlock<kBlock * kBlock>(even, counts + 1, filters && evenPixel(x, y), uint32_t(pixel));
  __syncthreads();
  appendInBlock<kBlock * kBlock>(odd, counts + 2, filters && !evenPixel(x, y), uint32_t(pixel));
}

// The later passes: a grid-stride loop over the listed pixels.
template <class Pass>
__device__ inline void forEachListed(const DenoiseFrameView& v, const uint32_t* pixels, const unsigned* count, Pass pass) {
  const unsigned n = *count;
  for (unsigned i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += gridDim.x * blockDim.x) {
    const uint32_t pixel = pixels[i];
    pass(int(pixel % unsigned(v.camera.width)), int(pixel / unsigned(v.camera.width)));
  }
}

__global__ void varianceKernel(DenoiseFrameView v, const uint32_t* pixels, const unsigned* count) {
  forEachListed(v, pixels, count, [&](int x, int y) { estimateDenoiseVariance(v, x, y); });
}

// At most 64 registers: four blocks of 256 threads per SM (at 75 it held three).
__global__ void __launch_bounds__(kListThreads, 4)
    atrousKernel(DenoiseFrameView v, int iteration, AtrousLevels levels, const uint32_t* pixels, const unsigned* count) {
  forEachListed(v, pixels, count, [&](int x, int y) { atrousDenoisePixel(v, iteration, levels, x, y); });
}
// The same under quarter photon passes, over the even or the odd pixels' list.
__global__ void __launch_bounds__(kListThreads, 4) atrousQuarterKernel(DenoiseFrameView v, int iteration, AtrousLevels levels,
                                                                      const uint32_t* pixels, const unsigned* count) {
  forEachListed(v, pixels, count, [&](int x, int y) { atrousDenoisePixelQuarter(v, iteration, levels, x, y); });
}

// A full-resolution eye's a-trous pass by tiles. At step s the image splits into s x s lattices of
// pixels s apart (one per offset); a block takes a 16x16 tile of one lattice, whose 3x3 taps all
// lie on that lattice, loads the tile and its one-sample rim into shared memory together (every
// load in flight at once, instead of each tap's waiting in turn), and filters the tile's pixels
// from there. Measured on the H100 (Sponza, one eye): step 1 181 us against 248 over the list,
// step 2 142 against 133, steps 4-16 slower still (a lattice's loads spread over a cache line
// each), so only the first pass uses it.
constexpr int kTile = kBlock, kTileRim = kTile + 2;

template <int S>
struct TileTaps {
  static constexpr bool kQuarterPhotonPasses = false;  // the first pass only
  const DenoiseGuide (*guides)[kTileRim];
  const ColourVariance (*values)[kTileRim][kTileRim];
  int tx, ty;  ///< the pixel's place in the tile (the rim excluded)
  __device__ DenoiseGuide guide(int i, int j, size_t) const { return guides[ty + 1 + j][tx + 1 + i]; }
  __device__ ColourVariance value(int s, int i, int j, size_t) const { return values[s][ty + 1 + j][tx + 1 + i]; }
};

// The tile's lattice for a block: its offset in the image (ox, oy) and the tile's first lattice point.
struct LatticeTile {
  int ox, oy, lx0, ly0;
};
__device__ inline LatticeTile latticeTile(int step, int tilesX) {
  const int lattices = step * step;
  const int tile = int(blockIdx.x) / lattices, offset = int(blockIdx.x) % lattices;
  return {offset % step, offset / step, (tile % tilesX) * kTile, (tile / tilesX) * kTile};
}

template <int S>
__global__ void __launch_bounds__(kTile * kTile, 4)
    atrousTileKernel(DenoiseFrameView v, int iteration, AtrousLevels levels, int tilesX) {
  __shared__ DenoiseGuide guides[kTileRim][kTileRim];
  __shared__ ColourVariance values[S][kTileRim][kTileRim];
  const int step = 1 << iteration;  // full resolution: a spacing of 1
  const LatticeTile t = latticeTile(step, tilesX);
  const int x = t.ox + (t.lx0 + int(threadIdx.x)) * step, y = t.oy + (t.ly0 + int(threadIdx.y)) * step;
  const bool inside = x < v.camera.width && y < v.camera.height;
  const bool mine = inside && filtersPixel(v, denoisePixel(v.camera, x, y));
  if (!__syncthreads_or(mine)) return;  // nothing to filter here (background)
  const MemoryTaps memory{v, levels};
  for (int e = int(threadIdx.y * kTile + threadIdx.x); e < kTileRim * kTileRim; e += kTile * kTile) {
    const int ex = e % kTileRim, ey = e / kTileRim;
    const int qx = t.ox + (t.lx0 + ex - 1) * step, qy = t.oy + (t.ly0 + ey - 1) * step;
    if (qx < 0 || qy < 0 || qx >= v.camera.width || qy >= v.camera.height) continue;  // never read
    const size_t q = denoisePixel(v.camera, qx, qy);
    guides[ey][ex] = v.guide[q];
    for (int s = 0; s < S; ++s) values[s][ey][ex] = memory.value(s, 0, 0, q);
  }
  __syncthreads();
  if (mine) atrousDenoisePixelOf<S>(v, iteration, levels, TileTaps<S>{guides, values, int(threadIdx.x), int(threadIdx.y)}, x, y);
}

// Blocks of a grid-stride kernel that fill every SM once (no partial last wave). The occupancy
// and SM-count queries are host calls: made once per device and kernel, not every frame.
template <class Kernel>
unsigned residentBlocks(Kernel kernel, size_t items) {
  static std::mutex mutex;
  static std::map<std::pair<int, const void*>, unsigned> filling;  // (device, kernel): blocks
  int device = 0;
  PVR_CUDA_CHECK(cudaGetDevice(&device));
  const std::pair<int, const void*> key(device, reinterpret_cast<const void*>(kernel));
  std::lock_guard<std::mutex> lock(mutex);
  auto found = filling.find(key);
  if (found == filling.end()) {
    int perSm = 0;
    PVR_CUDA_CHECK(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&perSm, kernel, int(kListThreads), 0));
    found = filling.emplace(key, unsigned(std::max(perSm, 1) * multiprocessorCount())).first;
  }
  return std::max(1u, std::min(blocksFor(items, kListThreads), found->second));
}

__global__ void remodulateKernel(DenoiseFrameView v, const uint32_t* pixels, const unsigned* count) {
  forEachListed(v, pixels, count, [&](int x, int y) { remodulateAccumulated(v, x, y); });
}

}  // namespace

void GpuDenoiser::denoise(Eye eye, const EyeCamera& camera, const DenoiseParams& params, const DenoiseInputs& in,
                          int stillFrames, cudaStream_t stream) {
  const int e = int(eye);
  EyeState& state = eyes_[e];
  const size_t pixels = size_t(camera.width) * camera.height;
  const int signals = in.direct ? 2 : 1;
  state.begin(camera, in);
  EyeState::History& next = state.next();
  // Levels are cleared when allocated: the a-trous taps read a neighbour's values before testing
  // its guide, also where no pass writes them (background), and leave them unused there.
  auto reserveCleared = [&](auto& level) {
    if (level.capacity() >= pixels) return;
    level.reserve(pixels, "denoiser filter levels");
    PVR_CUDA_CHECK(cudaMemsetAsync(level.data(), 0, level.bytes(), stream));
  };
  for (int s = 0; s < signals; ++s) {
    next.colour[s].reserve(pixels, "denoiser history");
    for (int k = 0; k < EyeState::levelCount(params, in, s); ++k) reserveCleared(state.levels[s][EyeState::levelBuffer(k, in)]);
  }
  next.moments.reserve(4 * pixels, "denoiser moments");
  next.length.reserve(pixels, "denoiser history length");
  next.guide.reserve(pixels, "denoiser guides");
  if (in.reusedFrom) next.reusedFrom.reserve(pixels, "denoiser history's reused pixels");
  state.depthGradient.reserve(2 * pixels, "denoiser depth gradient");
  state.out.reserve(pixels, "denoised image");
  state.filteredPixels.reserve(pixels, "denoiser pixel list");
  const bool quarter = runsQuarterPhotonPasses(params, in);
  const size_t evenPixels = size_t((camera.width + 1) / 2) * size_t((camera.height + 1) / 2);
  if (quarter) {
    state.evenPixels.reserve(evenPixels, "denoiser even pixel list");
    state.oddPixels.reserve(pixels - evenPixels, "denoiser odd pixel list");
  }
  filteredCount_.reserve(2 * kLists, "denoiser pixel count");
  const DenoiseFrameView v =
      denoiseFrameView(eye, camera, params, in, stillFrames, state, eyes_[int(Eye::Left)], state.out.data());

  const dim3 grid(unsigned((camera.width + kBlock - 1) / kBlock), unsigned((camera.height + kBlock - 1) / kBlock));
  const dim3 block(kBlock, kBlock);
  uint32_t* list = state.filteredPixels.data();
  unsigned* count = filteredCount_.data() + kLists * e;
  uint32_t* even = quarter ? state.evenPixels.data() : nullptr;
  uint32_t* odd = quarter ? state.oddPixels.data() : nullptr;
  // The lists' lengths stay on the device: their passes loop over whatever they hold.
  PVR_CUDA_CHECK(cudaMemsetAsync(count, 0, kLists * sizeof(unsigned), stream));
  launch("denoise accumulate", accumulateKernel, grid, block, 0, stream, v, list, count, even, odd);
  if (params.iterations == 0) {
    launch("denoise remodulate", remodulateKernel, residentBlocks(remodulateKernel, pixels), kListThreads, 0, stream, v,
           list, count);
  } else {
    launch("denoise variance", varianceKernel, residentBlocks(varianceKernel, pixels), kListThreads, 0, stream, v, list,
           count);
    // The first pass of a full-resolution eye of its own runs by tiles: its taps are read twice
    // (the variance's blur, then the filter), from shared memory. The later passes' lattices are
    // too sparse for tiles (each tap a cache line of its own: slower on the H100 from step 4),
    // and a foveated eye (taps at each sample's spacing) and a reusing right eye (a few pixels)
    // run over the list.
    const bool tiles = !in.sampleSpacing && !in.reusedFrom;
    const unsigned atrousBlocks = residentBlocks(atrousKernel, pixels);
    for (int i = 0; i < params.iterations; ++i) {
      if (i > 0 && quarter) {
        // The even pixels first: the odd ones' last pass interpolates what theirs wrote.
        for (AtrousPixels half : {AtrousPixels::Even, AtrousPixels::Odd}) {
          const AtrousLevels levels = atrousLevels(v, i, half);
          if (!levels.runs()) continue;
          const bool evens = half == AtrousPixels::Even;
          launch("denoise a-trous", atrousQuarterKernel,
                 residentBlocks(atrousQuarterKernel, evens ? evenPixels : pixels - evenPixels), kListThreads, 0, stream, v,
                 i, levels, evens ? even : odd, count + (evens ? 1 : 2));
        }
        continue;
      }
      const AtrousLevels levels = atrousLevels(v, i);
      if (!tiles || i > 0) {
        launch("denoise a-trous", atrousKernel, atrousBlocks, kListThreads, 0, stream, v, i, levels, list, count);
        continue;
      }
      const int step = 1 << i, tilesX = (camera.width + step * kTile - 1) / (step * kTile);
      const int tilesY = (camera.height + step * kTile - 1) / (step * kTile);
      const unsigned blocks = unsigned(step * step * tilesX * tilesY);
      if (levels.signals == 2) launch("denoise a-trous", atrousTileKernel<2>, blocks, block, 0, stream, v, i, levels, tilesX);
      else launch("denoise a-trous", atrousTileKernel<1>, blocks, block, 0, stream, v, i, levels, tilesX);
    }
  }
  state.end(camera, params, in, eyes_[int(Eye::Left)]);
}

size_t GpuDenoiser::memoryBytes() const {
  size_t bytes = filteredCount_.bytes();
  for (const EyeState& s : eyes_) {
    bytes += s.depthGradient.bytes() + s.out.bytes() + s.filteredPixels.bytes() + s.evenPixels.bytes() + s.oddPixels.bytes();
    for (const EyeState::History& h : s.history)
      bytes += h.colour[0].bytes() + h.colour[1].bytes() + h.moments.bytes() + h.length.bytes() + h.guide.bytes() +
               h.reusedFrom.bytes();
    for (int k = 0; k < 2; ++k)
      for (const auto& level : s.levels[k]) bytes += level.bytes();
  }
  return bytes;
}

}  // namespace pvr::cuda
