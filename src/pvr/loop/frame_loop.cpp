#include "pvr/loop/frame_loop.h"

#include "pvr/foveation/gaze.h"

namespace pvr {
namespace {

double msBetween(LoopClock::time_point a, LoopClock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

}  // namespace

FrameStats FrameLoop::run(const FrameLoopOptions& options) {
  FrameStats stats;
  FrameRequest request;
  request.rig = renderer_.rig();
  uint64_t rendered = 0;
  bool stopRequested = false;
  std::optional<LoopClock::time_point> previousStart;
  const LoopClock::time_point loopStart = LoopClock::now();
  BudgetController* controller = options.controller;
  RenderOptions asked = renderer_.options();  // under a controller: what the user asks for, the presenter adjusts
  ControlLog control;
  for (;;) {
    const bool stopNow = (options.stop && options.stop->load()) ||
                         (options.maxFrames && rendered >= options.maxFrames + options.warmupFrames);
    if (stopNow && !stopRequested) {
      presenter_.requestStop();
      stopRequested = true;
    }
    LoopClock::time_point waitStart = LoopClock::now();
    if (!presenter_.waitFrame(request)) break;
    LoopClock::time_point start = LoopClock::now();
    std::optional<ControlDecision> decision;
    if (controller) {
      if (controller->params().followsDisplay && request.displayPeriodMs) controller->setBudget(*request.displayPeriodMs);
      presenter_.adjustOptions(asked);
      controller->setBase(asked);
      decision = controller->decide(msBetween(loopStart, start));
      renderer_.options() = controller->optionsFor(decision->setting);
    } else {
      presenter_.adjustOptions(renderer_.options());
    }
    FrameRecord record;
    record.waitMs = msBetween(waitStart, start);
    record.intervalMs = previousStart ? msBetween(*previousStart, start) : 0.0;
    previousStart = start;
    const FrameOutput output = presenter_.output(renderer_);
    if (!request.shouldRender || stopRequested) {  // the display wants a frame, but not its content
      presenter_.present({request, nullptr, renderer_, false});
      stats.addSkipped();
      continue;
    }
    renderer_.rig() = request.rig;
    copyGaze(request, renderer_.options().foveation);
    FrameResult frame = renderer_.renderFrame(request.rig.head, nullptr, output);
    LoopClock::time_point rendered_at = LoopClock::now();
    presenter_.present({request, &frame, renderer_, output == FrameOutput::DeviceBuffers});
    LoopClock::time_point done = LoopClock::now();
    record.renderMs = msBetween(start, rendered_at);
    record.presentMs = msBetween(rendered_at, done);
    record.cpuMs = record.renderMs + record.presentMs;
    record.stages = frame.timings;
    record.gpuMs = frame.timings.totalMs();
    record.overheadMs = record.cpuMs - record.gpuMs;
    if (request.deadline) {
      record.hasDeadline = true;
      record.slackMs = msBetween(done, *request.deadline);
      record.missedDeadline = done > *request.deadline;
    }
    if (controller) controller->observe(ControlCosts::of(frame.timings, record.cpuMs));
    if (rendered++ >= options.warmupFrames) {
      stats.add(record);
      if (controller) control.add(*decision, record.cpuMs, ControlCosts::of(frame.timings, record.cpuMs));
    }
  }
  if (controller) stats.setControl(control.toJson(*controller), control.summary(*controller));
  return stats;
}

}  // namespace pvr
