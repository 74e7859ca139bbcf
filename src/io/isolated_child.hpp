// Runs a job in a forked child process (private to src/io). Used for TetGen: TetGen 1.5 can
// abort, double-free or crash on some bad surfaces, and a crash in the child becomes one
// MeshError line naming the file instead of a dead node or a signal-killed `tissue solve`.
#pragma once

#include <functional>
#include <string>

namespace stc::io {

// Forks; the child runs `job` and sends back the bytes it returns (or the what() of the
// exception it throws); the parent waits at most `timeout_s` seconds. Returns the job's bytes;
// throws MeshError "path: <what> failed: ..." when the child throws, crashes (signal), exits
// without an answer or overruns the timeout (the child is then killed). The child only runs
// `job` and then _exit()s: no destructors, no atexit handlers, so a corrupted heap in the child
// cannot reach the parent. Safe in multi-threaded parents (the ROS node) as long as `job` only
// allocates memory and computes (glibc's malloc is reset in the child after fork).
std::string run_isolated(const std::string& path, const std::string& what,
                         const std::function<std::string()>& job, double timeout_s);

}  // namespace stc::io
