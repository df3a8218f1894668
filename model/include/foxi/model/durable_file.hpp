// Output files that appear whole or not at all and survive a power loss, and the check of an
// output path before long work starts.
//
// A DurableFile writes to a temporary beside its target, named TARGET.foxi-tmp-PID-RANDOM (PID: the
// writer's process id), created exclusively and recorded in foxi/model/cleanup.hpp. commit() flushes
// it to disk (fsync), renames it over the target and flushes the folder (fsync), so that the new
// target is on disk when commit() returns; until then the old target, if any, is untouched. A
// DurableFile destroyed without commit() removes its temporary. Temporaries of the same target that
// writers left when they were killed (their process id no longer exists: kill(pid, 0) says ESRCH)
// are removed when a new DurableFile for that target is made; a live writer's (a concurrent run's)
// are left alone. Errors are IoError naming the target.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "foxi/api.hpp"

namespace foxi {

// Throws IoError unless `path` can be written: its folder exists, is a folder and is writable, and
// `path` itself is not a folder. Commands call it before long work, so that a mistyped -o fails
// at once rather than after an hour of meshing.
FOXI_API void check_output_path(const std::filesystem::path& path);

class FOXI_API DurableFile {
 public:
  // clean_stale = false skips the search for stale temporaries (a reading of the whole folder): for
  // many files written into one folder, after one remove_stale_temporaries_in(folder).
  explicit DurableFile(std::filesystem::path target, bool clean_stale = true);
  ~DurableFile();
  DurableFile(DurableFile&& other) noexcept;
  DurableFile& operator=(DurableFile&&) = delete;
  DurableFile(const DurableFile&) = delete;
  DurableFile& operator=(const DurableFile&) = delete;

  // Appends bytes (buffered).
  void write(const void* data, std::size_t bytes);
  void write(std::string_view s) { write(s.data(), s.size()); }
  // Bytes written so far.
  std::uint64_t size() const { return written_ + buffer_.size(); }
  // Rewrites bytes already written at `offset` (a header patched at the end).
  void overwrite(std::uint64_t offset, std::string_view s);
  // The temporary's descriptor, for libraries that write through one (after flushing foxi's buffer;
  // such a library must write at the end of the file and close only a dup() of it).
  int fd();

  // Writes out the buffer, flushes the temporary to disk and closes it; the temporary stays until
  // commit() or the destructor. Throws IoError (e.g. the disk is full).
  void finish();
  // finish(), then the temporary replaces the target, durably.
  void commit();

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& temp() const { return temp_; }

 private:
  friend void commit_together(std::span<DurableFile> files, std::ptrdiff_t marker);
  void flush_buffer();
  void write_through(const char* data, std::size_t bytes);
  void discard() noexcept;

  std::filesystem::path target_, temp_;
  std::string buffer_;
  std::uint64_t written_ = 0;
  int fd_ = -1;
  bool done_ = false;  // committed, or given up (temporary removed)
};

// Commits files written together (e.g. a TetGen .node/.ele/.face set) so that the set on disk is
// never a mix of old and new files, whenever the program is stopped, even by a power loss: all are
// flushed to disk first; then the old target of `marker` (the file a reader opens first and which
// names the set, e.g. the .node) is removed, the others are renamed into place, and the marker is
// renamed last, each step flushed to disk. So the marker's presence means the whole new set is
// there; after a stop in between, the marker is absent and the set reads as missing. The renames
// are done with foxi/model/cleanup.hpp's list locked, so an interrupt waits for them. On failure the
// temporaries and the part of the set already renamed are removed (the set is absent) and IoError
// is thrown. marker = -1: no marker, the files are simply renamed in order. (A reader that is
// reading the old set while it is replaced can still mix them: a set of files has no atomic
// replacement.)
FOXI_API void commit_together(std::span<DurableFile> files, std::ptrdiff_t marker = -1);

// Removes temporaries of `target` (TARGET.foxi-tmp-PID-*) whose writer process no longer exists;
// returns how many. DurableFile's constructor calls it.
FOXI_API std::size_t remove_stale_temporaries(const std::filesystem::path& target);
// The same for every target in `folder` (any NAME.foxi-tmp-PID-* of a writer that is gone).
FOXI_API std::size_t remove_stale_temporaries_in(const std::filesystem::path& folder);

}  // namespace foxi
