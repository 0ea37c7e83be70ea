// Safe outputs (issue #9): rdyn never deletes, truncates or replaces what it did not write,
// and an interrupted or failed run leaves nothing behind.
//
// OutputDir  — a result folder (simulate, validate). Files are written into a temporary
//   sibling folder; commit() writes a manifest (kManifest: the files rdyn wrote) and swaps
//   the folder into place atomically (renameat2 RENAME_EXCHANGE). An existing folder is
//   replaced only when it is empty or an rdyn output whose every entry its manifest lists;
//   any other folder is refused unless `force`, and then rdyn writes its files into it,
//   replacing same-named files only and keeping everything else.
// OutputFile — a single result file (extract, sweep, calibrate --write-scene). Written
//   beside the target and renamed into place. An existing regular file is replaced only
//   when it is empty or recognisably rdyn's (`is_ours` on its first bytes), or with `force`.
//   Character devices (/dev/null, /dev/stdout) and FIFOs with a reader are written through;
//   a FIFO without a reader, sockets, block devices and folders are refused.
// Paths under /dev/ and /proc/ (/dev/stdout, /dev/fd/N) are written through whatever they
// name — a terminal, a pipe, a redirected file — since they name a stream, not a file to keep.
// Both follow symbolic links (the link stays, its target is written), create missing
// parent folders, and register their temporaries for removal on SIGINT/SIGTERM/SIGHUP.
#pragma once

#include <functional>
#include <string>

namespace rdyn::validate {

class OutputError : public std::exception {
 public:
  explicit OutputError(std::string m) : msg_(std::move(m)) {}
  const char* what() const noexcept override { return msg_.c_str(); }

 private:
  std::string msg_;
};

inline constexpr const char* kManifest = ".rdyn-output";

class OutputDir {
 public:
  // Checks the destination and creates the temporary folder; throws OutputError naming
  // the folder and what is wrong (not a folder, foreign files, not writable...).
  explicit OutputDir(std::string final_path, bool force = false);
  ~OutputDir();  // removes the temporary folder unless committed
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  // Path of a file inside the (temporary) folder; `name` may hold one '/' level that the
  // caller created with make_subfolder.
  std::string file(const std::string& name) const;
  void make_subfolder(const std::string& name) const;
  // Moves the results into place (see above).
  void commit();
  const std::string& final_path() const { return final_; }

 private:
  enum class Mode { Create, Replace, Merge };
  std::string final_, tmp_;
  std::string created_;  // topmost parent folder this run created ("" none)
  Mode mode_ = Mode::Create;
  int slot_ = -1;
  bool committed_ = false;
};

class OutputFile {
 public:
  using Recogniser = std::function<bool(const std::string& first_bytes)>;
  OutputFile(std::string path, bool force, Recogniser is_ours);
  ~OutputFile();  // removes the temporary file unless committed
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  // Where to write: a temporary file beside the target, or the device itself.
  const std::string& write_path() const { return write_; }
  // Writes the whole result (checked): into the temporary file, or appended to the device,
  // FIFO or redirected standard stream without truncating it.
  void write(const std::string& text) const;
  void commit();
  const std::string& final_path() const { return final_; }

 private:
  std::string final_, write_;
  std::string created_;   // topmost parent folder this run created ("" none)
  bool through_ = false;  // a character device or a FIFO: written in place
  int fifo_fd_ = -1;      // keeps a FIFO's reader side connected until commit
  int slot_ = -1;
  bool committed_ = false;
};

// A file written in 1 MiB chunks, every write and the close checked: a full disk or a
// quota is an OutputError naming the file and the system's reason.
class TextSink {
 public:
  // Creates or truncates `path`; with `append`, opens an existing file, device or FIFO for
  // appending instead (a redirected /dev/stdout keeps what is already there).
  explicit TextSink(std::string path, bool append = false);
  ~TextSink();
  TextSink(const TextSink&) = delete;
  TextSink& operator=(const TextSink&) = delete;
  void add(const std::string& text);
  void close();  // flushes; throws OutputError

 private:
  void flush();
  std::string path_, buffer_;
  int fd_ = -1;
};

void write_text_file(const std::string& path, const std::string& text);

// Reads at most `max_bytes` from the start of a file ("" when it cannot be read).
std::string read_file_head(const std::string& path, size_t max_bytes);

}  // namespace rdyn::validate
