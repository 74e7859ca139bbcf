#!/usr/bin/env python3
"""Soak driver for ./tissue soak: drives a running tissue_node (name /tissue) as a user would
and reports whether it stayed live and honest.

Load: a random-walk scalpel on scalpel/pose at 100 Hz around the operation region (it presses,
cuts and leaves the tissue again), every ~5 s a burst of service calls from 4 threads
(~set_cutting, short ~cut paths, ~save), every ~60 s a ~reset. Measured: steps, cuts, worst
step (~stats step_ms), ~stats rate per 1 s window (percentiles), node RSS start/end, every
non-finite number in ~stats, ~scalpel/wrench and ~surface, node deaths. Exit 1 if the node
died or published a non-finite number."""
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
        self.lock = threading.Lock()
        self.steps = 0
        self.first_step = None
        self.last_step = 0
        self.cuts_total = 0
        self.cuts_seen = 0
        self.worst_step_ms = 0.0
        self.stats_per_second = {}
        self.nonfinite = {"stats": 0, "wrench": 0, "surface": 0}
        self.surfaces = 0
        self.region = None  # (centre, radius) of the operation region outline
        self.calls = {"ok": 0, "refused": 0, "failed": 0}
        self.resets = 0
        self.service_cuts = 0
        rospy.Subscriber("/tissue/stats", SimStats, self.on_stats, queue_size=1000)
        rospy.Subscriber("/tissue/scalpel/wrench", WrenchStamped, self.on_wrench, queue_size=1000)
        rospy.Subscriber("/tissue/surface", Marker, self.on_surface, queue_size=5)
        rospy.Subscriber("/tissue/markers", MarkerArray, self.on_markers, queue_size=5)
        self.pose_pub = rospy.Publisher("/scalpel/pose", PoseStamped, queue_size=100)

    def on_stats(self, m):
        values = [m.residual, m.contact_force, m.collision_ms, m.cutting_ms, m.assembly_ms,
                  m.solve_ms, m.recovery_ms, m.step_ms, m.rate_hz]
        with self.lock:
            if not all(math.isfinite(v) for v in values):
                self.nonfinite["stats"] += 1
            self.steps += 1
            if self.first_step is None:
                self.first_step = m.step
            self.last_step = m.step
            if m.cuts < self.cuts_seen:  # a reset
                self.cuts_seen = 0
            self.cuts_total += m.cuts - self.cuts_seen
            self.cuts_seen = m.cuts
            self.worst_step_ms = max(self.worst_step_ms, m.step_ms)
            sec = int(time.monotonic())
            self.stats_per_second[sec] = self.stats_per_second.get(sec, 0) + 1

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
        except Exception as e:  # a crashed or hung node shows here
            with self.lock:
                self.calls["failed"] += 1
            rospy.logwarn("soak: service call failed: %s", e)

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
        for _ in range(200):
            if self.steps > 0 and self.region is not None:
                break
            time.sleep(0.1)
        stop = threading.Event()
        walker = threading.Thread(target=self.walk, args=(stop,))
        walker.start()
        time.sleep(5.0)  # warm-up: RSS start after the first cuts' allocations settle a little
        rss_start = rss_mb(a.pid)
        rng = random.Random(7)
        reset = rospy.ServiceProxy("/tissue/reset", Trigger)
        tmp = tempfile.mkdtemp(prefix="soak_")
        t0 = time.monotonic()
        end = t0 + 60.0 * a.minutes
        next_burst, next_reset, next_print = t0 + 5, t0 + 60, t0 + 60
        died = False
        while time.monotonic() < end and not rospy.is_shutdown():
            now = time.monotonic()
            if not os.path.exists("/proc/%d" % a.pid):
                died = True
                break
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
        stop.set()
        walker.join()
        with self.lock:
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
                "  RSS:              %.0f MB -> %.0f MB" % (rss_start, rss_end),
                "  service calls:    %d ok, %d refused, %d failed; %d resets" % (
                    self.calls["ok"], self.calls["refused"], self.calls["failed"], self.resets),
                "  non-finite:       %d stats, %d wrench, %d surface (of %d surfaces)" % (
                    self.nonfinite["stats"], self.nonfinite["wrench"], self.nonfinite["surface"],
                    self.surfaces),
                "  node:             %s" % ("DIED" if died else "alive"),
            ]
            bad = died or sum(self.nonfinite.values()) > 0 or self.calls["failed"] > 0
        print("\n".join(report), flush=True)
        with open(os.path.join(a.out, "report.txt"), "w") as f:
            f.write("\n".join(report) + "\n")
        return 1 if bad else 0


def main():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--minutes", type=float, default=10.0)
    p.add_argument("--pid", type=int, required=True)
    p.add_argument("--out", default="/tmp")
    a = p.parse_args(rospy.myargv()[1:])
    rospy.init_node("tissue_soak", anonymous=True, disable_signals=True)
    sys.exit(Soak(a).run())


if __name__ == "__main__":
    main()
