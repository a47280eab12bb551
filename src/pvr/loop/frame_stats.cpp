#include "pvr/loop/frame_stats.h"

#include <cstdio>

namespace pvr {

size_t FrameStats::missedDeadlines() const {
  size_t n = 0;
  for (const FrameRecord& r : records_) n += r.missedDeadline ? 1 : 0;
  return n;
}

size_t FrameStats::framesWithDeadline() const {
  size_t n = 0;
  for (const FrameRecord& r : records_) n += r.hasDeadline ? 1 : 0;
  return n;
}

LatencyStats FrameStats::of(double FrameRecord::*field) const {
  std::vector<double> samples;
  samples.reserve(records_.size());
  for (const FrameRecord& r : records_) samples.push_back(r.*field);
  return latencyStats(std::move(samples));
}

LatencyStats FrameStats::interval() const {
  std::vector<double> samples;
  for (size_t i = 1; i < records_.size(); ++i) samples.push_back(records_[i].intervalMs);
  return latencyStats(std::move(samples));
}

nlohmann::json FrameStats::toJson() const {
  auto stage = [&](auto pick) {
    std::vector<double> samples;
    for (const FrameRecord& r : records_) samples.push_back(pick(r.stages));
    return nlohmann::json(latencyStats(std::move(samples)));
  };
  std::vector<double> slack;
  for (const FrameRecord& r : records_)
    if (r.hasDeadline) slack.push_back(r.slackMs);
  nlohmann::json out = {{"frames", frames()},
          {"skipped", skipped_},
          {"frames_with_deadline", framesWithDeadline()},
          {"missed_deadlines", missedDeadlines()},
          {"cpu_ms", cpu()},
          {"gpu_ms", gpu()},
          {"render_ms", of(&FrameRecord::renderMs)},
          {"present_ms", present()},
          {"overhead_ms", overhead()},
          {"wait_ms", of(&FrameRecord::waitMs)},
          {"interval_ms", interval()},
          {"deadline_slack_ms", latencyStats(std::move(slack))},
          {"stages_ms",
           {{"photon_trace", stage([](const StageTimings& t) { return t.photonTraceMs; })},
            {"map_build", stage([](const StageTimings& t) { return t.mapBuildMs; })},
            {"raster_prepass", stage([](const StageTimings& t) { return t.primaryMs; })},
            {"raster_draw", stage([](const StageTimings& t) { return t.primaryDrawMs; })},
            {"left_eye_rays", stage([](const StageTimings& t) { return t.eyeRayMs[0]; })},
            {"right_eye_rays", stage([](const StageTimings& t) { return t.eyeRayMs[1]; })},
            {"left_eye", stage([](const StageTimings& t) { return t.eyeMs[0]; })},
            {"right_eye", stage([](const StageTimings& t) { return t.eyeMs[1]; })}}}};
  if (!controlJson_.is_null()) out["controller"] = controlJson_;
  return out;
}

std::string FrameStats::summary() const {
  std::string text;
  char line[200];
  auto row = [&](const char* name, const LatencyStats& s) {
    std::snprintf(line, sizeof line, "  %-22s mean %8.3f  p50 %8.3f  p99 %8.3f  max %8.3f ms\n", name, s.mean, s.p50,
                  s.p99, s.max);
    text += line;
  };
  std::snprintf(line, sizeof line, "%zu frames rendered, %zu skipped by the display, %zu of %zu deadlines missed\n",
                frames(), skipped_, missedDeadlines(), framesWithDeadline());
  text += line;
  row("frame CPU+GPU (work)", cpu());
  row("stages (GPU or CPU)", gpu());
  row("hand-over to display", present());
  row("loop overhead", overhead());
  row("frame-to-frame", interval());
  text += controlSummary_;
  return text;
}

}  // namespace pvr
