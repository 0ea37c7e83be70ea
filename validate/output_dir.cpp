#include "validate/output_dir.hpp"

#include <unistd.h>

#include <filesystem>
#include <random>

namespace rdyn::validate {

namespace fs = std::filesystem;

OutputDir::OutputDir(std::string final_path) : final_(std::move(final_path)) {
  while (final_.size() > 1 && final_.back() == '/') final_.pop_back();
  if (final_.empty()) throw OutputError("output folder: empty path");
  const fs::path target = fs::absolute(final_);
  const fs::path parent = target.parent_path();
  std::error_code ec;
  if (!fs::is_directory(parent, ec))
    throw OutputError(final_ + ": cannot create output folder: parent '" + parent.string() + "' does not exist");
  if (fs::exists(target, ec) && !fs::is_directory(target, ec))
    throw OutputError(final_ + ": exists and is not a folder");
  if (access(parent.c_str(), W_OK) != 0)
    throw OutputError(final_ + ": cannot write output folder: '" + parent.string() + "' is not writable");
  std::random_device rd;
  tmp_ = (parent / ("." + target.filename().string() + ".tmp-" + std::to_string(rd()))).string();
  if (!fs::create_directory(tmp_, ec) || ec)
    throw OutputError(final_ + ": cannot create a temporary folder beside it: " + ec.message());
}

OutputDir::~OutputDir() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(tmp_, ec);
}

std::string OutputDir::file(const std::string& name) const { return tmp_ + "/" + name; }

void OutputDir::commit() {
  std::error_code ec;
  const std::string old = tmp_ + ".old";
  const bool had = fs::exists(final_, ec);
  if (had) fs::rename(final_, old, ec);
  if (ec) throw OutputError(final_ + ": cannot replace the existing folder: " + ec.message());
  fs::rename(tmp_, final_, ec);
  if (ec) {
    if (had) fs::rename(old, final_, ec);
    throw OutputError(final_ + ": cannot move the results into place: " + ec.message());
  }
  if (had) fs::remove_all(old, ec);
  committed_ = true;
}

}  // namespace rdyn::validate
