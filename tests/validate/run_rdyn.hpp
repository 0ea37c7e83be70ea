// Runs the rdyn binary without a shell (posix_spawn with an argument vector) in a working
// folder, capturing its standard output and error; for the end-to-end tests.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <functional>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace rdyn::test {

struct RdynRun {
  int status = -1;      // exit status; 128 + signal when killed
  bool timed_out = false;
  std::string out, err;
};

struct RunLimits {
  double time_limit_s = 120.0;  // a hang is a failure, not a stuck test
  long file_size_limit = -1;    // RLIMIT_FSIZE in bytes (a "full disk"); −1: none
  int signal_after_ms = -1;     // send `signal` after this many milliseconds
  int signal = SIGINT;
  int during_after_ms = -1;  // run `during` (in the test) this many milliseconds after the start
  std::function<void(const std::filesystem::path& cwd)> during;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// Any program (argv[0] looked up in PATH, as posix_spawnp does), e.g. the browser tests' chromium.
inline RdynRun run_argv(std::vector<std::string> argv, const std::filesystem::path& cwd, const RunLimits& limits = {}) {
  namespace fs = std::filesystem;
  const fs::path out_file = cwd / ".stdout", err_file = cwd / ".stderr";
  std::vector<char*> cargs;
  for (auto& a : argv) cargs.push_back(a.data());
  cargs.push_back(nullptr);

  RdynRun r;
  pid_t pid = fork();
  if (pid == 0) {
    if (chdir(cwd.c_str()) != 0) _exit(126);
    const int in = open("/dev/null", O_RDONLY);
    const int o = open(out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int e = open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(in, 0), dup2(o, 1), dup2(e, 2);
    if (limits.file_size_limit >= 0) {
      signal(SIGXFSZ, SIG_IGN);  // a write past the limit fails with EFBIG instead of killing
      rlimit rl{static_cast<rlim_t>(limits.file_size_limit), static_cast<rlim_t>(limits.file_size_limit)};
      setrlimit(RLIMIT_FSIZE, &rl);
    }
    execvp(cargs[0], cargs.data());
    _exit(127);
  }
  const auto start = std::chrono::steady_clock::now();
  bool signalled = false, during_done = false;
  int st = 0;
  for (;;) {
    if (waitpid(pid, &st, WNOHANG) == pid) break;
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (!during_done && limits.during && limits.during_after_ms >= 0 && ms >= limits.during_after_ms) {
      limits.during(cwd);
      during_done = true;
    }
    if (!signalled && limits.signal_after_ms >= 0 && ms >= limits.signal_after_ms) {
      kill(pid, limits.signal);
      signalled = true;
    }
    if (ms > 1000 * limits.time_limit_s) {
      kill(pid, SIGKILL);
      waitpid(pid, &st, 0);
      r.timed_out = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : WIFSIGNALED(st) ? 128 + WTERMSIG(st) : -1;
  r.out = slurp(out_file);
  r.err = slurp(err_file);
  fs::remove(out_file);
  fs::remove(err_file);
  return r;
}

inline RdynRun run_rdyn(const std::vector<std::string>& args, const std::filesystem::path& cwd,
                        const RunLimits& limits = {}) {
  std::vector<std::string> argv{RDYN_BINARY};
  argv.insert(argv.end(), args.begin(), args.end());
  return run_argv(std::move(argv), cwd, limits);
}

}  // namespace rdyn::test
