// Helpers for tests that run the photonbound executable: a per-test temporary folder and a
// runner that captures stderr and the exit code.
#pragma once

#include <gtest/gtest.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

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

// Runs `photonbound ARGS` through the shell (in `dir` when given), with a 60 s limit; `env`
// (NAME=VALUE ...) is put in its environment.
inline Outcome run_photonbound(const std::string& args, const std::string& dir = "",
                               const std::string& env = "") {
  std::string cmd = dir.empty() ? "" : "cd " + quote(dir) + " && ";
  cmd += env + " timeout 60 " + std::string(PHOTONBOUND_EXE) + " " + args + " 2>&1 >/dev/null";
  Outcome r;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), int(buf.size()), pipe)) r.err += buf.data();
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// Starts photonbound with `args` (args[0] is its name), stderr to /dev/null; its pid, or -1.
inline pid_t spawn(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  posix_spawn(&pid, PHOTONBOUND_EXE, &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return pid;
}

// Waits (at most 60 s) for a file to appear; false if it never does.
inline bool wait_for(const std::string& file) {
  for (int k = 0; k < 600; ++k) {
    if (std::filesystem::exists(file)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

// Waits until process pid catches `sig` (its handler is installed: the SigCgt mask of
// /proc/PID/status), so that a signal sent then is the program's to handle, however slowly a
// loaded machine starts it.
inline bool wait_for_handler(pid_t pid, int sig) {
  for (int k = 0; k < 600; ++k) {
    std::ifstream status("/proc/" + std::to_string(pid) + "/status");
    for (std::string line; std::getline(status, line);)
      if (line.rfind("SigCgt:", 0) == 0 &&
          (std::stoull(line.substr(7), nullptr, 16) >> (sig - 1)) & 1u)
        return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
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
