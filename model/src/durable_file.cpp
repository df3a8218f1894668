#include "foxi/model/durable_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <random>
#include <system_error>
#include <vector>

#include "foxi/model/cleanup.hpp"
#include "foxi/model/io_error.hpp"

namespace foxi {

namespace {

constexpr std::string_view kTempTag = ".foxi-tmp-";
constexpr std::size_t kBufferBytes = std::size_t{1} << 20;

[[noreturn]] void fail(const std::filesystem::path& target, const std::string& what, int err) {
  if (err == ENOSPC || err == EDQUOT || err == EIO || err == EFBIG)
    throw WriteError(target.string(), 0, IoError::kNoOffset, what + ": " + std::strerror(err));
  throw IoError(target.string(), 0, IoError::kNoOffset, what + ": " + std::strerror(err));
}

std::filesystem::path folder_of(const std::filesystem::path& path) {
  const std::filesystem::path parent = path.parent_path();
  return parent.empty() ? std::filesystem::path(".") : parent;
}

// Makes the folder's entries (a rename, a removal) durable. Some file systems cannot sync a folder
// (EINVAL): nothing more can be done there.
void sync_folder(const std::filesystem::path& target) {
  const int fd = ::open(folder_of(target).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) fail(target, "cannot open its folder to flush it", errno);
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0 && err != EINVAL && err != EROFS) fail(target, "cannot flush its folder to disk", err);
}

// Each distinct folder of the files once (a movie's frames share one).
void sync_folders(std::span<const DurableFile> files) {
  std::vector<std::filesystem::path> done;
  for (const DurableFile& f : files) {
    const std::filesystem::path folder = folder_of(f.target());
    bool seen = false;
    for (const auto& d : done) seen = seen || d == folder;
    if (seen) continue;
    done.push_back(folder);
    sync_folder(f.target());
  }
}

bool writer_gone(pid_t pid) {
  if (pid == ::getpid()) return false;  // this run: a tracked temporary is live (checked by the caller)
  return ::kill(pid, 0) != 0 && errno == ESRCH;
}

}  // namespace

void check_output_path(const std::filesystem::path& path) {
  std::error_code ec;
  if (path.empty()) throw IoError("", 0, IoError::kNoOffset, "empty output file name");
  if (std::filesystem::is_directory(path, ec))
    throw IoError(path.string(), 0, IoError::kNoOffset, "is a folder, not a file to write");
  // Written through NAME.foxi-tmp-PID-RANDOM: a name a file system takes can still be too long for
  // that (a 229-character name failed after the work).
  if (path.filename().string().size() + 32 > NAME_MAX)
    throw IoError(
        path.string(), 0, IoError::kNoOffset,
        "the file name is too long: foxi writes it through a temporary of 32 more characters, and a "
        "name has at most " +
            std::to_string(NAME_MAX));
  const std::filesystem::path folder = folder_of(path);
  const auto st = std::filesystem::status(folder, ec);
  if (!std::filesystem::exists(st))
    throw IoError(path.string(), 0, IoError::kNoOffset,
                  "cannot write: the folder " + folder.string() + " does not exist");
  if (!std::filesystem::is_directory(st))
    throw IoError(path.string(), 0, IoError::kNoOffset,
                  "cannot write: " + folder.string() + " is not a folder");
  if (::access(folder.c_str(), W_OK | X_OK) != 0)
    throw IoError(path.string(), 0, IoError::kNoOffset,
                  "cannot write in the folder " + folder.string() + ": " + std::strerror(errno));
}

namespace {

// Removes FOLDER/NAME.foxi-tmp-PID-* whose writer is gone, for one NAME (`name` given) or any.
std::size_t remove_stale(const std::filesystem::path& folder, const std::string* name) {
  std::error_code ec;
  std::filesystem::directory_iterator it(folder, ec), end;
  std::vector<std::filesystem::path> stale;
  for (; !ec && it != end; it.increment(ec)) {
    const std::string entry = it->path().filename().string();
    const std::size_t tag = name ? name->size() : entry.rfind(kTempTag);
    if (tag == std::string::npos || tag == 0) continue;
    if (name &&
        (entry.compare(0, name->size(), *name) != 0 || entry.compare(tag, kTempTag.size(), kTempTag) != 0))
      continue;
    // PID-RANDOM after the tag; anything else is not foxi's and is left alone.
    const char* p = entry.data() + tag + kTempTag.size();
    const char* e = entry.data() + entry.size();
    long pid = 0;
    const auto [q, err] = std::from_chars(p, e, pid);
    if (err != std::errc() || q == p || q == e || *q != '-' || pid <= 0) continue;
    if (pid == ::getpid() ? !cleanup::is_tracked(it->path()) : writer_gone(pid_t(pid)))
      stale.push_back(it->path());
  }
  std::size_t removed = 0;
  for (const auto& p : stale) removed += std::filesystem::remove_all(p, ec) > 0 ? 1 : 0;
  return removed;
}

}  // namespace

std::size_t remove_stale_temporaries(const std::filesystem::path& target) {
  const std::string name = target.filename().string();
  return remove_stale(folder_of(target), &name);
}

std::size_t remove_stale_temporaries_in(const std::filesystem::path& folder) {
  return remove_stale(folder, nullptr);
}

DurableFile::DurableFile(std::filesystem::path target, bool clean_stale) : target_(std::move(target)) {
  if (clean_stale) remove_stale_temporaries(target_);
  std::random_device rd;
  char suffix[64];
  std::snprintf(suffix, sizeof suffix, "%.*s%ld-%08x", int(kTempTag.size()), kTempTag.data(),
                long(::getpid()), static_cast<unsigned>(rd()));
  temp_ = target_;
  temp_ += suffix;
  int err = 0;
  // Created and recorded in one step: an interrupt removes it or finds it absent.
  cleanup::with_lock([&] {
    fd_ = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    err = errno;
    if (fd_ >= 0) cleanup::track(temp_);
  });
  if (fd_ < 0) {
    done_ = true;
    std::error_code ec;
    if (std::filesystem::is_directory(target_, ec))
      throw IoError(target_.string(), 0, IoError::kNoOffset, "is a folder, not a file to write");
    fail(target_, "cannot create the file", err);
  }
}

DurableFile::DurableFile(DurableFile&& o) noexcept
    : target_(std::move(o.target_)),
      temp_(std::move(o.temp_)),
      buffer_(std::move(o.buffer_)),
      written_(o.written_),
      fd_(o.fd_),
      done_(o.done_) {
  o.fd_ = -1;
  o.done_ = true;
}

DurableFile::~DurableFile() { discard(); }

void DurableFile::discard() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (done_) return;
  done_ = true;
  std::error_code ec;
  std::filesystem::remove(temp_, ec);
  cleanup::untrack(temp_);
}

void DurableFile::write_through(const char* p, std::size_t left) {
  while (left > 0) {
    const ssize_t n = ::write(fd_, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = n < 0 ? errno : ENOSPC;
      discard();
      fail(target_, err == ENOSPC ? "write failed (the disk is full)" : "write failed", err);
    }
    p += n;
    left -= std::size_t(n);
    written_ += std::uint64_t(n);
  }
}

void DurableFile::flush_buffer() {
  write_through(buffer_.data(), buffer_.size());
  buffer_.clear();
}

void DurableFile::write(const void* data, std::size_t bytes) {
  if (fd_ < 0) throw IoError(target_.string(), 0, IoError::kNoOffset, "written after it was closed");
  if (buffer_.size() + bytes > kBufferBytes) flush_buffer();
  if (bytes >= kBufferBytes) {
    write_through(static_cast<const char*>(data), bytes);  // big pieces skip the copy
    return;
  }
  if (buffer_.capacity() < kBufferBytes)
    buffer_.reserve(kBufferBytes);  // not before: a PNG writes through fd()
  buffer_.append(static_cast<const char*>(data), bytes);
}

void DurableFile::overwrite(std::uint64_t offset, std::string_view s) {
  if (fd_ < 0) throw IoError(target_.string(), 0, IoError::kNoOffset, "written after it was closed");
  flush_buffer();
  if (offset + s.size() > written_) throw IoError(target_.string(), 0, offset, "overwrite past the end");
  std::size_t done = 0;
  while (done < s.size()) {
    const ssize_t n = ::pwrite(fd_, s.data() + done, s.size() - done, off_t(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = n < 0 ? errno : ENOSPC;
      discard();
      fail(target_, "write failed", err);
    }
    done += std::size_t(n);
  }
}

int DurableFile::fd() {
  if (fd_ < 0) throw IoError(target_.string(), 0, IoError::kNoOffset, "written after it was closed");
  flush_buffer();
  return fd_;
}

void DurableFile::finish() {
  if (fd_ < 0) {
    if (done_) throw IoError(target_.string(), 0, IoError::kNoOffset, "already committed or abandoned");
    return;  // finished before
  }
  flush_buffer();
  std::string().swap(buffer_);  // a movie keeps thousands of finished frames
  int rc;
  while ((rc = ::fsync(fd_)) != 0 && errno == EINTR) {
  }
  const int err = errno;
  const int closed = ::close(fd_);
  const int close_err = errno;
  fd_ = -1;
  if (rc != 0 && err != EINVAL) {
    discard();
    fail(target_, "cannot flush to disk", err);
  }
  if (closed != 0 && close_err != EINTR) {
    discard();
    fail(target_, "write failed", close_err);
  }
}

void DurableFile::commit() {
  finish();
  int err = 0;
  cleanup::with_lock([&] {
    if (::rename(temp_.c_str(), target_.c_str()) == 0) {
      cleanup::untrack(temp_);
      done_ = true;
    } else {
      err = errno;
    }
  });
  if (err != 0) {
    discard();
    if (err == EISDIR)
      throw IoError(target_.string(), 0, IoError::kNoOffset, "is a folder, not a file to write");
    fail(target_, "cannot rename into place", err);
  }
  sync_folder(target_);
}

void commit_together(std::span<DurableFile> files, std::ptrdiff_t marker) {
  for (DurableFile& f : files) f.finish();
  std::vector<std::filesystem::path> placed;
  int err = 0;
  std::filesystem::path failed;
  const auto step = [&](DurableFile& f) {
    if (::rename(f.temp_.c_str(), f.target_.c_str()) != 0) {
      err = errno;
      failed = f.target_;
      return false;
    }
    cleanup::untrack(f.temp_);
    f.done_ = true;
    placed.push_back(f.target_);
    return true;
  };
  try {
    cleanup::with_lock([&] {
      if (marker >= 0) {
        DurableFile& m = files[std::size_t(marker)];
        if (::unlink(m.target_.c_str()) != 0 && errno != ENOENT) {
          err = errno;
          failed = m.target_;
          return;
        }
        sync_folder(m.target_);
      }
      for (std::size_t i = 0; i < files.size(); ++i)
        if (std::ptrdiff_t(i) != marker && !step(files[i])) return;
      if (marker >= 0) {
        sync_folders(files);
        step(files[std::size_t(marker)]);
      }
    });
    if (err == 0) sync_folders(files);
  } catch (...) {
    err = err == 0 ? EIO : err;
    if (failed.empty()) failed = files.empty() ? std::filesystem::path() : files[0].target_;
  }
  if (err != 0) {
    std::error_code ec;
    for (const auto& p : placed) std::filesystem::remove(p, ec);
    for (DurableFile& f : files) f.discard();
    fail(failed, "cannot rename into place", err);
  }
}

}  // namespace foxi
