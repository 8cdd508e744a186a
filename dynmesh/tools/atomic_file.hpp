// dynmesh/tools/atomic_file.hpp — output files written completely or not at all (private
// to the tool).
//
// Purpose: `dynmesh mesh` promises (docs/FORMATS.md) that a failed run leaves the files of
// an earlier run as they were. AtomicOutputs collects every output of a run, each written to
// a temporary file beside its target (same directory, so rename() cannot cross file
// systems); commit() then renames all temporaries into place. Writing everything before
// renaming anything means a write failure (disk full, a file size limit, unwritable
// directory) leaves every old file intact. An output comes in one of two ways:
//   add(path, text)     the whole text at once: written, flushed to disk and closed at once;
//   open_stream(path)   a Stream that takes the text piece by piece as the run produces it
//                       (the change feed of a long edit session), through a fixed buffer, so
//                       that the output never has to fit in memory; commit() flushes it to
//                       disk and closes it before the first rename.
// A target that exists but is not a regular file (a directory, a device such as /dev/stdout,
// a FIFO) is refused when the output is opened: renaming would replace it rather than write
// into it. An append (the stability CSV) is a rewrite: read_existing() gives the old
// content, and the old content plus the new goes through add().
// Invariants: a temporary is removed unless it was renamed (the destructor closes and
// removes the leftovers of a run that failed or never committed, streams included); renames
// follow the order in which the outputs were opened; errors are InputError(Io) naming the
// target path and the OS reason (strerror); a Stream whose write failed refuses every
// later append and the commit, so a torn file can never be renamed into place.
// Complexity: linear in the bytes written (an append rewrites the whole file); one fsync per
// file; a Stream holds one buffer of Stream::kBufferBytes, whatever it writes in all.
// Paper: none.
#pragma once

#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
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
  /// One output written while the run goes on: append() gathers text in the buffer and
  /// writes it to the temporary whenever the buffer would overflow. Owned by its
  /// AtomicOutputs, which finishes it at commit().
  class Stream {
   public:
    /// Large enough that the writes cost few system calls, small against any mesh.
    static constexpr std::size_t kBufferBytes = std::size_t{1} << 20;

    Stream(const Stream&) = delete;
    Stream& operator=(const Stream&) = delete;
    ~Stream() {
      if (fd_ >= 0) ::close(fd_);
    }

    /// Appends `text` to the output; InputError(Io) if a write fails.
    void append(std::string_view text) {
      if (fd_ < 0) fail(path_, closed_ ? "appended to after it was finished" : "an earlier write failed", 0);
      if (text.size() > kBufferBytes - used_) {
        flush();
        // Text as large as the buffer would only be copied through it.
        if (text.size() >= kBufferBytes) {
          write_all(text);
          return;
        }
      }
      std::memcpy(buffer_.get() + used_, text.data(), text.size());
      used_ += text.size();
    }

   private:
    friend class AtomicOutputs;

    Stream(std::string path, int fd, bool buffered)
        : path_(std::move(path)),
          fd_(fd),
          buffer_(buffered ? std::make_unique_for_overwrite<char[]>(kBufferBytes) : nullptr) {}

    void flush() {
      write_all(std::string_view(buffer_.get(), used_));
      used_ = 0;
    }

    /// Writes every byte of `bytes`, retrying short and interrupted writes; on an error
    /// closes the file, so that nothing more reaches it, and throws.
    void write_all(std::string_view bytes) {
      std::size_t done = 0;
      while (done < bytes.size()) {
        const ::ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
        if (n < 0) {
          if (errno == EINTR) continue;
          broken(errno, "write error");
        }
        done += static_cast<std::size_t>(n);
      }
    }

    /// Writes what the buffer holds, gives the file the usual permissions, flushes it to
    /// disk and closes it. Does nothing the second time.
    void finish() {
      if (closed_) return;
      if (fd_ < 0) fail(path_, "an earlier write failed", 0);
      if (buffer_) flush();
      buffer_.reset();
      // mkostemp creates 0600; give the file the usual permissions (0666 less the umask).
      const ::mode_t mask = ::umask(0);
      ::umask(mask);
      if (::fchmod(fd_, 0666 & ~mask) != 0) broken(errno, "cannot set permissions");
      if (::fsync(fd_) != 0) broken(errno, "cannot flush to disk");
      const int fd = std::exchange(fd_, -1);
      if (::close(fd) != 0) fail(path_, "write error on close", errno);
      closed_ = true;
    }

    [[noreturn]] void broken(int err, const char* what) {
      ::close(std::exchange(fd_, -1));
      fail(path_, what, err);
    }

    std::string path_;                 // the target, for messages
    int fd_;                           // the temporary; -1 once closed or broken
    std::unique_ptr<char[]> buffer_;   // kBufferBytes, or none for add()'s direct write
    std::size_t used_ = 0;             // bytes of buffer_ not yet written
    bool closed_ = false;              // finished: flushed to disk and closed
  };

  AtomicOutputs() = default;
  AtomicOutputs(const AtomicOutputs&) = delete;
  AtomicOutputs& operator=(const AtomicOutputs&) = delete;
  ~AtomicOutputs() {
    for (Pending& p : pending_) {
      p.stream.reset();
      ::unlink(p.temp.c_str());
    }
  }

  /// Writes `text` to a temporary beside `path`; the target itself is untouched until commit().
  void add(const std::string& path, std::string_view text) {
    Stream& out = open(path, /*buffered=*/false);
    out.write_all(text);
    out.finish();
  }

  /// Opens a temporary beside `path` for text that comes piece by piece; the target itself
  /// is untouched until commit(). The reference stays valid as long as this AtomicOutputs.
  Stream& open_stream(const std::string& path) { return open(path, /*buffered=*/true); }

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

  /// Finishes every stream, then renames every temporary into place, in the order opened.
  /// A stream that cannot be finished stops the commit before any rename.
  void commit() {
    for (Pending& p : pending_) p.stream->finish();
    for (std::size_t i = 0; i < pending_.size(); ++i) {
      if (std::rename(pending_[i].temp.c_str(), pending_[i].stream->path_.c_str()) != 0) {
        const int err = errno;
        pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(i));
        fail(pending_.front().stream->path_, "cannot rename the finished file into place", err);
      }
    }
    pending_.clear();
  }

 private:
  struct Pending {
    std::string temp;               // the temporary beside the target
    std::unique_ptr<Stream> stream; // the target's path and, until finished, the open file
  };

  /// Checks the target and creates its temporary, recorded at once so that the destructor
  /// removes it whatever happens next.
  Stream& open(const std::string& path, bool buffered) {
    const auto slash = path.find_last_of('/');
    const std::string dir = slash == std::string::npos ? std::string{} : path.substr(0, slash + 1);
    const std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
    if (base.empty()) fail(path, "not a file name", 0);
    struct ::stat st;
    if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) fail(path, "not a regular file", 0);
    std::string temp = dir + "." + base + ".tmp-XXXXXX";
    // Close-on-exec: a stream's file stays open while the run goes on.
    const int fd = ::mkostemp(temp.data(), O_CLOEXEC);
    if (fd < 0) fail(path, "cannot create a temporary file beside it", errno);
    std::unique_ptr<Stream> stream;
    try {
      stream.reset(new Stream(path, fd, buffered));
      pending_.push_back(Pending{temp, nullptr});
    } catch (...) {
      if (!stream) ::close(fd);
      ::unlink(temp.c_str());
      throw;
    }
    pending_.back().stream = std::move(stream);
    return *pending_.back().stream;
  }

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
