#include "pvr/loop/loop_keys.h"

#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>

namespace pvr {

std::string applyLoopKey(char key, RenderOptions& options) {
  GatherParams& g = options.gather;
  if (key >= '1' && key < '1' + kEffectLevels) {
    g.overrideEffects = true;
    g.effects = EffectLevel(key - '1');
  } else if (key == 'e') {
    g.effects = g.overrideEffects ? EffectLevel((int(g.effects) + 1) % kEffectLevels) : EffectLevel::Raster;
    g.overrideEffects = true;
  } else if (key == '0') {
    g.overrideEffects = false;
    return "each material at its own level";
  } else {
    return "";
  }
  return std::string("every material at ") + effectLevelName(g.effects);
}

namespace {

// The terminal's mode before photonvr changed it, restored by the destructor and, should the
// process exit without unwinding to it, by an atexit handler.
termios gSavedMode{};
bool gModeChanged = false;

void restoreTerminal() {
  if (gModeChanged) tcsetattr(STDIN_FILENO, TCSANOW, &gSavedMode);
  gModeChanged = false;
}

}  // namespace

bool TerminalKeys::standardInputIsTerminal() {
  // Only a process in the terminal's foreground group reads it: one in the background (under
  // `timeout`, `cmd &`) would be stopped by SIGTTIN / SIGTTOU.
  return isatty(STDIN_FILENO) == 1 && tcgetpgrp(STDIN_FILENO) == getpgrp();
}

TerminalKeys::TerminalKeys() {
  if (isatty(STDIN_FILENO) == 1) {
    if (!standardInputIsTerminal() || tcgetattr(STDIN_FILENO, &gSavedMode) != 0) {
      ended_ = true;
      return;
    }
    termios keys = gSavedMode;
    keys.c_lflag &= tcflag_t(~(ICANON | ECHO));  // keys as typed, not lines; not echoed over the log
    keys.c_cc[VMIN] = 1;                         // read only after poll saw a key: one byte, no wait
    keys.c_cc[VTIME] = 0;
    if (tcsetattr(STDIN_FILENO, TCSANOW, &keys) == 0) {
      gModeChanged = true;
      static const bool registered = std::atexit(restoreTerminal) == 0;
      (void)registered;
    }
  }
}

TerminalKeys::~TerminalKeys() { restoreTerminal(); }

int TerminalKeys::next() {
  if (ended_) return -1;
  // poll, not O_NONBLOCK: the flag would belong to the open file, which a terminal shares with
  // standard output and error (their writes could then fail).
  pollfd in{STDIN_FILENO, POLLIN, 0};
  const int ready = poll(&in, 1, 0);
  if (ready == 0 || (ready < 0 && errno == EINTR)) return -1;
  if (ready < 0 || !(in.revents & (POLLIN | POLLHUP))) {
    ended_ = true;
    return -1;
  }
  unsigned char c = 0;
  const ssize_t n = read(STDIN_FILENO, &c, 1);
  if (n == 1) return c;
  if (n == 0 || errno != EINTR) ended_ = true;  // end of a pipe or file
  return -1;
}

void KeyedPresenter::adjustOptions(RenderOptions& options) {
  inner_.adjustOptions(options);
  for (int key = keys_.next(); key >= 0; key = keys_.next()) {
    const std::string what = applyLoopKey(char(key), options);
    if (what.empty()) continue;  // newlines and unknown keys: look at the next one
    std::printf("%s: frame %llu: key '%c': %s\n", prefix_.c_str(), (unsigned long long)frame_, char(key), what.c_str());
    std::fflush(stdout);
    break;
  }
}

}  // namespace pvr
