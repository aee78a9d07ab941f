// A repair process for a file appended to in whole rows. SIGKILL (the OOM killer, kill -9)
// cannot be caught, and the kernel may stop a write(2) at any page boundary on its way, so the
// writing process alone cannot promise whole rows. Before each write the writer tells a small
// process (/bin/sh in its own session, started with posix_spawn) the file's size before and
// after it; if the writer dies without saying "done", that process cuts the file back to the
// size before an unfinished write. The file's flock is shared with it: a reader that takes
// flock(LOCK_SH) on the file waits until the repair is over (docs/errors.md, "Signals").
#pragma once

#include <sys/types.h>

namespace mbdae {

struct OutputGuard {
  pid_t pid = -1;  // the repair process; -1 if none runs (then the file is unguarded)
  int channel = -1;  // our end of the socket that is its standard input
};

// Starts the repair process for the open file fd. Returns {-1, -1} if it cannot be started (no
// /bin/sh, out of processes): the run goes on, its file as safe as write(2) makes it.
OutputGuard start_output_guard(int fd);

// Before a write that takes the file from `before` to `after` bytes.
void announce_write(const OutputGuard& g, long long before, long long after);

// The file is complete or already cut back by its writer: the repair process ends unused.
void end_output_guard(OutputGuard& g);

}  // namespace mbdae
