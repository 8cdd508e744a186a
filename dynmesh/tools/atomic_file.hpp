// dynmesh/tools/atomic_file.hpp — output files written completely or not at all (private
// to the tool).
//
// Purpose: `dynmesh mesh` promises (docs/FORMATS.md) that a failed run leaves the files of
// an earlier run as they were. AtomicOutputs collects every output of a run: add() writes
// the text to a temporary file beside its target (same directory, so rename() cannot cross
// file systems), flushes it to disk and closes it, checking every step; commit() then
// renames all temporaries into place. Writing everything before renaming anything means a
// write failure (disk full, a file size limit, unwritable directory) leaves every old file
// intact. A target that exists but is not a regular file (a directory, a device such as
// /dev/stdout, a FIFO) is refused: renaming would replace it rather than write into it.
// An append (the stability CSV) is a rewrite: read_existing() gives the old content, and the
// old content plus the new goes through add().
// Invariants: a temporary is removed unless it was renamed (the destructor removes the
// leftovers of a run that failed or never committed); errors are InputError(Io) naming the
// target path and the OS reason (strerror).
// Complexity: linear in the bytes written (an append rewrites the whole file); one fsync per
// file.
// Paper: none.
#pragma once

#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "dynmesh/errors.hpp"

namespace dynmesh::tool {

class AtomicOutputs {
 public:
  AtomicOutputs() = default;
  AtomicOutputs(const AtomicOutputs&) = delete;
  AtomicOutputs& operator=(const AtomicOutputs&) = delete;
  ~AtomicOutputs() {
    for (const Pending& p : pending_) ::unlink(p.temp.c_str());
  }

  /// Writes `text` to a temporary beside `path`; the target itself is untouched until commit().
  void add(const std::string& path, std::string_view text) {
    const auto slash = path.find_last_of('/');
    const std::string dir = slash == std::string::npos ? std::string{} : path.substr(0, slash + 1);
    const std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
    if (base.empty()) fail(path, "not a file name", 0);
    struct ::stat st;
    if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) fail(path, "not a regular file", 0);
    std::string temp = dir + "." + base + ".tmp-XXXXXX";
    const int fd = ::mkstemp(temp.data());
    if (fd < 0) fail(path, "cannot create a temporary file beside it", errno);
    pending_.push_back(Pending{path, temp});
    std::size_t done = 0;
    while (done < text.size()) {
      const ::ssize_t n = ::write(fd, text.data() + done, text.size() - done);
      if (n < 0) {
        if (errno == EINTR) continue;
        const int err = errno;
        ::close(fd);
        fail(path, "write error", err);
      }
      done += static_cast<std::size_t>(n);
    }
    // mkstemp creates 0600; give the file the usual permissions (0666 less the umask).
    const ::mode_t mask = ::umask(0);
    ::umask(mask);
    if (::fchmod(fd, 0666 & ~mask) != 0) {
      const int err = errno;
      ::close(fd);
      fail(path, "cannot set permissions", err);
    }
    if (::fsync(fd) != 0) {
      const int err = errno;
      ::close(fd);
      fail(path, "cannot flush to disk", err);
    }
    if (::close(fd) != 0) fail(path, "write error on close", errno);
  }

  /// The content of the file at `path`, or std::nullopt when there is none; InputError(Io)
  /// with the OS reason when it exists but cannot be read, and, as add(), when it is not a
  /// regular file (opened without blocking, so a FIFO or a terminal cannot hang the read).
  static std::optional<std::string> read_existing(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
    if (fd < 0) {
      if (errno == ENOENT) return std::nullopt;
      fail_read(path, errno);
    }
    struct ::stat st;
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
      ::close(fd);
      fail(path, "not a regular file", 0);
    }
    std::string text;
    char buf[1 << 16];
    while (true) {
      const ::ssize_t n = ::read(fd, buf, sizeof buf);
      if (n == 0) break;
      if (n < 0) {
        if (errno == EINTR) continue;
        const int err = errno;
        ::close(fd);
        fail_read(path, err);
      }
      text.append(buf, static_cast<std::size_t>(n));
    }
    ::close(fd);
    return text;
  }

  /// Renames every temporary into place, in the order added.
  void commit() {
    for (std::size_t i = 0; i < pending_.size(); ++i) {
      if (std::rename(pending_[i].temp.c_str(), pending_[i].path.c_str()) != 0) {
        const int err = errno;
        pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(i));
        fail(pending_.front().path, "cannot rename the finished file into place", err);
      }
    }
    pending_.clear();
  }

 private:
  struct Pending {
    std::string path;  // the target
    std::string temp;  // the temporary beside it
  };

  [[noreturn]] static void fail(const std::string& path, const std::string& what, int err) {
    std::string text = "cannot write output: " + what;
    if (err != 0) text += std::string(": ") + std::strerror(err);
    throw InputError(InputError::Kind::Io, text, path);
  }
  [[noreturn]] static void fail_read(const std::string& path, int err) {
    throw InputError(InputError::Kind::Io, std::string("cannot read: ") + std::strerror(err), path);
  }

  std::vector<Pending> pending_;
};

}  // namespace dynmesh::tool
