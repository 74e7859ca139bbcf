#!/usr/bin/env bash
# render_picture.sh BAG PNG [SCENE [SECONDS]]: replays a bag's /tissue/surface and
# /tissue/markers into rviz on a virtual X display and saves a screenshot (docs/DESIGN.md
# section 14: Xvfb + `import -window root`). SCENE (a scene YAML; default or `thigh`: the
# built-in thigh and config/tissue.rviz's camera) frames the scene's own incision: the camera
# from scripts/picture_view.py, the recorded markers turned so that the scene's up is rviz's
# +z (scripts/turn_bag.py). Needs the workspace sourced, xvfb-run, rviz and imagemagick.
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)"
abs() { case "$1" in /*) echo "$1" ;; *) echo "$PWD/$1" ;; esac; }
bag="$(abs "$1")" png="$(abs "$2")" scene="${3:-thigh}" wait_s="${4:-}"
[ "$scene" = thigh ] || scene="$(abs "$scene")"
export ROS_HOSTNAME="${ROS_HOSTNAME:-localhost}"
port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://localhost:$port"
if [ -z "${DISPLAY:-}" ] || [ "${TISSUE_RENDER_INNER:-}" != 1 ]; then
  exec env TISSUE_RENDER_INNER=1 xvfb-run -a -s "-screen 0 1280x1024x24" "$0" "$bag" "$png" \
    "$scene" ${wait_s:+"$wait_s"}
fi
view=()
if [ "$scene" != thigh ]; then
  rviz_config="${png%.png}_view.rviz" turned="${png%.png}_view.bag"
  q=$(/usr/bin/python3 "$HERE/picture_view.py" "$scene" "$HERE/../config/tissue.rviz" "$rviz_config")
  # shellcheck disable=SC2086
  /usr/bin/python3 "$HERE/turn_bag.py" "$bag" "$turned" $q
  bag="$turned"
  trap 'rm -f "$turned"' EXIT  # a turned copy of the whole bag: only for this picture
  view=(rviz_config:="$rviz_config")
fi
dur=$(/usr/bin/python3 -c "import rosbag,sys; b=rosbag.Bag(sys.argv[1]); print(b.get_end_time()-b.get_start_time())" "$bag")
# rviz start (~6 s on llvmpipe) + the bag at 2x + settle
[ -n "$wait_s" ] || wait_s=$(/usr/bin/python3 -c "print(int(6 + $dur / 2 + 5))")
roslaunch -p "$port" soft_tissue_cutting view_bag.launch bag:="$bag" "${view[@]+"${view[@]}"}" \
  >"${png%.png}_rviz.log" 2>&1 &
launch_pid=$!
sleep "$wait_s"
import -window root "$png"
# Keep rviz's 3D view only (the panels are rviz's own UI; geometry of the 1280x1024 screen).
convert "$png" -crop 878x906+364+63 +repage "$png"
kill -INT "$launch_pid" 2>/dev/null || true
wait "$launch_pid" 2>/dev/null || true
echo "picture: $png"
