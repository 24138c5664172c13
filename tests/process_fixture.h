// Helpers for tests that run the photonbound executable: a per-test temporary folder and a
// runner that captures stderr and the exit code.
#pragma once

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

namespace pb::test {

struct Outcome {
  int code = -1;    // exit code, -1 when the process did not exit normally
  std::string err;  // what it wrote to stderr
};

// Single-quotes a word for the shell.
inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs `photonbound ARGS` through the shell (in `dir` when given), with a 60 s limit.
inline Outcome run_photonbound(const std::string& args, const std::string& dir = "") {
  std::string cmd = dir.empty() ? "" : "cd " + quote(dir) + " && ";
  cmd += "timeout 60 " + std::string(PHOTONBOUND_EXE) + " " + args + " 2>&1 >/dev/null";
  Outcome r;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), int(buf.size()), pipe)) r.err += buf.data();
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// A folder name under the system temporary directory that no other process uses: the process
// id keeps two ctest runs of the same test (two checkouts, or a sanitizer build beside the
// normal one) out of each other's files.
inline std::filesystem::path unique_temp_path(const std::string& stem) {
  return std::filesystem::temp_directory_path() /
         ("pb_" + stem + "_" + std::to_string(static_cast<long>(::getpid())));
}

// A fresh, empty folder per test case, removed afterwards.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = unique_temp_path(std::string(info->test_suite_name()) + "_" + info->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::filesystem::path dir_;
};

}  // namespace pb::test
