#!/usr/bin/env bash
# rviz_window.sh PNG [SCENE]: a screenshot of the whole rviz window (panels included) with the
# thigh (or SCENE) cut by its scripted stroke and then the interactive scalpel handle
# (scalpel_marker.py) taking over at the blade's last pose, on a virtual X display (Xvfb).
# Used by `./tissue pictures` for docs/rviz_window.png. Needs the workspace sourced.
set -euo pipefail
png="$1" scene="${2:-thigh}"
export ROS_HOSTNAME="${ROS_HOSTNAME:-localhost}"
if [ -z "${DISPLAY:-}" ] || [ "${TISSUE_RENDER_INNER:-}" != 1 ]; then
  exec env TISSUE_RENDER_INNER=1 xvfb-run -a -s "-screen 0 1280x1024x24" "$0" "$@"
fi
port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://localhost:$port"
log="${png%.png}_rviz.log"
roslaunch -p "$port" soft_tissue_cutting tissue.launch scene:="$scene" rviz:=true >"$log" 2>&1 &
launch=$!
cleanup() { kill -INT ${marker:-} ${player:-} "$launch" 2>/dev/null || true; wait 2>/dev/null || true; }
trap cleanup EXIT
# the scripted stroke, then the handle where the blade stopped
for _ in $(seq 120); do rosparam get /tissue/trajectory >/dev/null 2>&1 && break; sleep 0.5; done
sleep 6  # rviz starts (~6 s on llvmpipe)
# (the player stays up, idle, after the stroke: it is stopped once the stroke has played)
rosrun soft_tissue_cutting trajectory_player.py _speed:=0.5 >"${log%.log}_player.log" 2>&1 &
player=$!
sleep 8
kill -INT "$player"
wait "$player" || true
player=
last=$(rosparam get /tissue/trajectory | /usr/bin/python3 -c '
import sys, yaml; p = yaml.safe_load(sys.stdin)[-1]
print(list(p["position"]), list(p.get("orientation", [0, 0, 0, 1])))')
pos="${last%%] *}]" ori="[${last#*] [}"
rosrun soft_tissue_cutting scalpel_marker.py _initial_position:="$pos" _initial_orientation:="$ori" \
  >"${log%.log}_marker.log" 2>&1 &
marker=$!
sleep 6
import -window root "$png"
# the rviz window (config/tissue.rviz: 1260 x 1000 at 0,0) without the empty screen around it
convert "$png" -crop 1260x1000+0+0 +repage "$png"
echo "picture: $png"
