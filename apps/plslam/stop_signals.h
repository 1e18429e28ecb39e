#pragma once
// SIGINT, SIGTERM and SIGHUP ask a long command to stop at its next frame boundary and still
// write what it has; a second signal exits at once. The handler only stores the signal number in
// a lock-free atomic (async-signal-safe); the command polls stop_requested() between frames.
namespace plslam::app {

// Installs the handlers (sigaction, once per process).
void install_stop_signals();
// 0 while no signal arrived, else the first signal's number.
int stop_signal();
inline bool stop_requested() { return stop_signal() != 0; }
// The shell convention for a run ended by a signal: 128 + its number (130, 143, 129).
inline int stop_exit_code() { return 128 + stop_signal(); }
// "SIGINT", "SIGTERM", "SIGHUP", or "" when none arrived.
const char* stop_signal_name();

}  // namespace plslam::app
