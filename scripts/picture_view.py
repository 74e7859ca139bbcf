#!/usr/bin/python3
"""picture_view.py SCENE.yaml RVIZ_IN RVIZ_OUT: an rviz config that frames a scene's incision.

Writes RVIZ_OUT: RVIZ_IN (config/tissue.rviz) with its camera aimed at where the scene's
scripted scalpel cuts, and prints one line: the rotation `qx qy qz qw` that turns the view's
"up" to +z, for scripts/turn_bag.py. Up is the way the blade's edge points, tip to heel
(docs/SCENE.md: the pose's local +x), averaged over the trajectory: out of the tissue where it
cuts (the livers: +y, the thigh_follow stroke on the thigh's side: +x); without a trajectory,
against gravity, or +z.

Why turn the scene: rviz's orbit camera turns about the fixed frame's z axis, and a scene may
cut in any direction. turn_bag.py turns the recorded markers (this Debian's ROS has no
static_transform_publisher nor tf2 Python messages to turn the frame instead); the camera
below is placed in the turned coordinates.

The view is derived from the scene alone (no mesh needed):
- the stroke: the two trajectory poses farthest apart across "up" give its direction and
  length; the focal point is the middle of the trajectory's bounding box across, and
  `SURFACE_HEIGHT_FRACTION` up from its deepest point (about the surface it cuts);
- the camera looks down at the incision from `PITCH` above the surface, from the side of the
  cut plane where the wall the node's shading lights (src/ros/markers.cpp, kLight) faces it,
  turned `AZIMUTH_FROM_NORMAL` towards the stroke's start (the blade ends behind the cut), so
  the far wall of the gap shows;
- its distance makes the stroke span `STROKE_FRACTION_OF_WIDTH` of the picture's width.
A scene without a trajectory is framed on its operation sphere or box; without either, the
camera of RVIZ_IN is kept and the rotation printed is the identity.
"""
import math
import sys

import yaml

# src/ros/markers.cpp: the direction of the light baked into the surface colours (tissue frame).
MARKER_LIGHT = (1.0, 0.35, 0.6)
PITCH = math.radians(60)
AZIMUTH_FROM_NORMAL = math.radians(25)
STROKE_FRACTION_OF_WIDTH = 0.33
MIN_DISTANCE = 0.05  # m
# Where the cut surface lies between the trajectory's lowest and highest point: the blade
# starts a little above the tissue and sinks deeper into it than it started above.
SURFACE_HEIGHT_FRACTION = 0.75


def unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v] if n > 0 else None


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def rotation_to_z(up):
    """Quaternion (x, y, z, w) of the smallest rotation taking `up` to +z."""
    c = max(-1.0, min(1.0, up[2]))
    if c < -1 + 1e-12:
        return [1.0, 0.0, 0.0, 0.0]  # 180 deg about x
    axis = cross(up, [0.0, 0.0, 1.0])
    s = math.sqrt(2 * (1 + c))  # = 2 cos(angle / 2)
    return [axis[0] / s, axis[1] / s, axis[2] / s, s / 2]


def rotate(q, v):
    """v rotated by the unit quaternion q = (x, y, z, w)."""
    u, w = q[:3], q[3]
    t = [2 * c for c in cross(u, v)]
    return [v[i] + w * t[i] + cross(u, t)[i] for i in range(3)]


def view_of(scene):
    """(rotation turning up to +z, then focal point, yaw, pitch, distance in the turned
    coordinates), or None when the scene says nothing about where to look."""
    poses = scene.get("trajectory") or []
    edges = [rotate(unit([float(c) for c in p.get("orientation", [0, 0, 0, 1])]), [1.0, 0.0, 0.0])
             for p in poses]
    gravity = [float(g) for g in scene.get("gravity", [0, 0, 0])]
    up = (unit([sum(e[i] for e in edges) for i in range(3)]) or unit([-g for g in gravity])
          or [0.0, 0.0, 1.0])
    q = rotation_to_z(up)
    points = [rotate(q, [float(c) for c in p["position"]]) for p in poses]
    region = scene.get("operation_region") or {}
    if len(points) >= 2:
        # a before b in time: `along` points the way the blade was drawn
        span, a, b = max(((math.hypot(p[0] - r[0], p[1] - r[1]), p, r)
                          for i, p in enumerate(points) for r in points[i + 1:]),
                         key=lambda t: t[0])
        lo = [min(p[i] for p in points) for i in range(3)]
        hi = [max(p[i] for p in points) for i in range(3)]
        focal = [(lo[i] + hi[i]) / 2 for i in range(3)]
        focal[2] = lo[2] + SURFACE_HEIGHT_FRACTION * (hi[2] - lo[2])
        along = unit([b[0] - a[0], b[1] - a[1], 0.0]) or [1.0, 0.0, 0.0]
        length = max(span, 0.01)
    elif isinstance(region, dict) and ("sphere" in region or "box" in region):
        if "sphere" in region:
            focal = rotate(q, [float(c) for c in region["sphere"]["center"]])
            length = 2 * float(region["sphere"]["radius"])
        else:
            lo, hi = region["box"]["min"], region["box"]["max"]
            focal = rotate(q, [(float(lo[i]) + float(hi[i])) / 2 for i in range(3)])
            length = max(abs(float(hi[i]) - float(lo[i])) for i in range(3))
        along = [1.0, 0.0, 0.0]
    else:
        return None
    # The side of the cut plane the lit wall faces: its normal has a positive light component.
    normal = [-along[1], along[0], 0.0]
    light = rotate(q, list(MARKER_LIGHT))
    if dot(normal, light) < 0:
        normal = [-c for c in normal]
    # Turned back towards where the stroke began: the blade, lifted out at its end, stays
    # behind the incision instead of in front of the camera.
    towards = [math.cos(AZIMUTH_FROM_NORMAL) * normal[i] - math.sin(AZIMUTH_FROM_NORMAL) * along[i]
               for i in range(3)]
    yaw = math.atan2(towards[1], towards[0])
    # Vertical field of view 0.785 rad (tissue.rviz); the cropped picture is about square.
    fov = 0.785
    distance = max(MIN_DISTANCE, length / STROKE_FRACTION_OF_WIDTH / (2 * math.tan(fov / 2)))
    return q, focal, yaw, PITCH, distance


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: picture_view.py SCENE.yaml RVIZ_IN RVIZ_OUT")
    scene_path, rviz_in, rviz_out = sys.argv[1:]
    with open(scene_path) as f:
        scene = yaml.safe_load(f) or {}
    with open(rviz_in) as f:
        config = yaml.safe_load(f)
    view = view_of(scene)
    q = [0.0, 0.0, 0.0, 1.0]
    if view is not None:
        q, focal, yaw, pitch, distance = view
        manager = config["Visualization Manager"]
        current = manager["Views"]["Current"]
        current["Focal Point"] = {"X": focal[0], "Y": focal[1], "Z": focal[2]}
        current["Yaw"] = yaw
        current["Pitch"] = pitch
        current["Distance"] = distance
        current["Near Clip Distance"] = 0.001
        current["Target Frame"] = "<Fixed Frame>"
        for display in manager["Displays"]:
            # The grid (the thigh view's floor at z = 0) would cut through the organ: off.
            if display.get("Class") == "rviz/Grid":
                display["Enabled"] = False
            # The operation region's outline would draw across the incision: off.
            if "operation_region" in display.get("Namespaces", {}):
                display["Namespaces"]["operation_region"] = False
    with open(rviz_out, "w") as f:
        yaml.safe_dump(config, f, default_flow_style=False, sort_keys=False)
    print("%.9f %.9f %.9f %.9f" % tuple(q))


if __name__ == "__main__":
    main()
