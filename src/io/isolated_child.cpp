// Forked-child isolation for library code that may crash (see isolated_child.hpp).
#include "isolated_child.hpp"

#include "text_cursor.hpp"

#include <poll.h>
#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <exception>

namespace stc::io {
namespace {

void write_all(int fd, const std::string& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // the parent went away: nothing left to tell it
    done += static_cast<std::size_t>(n);
  }
}

// The child's side: 'O' + payload on success, 'E' + message on an exception.
[[noreturn]] void child_main(int fd, const std::function<std::string()>& job) {
  std::string answer;
  try {
    answer = "O" + job();
  } catch (const std::exception& e) {
    answer = std::string("E") + e.what();
  } catch (int code) {  // TetGen throws ints
    answer = "Eerror code " + std::to_string(code);
  } catch (...) {
    answer = "Eunknown exception";
  }
  write_all(fd, answer);
  ::close(fd);
  std::fflush(stdout);  // keep a verbose TetGen's output (switches without Q)
  std::fflush(stderr);
  ::_exit(0);
}

std::string describe_status(int status) {
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    const char* name = sigabbrev_np(sig);
    return "crashed (signal " + std::to_string(sig) + (name ? std::string(", SIG") + name : "") +
           ")";
  }
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
  return "ended abnormally";
}

// ": <last non-empty line of the child's stderr>" (e.g. TetGen's failed assertion), or "".
std::string last_line(const std::string& text) {
  std::size_t end = text.find_last_not_of(" \t\r\n");
  if (end == std::string::npos) return "";
  const std::size_t begin = text.find_last_of('\n', end);
  std::string line = text.substr(begin == std::string::npos ? 0 : begin + 1,
                                 end + 1 - (begin == std::string::npos ? 0 : begin + 1));
  // "prog: /build/.../tetgen.cxx:11026: ...: Assertion `x' failed." -> from "Assertion" on
  const std::size_t assertion = line.find("Assertion");
  if (assertion != std::string::npos) line = line.substr(assertion);
  if (line.size() > 200) line = line.substr(0, 200) + "...";
  return ": " + line;
}

}  // namespace

std::string run_isolated(const std::string& path, const std::string& what,
                         const std::function<std::string()>& job, double timeout_s) {
  // fds: the answer; errs: the child's stderr (an assert()'s message, folded into the error
  // line instead of being printed).
  int fds[2], errs[2];
  if (::pipe(fds) != 0)
    fail(path, 0, what + " failed: cannot create a pipe: " + std::strerror(errno));
  if (::pipe(errs) != 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    fail(path, 0, what + " failed: cannot create a pipe: " + std::strerror(errno));
  }
  std::fflush(nullptr);  // buffered output must not be written twice (parent and child)
  const pid_t pid = ::fork();
  if (pid < 0) {
    for (int fd : {fds[0], fds[1], errs[0], errs[1]}) ::close(fd);
    fail(path, 0, what + " failed: cannot fork: " + std::strerror(errno));
  }
  if (pid == 0) {
    // The child dies by the signal of its crash, whatever handlers the parent installed (a
    // node's, a sanitizer's SEGV report, a debugger's): the parent names that signal.
    for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) ::signal(sig, SIG_DFL);
    ::close(fds[0]);
    ::close(errs[0]);
    ::dup2(errs[1], STDERR_FILENO);
    ::close(errs[1]);
    child_main(fds[1], job);
  }
  ::close(fds[1]);
  ::close(errs[1]);

  // Read everything the child writes (it may be more than a pipe holds) until both pipes reach
  // EOF (the child finished or died) or the timeout.
  std::string answer, err;
  bool timed_out = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  char buf[65536];
  pollfd p[2] = {{fds[0], POLLIN, 0}, {errs[0], POLLIN, 0}};
  std::string* sink[2] = {&answer, &err};
  while (p[0].fd >= 0 || p[1].fd >= 0) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timed_out = true;
      break;
    }
    const int r = ::poll(p, 2, static_cast<int>(std::min<long long>(left.count(), 1000)));
    if (r <= 0) continue;  // timeout slice or EINTR
    for (int k = 0; k < 2; ++k) {
      if (p[k].fd < 0 || p[k].revents == 0) continue;
      const ssize_t n = ::read(p[k].fd, buf, sizeof buf);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {  // EOF
        ::close(p[k].fd);
        p[k].fd = -1;
        continue;
      }
      sink[k]->append(buf, static_cast<std::size_t>(n));
    }
  }
  for (const pollfd& q : p)
    if (q.fd >= 0) ::close(q.fd);
  if (timed_out) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (timed_out) {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g", timeout_s);
    fail(path, 0, what + " did not finish within " + limit + " s (stopped)");
  }
  if (WIFSIGNALED(status) || !WIFEXITED(status) || WEXITSTATUS(status) != 0 || answer.empty())
    fail(path, 0,
         what + " " + describe_status(status) + last_line(err) +
             " (the surface is probably degenerate, self-intersecting or badly scaled)");
  if (answer[0] == 'E') {
    const std::string message = answer.substr(1);
    // Messages from fail() in the child already name the file.
    if (message.rfind(path, 0) == 0) throw MeshError(message);
    fail(path, 0, what + " failed: " + message);
  }
  return answer.substr(1);
}

}  // namespace stc::io
