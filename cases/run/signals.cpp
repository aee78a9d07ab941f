#include "cases/run/signals.h"

#include <csignal>

namespace mbdae {
namespace {

std::atomic<bool> g_stop{false};  // lock-free, so safe to set in a signal handler
volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_stop_signal(int sig) {
  if (g_stop.load()) {  // asked twice: stop now, the conventional way
    std::signal(sig, SIG_DFL);
    std::raise(sig);
    return;
  }
  g_signal = sig;
  g_stop.store(true);
}

}  // namespace

const std::atomic<bool>* install_stop_signals() {
  static_assert(std::atomic<bool>::is_always_lock_free, "the stop flag is set in a signal handler");
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  std::signal(SIGXFSZ, SIG_IGN);
  return &g_stop;
}

int stop_signal() { return g_signal; }

}  // namespace mbdae
