#pragma once
// Fixed-capacity max-heap on squared distance for k-nearest-neighbour photon queries
// (Jensen's "radius shrinking": once full, the root's distance bounds the search).
#include "pvr/pvr.h"

namespace pvr {

constexpr int kMaxKnn = 64;  ///< largest k a kNN query may ask for (registers/local memory on the GPU)

struct KnnHeap {
  float dist2[kMaxKnn];
  uint32_t index[kMaxKnn];
  int size = 0;
  int k = 1;

  PVR_HOST_DEVICE explicit KnnHeap(int kNearest) : k(kNearest) {}
  PVR_HOST_DEVICE bool full() const { return size == k; }
  PVR_HOST_DEVICE float maxDist2() const { return dist2[0]; }

  // Offers a candidate; `searchR2` shrinks to the k-th distance once the heap is full.
  PVR_HOST_DEVICE void offer(float d2, uint32_t idx, float& searchR2) {
    if (size < k) {
      int i = size++;
      while (i > 0) {  // sift up
        int parent = (i - 1) / 2;
        if (dist2[parent] >= d2) break;
        dist2[i] = dist2[parent];
        index[i] = index[parent];
        i = parent;
      }
      dist2[i] = d2;
      index[i] = idx;
    } else if (d2 < dist2[0]) {
      int i = 0;
      while (true) {  // sift down from the root
        int child = 2 * i + 1;
        if (child >= size) break;
        if (child + 1 < size && dist2[child + 1] > dist2[child]) ++child;
        if (dist2[child] <= d2) break;
        dist2[i] = dist2[child];
        index[i] = index[child];
        i = child;
      }
      dist2[i] = d2;
      index[i] = idx;
    } else {
      return;
    }
    if (size == k) searchR2 = dist2[0];
  }
};

}  // namespace pvr
