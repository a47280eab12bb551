// The frame loop: percentiles of its statistics, the offscreen presenter's poses, pacing and
// deadlines, and that a loop frame is the frame `render` makes for the same pose.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <thread>

#include "pvr/loop/frame_loop.h"
#include "pvr/loop/loop_keys.h"
#include "pvr/loop/offscreen_presenter.h"
#include "pvr/scene/scene.h"
#include "pvr/util/error.h"

namespace pvr {
namespace {

TEST(FrameStats, PercentilesByNearestRank) {
  FrameStats stats;
  for (int i = 1; i <= 200; ++i) {
    FrameRecord r;
    r.cpuMs = i;  // 1 .. 200 ms
    r.gpuMs = 0.5 * i;
    r.intervalMs = 10;
    r.hasDeadline = true;
    r.missedDeadline = i > 190;
    stats.add(r);
  }
  EXPECT_DOUBLE_EQ(stats.cpu().p50, 100);
  EXPECT_DOUBLE_EQ(stats.cpu().p99, 198);
  EXPECT_DOUBLE_EQ(stats.cpu().max, 200);
  EXPECT_DOUBLE_EQ(stats.cpu().mean, 100.5);
  EXPECT_DOUBLE_EQ(stats.gpu().p99, 99);
  EXPECT_EQ(stats.missedDeadlines(), 10u);
  nlohmann::json j = stats.toJson();
  EXPECT_EQ(j["frames"], 200);
  EXPECT_EQ(j["missed_deadlines"], 10);
  EXPECT_DOUBLE_EQ(j["cpu_ms"]["p99"].get<double>(), 198);
  EXPECT_DOUBLE_EQ(j["interval_ms"]["max"].get<double>(), 10);  // the first frame has no interval
}

TEST(FrameStats, EmptyIsZeroNotNan) {
  FrameStats stats;
  EXPECT_EQ(stats.cpu().p99, 0.0);
  EXPECT_EQ(stats.toJson()["frames"], 0);
}

// A presenter that records what it was handed.
class RecordingPresenter : public OffscreenPresenter {
 public:
  using OffscreenPresenter::OffscreenPresenter;
  std::vector<Image> left;
  void present(const PresentedFrame& frame) override {
    if (frame.result) left.push_back(frame.result->eyes[0].image);
    OffscreenPresenter::present(frame);
  }
};

TEST(FrameLoop, RendersThePosesItIsGivenAndStopsAfterTheFrameCount) {
  Scene scene = loadScene("cornell");
  Renderer renderer(scene, BackendKind::Cpu);
  renderer.rig().width = 24, renderer.rig().height = 20;
  renderer.options().photonsX = renderer.options().photonsY = 32;
  StereoRig rig = renderer.rig();
  std::vector<ScriptedView> path(3);
  for (int i = 0; i < 3; ++i) {
    path[i].head = rig.head;
    path[i].head.position = path[i].head.position + Vec3(0.05f * i, 0, 0);
  }
  OffscreenOptions oo;
  oo.refreshHz = 1.0;  // a generous slot: no deadline is missed
  RecordingPresenter presenter(rig, path, oo);
  FrameLoopOptions lo;
  lo.maxFrames = 4;
  FrameStats stats = FrameLoop(renderer, presenter).run(lo);
  EXPECT_EQ(stats.frames(), 4u);
  EXPECT_EQ(stats.missedDeadlines(), 0u);
  EXPECT_EQ(stats.framesWithDeadline(), 4u);
  ASSERT_EQ(presenter.left.size(), 4u);
  // Frame 3 is pose 0 again (the path cycles): the same image as frame 0; frame 1 differs.
  EXPECT_EQ(presenter.left[3].pixels, presenter.left[0].pixels);
  EXPECT_NE(presenter.left[1].pixels, presenter.left[0].pixels);
  // And each is what the renderer makes for that pose directly.
  Renderer direct(scene, BackendKind::Cpu);
  direct.rig() = rig;
  direct.options() = renderer.options();
  direct.rig().head = path[1].head;
  FrameResult frame = direct.renderFrame(path[1].head);
  EXPECT_EQ(frame.eyes[0].image.pixels, presenter.left[1].pixels);
  for (const FrameRecord& r : stats.records()) {
    EXPECT_GT(r.cpuMs, 0.0);
    EXPECT_GE(r.cpuMs + 1e-9, r.renderMs);
    EXPECT_NEAR(r.overheadMs, r.cpuMs - r.gpuMs, 1e-9);
  }
}

TEST(FrameLoop, AStopFlagEndsItCleanly) {
  Scene scene = loadScene("cornell");
  Renderer renderer(scene, BackendKind::Cpu);
  renderer.rig().width = 8, renderer.rig().height = 8;
  renderer.options().photonsX = renderer.options().photonsY = 8;
  std::atomic<bool> stop{true};
  OffscreenPresenter presenter(renderer.rig(), {}, OffscreenOptions());
  FrameLoopOptions lo;
  lo.stop = &stop;
  FrameStats stats = FrameLoop(renderer, presenter).run(lo);
  EXPECT_EQ(stats.frames(), 0u);
}

TEST(FrameLoop, PacedSlotsAreOnePeriodApartAndSlowFramesMissTheirDeadline) {
  Scene scene = loadScene("cornell");
  Renderer renderer(scene, BackendKind::Cpu);
  renderer.rig().width = 8, renderer.rig().height = 8;
  renderer.options().photonsX = renderer.options().photonsY = 8;
  OffscreenOptions oo;
  oo.refreshHz = 10.0;  // 100 ms slots: an 8x8 frame fits many times over, even on a loaded machine
  oo.paced = true;
  int calls = 0;
  oo.handOver = [&](const PresentedFrame&) {
    if (++calls == 3) std::this_thread::sleep_for(std::chrono::milliseconds(250));  // one slow frame
  };
  OffscreenPresenter presenter(renderer.rig(), {}, oo);
  FrameLoopOptions lo;
  lo.maxFrames = 5;
  FrameStats stats = FrameLoop(renderer, presenter).run(lo);
  ASSERT_EQ(stats.frames(), 5u);
  EXPECT_TRUE(stats.records()[2].missedDeadline);
  EXPECT_LT(stats.records()[2].slackMs, -100.0);
  EXPECT_GE(stats.missedDeadlines(), 1u);
  // Paced: about one slot apart (unpaced 8x8 frames would follow within a millisecond or two).
  for (size_t i = 1; i < 3; ++i) EXPECT_GE(stats.records()[i].intervalMs, 80.0);
}

TEST(OffscreenPresenter, RejectsABadRefreshRate) {
  OffscreenOptions oo;
  for (double hz : {0.0, -90.0, std::nan(""), 1e9}) {
    oo.refreshHz = hz;
    EXPECT_THROW(OffscreenPresenter(defaultRig(), {}, oo), Error);
  }
}

// xr's keys: 1-5 put every material at one level, e steps through them, 0 gives the scene's own
// levels back, anything else changes nothing.
TEST(LoopKeys, EffectLevelKeys) {
  RenderOptions o;
  ASSERT_FALSE(o.gather.overrideEffects);
  const RenderOptions before = o;
  for (char key : {'x', '\n', '6', ' ', 'E'}) {
    EXPECT_EQ(applyLoopKey(key, o), "") << int(key);
    EXPECT_FALSE(o.gather.overrideEffects);
    EXPECT_EQ(o.gather.effects, before.gather.effects);
  }
  const char* names[] = {"raster", "shadows", "reflections", "gi", "path"};
  for (int level = 0; level < kEffectLevels; ++level) {
    EXPECT_EQ(applyLoopKey(char('1' + level), o), std::string("every material at ") + names[level]);
    EXPECT_TRUE(o.gather.overrideEffects);
    EXPECT_EQ(o.gather.effects, EffectLevel(level));
  }
  // From path, e wraps to raster and steps up one level a key.
  for (int step = 0; step < 2 * kEffectLevels; ++step) {
    const int expected = step % kEffectLevels;
    EXPECT_EQ(applyLoopKey('e', o), std::string("every material at ") + names[expected]);
    EXPECT_EQ(o.gather.effects, EffectLevel(expected));
  }
  EXPECT_EQ(applyLoopKey('0', o), "each material at its own level");
  EXPECT_FALSE(o.gather.overrideEffects);
  EXPECT_EQ(applyLoopKey('e', o), "every material at raster");  // from the scene's own levels: the first
}

}  // namespace
}  // namespace pvr
