// The hash grid and the kd-tree must find exactly the photons brute force finds, and kNN the
// true k nearest, on random sets and on the edge cases that break grids: photons exactly on cell
// boundaries, a single photon, all photons in one cell, coincident photons, an empty map.
#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <set>

#include "pvr/photon/density.h"
#include "pvr/photon/hash_grid.h"
#include "pvr/photon/kd_tree.h"
#include "pvr/util/error.h"

namespace pvr {
namespace {

std::set<uint32_t> bruteForce(const std::vector<Photon>& photons, Vec3 q, float r) {
  std::set<uint32_t> found;
  for (uint32_t i = 0; i < photons.size(); ++i)
    if (photonDistance2(q, photons[i].position) <= r * r) found.insert(i);
  return found;
}

template <class View>
std::set<uint32_t> mapSearch(const View& view, const std::vector<uint32_t>& toInput, Vec3 q, float r) {
  std::set<uint32_t> found;
  float r2 = r * r;
  view.search(q, r2, [&](uint32_t i, float d2, float&) {
    EXPECT_LE(d2, r * r);
    EXPECT_TRUE(found.insert(toInput[i]).second) << "photon visited twice";
  });
  return found;
}

void expectSameAsBruteForce(const std::vector<Photon>& photons, float r, const std::vector<Vec3>& queries) {
  HashGrid grid = HashGrid::build(photons, r);
  KdTree tree = KdTree::build(photons);
  size_t nonEmpty = 0;
  for (Vec3 q : queries) {
    std::set<uint32_t> expected = bruteForce(photons, q, r);
    nonEmpty += !expected.empty();
    ASSERT_EQ(mapSearch(grid.view(), grid.sortedToInput(), q, r), expected) << "hash grid at " << q.x << "," << q.y << "," << q.z;
    ASSERT_EQ(mapSearch(tree.view(), tree.nodeToInput(), q, r), expected) << "kd-tree at " << q.x << "," << q.y << "," << q.z;
  }
  if (!photons.empty()) {
    EXPECT_GT(nonEmpty, 0u) << "the test's queries found nothing: it checks nothing";
  }
}

Photon photonAt(Vec3 p) { return {p, {1, 1, 1}, {0, -1, 0}}; }

std::vector<Photon> randomPhotons(std::mt19937& rng, size_t n, Vec3 lo, Vec3 hi) {
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<Photon> photons;
  for (size_t i = 0; i < n; ++i)
    photons.push_back(photonAt({lo.x + u(rng) * (hi.x - lo.x), lo.y + u(rng) * (hi.y - lo.y), lo.z + u(rng) * (hi.z - lo.z)}));
  return photons;
}

TEST(PhotonMaps, RandomSetsMatchBruteForce) {
  std::mt19937 rng(7);
  for (float r : {0.02f, 0.05f, 0.1f, 0.2f, 0.7f}) {
    auto photons = randomPhotons(rng, 3000, {-0.5f, 0, -0.5f}, {0.5f, 1, 0.5f});
    // Queries inside, on the edge of, and well outside the photons' bounds.
    std::vector<Vec3> queries;
    for (const Photon& p : randomPhotons(rng, 300, {-0.7f, -0.2f, -0.7f}, {0.7f, 1.2f, 0.7f})) queries.push_back(p.position);
    for (int i = 0; i < 100; ++i) queries.push_back(photons[i].position);
    queries.push_back({100, 100, 100});
    expectSameAsBruteForce(photons, r, queries);
  }
}

TEST(PhotonMaps, PhotonsExactlyOnCellBoundaries) {
  // A lattice whose spacing is exactly the grid's cell side, starting at the grid's first
  // interior cell corner, so every photon sits on a cell boundary.
  const float r = 0.125f;  // exact in binary
  const float cell = hashGridLayout(Bounds3{{0, 0, 0}, {1, 1, 1}}, r).cellSize;
  std::vector<Photon> photons;
  std::vector<Vec3> queries;
  for (int z = 0; z < 6; ++z)
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 6; ++x) {
        photons.push_back(photonAt(Vec3(float(x), float(y), float(z)) * cell));
        queries.push_back(Vec3(float(x), float(y), float(z)) * cell);
        queries.push_back(Vec3(x + 0.5f, float(y), z + 0.25f) * cell);
      }
  HashGrid onBoundaries = HashGrid::build(photons, r);
  ASSERT_EQ(onBoundaries.view().cellSize, cell);
  ASSERT_EQ(onBoundaries.view().origin.x, -cell);
  for (const Photon& p : photons)  // (p - origin) / cell is an integer: on a boundary
    ASSERT_EQ(std::floor((p.position.x - onBoundaries.view().origin.x) / cell), (p.position.x + cell) / cell);
  // Also a lattice at exactly the radius, where points at distance r must be included.
  std::vector<Photon> radiusLattice;
  for (int z = 0; z < 5; ++z)
    for (int y = 0; y < 5; ++y)
      for (int x = 0; x < 5; ++x) radiusLattice.push_back(photonAt(Vec3(float(x), float(y), float(z)) * r));
  std::vector<Vec3> latticeQueries;
  for (const Photon& p : radiusLattice) latticeQueries.push_back(p.position);
  expectSameAsBruteForce(photons, r, queries);
  expectSameAsBruteForce(radiusLattice, r, latticeQueries);
  // Each interior lattice point has 6 neighbours at exactly r, plus itself.
  HashGrid grid = HashGrid::build(radiusLattice, r);
  EXPECT_EQ(mapSearch(grid.view(), grid.sortedToInput(), Vec3(2, 2, 2) * r, r).size(), 7u);
}

TEST(PhotonMaps, SinglePhotonAllInOneCellCoincidentAndEmpty) {
  std::mt19937 rng(3);
  expectSameAsBruteForce({photonAt({0.3f, 0.2f, 0.1f})}, 0.05f, {{0.3f, 0.2f, 0.1f}, {0.33f, 0.2f, 0.1f}, {0.4f, 0.2f, 0.1f}});
  auto cluster = randomPhotons(rng, 500, {0.1f, 0.1f, 0.1f}, {0.105f, 0.105f, 0.105f});
  expectSameAsBruteForce(cluster, 0.05f, {{0.1f, 0.1f, 0.1f}, {0.14f, 0.1f, 0.1f}, {0.2f, 0.1f, 0.1f}});
  std::vector<Photon> same(200, photonAt({0.5f, 0.5f, 0.5f}));
  expectSameAsBruteForce(same, 0.01f, {{0.5f, 0.5f, 0.5f}, {0.505f, 0.5f, 0.5f}});
  expectSameAsBruteForce({}, 0.05f, {{0, 0, 0}, {1, 1, 1}});
  HashGrid empty = HashGrid::build({}, 0.05f);
  EXPECT_EQ(estimateFluxDensity(empty.view(), {0, 0, 0}, {0, 1, 0}, DensityParams{}), Vec3(0.0f));
}

TEST(PhotonMaps, NonFiniteQueryFindsNothing) {
  std::mt19937 rng(5);
  auto photons = randomPhotons(rng, 100, {0, 0, 0}, {1, 1, 1});
  HashGrid grid = HashGrid::build(photons, 0.1f);
  KdTree tree = KdTree::build(photons);
  Vec3 nanPoint{NAN, 0.5f, 0.5f};
  EXPECT_TRUE(mapSearch(grid.view(), grid.sortedToInput(), nanPoint, 0.1f).empty());
  EXPECT_TRUE(mapSearch(tree.view(), tree.nodeToInput(), nanPoint, 0.1f).empty());
}

TEST(PhotonMaps, KnnReturnsTheTrueKNearest) {
  std::mt19937 rng(11);
  auto photons = randomPhotons(rng, 4000, {-0.5f, 0, -0.5f}, {0.5f, 1, 0.5f});
  for (int i = 0; i < 50; ++i) photons.push_back(photons[i]);  // ties
  HashGrid grid = HashGrid::build(photons, 0.1f);
  KdTree tree = KdTree::build(photons);
  for (int k : {1, 8, 32, 64}) {
    for (const Photon& qp : randomPhotons(rng, 100, {-0.5f, 0, -0.5f}, {0.5f, 1, 0.5f})) {
      Vec3 q = qp.position;
      std::vector<float> all;
      for (const Photon& p : photons)
        if (photonDistance2(q, p.position) <= 0.01f) all.push_back(photonDistance2(q, p.position));
      std::sort(all.begin(), all.end());
      all.resize(std::min<size_t>(all.size(), k));
      auto knn = [&](auto view) {
        KnnHeap heap(k);
        float r2 = 0.01f;
        view.search(q, r2, [&](uint32_t i, float d2, float& sr2) { heap.offer(d2, i, sr2); });
        std::vector<float> d(heap.dist2, heap.dist2 + heap.size);
        std::sort(d.begin(), d.end());
        return d;
      };
      ASSERT_EQ(knn(grid.view()), all) << "hash grid, k=" << k;
      ASSERT_EQ(knn(tree.view()), all) << "kd-tree, k=" << k;
    }
  }
}

// The k nearest by searchNearest (rows nearest first, rows and cells beyond the shrinking radius
// skipped): brute force's distances for every k, also where float rounding is coarse against the
// cell (photons 1000 units from the origin, cells of 0.01), for queries on cell faces and
// corners, outside the photons' bounds, and with ties.
std::vector<float> kNearestByBruteForce(const std::vector<Photon>& photons, Vec3 q, float r2, int k) {
  std::vector<float> all;
  for (const Photon& p : photons)
    if (photonDistance2(q, p.position) <= r2) all.push_back(photonDistance2(q, p.position));
  std::sort(all.begin(), all.end());
  all.resize(std::min<size_t>(all.size(), size_t(k)));
  return all;
}

template <class View>
std::vector<float> kNearestBySearchNearest(const View& view, Vec3 q, float r2, int k, int* visits = nullptr) {
  KnnHeap heap(k);
  view.searchNearest(q, r2, [&](uint32_t i, float d2, float& sr2) {
    if (visits) ++*visits;
    heap.offer(d2, i, sr2);
  });
  std::vector<float> d(heap.dist2, heap.dist2 + heap.size);
  std::sort(d.begin(), d.end());
  return d;
}

TEST(PhotonMaps, NearestFirstKnnMatchesBruteForce) {
  std::mt19937 rng(21);
  for (Vec3 offset : {Vec3{0, 0, 0}, Vec3{1000, -1000, 1000}}) {
    const float r = offset.x == 0 ? 0.1f : 0.01f;
    const Vec3 lo = offset + Vec3{-0.5f, 0, -0.5f} * (r * 10), hi = offset + Vec3{0.5f, 1, 0.5f} * (r * 10);
    auto photons = randomPhotons(rng, 4000, lo, hi);
    for (int i = 0; i < 60; ++i) photons.push_back(photons[i]);  // ties
    HashGrid grid = HashGrid::build(photons, r);
    KdTree tree = KdTree::build(photons);
    const HashGridView v = grid.view();
    std::vector<Vec3> queries;
    for (const Photon& p : randomPhotons(rng, 200, lo - Vec3(r), hi + Vec3(r))) queries.push_back(p.position);
    for (int i = 0; i < 100; ++i) {  // on cell faces, edges and corners, as the grid computes them
      Vec3 q = queries[size_t(i)];
      for (int a = 0; a < 3 - i % 3; ++a) q[a] = v.origin[a] + std::floor((q[a] - v.origin[a]) * v.invCellSize) * v.cellSize;
      queries.push_back(q);
    }
    for (int i = 0; i < 40; ++i) queries.push_back(photons[size_t(i)].position);  // on photons
    for (int k : {1, 4, 16, 32, 64}) {
      for (Vec3 q : queries) {
        const float r2 = r * r;
        const std::vector<float> expected = kNearestByBruteForce(photons, q, r2, k);
        ASSERT_EQ(kNearestBySearchNearest(v, q, r2, k), expected)
            << "hash grid, k=" << k << " at " << q.x << "," << q.y << "," << q.z;
        ASSERT_EQ(kNearestBySearchNearest(tree.view(), q, r2, k), expected) << "kd-tree, k=" << k;
      }
    }
  }
}

// The point of searching nearest first: once the heap is full, fewer photons are offered to it.
TEST(PhotonMaps, NearestFirstKnnOffersFewerPhotons) {
  std::mt19937 rng(22);
  auto photons = randomPhotons(rng, 20000, {0, 0, 0}, {1, 1, 1});
  HashGrid grid = HashGrid::build(photons, 0.1f);
  int nearestVisits = 0, plainVisits = 0;
  for (const Photon& qp : randomPhotons(rng, 300, {0.1f, 0.1f, 0.1f}, {0.9f, 0.9f, 0.9f})) {
    kNearestBySearchNearest(grid.view(), qp.position, 0.01f, 8, &nearestVisits);
    KnnHeap heap(8);
    float r2 = 0.01f;
    grid.view().search(qp.position, r2, [&](uint32_t i, float d2, float& sr2) {
      ++plainVisits;
      heap.offer(d2, i, sr2);
    });
  }
  // About 84 photons lie within r of a query, the 8 nearest within about r/2.
  EXPECT_LT(nearestVisits, plainVisits * 0.8) << nearestVisits << " against " << plainVisits;
}

TEST(PhotonMaps, KdTreeIsACompleteBalancedSplitTree) {
  for (uint32_t n : {1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u, 100u, 1023u, 1024u, 1025u}) {
    // A complete binary tree of n nodes: left subtree sizes add up and nodes fill 0..n-1.
    uint32_t l = completeTreeLeftSize(n);
    EXPECT_LE(l, n - 1);
    EXPECT_GE(l, (n - 1) / 2);
  }
  std::mt19937 rng(13);
  auto photons = randomPhotons(rng, 1000, {0, 0, 0}, {2, 1, 0.5f});
  KdTree tree = KdTree::build(photons);
  KdTreeView v = tree.view();
  std::set<uint32_t> inputs(tree.nodeToInput().begin(), tree.nodeToInput().end());
  EXPECT_EQ(inputs.size(), photons.size());
  // Every node splits its subtree: left descendants <= split <= right descendants.
  std::function<void(uint32_t, int, float, bool)> check = [&](uint32_t node, int axis,
                                                                         float split, bool left) {
    if (node >= v.photonCount) return;
    float c = v.photons[node].position[axis];
    if (left) {
      ASSERT_LE(c, split);
    } else {
      ASSERT_GE(c, split);
    }
    check(2 * node + 1, axis, split, left);
    check(2 * node + 2, axis, split, left);
  };
  for (uint32_t node = 0; node < v.photonCount; ++node) {
    float split = v.photons[node].position[v.axes[node]];
    check(2 * node + 1, v.axes[node], split, true);
    check(2 * node + 2, v.axes[node], split, false);
  }
  EXPECT_EQ(v.axes[0], 0) << "the root splits the longest axis (x)";
}

// The tree is unique: with coordinates that tie (photons on a lattice), the build equals a plain
// recursive one that sorts every subtree by (coordinate, index), as the GPU build orders them.
// The GPU keeps the photons' bounds with integer atomics on orderedBits and ranks coordinates by
// radix-sorting them: the integers must order exactly as the floats do (-0 and +0 alike, as
// for the CPU's <) and give the float back.
TEST(PhotonMaps, OrderedBitsSortAsTheFloatsAndRoundTrip) {
  std::vector<float> values = {-INFINITY, -FLT_MAX, -1.0f, -FLT_MIN, -1e-45f, -0.0f, 0.0f, 1e-45f, FLT_MIN, 1.0f, FLT_MAX, INFINITY};
  std::mt19937 rng(7);
  std::uniform_int_distribution<uint32_t> bits;
  while (values.size() < 3000) {
    const float f = floatFromBits(bits(rng));
    if (!std::isnan(f)) values.push_back(f);
  }
  for (float a : values) {
    const float back = fromOrderedBits(orderedBits(a));
    EXPECT_EQ(floatBits(back), floatBits(a == 0.0f ? 0.0f : a)) << a;
    for (float b : values) {
      ASSERT_EQ(a < b, orderedBits(a) < orderedBits(b)) << a << " " << b;
      ASSERT_EQ(a == b, orderedBits(a) == orderedBits(b)) << a << " " << b;
    }
  }
}

TEST(PhotonMaps, KdTreeBreaksTiesByIndex) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> lattice(0, 3);
  std::vector<Photon> photons(3000);
  for (Photon& p : photons) p.position = Vec3(float(lattice(rng)), float(lattice(rng)) * 0.5f, float(lattice(rng)));
  std::vector<uint32_t> expected(photons.size());
  std::function<void(uint32_t, std::vector<uint32_t>)> build = [&](uint32_t node, std::vector<uint32_t> subset) {
    if (subset.empty()) return;
    Bounds3 b;
    for (uint32_t i : subset) b.extend(photons[i].position);
    const int axis = b.longestAxis();
    std::sort(subset.begin(), subset.end(), [&](uint32_t x, uint32_t y) {
      const float px = photons[x].position[axis], py = photons[y].position[axis];
      return px < py || (px == py && x < y);
    });
    const uint32_t median = completeTreeLeftSize(uint32_t(subset.size()));
    expected[node] = subset[median];
    build(2 * node + 1, std::vector<uint32_t>(subset.begin(), subset.begin() + median));
    build(2 * node + 2, std::vector<uint32_t>(subset.begin() + median + 1, subset.end()));
  };
  std::vector<uint32_t> all(photons.size());
  for (uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  build(0, all);
  EXPECT_EQ(KdTree::build(photons).nodeToInput(), expected);
}

// The GPU build's bookkeeping (kdBuildSlot): after every level's splits each slot of the order
// array is a node's median or lies in exactly one node still to split; with all levels split,
// the slots are the nodes 0..n-1, one each, at the depths of a complete tree.
TEST(PhotonMaps, KdBuildSlotsPlaceEveryNodeOnce) {
  for (uint32_t n : {1u, 2u, 3u, 5u, 7u, 8u, 9u, 100u, 1023u, 1024u, 1025u}) {
    const int levels = int(bitWidth(n));
    std::vector<int> placedAt(n, -1);
    for (int level = 0; level <= levels; ++level) {
      std::map<uint32_t, std::pair<uint32_t, uint32_t>> open;  // node -> its slots' range
      for (uint32_t slot = 0; slot < n; ++slot) {
        const KdBuildSlot s = kdBuildSlot(n, slot, level);
        if (s.placed) {
          ASSERT_LT(s.depth, level);
          ASSERT_LT(s.node, n);
          EXPECT_EQ(s.depth, int(bitWidth(s.node + 1)) - 1) << "node " << s.node << " at its depth";
          if (placedAt[s.node] < 0) placedAt[s.node] = int(slot);
          EXPECT_EQ(placedAt[s.node], int(slot)) << "node " << s.node << " has one slot";
          continue;
        }
        ASSERT_LT(level, levels) << "every slot is placed after the last level";
        ASSERT_LE(s.begin, slot);
        ASSERT_LT(slot, s.end);
        auto [it, added] = open.emplace(s.node, std::make_pair(s.begin, s.end));
        EXPECT_EQ(it->second, std::make_pair(s.begin, s.end)) << "one range per node";
      }
      uint32_t openSlots = 0;
      for (const auto& [node, range] : open) openSlots += range.second - range.first;
      uint32_t placed = 0;
      for (int slot : placedAt) placed += slot >= 0 ? 1 : 0;
      EXPECT_EQ(openSlots + placed, n) << n << " photons, level " << level;
    }
    for (uint32_t node = 0; node < n; ++node) EXPECT_GE(placedAt[node], 0) << n << " photons, node " << node;
  }
}

// The GPU build's algorithm run on the host, one slot at a time, with std::sort for the radix
// sorts (cuda/photon_map_build.cu runs the same per-slot steps in parallel): ranks along each
// axis, then per level each node's bounds and longest axis and one sort of the slots by
// kdSplitKey. It makes the recursive build's tree.
TEST(PhotonMaps, LevelByLevelBuildMakesTheSameTree) {
  std::mt19937 rng(21);
  std::uniform_int_distribution<int> lattice(0, 9);
  for (uint32_t n : {1u, 2u, 3u, 6u, 31u, 32u, 33u, 1000u, 4097u}) {
    std::vector<Photon> photons(n);
    for (Photon& p : photons) p.position = Vec3(float(lattice(rng)), float(lattice(rng)) * 0.3f, float(lattice(rng)) * 2.0f);
    std::vector<uint32_t> ranks[3];
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<uint32_t> sorted(n);
      for (uint32_t i = 0; i < n; ++i) sorted[i] = i;
      std::stable_sort(sorted.begin(), sorted.end(),
                       [&](uint32_t x, uint32_t y) { return photons[x].position[axis] < photons[y].position[axis]; });
      ranks[axis].resize(n);
      for (uint32_t r = 0; r < n; ++r) ranks[axis][sorted[r]] = r;
    }
    const int slotBits = int(bitWidth(std::max(n, 2u) - 1));
    std::vector<uint32_t> slots(n), nodeToInput(n, ~0u);
    std::vector<uint8_t> axes(n, 255);
    for (uint32_t i = 0; i < n; ++i) slots[i] = i;
    const int levels = int(bitWidth(n));
    for (int level = 0; level <= levels; ++level) {
      std::map<uint32_t, Bounds3> bounds;
      for (uint32_t i = 0; i < n; ++i) {
        const KdBuildSlot s = kdBuildSlot(n, i, level);
        if (s.placed && s.depth == level - 1) nodeToInput[s.node] = slots[i];
        if (!s.placed) bounds[s.node].extend(photons[slots[i]].position);
      }
      if (level == levels) break;
      std::vector<std::pair<uint64_t, uint32_t>> keyed(n);
      for (uint32_t i = 0; i < n; ++i) {
        const KdBuildSlot s = kdBuildSlot(n, i, level);
        uint32_t rank = 0;
        if (!s.placed) {
          const int axis = bounds[s.node].longestAxis();
          if (i == s.begin) axes[s.node] = uint8_t(axis);
          rank = ranks[axis][slots[i]];
        }
        keyed[i] = {kdSplitKey(s, i, rank, slotBits), slots[i]};
      }
      std::sort(keyed.begin(), keyed.end());
      for (uint32_t i = 0; i < n; ++i) slots[i] = keyed[i].second;
    }
    KdTree tree = KdTree::build(photons);
    EXPECT_EQ(nodeToInput, tree.nodeToInput()) << n << " photons";
    EXPECT_TRUE(std::equal(axes.begin(), axes.end(), tree.view().axes)) << n << " photons";
  }
}

TEST(PhotonMaps, HashGridLayoutFollowsThePaper) {
  HashGridView g = hashGridLayout(Bounds3{{0, 0, 0}, {1, 0.5f, 0.25f}}, 0.1f);
  EXPECT_GE(g.cellSize, 0.1f);
  EXPECT_LE(g.cellSize, 0.1f * 1.001f);
  // One padding layer: the origin is one cell below the photons' minimum corner.
  EXPECT_NEAR(g.origin.x, -g.cellSize, 1e-7f);
  EXPECT_EQ(g.dims[0], 10 + 2);  // floor(1 / 0.1001) + 1 interior cells + 2 padding
  EXPECT_EQ(g.hash(1, 2, 3), uint32_t(3 * g.dims[0] * g.dims[1] + 2 * g.dims[0] + 1));
  EXPECT_EQ(g.rowOffsets[4], -1) << "the middle row starts at the x-1 cell";
  EXPECT_EQ(g.rowOffsets[0], -g.dims[0] * g.dims[1] - g.dims[0] - 1);
}

TEST(PhotonMaps, TooManyCellsAndBadRadiusAreErrors) {
  std::vector<Photon> photons = {photonAt({0, 0, 0}), photonAt({100, 100, 100})};
  EXPECT_THROW(HashGrid::build(photons, 1e-4f), Error);
  EXPECT_THROW(HashGrid::build(photons, 0.0f), Error);
  EXPECT_THROW(HashGrid::build(photons, -1.0f), Error);
  EXPECT_THROW(HashGrid::build(photons, NAN), Error);
}

TEST(DensityEstimation, RadiusSumIsEquationOne) {
  // Photons of known power on a plane: the estimate is the in-radius power over pi r^2, and
  // photons arriving from behind the surface are ignored.
  std::vector<Photon> photons;
  for (int i = 0; i < 10; ++i) photons.push_back({{0.01f * i, 0, 0}, {0.5f, 1, 2}, {0, -1, 0}});
  photons.push_back({{0, 0, 0.01f}, {100, 100, 100}, {0, 1, 0}});  // from below: ignored
  HashGrid grid = HashGrid::build(photons, 0.05f);
  Vec3 e = estimateFluxDensity(grid.view(), {0, 0, 0}, {0, 1, 0}, DensityParams{0.05f, Estimator::Radius, 1});
  float expected = 6 * 0.5f / (kPi * 0.05f * 0.05f);  // photons at x = 0 .. 0.05
  EXPECT_NEAR(e.x, expected, 1e-3f * expected);
  // kNN with k = 3: three nearest (x = 0, 0.01, 0.02), radius = 0.02.
  Vec3 k3 = estimateFluxDensity(grid.view(), {0, 0, 0}, {0, 1, 0}, DensityParams{0.05f, Estimator::Knn, 3});
  float expectedK = 3 * 0.5f / (kPi * 0.02f * 0.02f);
  EXPECT_NEAR(k3.x, expectedK, 1e-3f * expectedK);
}

}  // namespace
}  // namespace pvr
