#!/usr/bin/python3
"""turn_bag.py IN.bag OUT.bag QX QY QZ QW: the bag's /tissue/surface and /tissue/markers,
every marker turned about the tissue frame's origin by the rotation q (as printed by
scripts/picture_view.py), written to OUT.bag with the original times. The markers keep their
frame: rviz shows them in it (as fixed frame) without any tf, turned so that the scene's up
is rviz's +z, the axis its orbit camera turns about.
"""
import sys

import rosbag

TOPICS = ["/tissue/surface", "/tissue/markers"]


def qmul(a, b):
    """Quaternion product a * b, (x, y, z, w)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def rotate(q, v):
    x, y, z, _ = qmul(qmul(q, (v[0], v[1], v[2], 0.0)), (-q[0], -q[1], -q[2], q[3]))
    return x, y, z


def turn(marker, q):
    """marker.pose <- q * marker.pose: its points (given in its pose) turn with it."""
    p, o = marker.pose.position, marker.pose.orientation
    p.x, p.y, p.z = rotate(q, (p.x, p.y, p.z))
    if o.x == 0 and o.y == 0 and o.z == 0 and o.w == 0:
        o.w = 1.0  # rviz reads an all-zero quaternion as the identity
    o.x, o.y, o.z, o.w = qmul(q, (o.x, o.y, o.z, o.w))


def main():
    if len(sys.argv) != 7:
        sys.exit("usage: turn_bag.py IN.bag OUT.bag QX QY QZ QW")
    q = tuple(float(v) for v in sys.argv[3:7])
    with rosbag.Bag(sys.argv[1]) as src, rosbag.Bag(sys.argv[2], "w") as dst:
        for topic, msg, t in src.read_messages(topics=TOPICS):
            for marker in (msg.markers if hasattr(msg, "markers") else [msg]):
                turn(marker, q)
            dst.write(topic, msg, t)


if __name__ == "__main__":
    main()
