#pragma once

/// \file
/// \brief Where tests find the source tree, the build tree and the shared test data.

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

namespace basalt::test {

inline std::filesystem::path sourceDir() { return BASALT_SOURCE_DIR; }
inline std::filesystem::path binaryDir() { return BASALT_BINARY_DIR; }

/// \brief `../shared/testdata` beside the checkout, or $BASALT_TESTDATA. Empty when missing;
/// tests that need it skip with the reason.
inline std::filesystem::path testdataDir() {
  if (const char* env = std::getenv("BASALT_TESTDATA"); env && *env) return env;
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::weakly_canonical(BASALT_TESTDATA_DIR, ec);
  return std::filesystem::is_directory(p, ec) ? p : std::filesystem::path{};
}

/// \brief A fresh, empty folder for one test's files under the build tree.
inline std::filesystem::path scratchDir(const std::string& name) {
  const std::filesystem::path p = binaryDir() / "test-scratch" / name;
  std::error_code ec;
  std::filesystem::remove_all(p, ec);
  std::filesystem::create_directories(p);
  return p;
}

/// \brief A GoogleTest case name made of `text` (a path, a show's folder): every character that is
/// not a letter or a digit becomes '_'. Parameterized suites name their cases with it, and ctest
/// lists the names as they are (gtest_discover_tests' NO_PRETTY_VALUES in tests/CMakeLists.txt).
inline std::string caseName(std::string_view text) {
  std::string name(text);
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

}  // namespace basalt::test
