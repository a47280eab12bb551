#pragma once
// Keys that change the loop's options while it runs, for displays without a panel (`xr`, with a
// headset on or offscreen): typed in the terminal, or piped in (tests, scripts).
//   1 2 3 4 5  every material at raster, shadows, reflections, gi, path (Ray-VR's effect levels)
//   e          every material at the next level (from the scene's own levels: raster; path wraps
//              to raster)
//   0          each material at its own level again (the scene's)
#include <string>

#include "pvr/loop/presenter.h"

namespace pvr {

// Applies one key; returns what it did ("every material at shadows"), or empty for a key that
// does nothing (the options are then unchanged).
std::string applyLoopKey(char key, RenderOptions& options);

// Standard input as a source of keys, polled without blocking. A terminal is switched to
// unbuffered, unechoed input while this lives (restored by the destructor, or at exit); other
// input (a pipe, a file) is read as it is. EOF or an error ends the keys; so does a terminal of
// which this process is not in the foreground.
class TerminalKeys {
 public:
  TerminalKeys();
  ~TerminalKeys();
  TerminalKeys(const TerminalKeys&) = delete;
  TerminalKeys& operator=(const TerminalKeys&) = delete;
  // The next key typed or piped, or -1 if none is waiting.
  int next();
  // Standard input is a terminal whose foreground process group is this process's.
  static bool standardInputIsTerminal();

 private:
  bool ended_ = false;
};

// A presenter with keys: everything goes to `inner`; before each frame one waiting key is applied
// (one a frame, so that piped keys land on successive frames) and what it did is printed.
class KeyedPresenter : public Presenter {
 public:
  KeyedPresenter(Presenter& inner, TerminalKeys& keys, std::string prefix)
      : inner_(inner), keys_(keys), prefix_(std::move(prefix)) {}
  std::string name() const override { return inner_.name(); }
  FrameOutput output(const Renderer& renderer) const override { return inner_.output(renderer); }
  bool waitFrame(FrameRequest& request) override { return inner_.waitFrame(request); }
  void present(const PresentedFrame& frame) override {
    inner_.present(frame);
    ++frame_;
  }
  void requestStop() override { inner_.requestStop(); }
  void adjustOptions(RenderOptions& options) override;

 private:
  Presenter& inner_;
  TerminalKeys& keys_;
  std::string prefix_;
  uint64_t frame_ = 0;
};

}  // namespace pvr
