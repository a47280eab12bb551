#include "pvr/xr/session_lifecycle.h"

namespace pvr {

SessionCommand SessionLifecycle::onStateChanged(XrSessionState state) {
  const bool wasFocused = focused();
  state_ = state;
  if (wasFocused != focused()) ++focusChanges_;
  if (finished_) return SessionCommand::None;
  switch (state) {
    case XR_SESSION_STATE_READY:
      if (stopRequested_) {  // asked to stop before the session began: nothing to walk down
        finished_ = true;
        return SessionCommand::Shutdown;
      }
      running_ = true;
      ++sessionsBegun_;
      return SessionCommand::BeginSession;
    case XR_SESSION_STATE_STOPPING:
      if (!running_) return SessionCommand::None;
      running_ = false;
      return SessionCommand::EndSession;
    case XR_SESSION_STATE_IDLE:
      // Ended at our request: the runtime goes on to EXITING. Ended by the runtime (headset
      // taken off): wait for READY again.
      return SessionCommand::None;
    case XR_SESSION_STATE_EXITING:
      finished_ = true;
      running_ = false;
      return SessionCommand::Shutdown;
    case XR_SESSION_STATE_LOSS_PENDING:
      finished_ = true;
      lost_ = true;
      running_ = false;
      return SessionCommand::Shutdown;
    default:
      return SessionCommand::None;
  }
}

SessionCommand SessionLifecycle::onInstanceLossPending() {
  if (finished_) return SessionCommand::None;
  finished_ = true;
  lost_ = true;
  running_ = false;
  return SessionCommand::Shutdown;
}

SessionCommand SessionLifecycle::requestStop() {
  stopRequested_ = true;
  if (finished_) return SessionCommand::None;
  if (running_) {
    if (exitRequested_) return SessionCommand::None;
    exitRequested_ = true;
    return SessionCommand::RequestExit;
  }
  finished_ = true;
  return SessionCommand::Shutdown;
}

const char* sessionStateName(XrSessionState state) {
  switch (state) {
    case XR_SESSION_STATE_IDLE: return "IDLE";
    case XR_SESSION_STATE_READY: return "READY";
    case XR_SESSION_STATE_SYNCHRONIZED: return "SYNCHRONIZED";
    case XR_SESSION_STATE_VISIBLE: return "VISIBLE";
    case XR_SESSION_STATE_FOCUSED: return "FOCUSED";
    case XR_SESSION_STATE_STOPPING: return "STOPPING";
    case XR_SESSION_STATE_LOSS_PENDING: return "LOSS_PENDING";
    case XR_SESSION_STATE_EXITING: return "EXITING";
    default: return "UNKNOWN";
  }
}

}  // namespace pvr
