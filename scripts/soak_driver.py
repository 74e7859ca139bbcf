#!/usr/bin/env python3
"""Soak driver for ./tissue soak: drives a running tissue_node (name /tissue) as a user would
and reports whether it stayed live and honest.

Load: a random-walk scalpel on scalpel/pose at 100 Hz around the operation region (it presses,
cuts and leaves the tissue again), every ~5 s a burst of service calls from 4 threads
(~set_cutting, short ~cut paths, ~save), every ~60 s a ~reset. Measured: steps, cuts, worst
step (~stats step_ms), ~stats rate per 1 s window (percentiles), node RSS at the start, its peak
(with the tets the model had then), at the end and after a final ~reset, every non-finite number
in ~stats, ~scalpel/wrench and ~surface, the longest time without a ~stats message,
/diagnostics levels, node deaths.

Pass/fail (the last line says PASS or FAIL and why; exit 1 on FAIL): the node stays alive, no
non-finite number is published, no service call fails (crash or hang), no stall (~stats never
goes quiet for longer than --max-gap-s), and memory: while cutting, RSS grows (peak - start,
after a 5 s warm-up) by at most --max-rss-growth-mb plus --max-kb-per-tet for each tet the cuts
added - the cut model grows, and a faster loop cuts more in a minute - and after a final ~reset
(the initial model again, the freed heap given back) RSS is within --max-rss-leak-mb of the
start: what stays held something that outlived its model, a leak."""
import argparse
import math
import os
import random
import sys
import tempfile
import threading
import time

import rospy
from geometry_msgs.msg import PoseStamped, WrenchStamped
from soft_tissue_cutting.msg import SimStats
from soft_tissue_cutting.srv import Cut, CutRequest, SaveMesh
from diagnostic_msgs.msg import DiagnosticArray
from std_srvs.srv import SetBool, Trigger
from visualization_msgs.msg import Marker, MarkerArray


def rss_mb(pid):
    try:
        with open("/proc/%d/status" % pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        return float("nan")
    return float("nan")


def percentile(values, p):
    if not values:
        return float("nan")
    v = sorted(values)
    return v[min(len(v) - 1, int(round(p / 100.0 * (len(v) - 1))))]


class Soak:
    def __init__(self, args):
        self.args = args
        self.measuring = False  # gaps count from the end of the warm-up
        self.lock = threading.Lock()
        self.steps = 0
        self.first_step = None
        self.last_step = 0
        self.cuts_total = 0
        self.model_now = (0, 0, 0)  # tets, nodes, free DOFs of the last ~stats
        self.peak_tets = 0
        self.cuts_seen = 0
        self.worst_step_ms = 0.0
        self.stats_per_second = {}
        self.nonfinite = {"stats": 0, "wrench": 0, "surface": 0}
        self.surfaces = 0
        self.region = None  # (centre, radius) of the operation region outline
        self.calls = {"ok": 0, "refused": 0, "failed": 0}
        self.resets = 0
        self.service_cuts = 0
        self.last_stats_time = None  # monotonic time of the last ~stats message
        self.longest_gap_s = 0.0
        self.diagnostics = {0: 0, 1: 0, 2: 0, 3: 0}  # tissue: simulation, by level
        self.diagnostics_errors = {}  # summary -> count (ERROR only)
        rospy.Subscriber("/tissue/stats", SimStats, self.on_stats, queue_size=1000)
        rospy.Subscriber("/tissue/scalpel/wrench", WrenchStamped, self.on_wrench, queue_size=1000)
        rospy.Subscriber("/tissue/surface", Marker, self.on_surface, queue_size=5)
        rospy.Subscriber("/tissue/markers", MarkerArray, self.on_markers, queue_size=5)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=10)
        self.pose_pub = rospy.Publisher("/scalpel/pose", PoseStamped, queue_size=100)

    def on_stats(self, m):
        values = [m.residual, m.contact_force, m.collision_ms, m.cutting_ms, m.assembly_ms,
                  m.solve_ms, m.recovery_ms, m.step_ms, m.rate_hz]
        now = time.monotonic()
        with self.lock:
            if not all(math.isfinite(v) for v in values):
                self.nonfinite["stats"] += 1
            if self.last_stats_time is not None and self.measuring:
                self.longest_gap_s = max(self.longest_gap_s, now - self.last_stats_time)
            self.last_stats_time = now
            self.steps += 1
            if self.first_step is None:
                self.first_step = m.step
            self.last_step = m.step
            if m.cuts < self.cuts_seen:  # a reset
                self.cuts_seen = 0
            self.cuts_total += m.cuts - self.cuts_seen
            self.cuts_seen = m.cuts
            self.worst_step_ms = max(self.worst_step_ms, m.step_ms)
            self.model_now = (m.tets, m.nodes, m.dof_operation)
            self.peak_tets = max(self.peak_tets, m.tets)
            sec = int(time.monotonic())
            self.stats_per_second[sec] = self.stats_per_second.get(sec, 0) + 1

    def on_diagnostics(self, a):
        for st in a.status:
            if not st.name.endswith("simulation"):
                continue
            level = ord(st.level) if isinstance(st.level, bytes) else int(st.level)
            with self.lock:
                self.diagnostics[level] = self.diagnostics.get(level, 0) + 1
                if level == 2:
                    key = st.message.split(":")[0]
                    self.diagnostics_errors[key] = self.diagnostics_errors.get(key, 0) + 1

    def on_wrench(self, w):
        f, t = w.wrench.force, w.wrench.torque
        if not all(math.isfinite(v) for v in (f.x, f.y, f.z, t.x, t.y, t.z)):
            with self.lock:
                self.nonfinite["wrench"] += 1

    def on_surface(self, m):
        bad = any(not (math.isfinite(p.x) and math.isfinite(p.y) and math.isfinite(p.z))
                  for p in m.points)
        with self.lock:
            self.surfaces += 1
            if bad:
                self.nonfinite["surface"] += 1

    def on_markers(self, a):
        for m in a.markers:
            if m.ns == "operation_region" and m.points and self.region is None:
                n = len(m.points)
                c = [sum(p.x for p in m.points) / n, sum(p.y for p in m.points) / n,
                     sum(p.z for p in m.points) / n]
                r = max(math.dist(c, (p.x, p.y, p.z)) for p in m.points)
                self.region = (c, r)

    # -- load -------------------------------------------------------------------------------
    def walk(self, stop):
        rng = random.Random(12)
        while self.region is None and not stop.is_set():
            time.sleep(0.1)
        if stop.is_set():
            return
        c, r = self.region
        p = list(c)
        q = [0.0, 0.0, 0.0, 1.0]
        step = max(r / 100.0, 1e-4)
        rate = rospy.Rate(100)
        while not stop.is_set() and not rospy.is_shutdown():
            for k in range(3):
                p[k] += rng.gauss(0.0, step)
            d = math.dist(p, c)
            if d > 1.3 * r:  # pulled back towards the region
                p = [c[k] + (p[k] - c[k]) * 1.3 * r / d for k in range(3)]
            for k in range(4):
                q[k] += rng.gauss(0.0, 0.01)
            n = math.sqrt(sum(x * x for x in q))
            q = [x / n for x in q]
            msg = PoseStamped()
            msg.header.frame_id = "tissue"
            msg.header.stamp = rospy.Time.now()
            msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = p
            (msg.pose.orientation.x, msg.pose.orientation.y, msg.pose.orientation.z,
             msg.pose.orientation.w) = q
            self.pose_pub.publish(msg)
            rate.sleep()

    def call(self, fn, *a):
        try:
            r = fn(*a)
            ok = getattr(r, "success", True)
            with self.lock:
                self.calls["ok" if ok else "refused"] += 1
            return ok
        except Exception as e:  # a crashed or hung node shows here
            with self.lock:
                self.calls["failed"] += 1
            rospy.logwarn("soak: service call failed: %s", e)
            return False

    def burst(self, rng, tmp):
        set_cutting = rospy.ServiceProxy("/tissue/set_cutting", SetBool)
        cut = rospy.ServiceProxy("/tissue/cut", Cut)
        save = rospy.ServiceProxy("/tissue/save", SaveMesh)
        c, r = self.region

        def worker(i):
            for k in range(5):
                kind = rng.randrange(3)
                if kind == 0:
                    self.call(set_cutting, True)
                elif kind == 1:
                    req = CutRequest()
                    a = [c[j] + rng.uniform(-r, r) for j in range(3)]
                    b = [a[j] + rng.uniform(-r, r) for j in range(3)]
                    n = rng.choice([2, 10, 200])
                    for s in range(n):
                        t = s / (n - 1)
                        ps = PoseStamped()
                        ps.pose.position.x, ps.pose.position.y, ps.pose.position.z = [
                            a[j] + min(1.0, t) * (b[j] - a[j]) for j in range(3)]
                        ps.pose.orientation.w = 1.0
                        req.poses.append(ps)
                    self.call(cut, req)
                    with self.lock:
                        self.service_cuts += 1
                else:
                    self.call(save, os.path.join(tmp, "s%d.vtk" % i), os.path.join(tmp, "s%d.json" % i))

        threads = [threading.Thread(target=worker, args=(i,)) for i in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()

    def run(self):
        a = self.args
        # Start-up: an organ-scale scene condenses for tens of seconds (longer on a loaded
        # machine) before the first step; the load starts only once the node steps.
        started = time.monotonic()
        while not (self.steps > 0 and self.region is not None):
            if time.monotonic() - started > a.startup_s or not os.path.exists("/proc/%d" % a.pid):
                print("soak: FAIL: the node did not start stepping within %.0f s" % a.startup_s,
                      flush=True)
                return 1
            time.sleep(0.1)
        print("soak: node stepping after %.1f s; load starts" % (time.monotonic() - started),
              flush=True)
        stop = threading.Event()
        # daemon: an exception in the driver must not leave the process (and the node) running
        walker = threading.Thread(target=self.walk, args=(stop,), daemon=True)
        walker.start()
        time.sleep(5.0)  # warm-up: RSS start after the first cuts' allocations settle a little
        rss_start = rss_mb(a.pid)
        with self.lock:
            self.measuring = True
            model_start = self.model_now
        rng = random.Random(7)
        reset = rospy.ServiceProxy("/tissue/reset", Trigger)
        tmp = tempfile.mkdtemp(prefix="soak_")
        t0 = time.monotonic()
        end = t0 + 60.0 * a.minutes
        next_burst, next_reset, next_print = t0 + 5, t0 + 60, t0 + 60
        died = False
        rss_peak, tets_at_peak = rss_start, model_start[0]
        while time.monotonic() < end and not rospy.is_shutdown():
            now = time.monotonic()
            if not os.path.exists("/proc/%d" % a.pid):
                died = True
                break
            rss = rss_mb(a.pid)
            if rss > rss_peak:
                with self.lock:
                    rss_peak, tets_at_peak = rss, self.model_now[0]
            if now >= next_burst:
                self.burst(rng, tmp)
                next_burst = now + 5
            if now >= next_reset:
                self.call(reset)
                with self.lock:
                    self.resets += 1
                next_reset = now + 60
            if now >= next_print:
                with self.lock:
                    print("soak: %.0f min: %d steps, %d cuts, worst step %.1f ms, RSS %.0f MB" % (
                        (now - t0) / 60, self.steps, self.cuts_total, self.worst_step_ms,
                        rss_mb(a.pid)), flush=True)
                next_print = now + 60
            time.sleep(0.2)
        rss_end = rss_mb(a.pid)
        with self.lock:
            model_end = self.model_now
        if rss_end > rss_peak:
            rss_peak, tets_at_peak = rss_end, model_end[0]
        stop.set()
        walker.join()
        # Leak check at equal model state: a final ~reset rebuilds the initial model and the node
        # gives the freed heap back (malloc_trim), so what stays above the start is held by
        # something that outlived its model.
        rss_reset = float("nan")
        if not died and os.path.exists("/proc/%d" % a.pid) and self.call(reset):
            with self.lock:
                self.resets += 1
            time.sleep(2.0)
            rss_reset = rss_mb(a.pid)
        with self.lock:
            if self.last_stats_time is not None:  # a gap still open at the end counts too
                self.longest_gap_s = max(self.longest_gap_s, time.monotonic() - self.last_stats_time)
            secs = sorted(self.stats_per_second)[1:-1]  # whole seconds only
            rates = [self.stats_per_second[s] for s in secs]
            report = [
                "soak report (%.1f min)" % ((time.monotonic() - t0) / 60),
                "  steps:            %d ~stats received (node step %s -> %s; resets restart it)" % (
                    self.steps, self.first_step, self.last_step),
                "  cuts:             %d cut steps (from ~stats), %d ~cut calls" % (
                    self.cuts_total, self.service_cuts),
                "  worst step:       %.1f ms" % self.worst_step_ms,
                "  rate (Hz, 1 s):   p1 %s  p5 %s  p50 %s  p95 %s  min %s" % (
                    percentile(rates, 1), percentile(rates, 5), percentile(rates, 50),
                    percentile(rates, 95), min(rates) if rates else "nan"),
                "  RSS:              %.0f MB -> %.0f MB (peak %.0f MB at %d tets), %.0f MB after "
                "a final ~reset" % (rss_start, rss_end, rss_peak, tets_at_peak, rss_reset),
                "  model:            %d -> %d tets (peak %d), %d -> %d nodes, %d -> %d free DOFs; "
                "%.1f KB of RSS per tet the cuts added" % (
                    model_start[0], model_end[0], self.peak_tets, model_start[1], model_end[1],
                    model_start[2], model_end[2],
                    1024 * (rss_peak - rss_start) / max(1, tets_at_peak - model_start[0])),
                "  service calls:    %d ok, %d refused, %d failed; %d resets" % (
                    self.calls["ok"], self.calls["refused"], self.calls["failed"], self.resets),
                "  non-finite:       %d stats, %d wrench, %d surface (of %d surfaces)" % (
                    self.nonfinite["stats"], self.nonfinite["wrench"], self.nonfinite["surface"],
                    self.surfaces),
                "  longest ~stats gap: %.2f s" % self.longest_gap_s,
                "  /diagnostics:     %d OK, %d WARN, %d ERROR%s" % (
                    self.diagnostics[0], self.diagnostics[1], self.diagnostics[2],
                    "" if not self.diagnostics_errors else " (" + ", ".join(
                        "%s: %d" % kv for kv in sorted(self.diagnostics_errors.items())) + ")"),
                "  node:             %s" % ("DIED" if died else "alive"),
            ]
            growth = rss_peak - rss_start
            # The cut model grows (new tets, a larger operation part and its factor): the budget
            # is a fixed slack plus a cost per tet the cuts added, so a faster loop that cuts
            # more in a minute is not mistaken for a leak - the final reset measures leaks.
            added = max(0, tets_at_peak - model_start[0])
            budget = a.max_rss_growth_mb + a.max_kb_per_tet * added / 1024.0
            leak = rss_reset - rss_start
            failures = []
            if died:
                failures.append("the node died")
            if sum(self.nonfinite.values()) > 0:
                failures.append("%d non-finite outputs" % sum(self.nonfinite.values()))
            if self.calls["failed"] > 0:
                failures.append("%d service calls failed" % self.calls["failed"])
            if not math.isfinite(growth) or growth > budget:
                failures.append("RSS grew by %.0f MB while cutting (limit %.0f MB + %.0f KB for "
                                "each of %d tets added = %.0f MB)" % (
                                    growth, a.max_rss_growth_mb, a.max_kb_per_tet, added, budget))
            if not died and (not math.isfinite(leak) or leak > a.max_rss_leak_mb):
                failures.append("RSS %.0f MB above the start after a final ~reset (limit %.0f MB)" % (
                    leak, a.max_rss_leak_mb))
            if self.steps == 0 or self.longest_gap_s > a.max_gap_s:
                failures.append("stall: no ~stats for %.2f s (limit %.2f s)" % (
                    self.longest_gap_s, a.max_gap_s))
            report.append("soak: PASS" if not failures else "soak: FAIL: " + "; ".join(failures))
            bad = bool(failures)
        print("\n".join(report), flush=True)
        with open(os.path.join(a.out, "report.txt"), "w") as f:
            f.write("\n".join(report) + "\n")
        return 1 if bad else 0


def main():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--minutes", type=float, default=10.0)
    p.add_argument("--pid", type=int, required=True)
    p.add_argument("--out", default="/tmp")
    p.add_argument("--max-rss-growth-mb", type=float, default=64.0,
                   help="fail if the node's RSS grows by more than this plus --max-kb-per-tet for "
                   "each tet the cuts added (peak - start after warm-up)")
    p.add_argument("--max-kb-per-tet", type=float, default=16.0,
                   help="RSS allowed per tet the cuts added (the thigh's cut model: ~10 KB)")
    p.add_argument("--max-rss-leak-mb", type=float, default=16.0,
                   help="fail if RSS after a final ~reset stays more than this above the start")
    p.add_argument("--startup-s", type=float, default=600.0,
                   help="fail if the node has not stepped (and drawn its region) by then")
    p.add_argument("--max-gap-s", type=float, default=2.0,
                   help="fail if ~stats goes quiet for longer (a stalled loop)")
    a = p.parse_args(rospy.myargv()[1:])
    rospy.init_node("tissue_soak", anonymous=True, disable_signals=True)
    sys.exit(Soak(a).run())


if __name__ == "__main__":
    main()
