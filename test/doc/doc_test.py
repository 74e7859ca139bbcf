#!/usr/bin/python3
"""Doc test: every shell command README.md and docs/ROS.md show is run as written.

Convention (for everyone editing those files):

* A fenced block whose language is `bash`, `sh`, `shell` or `console` is a shell block; every
  other fence (yaml, text, none) is only shown.
* A shell block is RUN by default. Tag it ```` ```bash show-only ```` to only show it (say why
  in the text around it, e.g. a command that needs your robot). GitHub ignores the tag.
* The one exception: a line `./tissue test`, which is what runs this test (CI: .ci/run).
* Each line is one command (a trailing backslash continues it), run by bash as written, as a
  reader typing into one terminal: `cd`, `source` and exports carry over to the next line and
  the next block of the same file. Every file starts in the repository root with a scratch
  HOME (so `~/ws` is a fresh workspace), TISSUE_WS = the workspace ./tissue built, a private
  ROS master port, ROS_HOME in the scratch dir and an X display (run under xvfb-run).
* A command must exit 0 within its time limit (TIMEOUT_S), unless it is long-running:
  its first word is `roslaunch`, `rosrun` or `roscore`, or it ends with `&`. A long-running
  command is started in its own process group. One ending in `&` keeps running until the end
  of the block; any other is judged, then stopped with SIGINT. Judging = a JUDGES entry below
  (the first whose pattern matches the command) runs test/doc/judge.py, which subscribes and
  waits for what the command must publish. A long-running command no judge matches fails:
  add a judge for it here when you document a new one.
* Results: one JUnit testcase per command in --junit (catkin_test_results counts them).

Usage: doc_test.py [--junit OUT.xml] [--only README.md] [--list]
"""
import argparse
import os
import re
import shlex
import signal
import socket
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DOCS = ["README.md", "docs/ROS.md"]
SHELL_LANGS = {"bash", "sh", "shell", "console"}
LONG_RUNNING = {"roslaunch", "rosrun", "roscore"}
TIMEOUT_S = 1200  # a short command (catkin_make in a fresh workspace is the longest)
STOP_S = 15       # SIGINT -> SIGKILL grace period

# (pattern on the command, judge name, judge arguments). judge.py documents each judge.
JUDGES = [
    (r"\broslaunch\s+soft_tissue_cutting\s+demo\.launch\b", "demo", []),
    (r"\broslaunch\s+soft_tissue_cutting\s+tissue\.launch\b.*\brviz:=true\b", "surface", ["--rviz"]),
    (r"\broslaunch\s+soft_tissue_cutting\s+tissue\.launch\b", "surface", []),
    (r"\brosrun\s+soft_tissue_cutting\s+scalpel_marker\.py\b", "scalpel_marker", []),
    (r"\brosrun\s+soft_tissue_cutting\s+trajectory_player\.py\b", "trajectory_player", []),
]


def blocks(path):
    """Yields (first line number, info words, [(line number, command)]) per shell block."""
    lines = open(path, encoding="utf-8").read().split("\n")
    i = 0
    while i < len(lines):
        m = re.match(r"^(\s*)(```+|~~~+)\s*(.*)$", lines[i])
        if not m:
            i += 1
            continue
        fence, info = m.group(2), m.group(3).split()
        start = i + 1
        body = []
        i += 1
        while i < len(lines) and not lines[i].strip().startswith(fence):
            body.append((i + 1, lines[i]))
            i += 1
        i += 1
        if not info or info[0] not in SHELL_LANGS:
            continue
        cmds, pending, pending_line = [], "", 0
        for number, text in body:
            text = text.strip()
            if info[0] == "console":
                if not text.startswith("$ ") and not pending:
                    continue  # output lines of a console transcript
                text = text[2:] if text.startswith("$ ") else text
            if not pending and (not text or text.startswith("#")):
                continue
            if not pending:
                pending_line = number
            if text.endswith("\\"):
                pending += text[:-1] + " "
                continue
            cmds.append((pending_line, pending + text))
            pending = ""
        yield start, info[1:], cmds


def strip_comment(cmd):
    """The command without a trailing `# comment` (shlex-aware), for classification only."""
    try:
        lexer = shlex.shlex(cmd, posix=True, punctuation_chars=True)
        lexer.whitespace_split = True
        lexer.commenters = "#"
        tokens = list(lexer)
    except ValueError:
        return cmd.strip(), cmd.split()
    out = cmd
    if "#" in cmd:
        # cut at the first # that starts a word outside quotes
        quote = None
        for k, ch in enumerate(cmd):
            if quote:
                if ch == quote:
                    quote = None
            elif ch in "'\"":
                quote = ch
            elif ch == "#" and (k == 0 or cmd[k - 1].isspace()):
                out = cmd[:k]
                break
    return out.strip(), tokens


def free_port():
    s = socket.socket()
    s.bind(("", 0))
    port = s.getsockname()[1]
    s.close()
    return port


class Session:
    """One reader's terminal: cwd and environment carried from command to command."""

    def __init__(self, scratch, base_env):
        self.cwd = ROOT
        self.env = dict(base_env)
        self.scratch = scratch
        self.background = []

    def run_short(self, cmd, log):
        state = os.path.join(self.scratch, "state")
        script = ('cd "$DOC_TEST_CWD" || exit 97\n' + cmd + '\n__rc=$?\n'
                  'pwd > "$DOC_TEST_STATE.cwd"; env -0 > "$DOC_TEST_STATE.env"; exit $__rc\n')
        env = dict(self.env, DOC_TEST_CWD=self.cwd, DOC_TEST_STATE=state)
        try:
            r = subprocess.run(["bash", "-c", script], env=env, stdout=log, stderr=subprocess.STDOUT,
                               timeout=TIMEOUT_S, start_new_session=True)
        except subprocess.TimeoutExpired:
            return False, "did not finish within %d s" % TIMEOUT_S
        if os.path.exists(state + ".cwd"):
            self.cwd = open(state + ".cwd").read().strip() or self.cwd
            raw = open(state + ".env", "rb").read().split(b"\0")
            env = {}
            for item in raw:
                if b"=" in item:
                    k, v = item.split(b"=", 1)
                    env[k.decode()] = v.decode(errors="replace")
            for k in ("DOC_TEST_CWD", "DOC_TEST_STATE", "__rc", "PWD", "OLDPWD", "SHLVL", "_"):
                env.pop(k, None)
            self.env = env
            os.remove(state + ".cwd")
            os.remove(state + ".env")
        if r.returncode != 0:
            return False, "exit status %d" % r.returncode
        return True, ""

    def start(self, cmd, log):
        return subprocess.Popen(["bash", "-c", 'cd "$DOC_TEST_CWD" && exec ' + cmd],
                                env=dict(self.env, DOC_TEST_CWD=self.cwd), stdout=log,
                                stderr=subprocess.STDOUT, start_new_session=True)

    @staticmethod
    def stop(proc):
        if proc.poll() is not None:
            return
        try:
            os.killpg(proc.pid, signal.SIGINT)
            proc.wait(STOP_S)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        except ProcessLookupError:
            pass

    def end_block(self):
        for proc in reversed(self.background):
            self.stop(proc)
        self.background = []


def judge(session, name, args, proc, log):
    """Runs judge.py with the session's environment while `proc` runs."""
    cmd = [sys.executable, os.path.join(ROOT, "test", "doc", "judge.py"), name] + args
    try:
        r = subprocess.run(cmd, env=session.env, cwd=session.cwd, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, timeout=240, text=True)
        out = r.stdout.strip()
        ok = r.returncode == 0
    except subprocess.TimeoutExpired:
        ok, out = False, "judge did not finish within 240 s"
    log.write(("judge %s: %s\n" % (name, out)).encode())
    log.flush()
    if proc.poll() is not None and not ok:
        out += " (the command exited with status %d)" % proc.returncode
    return ok, out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--junit")
    ap.add_argument("--only", action="append")
    ap.add_argument("--list", action="store_true")
    opts = ap.parse_args()
    docs = opts.only or DOCS

    plan = []  # (doc, block line, tags, line, command)
    for doc in docs:
        for start, tags, cmds in blocks(os.path.join(ROOT, doc)):
            for number, cmd in cmds:
                plan.append((doc, start, tags, number, cmd))
    if opts.list:
        for doc, _, tags, number, cmd in plan:
            print("%s:%d%s %s" % (doc, number, " [show-only]" if "show-only" in tags else "", cmd))
        return 0

    scratch_root = tempfile.mkdtemp(prefix="doc_test_", dir=os.environ.get("DOC_TEST_SCRATCH"))
    results = []  # (name, seconds, failure or None, skipped)
    current_doc, session, current_block = None, None, None
    log_path = os.path.join(scratch_root, "doc_test.log")
    log = open(log_path, "wb")
    print("doc test: %d commands in %s (log: %s)" % (len(plan), ", ".join(docs), log_path))
    for doc, start, tags, number, cmd in plan:
        name = "%s:%d %s" % (doc, number, cmd)
        if doc != current_doc:
            if session:
                session.end_block()
            home = os.path.join(scratch_root, re.sub(r"\W", "_", doc), "home")
            os.makedirs(home)
            base = dict(os.environ)
            base.update(HOME=home, ROS_HOME=os.path.join(home, ".ros"), ROS_HOSTNAME="localhost",
                        ROS_MASTER_URI="http://localhost:%d" % free_port())
            for k in ("ROS_PACKAGE_PATH", "CMAKE_PREFIX_PATH", "ROS_ROOT", "PYTHONPATH",
                      "LD_LIBRARY_PATH", "PKG_CONFIG_PATH", "ROSLISP_PACKAGE_DIRECTORIES"):
                base.pop(k, None)  # a reader starts from a plain shell
            session = Session(os.path.join(scratch_root, re.sub(r"\W", "_", doc)), base)
            current_doc, current_block = doc, None
        if (doc, start) != current_block:
            session.end_block()
            current_block = (doc, start)
        if "show-only" in tags:
            results.append((name, 0.0, None, True))
            continue
        bare, tokens = strip_comment(cmd)
        if re.fullmatch(r"\./tissue\s+test\b.*", bare):
            results.append((name, 0.0, None, True))  # this test is part of ./tissue test
            continue
        log.write(("\n===== %s\n" % name).encode())
        log.flush()
        t0 = time.time()
        background = bare.endswith("&") and not bare.endswith("&&")
        long_running = background or (tokens and tokens[0] in LONG_RUNNING)
        failure = None
        if not long_running:
            ok, why = session.run_short(cmd, log)
            failure = None if ok else why
        elif background:
            session.background.append(session.start(bare[:-1].strip(), log))
            time.sleep(2)  # the command's master comes up before the next line needs it
        else:
            entry = next((j for j in JUDGES if re.search(j[0], bare)), None)
            if entry is None:
                failure = "long-running command without a judge: add one to JUDGES in %s" % __file__
            else:
                proc = session.start(bare, log)
                ok, why = judge(session, entry[1], entry[2], proc, log)
                session.stop(proc)
                failure = None if ok else why
        dt = time.time() - t0
        results.append((name, dt, failure, False))
        print("doc test: %-4s %5.1f s  %s%s" % ("ok" if not failure else "FAIL", dt, name,
                                                "" if not failure else "\n    -> " + failure),
              flush=True)
    if session:
        session.end_block()
    log.close()

    passed = sum(1 for r in results if not r[2] and not r[3])
    failed = sum(1 for r in results if r[2])
    skipped = sum(1 for r in results if r[3])
    print("doc test: %d passed, %d failed, %d shown only (log: %s)" % (passed, failed, skipped,
                                                                       log_path))
    if opts.junit:
        suite = ET.Element("testsuite", name="doc_test", tests=str(len(results)),
                           failures=str(failed), errors="0", skipped=str(skipped))
        for name, dt, failure, skip in results:
            tc = ET.SubElement(suite, "testcase", classname="doc_test", name=name,
                               time="%.1f" % dt)
            if failure:
                ET.SubElement(tc, "failure", message=failure).text = failure
            elif skip:
                ET.SubElement(tc, "skipped")
        os.makedirs(os.path.dirname(os.path.abspath(opts.junit)), exist_ok=True)
        ET.ElementTree(suite).write(opts.junit, encoding="utf-8", xml_declaration=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
