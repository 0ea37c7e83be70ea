#include "validate/io/cleanup_on_signal.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <atomic>
#include <csignal>
#include <cstring>
#include <mutex>

namespace rdyn::validate {

namespace {

constexpr int kSlots = 64;        // temporaries alive at once (a suite has one folder)
constexpr int kPathMax = 4096;    // PATH_MAX on Linux
constexpr int kMaxDepth = 8;      // rdyn writes at most folder/scene/file

char g_paths[kSlots][kPathMax];
size_t g_created_top_len[kSlots];  // 0: no parent folders to remove
std::atomic<bool> g_used[kSlots];
std::mutex g_mutex;  // registration only; the handler reads without locking
std::once_flag g_installed;

struct LinuxDirent64 {
  unsigned long long d_ino;
  long long d_off;
  unsigned short d_reclen;
  unsigned char d_type;
  char d_name[];
};

int remove_contents(int dirfd, int depth);

// Empties the folder open as `fd`: deleting while reading may skip entries, so a few bounded
// passes from the start, until a pass finds nothing.
void empty_folder(int fd, int depth) {
  for (int pass = 0; pass < 4; ++pass) {
    lseek(fd, 0, SEEK_SET);
    if (remove_contents(fd, depth) == 0) return;
  }
}

// Removes the entries of the folder open as `dirfd`, recursively; returns how many it saw.
// Signal-safe: no allocation, no stdio, no locks.
int remove_contents(int dirfd, int depth) {
  if (depth > kMaxDepth) return 0;
  alignas(8) char buf[4096];
  int seen = 0;
  for (;;) {
    const long n = syscall(SYS_getdents64, dirfd, buf, sizeof buf);
    if (n <= 0) break;
    for (long off = 0; off < n;) {
      auto* d = reinterpret_cast<LinuxDirent64*>(buf + off);
      off += d->d_reclen;
      const char* name = d->d_name;
      if (name[0] == '.' && (name[1] == 0 || (name[1] == '.' && name[2] == 0))) continue;
      ++seen;
      // d_type is DT_UNKNOWN on some file systems: then a folder shows as EISDIR.
      if (d->d_type == DT_DIR || (d->d_type == DT_UNKNOWN && unlinkat(dirfd, name, 0) != 0 && errno == EISDIR)) {
        const int sub = openat(dirfd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
        if (sub >= 0) {
          empty_folder(sub, depth + 1);
          close(sub);
        }
        unlinkat(dirfd, name, AT_REMOVEDIR);
      } else if (d->d_type != DT_UNKNOWN) {
        unlinkat(dirfd, name, 0);
      }
    }
  }
  return seen;
}

// Removes the now empty parent folders of `path` down to the first `top_len` characters
// (rmdir fails on a folder that is not empty, and the walk stops there).
void remove_empty_parents(const char* path, size_t top_len) {
  char buf[kPathMax];
  size_t n = 0;
  while (path[n] && n + 1 < sizeof buf) buf[n] = path[n], ++n;
  buf[n] = 0;
  while (n > 0) {
    while (n > 0 && buf[n - 1] != '/') --n;  // cut the last component
    if (n > 0) --n;
    buf[n] = 0;
    if (n < top_len || rmdir(buf) != 0) return;
  }
}

void on_signal(int sig) {
  for (int i = 0; i < kSlots; ++i)
    if (g_used[i].load(std::memory_order_acquire)) {
      remove_tree_signal_safe(g_paths[i]);
      if (g_created_top_len[i] > 0) remove_empty_parents(g_paths[i], g_created_top_len[i]);
    }
  std::signal(sig, SIG_DFL);
  raise(sig);
}

}  // namespace

bool remove_tree_signal_safe(const char* path) {
  const int fd = open(path, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return unlink(path) == 0 || errno == ENOENT;
  empty_folder(fd, 0);
  close(fd);
  return rmdir(path) == 0;
}

void install_cleanup_handlers() {
  std::call_once(g_installed, [] {
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&sa.sa_mask, s);
    for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaction(s, &sa, nullptr);
  });
}

int register_temporary(const std::string& path, const std::string& created_top) {
  install_cleanup_handlers();
  if (path.size() + 1 > static_cast<size_t>(kPathMax)) return -1;
  const bool prefix = !created_top.empty() && path.compare(0, created_top.size(), created_top) == 0;
  std::lock_guard<std::mutex> lock(g_mutex);
  for (int i = 0; i < kSlots; ++i) {
    if (g_used[i].load()) continue;
    std::memcpy(g_paths[i], path.c_str(), path.size() + 1);
    g_created_top_len[i] = prefix ? created_top.size() : 0;
    g_used[i].store(true, std::memory_order_release);
    return i;
  }
  return -1;
}

void unregister_temporary(int slot) {
  if (slot < 0 || slot >= kSlots) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  g_used[slot].store(false, std::memory_order_release);
}

}  // namespace rdyn::validate
