// Removal of rdyn's temporary outputs when the process is interrupted (SIGINT, SIGTERM,
// SIGHUP): an interrupted run leaves nothing behind (issue #9, "outputs are atomic").
//
// Paths are kept in a fixed table of plain character arrays and removed by the signal
// handler with async-signal-safe system calls only (open, getdents64, unlinkat, close), then
// the signal is re-raised with its default action, so the exit status still says "killed by
// SIGINT" to the shell.
#pragma once

#include <string>

namespace rdyn::validate {

// Installs the handlers (idempotent). Called by the first registration.
void install_cleanup_handlers();

// Registers a temporary file or folder (absolute path) to remove on a signal; returns a
// slot id for unregister_temporary, or −1 when the table is full (then the path is still
// removed by the normal error paths, only not on a signal). `created_top`, when given, is the
// topmost parent folder this run created (a prefix of `path`): after the temporary, the
// handler removes the folders from its parent up to `created_top` with rmdir, which only
// removes empty folders — anything another run or the user put there meanwhile stays.
int register_temporary(const std::string& path, const std::string& created_top = "");
void unregister_temporary(int slot);

// Removes a file or a folder tree (depth ≤ 8) with the same async-signal-safe routine the
// handler uses; exposed for tests. Returns true when nothing is left.
bool remove_tree_signal_safe(const char* path);

}  // namespace rdyn::validate
