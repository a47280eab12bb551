#pragma once
// Per-frame statistics of the frame loop: what each frame cost on the host and on the GPU, the
// time between frames, and whether it reached the display in time. Kept for every frame and
// summarised as mean / p50 / p99 / max (a headset drops a frame on one slow frame).
#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pvr/pipeline/frame_result.h"
#include "pvr/util/latency_stats.h"

namespace pvr {

struct FrameRecord {
  double waitMs = 0;      ///< blocked in the presenter's waitFrame (pacing, not work)
  double renderMs = 0;    ///< host wall time of the frame pipeline (all stages, read-back included)
  double presentMs = 0;   ///< host wall time of the hand-over to the display
  double cpuMs = 0;       ///< renderMs + presentMs: the frame's work, end to end
  double gpuMs = 0;       ///< sum of the stage timings (GPU events on CUDA, host clocks on the CPU)
  double overheadMs = 0;  ///< cpuMs - gpuMs: what the loop and hand-over add to the stages
  double intervalMs = 0;  ///< since the previous frame began (0 for the first)
  double slackMs = 0;     ///< deadline minus hand-over completion; negative: late
  bool hasDeadline = false, missedDeadline = false;
  StageTimings stages;
};

class FrameStats {
 public:
  void add(const FrameRecord& record) { records_.push_back(record); }
  void addSkipped() { ++skipped_; }  ///< a frame the display did not want rendered
  // A controlled loop's decisions (toJson's "controller" and the summary's last line), taken when
  // the loop ends: the stats outlive the controller.
  void setControl(nlohmann::json json, std::string summary) { controlJson_ = std::move(json), controlSummary_ = std::move(summary); }
  size_t frames() const { return records_.size(); }
  size_t skipped() const { return skipped_; }
  size_t missedDeadlines() const;
  size_t framesWithDeadline() const;
  const std::vector<FrameRecord>& records() const { return records_; }

  LatencyStats cpu() const { return of(&FrameRecord::cpuMs); }
  LatencyStats gpu() const { return of(&FrameRecord::gpuMs); }
  LatencyStats present() const { return of(&FrameRecord::presentMs); }
  LatencyStats overhead() const { return of(&FrameRecord::overheadMs); }
  LatencyStats interval() const;  ///< over frames after the first
  LatencyStats of(double FrameRecord::*field) const;

  // {"frames", "skipped", "missed_deadlines", "cpu_ms": {mean, p50, p99, max}, ... "stages_ms": {...}}
  nlohmann::json toJson() const;
  // One line per measure, for the terminal.
  std::string summary() const;

 private:
  std::vector<FrameRecord> records_;
  size_t skipped_ = 0;
  nlohmann::json controlJson_;  ///< null: no controller
  std::string controlSummary_;
};

}  // namespace pvr
