// Stop requests from the operating system for a program that runs a coupled
// scene: SIGINT (Ctrl-C), SIGTERM and SIGHUP.
//
// The first request is a flag the coupler reads at its next control round:
// the sides shut down, outputs are flushed, run.json says "interrupted".
// The second ends the process at once (exit status 128 + the signal) after
// the registered abort cleanup (the coupler's: remove the ipc directory,
// mark run.json "aborted"); the side processes it started die with it
// (ChildProcess asks the kernel for that). After kill -9 run.json keeps
// "running" with the coupler's pid, host and start time.
#pragma once

#include <atomic>
#include <functional>
#include <string>

namespace hfmpm::coupling {

// Blocks the three signals in the calling thread, so in every thread it
// starts later, and starts a thread that waits for them. Call once, before
// any other thread starts. Returns the flag: 0, or the first signal's number.
const std::atomic<int>& install_stop_signals();

// What to do before the process ends on a second signal (replaces the last
// one; an empty function removes it). Runs on the signal thread, so it must
// not use state the stopped run may be changing: copy what it needs.
void set_abort_cleanup(std::function<void(int signal)> cleanup);

// "SIGINT", "SIGTERM", ... ("signal N" for one without a name).
std::string signal_name(int signal);

// The conventional exit status of a program stopped by `signal`: 128 + signal.
inline int exit_status_for_signal(int signal) { return 128 + signal; }

}  // namespace hfmpm::coupling
