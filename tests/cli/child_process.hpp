#pragma once
// The `uh` program run as a child process the test can signal: its output into files, its end
// awaited with a limit (a hang is a failure, not a wait). Shared by the signal tests of `uh run`
// and of `uh museum station`.

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace uh::test_support {

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Finished {
  bool exited = false;
  int code = -1;
};

// Waits for `pid` to end, at most `limit` (then kills it: a hang is a failure, not a wait).
inline Finished wait_for_exit(pid_t pid, std::chrono::seconds limit) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return {};
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return {WIFEXITED(status), WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

// One child: `args` (the program first), this process's environment with `env` entries
// (NAME=VALUE) in place of same-named ones, stdout and stderr into `out` and `err`. Killed and
// reaped on destruction if it is still running.
class ChildProcess {
 public:
  ChildProcess(std::vector<std::string> args, const std::vector<std::string>& env,
               const std::filesystem::path& out, const std::filesystem::path& err)
      : out_(out), err_(err) {
    // everything the child needs is prepared before fork(): it only redirects and execs
    std::vector<std::string> env_storage = env;
    for (char** e = environ; *e != nullptr; ++e) {
      const std::string entry(*e);
      bool replaced = false;
      for (const std::string& mine : env)
        replaced = replaced || entry.rfind(mine.substr(0, mine.find('=') + 1), 0) == 0;
      if (!replaced) env_storage.push_back(entry);
    }
    std::vector<char*> argv, envp;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    for (auto& e : env_storage) envp.push_back(e.data());
    envp.push_back(nullptr);
    const std::string out_path = out.string(), err_path = err.string();
    const pid_t parent = getpid();
    pid_ = fork();
    if (pid_ == 0) {
      // a test process that aborts (a failed assertion in a fatal handler, a sanitizer report)
      // never runs the destructor: the kernel ends the child with it instead of leaving a server
      // or a bot running. The signal follows the creating thread, which is the test's own.
      if (prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || getppid() != parent) _exit(122);
      const int o = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int e = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int in = open("/dev/null", O_RDONLY);
      if (o < 0 || e < 0 || in < 0 || dup2(o, STDOUT_FILENO) < 0 || dup2(e, STDERR_FILENO) < 0 ||
          dup2(in, STDIN_FILENO) < 0)
        _exit(120);
      execve(argv[0], argv.data(), envp.data());
      _exit(121);
    }
  }
  ~ChildProcess() {
    if (running()) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }
  bool started() const { return pid_ > 0; }
  // false once it ended (and was reaped here)
  bool running() {
    if (pid_ <= 0 || finished_) return false;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == 0) return true;
    finished_ = true;
    result_ = {WIFEXITED(status), WIFEXITED(status) ? WEXITSTATUS(status) : -1};
    return false;
  }
  bool signal(int signal_number) { return running() && kill(pid_, signal_number) == 0; }
  Finished wait(std::chrono::seconds limit) {
    if (!finished_ && pid_ > 0) {
      result_ = wait_for_exit(pid_, limit);
      finished_ = true;
    }
    return result_;
  }
  std::string out() const { return read_text(out_); }
  std::string err() const { return read_text(err_); }

 private:
  std::filesystem::path out_, err_;
  pid_t pid_ = -1;
  bool finished_ = false;
  Finished result_{};
};

}  // namespace uh::test_support
