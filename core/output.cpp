#include "core/output.h"

#include "core/errors.h"
#include "core/output_guard.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace mbdae {
namespace {

constexpr size_t kBufferBytes = 1 << 16;  // whole rows collected per write(2)

// Test hook: MBDAE_OUTPUT_FAULT_BYTES=N makes every output file hold at most N bytes, as if the
// file system were full (a write that crosses N writes up to N, then fails with ENOSPC). Read at
// every write (one per 64 kB of rows), so that a test can set and clear it.
long long fault_limit() {
  const char* s = std::getenv("MBDAE_OUTPUT_FAULT_BYTES");
  return s && *s ? std::atoll(s) : -1LL;
}

// Writes n bytes at the end of a file that holds `written` bytes; 0 or the errno of the failure.
int write_all(int fd, const char* data, size_t n, long long written) {
  const long long limit = fault_limit();
  while (n > 0) {
    size_t chunk = n;
    if (limit >= 0) {
      if (written >= limit) return ENOSPC;
      chunk = static_cast<size_t>(std::min<long long>(static_cast<long long>(n), limit - written));
    }
    const ssize_t w = ::write(fd, data, chunk);
    if (w < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    data += w;
    n -= static_cast<size_t>(w);
    written += w;
  }
  return 0;
}

std::string os_error(int err) { return std::strerror(err); }

void rename_or_throw(const std::string& from, const std::string& to) {
  if (std::rename(from.c_str(), to.c_str()) != 0)
    throw OutputError("cannot rename " + from + " to " + to + ": " + os_error(errno));
}

int open_for_writing(const std::string& path) {
  return ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
}

// A new file (a new inode) in place of any old one: the repair process of an earlier, killed run
// may still hold the old one (core/output_guard.h) and must not cut this run's rows. Locked
// (flock) while it is written.
int open_new_file(const std::string& path) {
  if (::unlink(path.c_str()) != 0 && errno != ENOENT) return -1;
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd >= 0 && ::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    // A file system without locks: readers cannot wait for a repair, nothing else changes.
  }
  return fd;
}

constexpr size_t kPageBytes = 4096;  // a write within one page is never cut by SIGKILL

}  // namespace

std::string csv_field(const std::string& name) {
  if (name.find_first_of(",\"\r\n") == std::string::npos) return name;
  std::string q = "\"";
  for (char c : name) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + "\"";
}

CsvWriter::~CsvWriter() {
  if (fd_ < 0) return;
  try {
    if (!failed_) close();
  } catch (const std::exception&) {
  }
  end_output_guard(guard_);
  if (fd_ >= 0) ::close(fd_);
}

void CsvWriter::open(const std::string& path, const std::vector<std::string>& columns) {
  path_ = path;
  columns_ = columns.size();
  line_.assign(32 * columns_ + 2, '\0');
  buffer_.assign(std::max(kBufferBytes, 2 * line_.size()), '\0');
  used_ = rows_buffered_ = 0;
  rows_ = rows_on_disk_ = 0;
  bytes_on_disk_ = 0;
  failed_ = false;
  const std::string partial = path + ".partial";
  fd_ = open_new_file(partial);
  if (fd_ < 0) throw OutputError("cannot write " + partial + ": " + os_error(errno));
  std::string header;
  for (size_t k = 0; k < columns.size(); ++k) header += (k ? "," : "") + csv_field(columns[k]);
  header += '\n';
  if (header.size() > kPageBytes) {
    guard_ = start_output_guard(fd_);
    announce_write(guard_, 0, static_cast<long long>(header.size()));
  }
  const int err = write_all(fd_, header.data(), header.size(), 0);
  if (err) {
    failed_ = true;
    throw OutputError("cannot write " + partial + ": " + os_error(err));
  }
  bytes_on_disk_ = static_cast<long long>(header.size());
}

void CsvWriter::row(const double* v) {
  if (fd_ < 0 || failed_) throw OutputError("cannot write " + path_ + ".partial: the file is not open");
  // The same text as printf's %.15g, by std::to_chars (several times faster than fprintf: it
  // was 8 % of a kinematic sweep's CPU time), into a buffer kept for the run.
  char* p = line_.data();
  char* const end = line_.data() + line_.size() - 1;
  for (size_t k = 0; k < columns_; ++k) {
    if (k) *p++ = ',';
    const auto r = std::to_chars(p, end, v[k], std::chars_format::general, 15);
    if (r.ec != std::errc()) break;  // cannot happen: 24 characters per value are reserved
    p = r.ptr;
  }
  *p++ = '\n';
  const size_t n = static_cast<size_t>(p - line_.data());
  if (used_ + n > buffer_.size()) write_buffer();
  std::memcpy(buffer_.data() + used_, line_.data(), n);
  used_ += n;
  ++rows_buffered_;
  ++rows_;
}

// One write of whole rows; on a failure the file is cut back to its last whole row. The repair
// process starts at the first write that can be cut (most runs end before it: no process).
void CsvWriter::write_buffer() {
  if (used_ == 0) return;
  if (guard_.pid < 0 && used_ > kPageBytes - static_cast<size_t>(bytes_on_disk_ % kPageBytes))
    guard_ = start_output_guard(fd_);
  announce_write(guard_, bytes_on_disk_, bytes_on_disk_ + static_cast<long long>(used_));
  const int err = write_all(fd_, buffer_.data(), used_, bytes_on_disk_);
  if (err) {
    failed_ = true;
    if (::ftruncate(fd_, bytes_on_disk_) != 0) {
      // Nothing more to do: the message below already says the file is incomplete.
    }
    throw OutputError("cannot write " + path_ + ".partial: " + os_error(err) + " (" +
                      std::to_string(rows_on_disk_) + " rows written, the file is incomplete)");
  }
  bytes_on_disk_ += static_cast<long long>(used_);
  rows_on_disk_ += static_cast<long>(rows_buffered_);
  used_ = rows_buffered_ = 0;
}

void CsvWriter::flush() {
  if (fd_ >= 0 && !failed_) write_buffer();
}

void CsvWriter::close() {
  if (fd_ < 0) return;
  if (failed_) throw OutputError("cannot write " + path_ + ".partial: an earlier write failed");
  write_buffer();
  end_output_guard(guard_);
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) {
    failed_ = true;
    throw OutputError("cannot write " + path_ + ".partial: " + os_error(errno));
  }
  rename_or_throw(path_ + ".partial", path_);
}

void write_json_file(const std::string& path, const nlohmann::ordered_json& j) {
  const std::string tmp = path + ".partial";
  const std::string text = j.dump(2) + "\n";
  const int fd = open_for_writing(tmp);
  if (fd < 0) throw OutputError("cannot write " + tmp + ": " + os_error(errno));
  int err = write_all(fd, text.data(), text.size(), 0);
  if (::close(fd) != 0 && !err) err = errno;
  if (err) {
    std::remove(tmp.c_str());  // a cut JSON file is of no use
    throw OutputError("cannot write " + tmp + ": " + os_error(err));
  }
  rename_or_throw(tmp, path);
}

void prepare_output_folder(const std::string& dir, const std::vector<std::string>& files) {
  auto refuse = [&](const std::string& why) {
    throw ModelError("", 0, "--out", "output folder '" + dir + "' " + why);
  };
  std::error_code ec, ec2;
  std::filesystem::create_directories(dir, ec);
  if (!std::filesystem::is_directory(dir, ec2))
    refuse("cannot be created" + (ec || ec2 ? " (" + (ec ? ec : ec2).message() + ")" : std::string()));
  std::vector<std::string> probes = {".mbdae_write_test"};
  for (const auto& f : files) {
    const std::string path = dir + "/" + f;
    if (std::filesystem::is_directory(path, ec)) refuse("holds a folder named '" + f + "' where the file goes");
    probes.push_back(f + ".partial");
  }
  for (const auto& name : probes) {
    const std::string path = dir + "/" + name;
    if (std::filesystem::is_directory(path, ec)) refuse("holds a folder named '" + name + "' where a temporary file goes");
    const bool existed = std::filesystem::exists(path, ec);
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) refuse(name == probes[0] ? "is not writable (" + os_error(errno) + ")"
                                         : "cannot hold '" + name + "' (" + os_error(errno) + ")");
    ::close(fd);
    if (!existed) ::unlink(path.c_str());
  }
}

OutputFolderLock::OutputFolderLock(const std::string& dir) {
  const std::string path = dir + "/.mbdae.lock";
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw OutputError("cannot lock output folder '" + dir + "' (" + path + ": " + os_error(errno) + ")");
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    if (err == ENOLCK || err == EOPNOTSUPP || err == ENOTSUP) return;  // a file system without locks: run unlocked
    char pid[32] = {0};
    const ssize_t n = ::pread(fd_, pid, sizeof pid - 1, 0);
    ::close(fd_);
    fd_ = -1;
    if (err == EWOULDBLOCK || err == EAGAIN)
      throw OutputError("output folder '" + dir + "' is in use by another run" +
                        (n > 0 ? " (process " + std::string(pid, static_cast<size_t>(n)) + ")" : std::string()) +
                        "; wait for it or choose another --out");
    throw OutputError("cannot lock output folder '" + dir + "' (" + path + ": " + os_error(err) + ")");
  }
  const std::string me = std::to_string(::getpid());
  if (::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, me.data(), me.size(), 0) < 0) {
    // The process id is only for the message another run prints.
  }
}

OutputFolderLock::~OutputFolderLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

OutputFolderLock& OutputFolderLock::operator=(OutputFolderLock&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = o.fd_;
    o.fd_ = -1;
  }
  return *this;
}

OutputFolderLock claim_output_folder(const std::string& dir, const std::vector<std::string>& files) {
  prepare_output_folder(dir, files);
  OutputFolderLock lock(dir);
  const std::string summary = dir + "/summary.json";
  if (std::remove(summary.c_str()) != 0 && errno != ENOENT)
    throw OutputError("cannot remove the previous run's " + summary + ": " + os_error(errno));
  return lock;
}

}  // namespace mbdae
