#!/usr/bin/python3
"""Publishes scalpel/pose (geometry_msgs/PoseStamped) along a scripted trajectory.

Sources (first that applies):
  ~file             a CSV (t,x,y,z,qx,qy,qz,qw per row; a header row and # comments are
                    skipped) or a YAML file: a scene YAML (its `trajectory`), a mapping with
                    `poses`, or a plain list of {t, position: [x,y,z], orientation: [qx,qy,qz,qw]}
  ~trajectory_param the name of a parameter holding such a list; default /tissue/trajectory,
                    which tissue_node sets from its scene (the built-in thigh's scripted
                    scalpel), so `thigh` needs no file.
Parameters: ~rate (Hz, 100), ~loop (false), ~frame_id (tissue), ~speed (time scale, 1.0),
~delay (s before the first pose, 0), ~wait_subscriber (s, 10).
Positions are interpolated linearly, orientations by slerp. Times are wall-clock (no sim time).
"""
import csv
import math
import os
import sys
import time

import rospy
import yaml
from geometry_msgs.msg import PoseStamped


def _pose(entry, where):
    try:
        t = float(entry["t"])
        p = [float(v) for v in entry["position"]]
        q = [float(v) for v in entry.get("orientation", [0.0, 0.0, 0.0, 1.0])]
    except (KeyError, TypeError, ValueError) as e:
        raise ValueError("%s: bad pose %r (%s)" % (where, entry, e))
    if len(p) != 3 or len(q) != 4:
        raise ValueError("%s: position needs 3 and orientation 4 numbers" % where)
    return (t, p, _normalized(q))


def _normalized(q):
    n = math.sqrt(sum(v * v for v in q))
    if not n > 0:
        raise ValueError("zero quaternion")
    return [v / n for v in q]


def load_list(entries, where):
    if not isinstance(entries, list) or not entries:
        raise ValueError("%s: no trajectory poses" % where)
    poses = [_pose(e, where) for e in entries]
    poses.sort(key=lambda p: p[0])
    return poses


def load_file(path):
    if not os.path.isfile(path):
        raise ValueError("%s: no such file" % path)
    if path.lower().endswith(".csv"):
        poses = []
        with open(path) as f:
            for n, row in enumerate(csv.reader(f), 1):
                if not row or row[0].strip().startswith("#"):
                    continue
                try:
                    v = [float(x) for x in row]
                except ValueError:
                    if not poses:
                        continue  # header row
                    raise ValueError("%s:%d: not numbers" % (path, n))
                if len(v) != 8:
                    raise ValueError("%s:%d: need t,x,y,z,qx,qy,qz,qw" % (path, n))
                poses.append((v[0], v[1:4], _normalized(v[4:8])))
        return load_list([{"t": t, "position": p, "orientation": q} for t, p, q in poses], path)
    with open(path) as f:
        data = yaml.safe_load(f)
    if isinstance(data, dict):
        data = data.get("trajectory", data.get("poses"))
    return load_list(data, path)


def slerp(q0, q1, s):
    d = sum(a * b for a, b in zip(q0, q1))
    if d < 0:
        q1, d = [-v for v in q1], -d
    if d > 0.9995:
        return _normalized([a + s * (b - a) for a, b in zip(q0, q1)])
    th = math.acos(d)
    w0, w1 = math.sin((1 - s) * th) / math.sin(th), math.sin(s * th) / math.sin(th)
    return [w0 * a + w1 * b for a, b in zip(q0, q1)]


def sample(poses, t):
    if t <= poses[0][0]:
        return poses[0][1], poses[0][2]
    for (t0, p0, q0), (t1, p1, q1) in zip(poses, poses[1:]):
        if t <= t1:
            s = (t - t0) / (t1 - t0) if t1 > t0 else 1.0
            return [a + s * (b - a) for a, b in zip(p0, p1)], slerp(q0, q1, s)
    return poses[-1][1], poses[-1][2]


def main():
    rospy.init_node("trajectory_player")
    path = rospy.get_param("~file", "")
    param = rospy.get_param("~trajectory_param", rospy.get_param("~source", "/tissue/trajectory"))
    rate = float(rospy.get_param("~rate", 100.0))
    loop = bool(rospy.get_param("~loop", False))
    frame_id = rospy.get_param("~frame_id", "tissue")
    speed = float(rospy.get_param("~speed", 1.0))
    delay = float(rospy.get_param("~delay", 0.0))
    wait_sub = float(rospy.get_param("~wait_subscriber", 10.0))
    try:
        if path and path != "thigh":
            poses, where = load_file(path), path
        else:
            deadline = time.monotonic() + 30.0
            while not rospy.has_param(param):
                if rospy.is_shutdown() or time.monotonic() > deadline:
                    raise ValueError("parameter %s not set (is tissue_node running?)" % param)
                time.sleep(0.1)
            poses, where = load_list(rospy.get_param(param), param), param
    except (ValueError, yaml.YAMLError) as e:
        rospy.logfatal("trajectory_player: %s", e)
        sys.exit(1)
    if not (rate > 0 and speed > 0):
        rospy.logfatal("trajectory_player: ~rate and ~speed must be positive")
        sys.exit(1)

    pub = rospy.Publisher("scalpel/pose", PoseStamped, queue_size=10)
    deadline = time.monotonic() + wait_sub
    while pub.get_num_connections() == 0 and time.monotonic() < deadline and not rospy.is_shutdown():
        time.sleep(0.05)
    duration = (poses[-1][0] - poses[0][0]) / speed
    rospy.loginfo("trajectory_player: %d poses from %s, %.2f s at speed %.2f, %s",
                  len(poses), where, duration, speed, "looping" if loop else "once")
    time.sleep(delay)
    start = time.monotonic()
    period = 1.0 / rate
    next_tick = start
    while not rospy.is_shutdown():
        elapsed = (time.monotonic() - start) * speed
        if loop and duration > 0:
            elapsed = elapsed % (poses[-1][0] - poses[0][0])
        t = poses[0][0] + elapsed
        p, q = sample(poses, t)
        msg = PoseStamped()
        msg.header.stamp = rospy.Time.now()
        msg.header.frame_id = frame_id
        msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = p
        (msg.pose.orientation.x, msg.pose.orientation.y, msg.pose.orientation.z,
         msg.pose.orientation.w) = q
        pub.publish(msg)
        if not loop and t >= poses[-1][0]:
            rospy.loginfo("trajectory_player: done")
            break
        next_tick += period
        time.sleep(max(0.0, next_tick - time.monotonic()))
    if not loop:
        rospy.spin()  # stay up (idle) so roslaunch does not report a dead node


if __name__ == "__main__":
    main()
