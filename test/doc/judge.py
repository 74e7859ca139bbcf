#!/usr/bin/python3
"""Judges a documented long-running command by what it publishes (used by doc_test.py).

judge.py NAME [--rviz]; exit 0 and one line on success, exit 1 and the reason otherwise.
  surface            /tissue/surface: a TRIANGLE_LIST with >= 100 triangles, every coordinate
                     finite; --rviz: the /rviz node registered with the master and still alive
                     after the surface arrived
  demo               /tissue/stats reports at least one cut (the scripted stroke cut)
  scalpel_marker     drives the interactive scalpel like rviz does (InteractiveMarkerFeedback
                     POSE_UPDATE on /scalpel_marker/feedback): /scalpel/pose follows to the
                     commanded pose (1e-9 m); if a tissue node runs, its blade marker too
  trajectory_player  /scalpel/pose starts at the first pose of /tissue/trajectory and the tissue
                     node reports a cut (/tissue/stats)
"""
import math
import sys
import time

import rosgraph
import rospy
from geometry_msgs.msg import PoseStamped
from visualization_msgs.msg import InteractiveMarkerFeedback, Marker, MarkerArray

LIMIT_S = 120.0


def wait_for(what, predicate, limit=LIMIT_S):
    end = time.time() + limit
    while time.time() < end and not rospy.is_shutdown():
        if predicate():
            return
        time.sleep(0.05)
    raise SystemExit("judge: no %s within %.0f s" % (what, limit))


def latest(topic, cls):
    box = {}

    def cb(msg):
        box["msg"] = msg
        box.setdefault("count", 0)
        box["count"] += 1
    sub = rospy.Subscriber(topic, cls, cb, queue_size=50)
    return box, sub


def node_alive(name):
    try:
        uri = rosgraph.Master("/doc_judge").lookupNode(name)
    except Exception:
        return False
    try:
        import xmlrpc.client
        code, _, _ = xmlrpc.client.ServerProxy(uri).getPid("/doc_judge")
        return code == 1
    except Exception:
        return False


def wait_master():
    end = time.time() + LIMIT_S
    while time.time() < end:
        try:
            rosgraph.Master("/doc_judge").getPid()
            return
        except Exception:
            time.sleep(0.2)
    raise SystemExit("judge: no ROS master within %.0f s" % LIMIT_S)


def rviz_marker_warnings(m):
    """What rviz 1.14's marker checks (marker_utils.cpp) would put in the display's status for
    this TRIANGLE_LIST (they turn the "Tissue surface" display's status to Warn/Error)."""
    out = []
    if m.text:
        out.append("non-empty text (rviz: 'Non-empty text is ignored.')")
    if len(m.points) % 3:
        out.append("points not a multiple of 3")
    if m.colors and len(m.colors) != len(m.points):
        out.append("%d colours for %d points" % (len(m.colors), len(m.points)))
    q = m.pose.orientation
    if abs(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w - 1.0) > 1e-3:
        out.append("pose orientation not a unit quaternion")
    if min(m.scale.x, m.scale.y, m.scale.z) <= 0:
        out.append("scale not positive")
    if m.mesh_resource:
        out.append("non-empty mesh_resource")
    if any(c.a <= 0 for c in m.colors) or (not m.colors and m.color.a <= 0):
        out.append("zero alpha")
    return out


def judge_surface(args):
    box, _ = latest("/tissue/surface", Marker)

    def good():
        m = box.get("msg")
        return (m is not None and m.type == Marker.TRIANGLE_LIST and len(m.points) >= 300 and
                all(math.isfinite(v) for p in m.points for v in (p.x, p.y, p.z)))
    wait_for("/tissue/surface TRIANGLE_LIST with >= 100 finite triangles", good)
    problems = rviz_marker_warnings(box["msg"])
    if problems:
        raise SystemExit("judge: rviz would flag /tissue/surface: " + "; ".join(problems))
    line = "surface with %d triangles, nothing rviz flags" % (len(box["msg"].points) // 3)
    if "--rviz" in args:
        wait_for("/rviz node", lambda: node_alive("/rviz"), 60)
        time.sleep(5)  # rviz has loaded its displays: still alive?
        if not node_alive("/rviz"):
            raise SystemExit("judge: rviz died after starting")
        line += "; rviz running"
    return line


def stats_class():
    from soft_tissue_cutting.msg import SimStats
    return SimStats


def judge_demo(args):
    box, _ = latest("/tissue/stats", stats_class())
    wait_for("cut in /tissue/stats", lambda: box.get("msg") is not None and box["msg"].cuts >= 1)
    return "%d cuts at step %d" % (box["msg"].cuts, box["msg"].step)


def judge_scalpel_marker(args):
    poses, _ = latest("/scalpel/pose", PoseStamped)
    markers, _ = latest("/tissue/markers", MarkerArray)
    fb_pub = rospy.Publisher("/scalpel_marker/feedback", InteractiveMarkerFeedback, queue_size=1)
    wait_for("/scalpel/pose from scalpel_marker.py", lambda: "msg" in poses)
    start = poses["msg"].pose.position
    # a small drag (within the node's ~max_pose_jump) from where the handle starts
    target = (start.x - 0.005, start.y + 0.001, start.z + 0.002)
    fb = InteractiveMarkerFeedback()
    fb.client_id = "/doc_judge"
    fb.marker_name = "scalpel"
    fb.control_name = "move_x"
    fb.event_type = InteractiveMarkerFeedback.POSE_UPDATE
    fb.header.frame_id = poses["msg"].header.frame_id or "tissue"
    fb.pose.position.x, fb.pose.position.y, fb.pose.position.z = target
    fb.pose.orientation.w = 1.0

    def follows():
        fb_pub.publish(fb)
        p = poses["msg"].pose.position
        return max(abs(p.x - target[0]), abs(p.y - target[1]), abs(p.z - target[2])) < 1e-9
    wait_for("/scalpel/pose at the dragged pose", follows, 30)
    line = "scalpel/pose follows the dragged handle to %s" % (target,)
    if node_alive("/tissue"):
        def blade_moved():
            fb_pub.publish(fb)
            m = markers.get("msg")
            if m is None:
                return False
            blade = [k for k in m.markers if k.ns == "scalpel" and k.id == 0 and k.action == Marker.ADD]
            if not blade:
                return False
            pts = blade[0].points
            return any(abs(q.x - target[0]) < 1e-6 and abs(q.y - target[1]) < 1e-6 and
                       abs(q.z - target[2]) < 1e-6 for q in pts) or (
                abs(blade[0].pose.position.x - target[0]) < 1e-6 and
                abs(blade[0].pose.position.y - target[1]) < 1e-6 and
                abs(blade[0].pose.position.z - target[2]) < 1e-6)
        wait_for("tissue blade marker at the dragged pose", blade_moved)
        line += "; the tissue node's blade marker too"
    return line


def judge_trajectory_player(args):
    poses, _ = latest("/scalpel/pose", PoseStamped)
    stats, _ = latest("/tissue/stats", stats_class())
    wait_for("/tissue/trajectory parameter", lambda: rospy.has_param("/tissue/trajectory"))
    first = rospy.get_param("/tissue/trajectory")[0]["position"]
    wait_for("/scalpel/pose from trajectory_player.py", lambda: "msg" in poses)
    p = poses["msg"].pose.position
    # the first message may already be a little along the stroke: 5 mm
    if max(abs(p.x - first[0]), abs(p.y - first[1]), abs(p.z - first[2])) > 5e-3:
        raise SystemExit("judge: first /scalpel/pose %s is not the trajectory's start %s" %
                         ((p.x, p.y, p.z), first))
    wait_for("cut in /tissue/stats", lambda: stats.get("msg") is not None and stats["msg"].cuts >= 1)
    return "%d poses, %d cuts" % (poses["count"], stats["msg"].cuts)


def main():
    name, args = sys.argv[1], sys.argv[2:]
    fn = globals().get("judge_" + name)
    if fn is None:
        raise SystemExit("judge: unknown judge %r" % name)
    wait_master()
    rospy.init_node("doc_judge", anonymous=True, disable_signals=True)
    print("judge %s: %s" % (name, fn(args)))


if __name__ == "__main__":
    main()
