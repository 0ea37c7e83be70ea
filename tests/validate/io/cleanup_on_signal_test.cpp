// The signal-safe remover empties a folder tree (what the SIGINT/SIGTERM/SIGHUP handler
// runs); the handler itself is exercised end to end by the hostile suite's interrupted runs.
#include "validate/io/cleanup_on_signal.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

TEST(CleanupOnSignal, RemovesANestedTreeButNotWhatALinkPointsTo) {
  const fs::path root = fs::temp_directory_path() / ("rdyn_cleanup_" + std::to_string(getpid()));
  const fs::path keep = fs::temp_directory_path() / ("rdyn_keep_" + std::to_string(getpid()));
  fs::create_directories(root / "a/b/c");
  fs::create_directories(keep);
  std::ofstream(keep / "precious") << "x";
  for (int i = 0; i < 300; ++i) std::ofstream(root / "a" / ("f" + std::to_string(i))) << i;  // > one getdents block
  std::ofstream(root / "a/b/c/deep") << "d";
  fs::create_directory_symlink(keep, root / "link");  // removed as a link, never followed
  EXPECT_TRUE(remove_tree_signal_safe(root.c_str()));
  EXPECT_FALSE(fs::exists(root));
  EXPECT_TRUE(fs::exists(keep / "precious"));
  fs::remove_all(keep);
  // A single file, and a path that is already gone.
  std::ofstream(root.string() + ".f") << "x";
  EXPECT_TRUE(remove_tree_signal_safe((root.string() + ".f").c_str()));
  EXPECT_TRUE(remove_tree_signal_safe((root.string() + ".absent").c_str()));
}

TEST(CleanupOnSignal, RegistrationSlotsAreReused) {
  std::vector<int> slots;
  for (int i = 0; i < 10; ++i) slots.push_back(register_temporary("/tmp/rdyn-never-" + std::to_string(i)));
  for (int s : slots) EXPECT_GE(s, 0);
  for (int s : slots) unregister_temporary(s);
  EXPECT_EQ(register_temporary("/tmp/rdyn-never-again"), slots.front());
  unregister_temporary(slots.front());
}

}  // namespace
}  // namespace rdyn::validate
