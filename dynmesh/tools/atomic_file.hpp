// dynmesh/tools/atomic_file.hpp — output files written completely or not at all (private
// to the tool).
//
// Purpose: `dynmesh mesh` promises (shared/FORMATS.md) that a failed run leaves the files of
// an earlier run as they were. AtomicOutputs collects every output of a run: add() writes
// the text to a temporary file beside its target (same directory, so rename() cannot cross
// file systems), flushes it to disk and closes it, checking every step; commit() then
// renames all temporaries into place. Writing everything before renaming anything means a
// write failure (disk full, unwritable directory) leaves every old file intact.
// Invariants: a temporary is removed unless it was renamed (the destructor removes the
// leftovers of a run that failed or never committed); errors are InputError(Io) naming the
// target path and the OS reason (strerror).
// Complexity: linear in the bytes written; one fsync per file.
// Paper: none.
#pragma once

#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
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

  std::vector<Pending> pending_;
};

}  // namespace dynmesh::tool
