#pragma once
// Tail latency of repeated timings: a VR headset drops a frame on one slow frame, so the benches
// report the mean together with the median, the 99th percentile and the worst sample.
#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace pvr {

struct LatencyStats {
  double mean = 0, p50 = 0, p99 = 0, max = 0;  ///< ms; all 0 for no samples
};

// Percentile p (integer percent) of sorted samples by the nearest-rank rule: the ceil(p/100 * n)-th
// smallest; so p99 of fewer than 100 samples is their max.
inline double nearestRankPercentile(const std::vector<double>& sorted, size_t percent) {
  if (sorted.empty()) return 0.0;
  const size_t rank = std::max<size_t>((percent * sorted.size() + 99) / 100, 1);  // integer ceil
  return sorted[std::min(rank, sorted.size()) - 1];
}

inline LatencyStats latencyStats(std::vector<double> samples) {
  LatencyStats s;
  if (samples.empty()) return s;
  std::sort(samples.begin(), samples.end());
  s.mean = std::accumulate(samples.begin(), samples.end(), 0.0) / double(samples.size());
  s.p50 = nearestRankPercentile(samples, 50);
  s.p99 = nearestRankPercentile(samples, 99);
  s.max = samples.back();
  return s;
}

// {"mean": .., "p50": .., "p99": .., "max": ..}, found by nlohmann::json through ADL.
inline void to_json(nlohmann::json& j, const LatencyStats& s) {
  j = {{"mean", s.mean}, {"p50", s.p50}, {"p99", s.p99}, {"max", s.max}};
}

// "mean / p99" for table cells, both with `decimals` decimals.
inline std::string meanP99(const LatencyStats& s, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f / %.*f", decimals, s.mean, decimals, s.p99);
  return text;
}

}  // namespace pvr
