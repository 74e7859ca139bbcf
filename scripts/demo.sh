#!/usr/bin/env bash
# The headless demo (`./tissue demo [SCENE]`, which builds and sources the workspace first):
# tissue_node on SCENE + the scripted scalpel (trajectory_player.py playing the scene's
# `trajectory`) + a bag recording, stopped with SIGINT so the bag closes cleanly; then a summary
# from the bag, `rosbag info`, and a picture of the cut tissue rendered by rviz under Xvfb.
# SCENE: `thigh` (default, the built-in scene), the name of a scene in config/scenes/ (e.g.
# `liver_cut`) or a scene YAML path. The picture frames the scene's own incision
# (scripts/picture_view.py; the thigh: config/tissue.rviz's view). Writes ONLY under out/demo/
# (git-ignored: demo.bag, logs, cut_tissue.png); `./tissue pictures` is what refreshes the
# README's pictures in docs/. Environment: TISSUE_DEMO_SECONDS (default: 12, or the scene's
# trajectory at demo.launch's speed 0.25 plus 8 s when that is longer), TISSUE_DEMO_PICTURE=0
# skips the picture.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="$ROOT/out/demo"
mkdir -p "$OUT"
export PATH="/usr/bin:/bin:$PATH"
export ROS_IP=127.0.0.1  # no name resolution needed (not even localhost)
unset ROS_HOSTNAME
export ROS_HOME="$OUT/ros_home"
mkdir -p "$ROS_HOME"
if ! command -v roslaunch >/dev/null || [ -z "${ROS_PACKAGE_PATH:-}" ]; then
  set +u
  # shellcheck disable=SC1091
  source "$("$ROOT/tissue" where)"
  set -u
fi
# shellcheck source=scene_path.sh
source "$ROOT/scripts/scene_path.sh"
scene="${1:-thigh}"
if ! scene="$(scene_path "$scene" "$ROOT")"; then
  echo "demo: unknown scene '${1}': use thigh, a scene YAML, or one of:" \
    "$(cd "$ROOT/config/scenes" && ls -- *.yaml | sed 's/\.yaml$//' | tr '\n' ' ')" >&2
  exit 1
fi
if [ "$scene" != thigh ] && ! grep -qE '^trajectory:' "$scene"; then
  echo "demo: note: $(basename "$scene") has no 'trajectory': the node runs without a scalpel"
fi
# Long enough for the node to start (TetGen, condensation), the player's 1 s delay and the
# whole trajectory at speed 0.25 (demo.launch): 12 s for the thigh's 1 s stroke.
default_seconds=12
if [ "$scene" != thigh ]; then
  default_seconds=$(/usr/bin/python3 -c '
import math, sys, yaml
poses = (yaml.safe_load(open(sys.argv[1])) or {}).get("trajectory") or []
end = max((float(p["t"]) for p in poses), default=0.0)
print(max(12, math.ceil(end / 0.25 + 8)))' "$scene")
fi
seconds="${TISSUE_DEMO_SECONDS:-$default_seconds}"
bag="$OUT/demo.bag"
rm -f "$bag" "$bag.active"
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://127.0.0.1:$port"

echo "demo: $(basename "$scene") + scripted scalpel for ${seconds} s (log: out/demo/roslaunch.log)"
rc=0
timeout -s INT -k 15 "$seconds" roslaunch -p "$port" soft_tissue_cutting demo.launch \
  scene:="$scene" bag:="$bag" >"$OUT/roslaunch.log" 2>&1 || rc=$?
# 124: stopped by the SIGINT from timeout, as intended.
if [ "$rc" -ne 0 ] && [ "$rc" -ne 124 ]; then
  tail -30 "$OUT/roslaunch.log"
  echo "demo: roslaunch failed ($rc)" >&2
  exit 1
fi
[ -f "$bag" ] || { tail -30 "$OUT/roslaunch.log"; echo "demo: no bag recorded" >&2; exit 1; }

echo "demo: summary"
python3 - "$bag" <<'PY'
import statistics, sys
import rosbag
bag = rosbag.Bag(sys.argv[1])
stats = [m for _, m, _ in bag.read_messages(topics=["/tissue/stats"])]
wrench = [m for _, m, _ in bag.read_messages(topics=["/tissue/scalpel/wrench"])]
poses = bag.get_message_count("/scalpel/pose")
hashes = [m.data for _, m, _ in bag.read_messages(topics=["/tissue/mesh_hash"])]
# The cut faces as last shown (namespace cut_faces of ~markers: both lips, deformed).
cut_faces = None
for _, m, _ in bag.read_messages(topics=["/tissue/markers"]):
    cut_faces = next((k for k in m.markers if k.ns == "cut_faces"), cut_faces)
def triangles_area(points):
    area = 0.0
    for a, b, c in zip(points[0::3], points[1::3], points[2::3]):
        u = (b.x - a.x, b.y - a.y, b.z - a.z)
        v = (c.x - a.x, c.y - a.y, c.z - a.z)
        n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        area += 0.5 * (n[0] ** 2 + n[1] ** 2 + n[2] ** 2) ** 0.5
    return area
cut_area = triangles_area(cut_faces.points) if cut_faces and cut_faces.action == 0 else 0.0
if not stats:
    sys.exit("demo: no /tissue/stats in the bag")
last = stats[-1]
fpeak = max((m.wrench.force.x ** 2 + m.wrench.force.y ** 2 + m.wrench.force.z ** 2) ** 0.5
            for m in wrench) if wrench else 0.0
first_cut = next((s.step for s in stats if s.cutting), None)
print(f"  steps             {len(stats)} (last step {last.step})")
print(f"  scalpel poses     {poses}")
print(f"  cuts              {last.cuts}  (tets split {last.tets_split}, first cut at step {first_cut})")
print(f"  tets              {stats[0].tets} -> {last.tets}, nodes {stats[0].nodes} -> {last.nodes}")
print(f"  open cut faces    {cut_area * 1e4:.1f} cm2 (both lips, deformed)")
print(f"  median step       {statistics.median(s.step_ms for s in stats):.3f} ms "
      f"(max {max(s.step_ms for s in stats):.3f} ms)")
print(f"  achieved rate     {statistics.median(s.rate_hz for s in stats):.1f} Hz (median)")
print(f"  contact steps     {sum(s.in_contact for s in stats)}")
print(f"  force peak        {fpeak:.4f} N")
print(f"  backend           {last.backend}")
print(f"  final mesh hash   {hashes[-1] if hashes else '?'}")
PY
echo "demo: rosbag info"
rosbag info "$bag"

if [ "${TISSUE_DEMO_PICTURE:-1}" != 0 ]; then
  echo "demo: rendering the cut tissue with rviz under Xvfb"
  if "$ROOT/scripts/render_picture.sh" "$bag" "$OUT/cut_tissue.png" "$scene" \
    >"$OUT/render.log" 2>&1; then
    echo "demo: picture out/demo/cut_tissue.png"
  else
    tail -10 "$OUT/render.log"
    echo "demo: picture failed (see out/demo/render.log); the demo itself succeeded" >&2
  fi
fi
echo "demo: done (bag: out/demo/demo.bag)"
