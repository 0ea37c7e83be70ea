// Output folder written atomically: files go to a temporary sibling folder that is
// renamed into place by commit(); a failed run leaves nothing behind.
#pragma once

#include <string>

namespace rdyn::validate {

class OutputError : public std::exception {
 public:
  explicit OutputError(std::string m) : msg_(std::move(m)) {}
  const char* what() const noexcept override { return msg_.c_str(); }

 private:
  std::string msg_;
};

class OutputDir {
 public:
  // Creates the temporary folder; throws OutputError naming the folder when the parent
  // does not exist or is not writable.
  explicit OutputDir(std::string final_path);
  ~OutputDir();  // removes the temporary folder unless committed
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  // Path of a file inside the (temporary) folder.
  std::string file(const std::string& name) const;
  // Moves the folder into place, replacing an earlier one of the same name.
  void commit();
  const std::string& final_path() const { return final_; }

 private:
  std::string final_, tmp_;
  bool committed_ = false;
};

}  // namespace rdyn::validate
