#include "core/output_guard.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <mutex>
#include <vector>

extern char** environ;

namespace mbdae {
namespace {

// Reads "before after" lines until "done" or the end of input (the writer's death); at the end
// of input, if the file (descriptor 3) is not at the announced size, it is cut back to `before`.
// Signals that stop the writer's process group or session do not reach it (own session, INT,
// TERM and HUP ignored).
constexpr const char* kRepairScript =
    "trap '' INT TERM HUP PIPE\n"
    "before=; after=\n"
    "while read -r a b; do\n"
    "  [ \"$a\" = done ] && exit 0\n"
    "  before=$a; after=$b\n"
    "done\n"
    "[ -n \"$after\" ] || exit 0\n"
    "size=$(stat -L -c %s /dev/fd/3) || exit 1\n"
    "[ \"$size\" = \"$after\" ] || truncate -s \"$before\" /dev/fd/3\n";

// A line of a few bytes: one send, all or nothing. MSG_NOSIGNAL: a repair process that is gone
// (killed on its own) gives EPIPE, not a SIGPIPE that would end the writer.
// A failed send leaves the file unguarded from then on; the run goes on.
void write_line(int fd, const char* text, size_t n) {
  while (n > 0) {
    const ssize_t w = ::send(fd, text, n, MSG_NOSIGNAL);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return;
    text += w;
    n -= static_cast<size_t>(w);
  }
}

// Repair processes told "done" but not yet exited. Waiting for each would add its exit (about
// 0.1 ms, more if it is still starting) to every run; they are reaped later without waiting.
std::mutex g_ended_mutex;
std::vector<pid_t> g_ended;

void reap_ended() {
  std::lock_guard<std::mutex> lock(g_ended_mutex);
  for (size_t k = 0; k < g_ended.size();) {
    const pid_t r = ::waitpid(g_ended[k], nullptr, WNOHANG);
    if (r == 0) {
      ++k;
    } else {  // reaped, or not ours any more (ECHILD: someone else reaped it)
      g_ended[k] = g_ended.back();
      g_ended.pop_back();
    }
  }
}

}  // namespace

OutputGuard start_output_guard(int fd) {
  reap_ended();
  // A socket pair rather than a pipe, for MSG_NOSIGNAL. Both descriptors the child gets are
  // first copied above 9, so that the dup2 actions below never overwrite one another.
  int p[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, p) != 0) return {};
  const int in = ::fcntl(p[0], F_DUPFD_CLOEXEC, 10);
  const int file = ::fcntl(fd, F_DUPFD_CLOEXEC, 10);
  ::close(p[0]);
  if (in < 0 || file < 0) {
    for (int d : {in, file, p[1]})
      if (d >= 0) ::close(d);
    return {};
  }
  posix_spawn_file_actions_t fa;
  posix_spawnattr_t attr;
  posix_spawn_file_actions_init(&fa);
  posix_spawnattr_init(&attr);
  posix_spawn_file_actions_adddup2(&fa, in, 0);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&fa, file, 3);
  posix_spawn_file_actions_addclosefrom_np(&fa, 4);  // nothing else of the writer's is held open
  sigset_t none, all;
  sigemptyset(&none);
  sigfillset(&all);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setsigdefault(&attr, &all);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSID | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  char* argv[] = {const_cast<char*>("sh"), const_cast<char*>("-c"), const_cast<char*>(kRepairScript),
                  const_cast<char*>("mbdae-output-guard"), nullptr};
  pid_t pid = -1;
  const int err = posix_spawn(&pid, "/bin/sh", &fa, &attr, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&attr);
  ::close(in);
  ::close(file);
  if (err != 0) {
    ::close(p[1]);
    return {};
  }
  return {pid, p[1]};
}

void announce_write(const OutputGuard& g, long long before, long long after) {
  if (g.channel < 0) return;
  char line[64];
  const int n = std::snprintf(line, sizeof line, "%lld %lld\n", before, after);
  write_line(g.channel, line, static_cast<size_t>(n));
}

void end_output_guard(OutputGuard& g) {
  if (g.channel < 0) return;
  write_line(g.channel, "done\n", 5);
  ::close(g.channel);
  {
    std::lock_guard<std::mutex> lock(g_ended_mutex);
    g_ended.push_back(g.pid);
  }
  reap_ended();
  g = OutputGuard{};
}

}  // namespace mbdae
