#include "pvr/photon/kd_tree.h"

#include <algorithm>

#include "pvr/util/parallel_for.h"

namespace pvr {

namespace {

struct Builder {
  std::vector<uint32_t>& order;  // input indices, permuted in place
  const std::vector<Photon>& input;
  Photon* photons;
  uint8_t* axes;
  uint32_t* nodeToInput;

  void build(uint32_t node, uint32_t begin, uint32_t end) {
    uint32_t n = end - begin;
    if (n == 0) return;
    Bounds3 b;
    for (uint32_t i = begin; i < end; ++i) b.extend(input[order[i]].position);
    int axis = b.longestAxis();
    uint32_t median = begin + completeTreeLeftSize(n);
    std::nth_element(order.begin() + begin, order.begin() + median, order.begin() + end,
                     [&](uint32_t x, uint32_t y) {
                       const float px = input[x].position[axis], py = input[y].position[axis];
                       return px < py || (px == py && x < y);  // ties by index: the tree is unique
                     });
    photons[node] = input[order[median]];
    axes[node] = uint8_t(axis);
    nodeToInput[node] = order[median];
    if (n > 16384) {
      parallelInvoke([&] { build(2 * node + 1, begin, median); }, [&] { build(2 * node + 2, median + 1, end); });
    } else {
      build(2 * node + 1, begin, median);
      build(2 * node + 2, median + 1, end);
    }
  }
};

}  // namespace

KdTree KdTree::build(const std::vector<Photon>& input) {
  KdTree tree;
  size_t n = input.size();
  tree.photons_.resize(n);
  tree.axes_.resize(n);
  tree.nodeToInput_.resize(n);
  std::vector<uint32_t> order(n);
  for (uint32_t i = 0; i < n; ++i) order[i] = i;
  Builder b{order, input, tree.photons_.data(), tree.axes_.data(), tree.nodeToInput_.data()};
  b.build(0, 0, uint32_t(n));
  return tree;
}

}  // namespace pvr
