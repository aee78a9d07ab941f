// Signals of the command-line program. SIGINT and SIGTERM ask the run to stop at the next step
// (it then writes the rows so far and a summary with status "interrupted"); a second one ends the
// program at once. SIGXFSZ is ignored, so that a write beyond the file size limit (ulimit -f)
// fails with EFBIG and is reported as an output error instead of killing the program.
#pragma once

#include <atomic>

namespace mbdae {

// Installs the handlers; returns the flag they set (for RunOptions::stop).
const std::atomic<bool>* install_stop_signals();
// The signal that asked to stop, 0 if none. The conventional exit code is 128 + this.
int stop_signal();

}  // namespace mbdae
