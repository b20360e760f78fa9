// The one helper end-to-end tests use to run the emaki binary: its exit code or signal, its
// stderr, and a wall-clock and address-space bound, so that a hostile input that hangs or
// allocates without bound fails the test instead of the machine.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/test_dir.h"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define EMAKI_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define EMAKI_TEST_SANITIZED 1
#endif
#endif

namespace emaki::test {

struct CliResult {
  int exit_code = -1;  // exit status, or -1 when killed by a signal
  int signal = 0;      // the signal that ended it, 0 when it exited
  bool timed_out = false;
  double seconds = 0;
  std::string err;  // stderr
  std::string out;  // stdout
};

struct CliOptions {
  std::filesystem::path cwd;                       // empty: the test's own
  int64_t address_space_bytes = int64_t(2) << 30;  // RLIMIT_AS; not set under sanitizers
  int timeout_seconds = 60;
  std::vector<std::string> env;  // extra NAME=VALUE entries
};

inline std::string slurp_file(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// In a forked child: replaces it with `binary args...` (exit code 127 when that fails).
[[noreturn]] inline void exec_cli(const std::string& binary, const std::vector<std::string>& args) {
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(binary.c_str()));
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  ::execv(binary.c_str(), argv.data());
  ::_exit(127);
}

// Runs `binary args...`; stdout and stderr are captured through files in a temporary folder.
inline CliResult run_cli(const std::string& binary, const std::vector<std::string>& args,
                         const CliOptions& opt = {}) {
  namespace fs = std::filesystem;
  static int serial = 0;
  const fs::path cap = fs::temp_directory_path() /
                       ("emaki_cli_" + std::to_string(::getpid()) + "_" + std::to_string(++serial));
  fs::create_directories(cap);
  const std::string out_path = (cap / "out").string(), err_path = (cap / "err").string();
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (!opt.cwd.empty() && ::chdir(opt.cwd.c_str()) != 0) ::_exit(126);
    const int o = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    const int e = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (o < 0 || e < 0) ::_exit(126);
    ::dup2(o, 1);
    ::dup2(e, 2);
#ifndef EMAKI_TEST_SANITIZED
    if (opt.address_space_bytes > 0) {
      rlimit rl{rlim_t(opt.address_space_bytes), rlim_t(opt.address_space_bytes)};
      ::setrlimit(RLIMIT_AS, &rl);
    }
#endif
    for (const auto& kv : opt.env) ::putenv(const_cast<char*>(kv.c_str()));
    exec_cli(binary, args);
  }
  CliResult r;
  int status = 0;
  const auto deadline = t0 + std::chrono::seconds(opt.timeout_seconds);
  for (;;) {
    const pid_t w = ::waitpid(pid, &status, WNOHANG);
    if (w == pid) break;
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      r.timed_out = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
  r.out = slurp_file(out_path);
  r.err = slurp_file(err_path);
  fs::remove_all(cap);
  return r;
}

// Starts `binary args...` in the background with stderr to `err_path`; the caller waits for it.
inline pid_t spawn_cli(const std::string& binary, const std::vector<std::string>& args,
                       const std::string& err_path) {
  const pid_t pid = ::fork();
  if (pid != 0) return pid;
  const int e = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  if (e < 0) ::_exit(126);
  ::dup2(e, 2);
  exec_cli(binary, args);
}

// Splits a command line on spaces (tests only pass paths without spaces).
inline std::vector<std::string> split_args(const std::string& line) {
  std::vector<std::string> v;
  std::istringstream is(line);
  for (std::string a; is >> a;) v.push_back(a);
  return v;
}

inline int count_lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

}  // namespace emaki::test
