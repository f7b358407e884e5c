#pragma once

// Files for tests that write their own fixtures: a temporary folder removed afterwards, a file
// writer, and a readable check that an error message names what it should; and where the shared
// real data lives for the tests that read it (they skip when it is absent).

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace hybrid_vo {
namespace testing {

class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "hybrid_vo_test") {
    std::string pattern =
        (std::filesystem::temp_directory_path() / (prefix + "_XXXXXX")).string();
    if (!mkdtemp(pattern.data())) std::abort();
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline void write_file(const std::filesystem::path& path, const std::string& content) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path);
  out << content;
  ASSERT_TRUE(out.good()) << path;
}

inline ::testing::AssertionResult contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

// The real data sets (../shared/data/README.md): $HYBRID_VO_DATA when set, else ../shared/data
// beside the source tree (HYBRID_VO_SHARED_DATA, set by CMakeLists.txt). From a git worktree
// elsewhere, set HYBRID_VO_DATA.
inline std::filesystem::path shared_data_dir() {
  if (const char* env = std::getenv("HYBRID_VO_DATA")) return env;
#ifdef HYBRID_VO_SHARED_DATA
  return std::filesystem::path(HYBRID_VO_SHARED_DATA).lexically_normal();
#else
  return {};
#endif
}

}  // namespace testing
}  // namespace hybrid_vo
