#include "validate/io/output_dir.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <vector>

#include "validate/io/cleanup_on_signal.hpp"

namespace rdyn::validate {

namespace fs = std::filesystem;

namespace {

constexpr const char* kManifestHeader = "rdyn output v1";
constexpr int kMaxLinks = 40;           // as the kernel's ELOOP limit
constexpr size_t kMaxForeignListed = 3;  // names quoted in a refusal

std::string sys_error() { return std::strerror(errno); }

// The path with every symbolic link of its last component followed (the link itself is
// kept: rdyn writes where it points), made absolute and normal.
fs::path resolve_links(const std::string& given) {
  fs::path p = fs::absolute(given).lexically_normal();
  for (int i = 0; i < kMaxLinks; ++i) {
    std::error_code ec;
    if (!fs::is_symlink(fs::symlink_status(p, ec))) return p;
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) throw OutputError(given + ": cannot read the symbolic link: " + ec.message());
    p = (target.is_absolute() ? target : p.parent_path() / target).lexically_normal();
  }
  throw OutputError(given + ": too many levels of symbolic links");
}

// Creates the missing parent folders of `target`; returns the topmost one it created (empty
// when none), so a run that does not finish removes them again.
std::string make_parents(const std::string& given, const fs::path& target) {
  const fs::path parent = target.parent_path();
  std::error_code ec;
  if (fs::is_directory(parent, ec)) return {};
  fs::path top = parent;
  while (top.has_parent_path() && top.parent_path() != top && !fs::exists(top.parent_path(), ec)) top = top.parent_path();
  fs::create_directories(parent, ec);
  if (ec || !fs::is_directory(parent))
    throw OutputError(given + ": cannot create the folder '" + parent.string() + "'" +
                      (ec ? ": " + ec.message() : std::string()));
  return top.string();
}

// Removes the folders make_parents created, deepest first, as long as they are empty.
void remove_created_parents(const fs::path& target, const std::string& top) {
  if (top.empty()) return;
  for (fs::path p = target.parent_path(); !p.empty(); p = p.parent_path()) {
    if (rmdir(p.c_str()) != 0 || p == fs::path(top)) return;
  }
}

void require_writable(const std::string& given, const fs::path& folder) {
  if (access(folder.c_str(), W_OK | X_OK) != 0)
    throw OutputError(given + ": cannot write in '" + folder.string() + "': " + sys_error());
}

std::string random_suffix() {
  std::random_device rd;
  return std::to_string(rd()) + std::to_string(getpid());
}

// Every entry below `root` (folders end with '/'), relative to it, in order.
std::vector<std::string> entries_below(const fs::path& root) {
  std::vector<std::string> out;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(root, fs::directory_options::none, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    // Lexically: fs::relative resolves links and gave '' for every entry of /proc/self (issue #23).
    std::string rel = it->path().lexically_relative(root).string();
    if (it->is_directory(ec) && !it->is_symlink(ec)) rel += "/";
    out.push_back(rel);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The files an rdyn output folder lists in its manifest; empty when it has none.
std::set<std::string> read_manifest(const fs::path& folder, bool& has_manifest) {
  std::set<std::string> files;
  std::ifstream f(folder / kManifest);
  std::string line;
  has_manifest = std::getline(f, line) && line == kManifestHeader;
  if (!has_manifest) return files;
  for (int n = 0; std::getline(f, line) && n < 1000000; ++n) files.insert(line);
  return files;
}

// Names in `folder` that rdyn did not write (not in its manifest); empty when the folder is
// empty or an rdyn output.
std::vector<std::string> foreign_entries(const fs::path& folder) {
  bool has_manifest = false;
  const auto listed = read_manifest(folder, has_manifest);
  // Folders rdyn made are the parents of the files it lists; any other folder is the user's.
  std::set<std::string> folders;
  for (const auto& f : listed)
    for (size_t at = f.find('/'); at != std::string::npos; at = f.find('/', at + 1)) folders.insert(f.substr(0, at + 1));
  std::vector<std::string> foreign;
  for (const auto& e : entries_below(folder)) {
    if (e == kManifest) continue;
    if (!listed.count(e) && !(e.back() == '/' && folders.count(e))) foreign.push_back(e);
  }
  (void)has_manifest;
  return foreign;
}

std::string quote_some(const std::vector<std::string>& names) {
  std::string s;
  for (size_t i = 0; i < names.size() && i < kMaxForeignListed; ++i) s += (i ? ", '" : "'") + names[i] + "'";
  if (names.size() > kMaxForeignListed) s += " and " + std::to_string(names.size() - kMaxForeignListed) + " more";
  return s;
}

// Writes the manifest: every file below `folder` (the results) plus `also` (files an
// earlier rdyn output left there that are kept, in merge mode).
void write_manifest(const fs::path& folder, const std::set<std::string>& also) {
  std::set<std::string> files(also.begin(), also.end());
  for (const auto& e : entries_below(folder))
    if (e != kManifest) files.insert(e);  // files, and folders (ending in '/') even when empty
  std::string text = std::string(kManifestHeader) + "\n";
  for (const auto& f : files) text += f + "\n";
  write_text_file((folder / kManifest).string(), text);
}

// Removes an earlier rdyn output that was swapped out: only the files its manifest lists and
// the folders they leave empty (a file that appeared meanwhile is kept).
void remove_rdyn_output(const fs::path& folder) {
  bool has_manifest = false;
  const auto listed = read_manifest(folder, has_manifest);
  std::error_code ec;
  for (const auto& f : listed) {
    if (f.empty() || f.back() == '/' || f.find("..") != std::string::npos || f.front() == '/') continue;
    fs::remove(folder / f, ec);
  }
  fs::remove(folder / kManifest, ec);
  auto entries = entries_below(folder);
  std::reverse(entries.begin(), entries.end());  // deepest folders first
  for (const auto& e : entries)
    if (e.back() == '/') fs::remove(folder / e, ec);  // only succeeds when empty
  fs::remove(folder, ec);
}

}  // namespace

// ---------------------------------------------------------------------------------------
// OutputDir

OutputDir::OutputDir(std::string final_path, bool force) {
  while (final_path.size() > 1 && final_path.back() == '/') final_path.pop_back();
  if (final_path.empty()) throw OutputError("--out: empty path");
  const fs::path target = resolve_links(final_path);
  if (target == target.root_path() || target.filename() == "." || target.filename() == "..")
    throw OutputError(final_path + ": not a folder rdyn can write its results to");
  // The kernel's file systems hold processes and devices, never results (a folder under /dev,
  // such as /dev/shm, is an ordinary one and goes through the checks below).
  for (const std::string sys : {"/proc", "/sys"})
    if (target == fs::path(sys) || target.string().rfind(sys + "/", 0) == 0)
      throw OutputError(final_path + ": lies in " + sys + ", the kernel's own file system, not a folder rdyn can " +
                        "write its results to; choose another --out");
  final_ = target.string();
  created_ = make_parents(final_path, target);
  std::error_code ec;
  const auto st = fs::status(target, ec);
  if (fs::exists(st)) {
    if (!fs::is_directory(st))
      throw OutputError(final_path + ": exists and is not a folder (rdyn writes a folder of results here)");
    const auto foreign = foreign_entries(target);
    if (foreign.empty()) {
      mode_ = Mode::Replace;
    } else if (force) {
      mode_ = Mode::Merge;
      require_writable(final_path, target);
    } else {
      throw OutputError(final_path + ": the folder holds files rdyn did not write (" + quote_some(foreign) +
                        "); choose another --out, or pass --force to write rdyn's files into it (same-named files "
                        "are replaced, nothing else is touched)");
    }
  }
  require_writable(final_path, target.parent_path());
  tmp_ = (target.parent_path() / ("." + target.filename().string() + ".rdyn-tmp-" + random_suffix())).string();
  if (mkdir(tmp_.c_str(), 0755) != 0) {
    const std::string why = sys_error();
    remove_created_parents(target, created_);
    throw OutputError(final_path + ": cannot create a temporary folder beside it: " + why);
  }
  // On a signal: the temporary, then the parents this run created while they are empty.
  slot_ = register_temporary(tmp_, created_);
}

OutputDir::~OutputDir() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(tmp_, ec);  // our own temporary folder
  remove_created_parents(fs::path(final_), created_);
  unregister_temporary(slot_);
}

std::string OutputDir::file(const std::string& name) const { return tmp_ + "/" + name; }

void OutputDir::make_subfolder(const std::string& name) const {
  if (mkdir(file(name).c_str(), 0755) != 0 && errno != EEXIST)
    throw OutputError(final_ + "/" + name + ": cannot create: " + sys_error());
}

void OutputDir::commit() {
  const fs::path target(final_);
  std::error_code ec;
  if (mode_ == Mode::Merge) {
    bool had = false;
    const auto kept = read_manifest(target, had);
    std::set<std::string> still_there;
    for (const auto& f : kept)
      if (fs::is_regular_file(target / f, ec)) still_there.insert(f);
    write_manifest(tmp_, still_there);
    const auto entries = entries_below(tmp_);
    // Every destination is checked before the first move: a refusal half-way had already
    // replaced the user's run.json and left a manifest behind (issue #23). Nothing is changed
    // when one of them cannot take rdyn's entry.
    for (const auto& e : entries) {
      // Without the folder's trailing '/': "figures/" of a file called figures does not exist.
      const fs::path to = target / (e.back() == '/' ? e.substr(0, e.size() - 1) : e);
      const auto st = fs::symlink_status(to, ec);
      if (!fs::exists(st)) continue;
      if (e.back() == '/' && !fs::is_directory(fs::status(to, ec)))
        throw OutputError(final_ + "/" + e.substr(0, e.size() - 1) +
                          ": exists and is not a folder; rdyn would write its folder of that name there. Nothing "
                          "was written; move it away or choose another --out");
      if (e.back() != '/' && fs::is_directory(st))
        throw OutputError(final_ + "/" + e + ": is a folder; rdyn would write a file of that name there. Nothing "
                          "was written; move it away or choose another --out");
    }
    for (const auto& e : entries) {
      const fs::path from = fs::path(tmp_) / e, to = target / e;
      if (e.back() == '/') {
        if (mkdir(to.c_str(), 0755) != 0 && errno != EEXIST)
          throw OutputError(final_ + "/" + e + ": cannot create: " + sys_error());
        continue;
      }
      if (std::rename(from.c_str(), to.c_str()) != 0)
        throw OutputError(final_ + "/" + e + ": cannot move into place: " + sys_error());
    }
    fs::remove_all(tmp_, ec);
  } else {
    write_manifest(tmp_, {});
    if (mode_ == Mode::Create) {
      // RENAME_NOREPLACE: a folder that appeared meanwhile is not replaced.
      if (renameat2(AT_FDCWD, tmp_.c_str(), AT_FDCWD, final_.c_str(), RENAME_NOREPLACE) != 0)
        throw OutputError(final_ + ": cannot move the results into place: " + sys_error());
    } else {
      // Check again (a file may have been added meanwhile), then swap atomically: at every
      // instant the folder holds either the old or the new results.
      const auto foreign = foreign_entries(target);
      if (!foreign.empty())
        throw OutputError(final_ + ": files rdyn did not write appeared during the run (" + quote_some(foreign) +
                          "); nothing was replaced");
      if (renameat2(AT_FDCWD, tmp_.c_str(), AT_FDCWD, final_.c_str(), RENAME_EXCHANGE) == 0) {
        remove_rdyn_output(tmp_);  // now the earlier results
      } else if (errno == EINVAL || errno == ENOSYS) {
        // A file system without RENAME_EXCHANGE: move the old results aside, then the new in.
        const std::string aside = tmp_ + ".old";
        if (std::rename(final_.c_str(), aside.c_str()) != 0)
          throw OutputError(final_ + ": cannot replace the earlier results: " + sys_error());
        if (std::rename(tmp_.c_str(), final_.c_str()) != 0) {
          const std::string why = sys_error();
          std::rename(aside.c_str(), final_.c_str());
          throw OutputError(final_ + ": cannot move the results into place: " + why);
        }
        remove_rdyn_output(aside);
      } else {
        throw OutputError(final_ + ": cannot swap the results into place: " + sys_error());
      }
    }
  }
  unregister_temporary(slot_);
  committed_ = true;
}

// ---------------------------------------------------------------------------------------
// OutputFile

OutputFile::OutputFile(std::string path, bool force, Recogniser is_ours) {
  if (path.empty()) throw OutputError("--out: empty path");
  // Standard streams and devices by name (/dev/stdout → /proc/self/fd/1 → "pipe:[…]" cannot be
  // resolved as a path): written through, checked like a FIFO when they are one.
  struct stat given {};
  const bool stream_name = path.rfind("/dev/", 0) == 0 || path.rfind("/proc/", 0) == 0;
  if (stat(path.c_str(), &given) == 0 && (stream_name || S_ISCHR(given.st_mode) || S_ISFIFO(given.st_mode))) {
    if (S_ISDIR(given.st_mode)) throw OutputError(path + ": is a folder; give a file name");
    // A regular file there is a stream only through a descriptor (/dev/stdout into a redirected
    // file); any other is the kernel's (/proc/sys/kernel/hostname: written through as root it
    // changed a setting) or a process's own (/proc/self/comm).
    const bool descriptor = path == "/dev/stdout" || path == "/dev/stderr" || path.rfind("/dev/fd/", 0) == 0 ||
                            (path.rfind("/proc/", 0) == 0 && path.find("/fd/") != std::string::npos);
    if (S_ISREG(given.st_mode) && !descriptor)
      throw OutputError(path + ": is a kernel or device file, not an output (of /dev and /proc only devices, FIFOs, "
                               "/dev/stdout, /dev/stderr and …/fd/N descriptors are written through)");
    if (S_ISFIFO(given.st_mode)) {
      fifo_fd_ = open(path.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
      if (fifo_fd_ < 0)
        throw OutputError(path + ": is a FIFO " + (errno == ENXIO ? "with no reader" : "that cannot be opened: " + sys_error()));
    } else if (S_ISSOCK(given.st_mode) || S_ISBLK(given.st_mode)) {
      throw OutputError(path + ": is a special file (socket or block device); refused");
    }
    through_ = true;
    final_ = write_ = path;
    return;
  }
  const fs::path target = resolve_links(path);
  if (target.filename().empty() || target.filename() == "." || target.filename() == "..")
    throw OutputError(path + ": names a folder; give a file name");
  final_ = target.string();
  struct stat st {};
  if (stat(final_.c_str(), &st) == 0) {
    if (S_ISCHR(st.st_mode)) {  // /dev/null, /dev/stdout, a terminal: written through
      through_ = true;
      write_ = final_;
      return;
    }
    if (S_ISFIFO(st.st_mode)) {  // written through when a reader is there; never blocks
      fifo_fd_ = open(final_.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
      if (fifo_fd_ < 0)
        throw OutputError(path + ": is a FIFO " + (errno == ENXIO ? "with no reader" : "that cannot be opened: " + sys_error()));
      through_ = true;
      write_ = final_;
      return;
    }
    if (S_ISDIR(st.st_mode)) throw OutputError(path + ": is a folder; give a file name");
    if (!S_ISREG(st.st_mode)) throw OutputError(path + ": is a special file (socket or block device); refused");
    const std::string head = read_file_head(final_, 4096);
    if (!force && st.st_size > 0 && !(is_ours && is_ours(head)))
      throw OutputError(path + ": exists and was not written by rdyn; choose another name, or pass --force to "
                        "replace it");
  }
  created_ = make_parents(path, target);
  require_writable(path, target.parent_path());
  write_ = (target.parent_path() / ("." + target.filename().string() + ".rdyn-tmp-" + random_suffix())).string();
  slot_ = register_temporary(write_, created_);
}

OutputFile::~OutputFile() {
  if (fifo_fd_ >= 0) close(fifo_fd_);
  if (committed_ || through_) return;
  unlink(write_.c_str());
  remove_created_parents(fs::path(final_), created_);
  unregister_temporary(slot_);
}

void OutputFile::write(const std::string& text) const {
  TextSink sink(write_, through_);
  sink.add(text);
  sink.close();
}

void OutputFile::commit() {
  if (!through_) {
    if (std::rename(write_.c_str(), final_.c_str()) != 0)
      throw OutputError(final_ + ": cannot move the result into place: " + sys_error());
    unregister_temporary(slot_);
  }
  committed_ = true;
}

// ---------------------------------------------------------------------------------------

TextSink::TextSink(std::string path, bool append) : path_(std::move(path)) {
  fd_ = append ? open(path_.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC)
               : open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw OutputError(path_ + ": cannot open for writing: " + sys_error());
}

TextSink::~TextSink() {
  if (fd_ >= 0) ::close(fd_);
}

void TextSink::add(const std::string& text) {
  buffer_ += text;
  if (buffer_.size() >= (1u << 20)) flush();
}

void TextSink::flush() {
  size_t done = 0;
  while (done < buffer_.size()) {
    const ssize_t n = write(fd_, buffer_.data() + done, buffer_.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw OutputError(path_ + ": cannot write: " + (n < 0 ? sys_error() : std::string("nothing written")));
    done += static_cast<size_t>(n);
  }
  buffer_.clear();
}

void TextSink::close() {
  flush();
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) throw OutputError(path_ + ": cannot write: " + sys_error());
}

void write_text_file(const std::string& path, const std::string& text) {
  TextSink sink(path);
  sink.add(text);
  sink.close();
}

std::string read_file_head(const std::string& path, size_t max_bytes) {
  std::ifstream f(path, std::ios::binary);
  std::string s(max_bytes, '\0');
  f.read(s.data(), static_cast<std::streamsize>(max_bytes));
  s.resize(static_cast<size_t>(std::max<std::streamsize>(0, f.gcount())));
  return s;
}

}  // namespace rdyn::validate
