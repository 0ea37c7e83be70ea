// A reduced table written by the rdyn binary (`rdyn extract`), for tests that read tables
// from files as an embedding program does.
#pragma once

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

namespace rdyn::test {

// Runs `rdyn extract SCENE --grid-deg GRID --out PATH --force` (no shell); returns its exit
// status, −1 when it could not run.
inline int extract_table_with_cli(const std::string& scene, const std::string& grid_deg,
                                  const std::string& path) {
  std::vector<std::string> args{RDYN_BINARY, "extract", scene, "--grid-deg",
                                grid_deg,    "--out",   path,  "--force"};
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

}  // namespace rdyn::test
