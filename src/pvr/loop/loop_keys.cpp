#include "pvr/loop/loop_keys.h"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>

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

struct TerminalKeys::Saved {
  bool terminal = false;
  termios mode{};
  int flags = 0;
};

bool TerminalKeys::standardInputIsTerminal() { return isatty(STDIN_FILENO) == 1; }

TerminalKeys::TerminalKeys() : saved_(std::make_unique<Saved>()) {
  saved_->flags = fcntl(STDIN_FILENO, F_GETFL);
  if (saved_->flags < 0) {
    ended_ = true;  // no standard input at all
    return;
  }
  if (standardInputIsTerminal() && tcgetattr(STDIN_FILENO, &saved_->mode) == 0) {
    termios raw = saved_->mode;
    raw.c_lflag &= tcflag_t(~(ICANON | ECHO));  // keys as typed, not lines; not echoed over the log
    raw.c_cc[VMIN] = 0;
    raw.c_cc[VTIME] = 0;
    saved_->terminal = tcsetattr(STDIN_FILENO, TCSANOW, &raw) == 0;
  }
  fcntl(STDIN_FILENO, F_SETFL, saved_->flags | O_NONBLOCK);
}

TerminalKeys::~TerminalKeys() {
  if (saved_->flags >= 0) fcntl(STDIN_FILENO, F_SETFL, saved_->flags);
  if (saved_->terminal) tcsetattr(STDIN_FILENO, TCSANOW, &saved_->mode);
}

int TerminalKeys::next() {
  if (ended_) return -1;
  unsigned char c = 0;
  const ssize_t n = read(STDIN_FILENO, &c, 1);
  if (n == 1) return c;
  if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) ended_ = true;
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
