// Test helper: a fresh directory under /tmp for one test or suite, removed with everything in it
// when the object goes. STEREOHASH_KEEP=1 in the environment keeps it (its path is printed) so a
// failing test's files can be looked at.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

namespace sh::testing {

class TempDir {
 public:
  // /tmp/stereohash_<tag>_XXXXXX; ok() is false (and path() names no directory) if mkdtemp failed.
  explicit TempDir(const std::string& tag) {
    std::string pattern = "/tmp/stereohash_" + tag + "_XXXXXX";
    if (mkdtemp(pattern.data()) != nullptr) path_ = pattern;
  }
  ~TempDir() {
    if (path_.empty()) return;
    if (std::getenv("STEREOHASH_KEEP") != nullptr) {
      std::fprintf(stderr, "kept %s\n", path_.c_str());
      return;
    }
    std::error_code ignored;  // a test that fails half-way may leave anything behind
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  bool ok() const { return !path_.empty(); }
  const std::string& path() const { return path_; }
  // A path inside the directory.
  std::string Sub(const std::string& name) const { return path_ + "/" + name; }
  // A new directory inside it; its path.
  std::string Mkdir(const std::string& name) const {
    std::error_code ignored;  // an existing directory is fine; a failure shows in the test's use
    std::filesystem::create_directory(Sub(name), ignored);
    return Sub(name);
  }

 private:
  std::string path_;
};

}  // namespace sh::testing
