#pragma once
// The OpenXR session's life cycle as a state machine without the runtime: it is fed the
// session-state events (and instance loss) and says which call the application must make now.
// The presenter drives it with real events; tests drive it with recorded sequences.
#include <openxr/openxr.h>

#include <string>

namespace pvr {

enum class SessionCommand {
  None,
  BeginSession,        ///< READY: xrBeginSession, then submit frames
  EndSession,          ///< STOPPING: xrEndSession
  RequestExit,         ///< the application wants out while running: xrRequestExitSession
  Shutdown,            ///< EXITING, LOSS_PENDING or instance loss: destroy session and instance
};

class SessionLifecycle {
 public:
  SessionCommand onStateChanged(XrSessionState state);
  SessionCommand onInstanceLossPending();
  // Ctrl-C or the frame count reached. Once running: ask the runtime to exit (it walks the
  // session down through STOPPING); before the session began: shut down at once.
  SessionCommand requestStop();

  XrSessionState state() const { return state_; }
  bool running() const { return running_; }   ///< between xrBeginSession and xrEndSession: frames are due
  bool visible() const { return state_ == XR_SESSION_STATE_VISIBLE || state_ == XR_SESSION_STATE_FOCUSED; }
  bool focused() const { return state_ == XR_SESSION_STATE_FOCUSED; }
  bool finished() const { return finished_; }  ///< nothing more to do: clean up
  bool lost() const { return lost_; }          ///< finished because the runtime or device went away
  bool stopRequested() const { return stopRequested_; }
  int focusChanges() const { return focusChanges_; }
  int sessionsBegun() const { return sessionsBegun_; }

 private:
  XrSessionState state_ = XR_SESSION_STATE_UNKNOWN;
  bool running_ = false, finished_ = false, lost_ = false, stopRequested_ = false, exitRequested_ = false;
  int focusChanges_ = 0, sessionsBegun_ = 0;
};

const char* sessionStateName(XrSessionState state);

}  // namespace pvr
