// A reduced table written by the rdyn binary (`rdyn extract`), for tests that read tables
// from files as an embedding program does; and other runs of the binary whose files such a
// test compares with (`rdyn drive`).
#pragma once

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

namespace rdyn::test {

// Runs the rdyn binary with `args` (no shell; standard output to /dev/null); returns its exit
// status, −1 when it could not run.
inline int run_rdyn_cli(std::vector<std::string> args) {
  args.insert(args.begin(), RDYN_BINARY);
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    const int null = open("/dev/null", O_WRONLY);  // keep the test log to failures (stderr)
    if (null >= 0) dup2(null, STDOUT_FILENO);
    execv(argv[0], argv.data());
    _exit(127);
  }
  int st = 0;
  if (pid < 0 || waitpid(pid, &st, 0) != pid) return -1;
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

// Runs `rdyn extract SCENE --grid-deg GRID --out PATH --force`.
inline int extract_table_with_cli(const std::string& scene, const std::string& grid_deg,
                                  const std::string& path) {
  return run_rdyn_cli({"extract", scene, "--grid-deg", grid_deg, "--out", path, "--force"});
}

}  // namespace rdyn::test
