// Helpers shared by the tests: data paths, temporary folders, Eigen comparisons.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <filesystem>
#include <random>
#include <string>

namespace pdvo::test {

// Path of a real data set under ../shared/data, or "" if it is absent.
inline std::string DataPath(const std::string& name) {
  const std::filesystem::path p = std::filesystem::path(PDVO_TEST_DATA_DIR) / name;
  return std::filesystem::exists(p) ? p.string() : "";
}

// In a test: skips, saying so, when the data set is absent.
#define PDVO_REQUIRE_DATA(var, name)                    \
  const std::string var = ::pdvo::test::DataPath(name); \
  if (var.empty()) GTEST_SKIP() << "data set " << name << " not found under " PDVO_TEST_DATA_DIR

// A fresh, empty folder for one test, removed when the object dies.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("pdvo_test_" + std::string(info ? info->test_suite_name() : "x") + "_" +
             std::string(info ? info->name() : "y") + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  std::string str() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

// The largest absolute difference between two matrices of equal size.
template <class A, class B>
double MaxAbsDiff(const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

}  // namespace pdvo::test
