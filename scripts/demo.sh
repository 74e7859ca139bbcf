#!/usr/bin/env bash
# The headless demo (SPEC 2, `./tissue demo`, which builds and sources .build/devel/setup.bash
# first): tissue_node on the built-in thigh + the scripted scalpel (trajectory_player.py)
# + a bag recording, stopped with SIGINT so the bag closes cleanly; then a summary from the
# bag, `rosbag info`, and a picture of the cut tissue rendered by rviz under Xvfb.
# Outputs: out/demo/ (git-ignored: demo.bag, logs, cut_tissue.png) and docs/cut_tissue.png.
# Environment: TISSUE_DEMO_SECONDS (default 12), TISSUE_DEMO_PICTURE=0 skips the picture.
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
  source "$ROOT/.build/devel/setup.bash"
  set -u
fi
seconds="${TISSUE_DEMO_SECONDS:-12}"
bag="$OUT/demo.bag"
rm -f "$bag" "$bag.active"
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://127.0.0.1:$port"

echo "demo: thigh + scripted scalpel for ${seconds} s (log: out/demo/roslaunch.log)"
rc=0
timeout -s INT -k 15 "$seconds" roslaunch -p "$port" soft_tissue_cutting demo.launch \
  bag:="$bag" >"$OUT/roslaunch.log" 2>&1 || rc=$?
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
  if "$ROOT/scripts/render_picture.sh" "$bag" "$OUT/cut_tissue.png" >"$OUT/render.log" 2>&1; then
    mkdir -p "$ROOT/docs"
    cp "$OUT/cut_tissue.png" "$ROOT/docs/cut_tissue.png"
    echo "demo: picture out/demo/cut_tissue.png (copied to docs/cut_tissue.png)"
  else
    tail -10 "$OUT/render.log"
    echo "demo: picture failed (see out/demo/render.log); the demo itself succeeded" >&2
  fi
fi
echo "demo: done (bag: out/demo/demo.bag)"
