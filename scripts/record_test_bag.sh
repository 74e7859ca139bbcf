#!/usr/bin/env bash
# Records a scene's scripted scalpel into a committed test bag of /scalpel/pose only. Run with
# the workspace sourced.
#   scripts/record_test_bag.sh [--scene SCENE] [--bag NAME] [--speed S] [SECONDS]
# SCENE: `thigh` (default, the built-in scene), a scene in config/scenes/ (e.g. thigh_follow)
# or a scene YAML; NAME: the bag in test/bags/ (default thigh_cut.bag); S: the player's time
# scale (default 0.5); SECONDS: how long the recording runs (default 8).
# The defaults re-record test/bags/thigh_cut.bag (test/ros/rostest_bag_replay): the thigh's
# stroke at half speed (2 s). test/bags/thigh_follow_cut.bag (rostest_bag_replay_follow):
#   scripts/record_test_bag.sh --scene thigh_follow --bag thigh_follow_cut.bag --speed 1 8
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
scene=thigh name=thigh_cut.bag speed=0.5 seconds=8
while [ $# -gt 0 ]; do
  case "$1" in
    --scene) scene="$2"; shift 2 ;;
    --bag) name="$2"; shift 2 ;;
    --speed) speed="$2"; shift 2 ;;
    [0-9]*) seconds="$1"; shift ;;
    *) echo "record_test_bag: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
# shellcheck source=scene_path.sh
source "$ROOT/scripts/scene_path.sh"
if ! scene="$(scene_path "$scene" "$ROOT")"; then
  echo "record_test_bag: unknown scene '$scene': use thigh, a scene YAML or a name in" \
    "config/scenes/" >&2
  exit 2
fi
if [ "$scene" != thigh ]; then
  grep -qE '^trajectory:' "$scene" || { echo "record_test_bag: $scene has no trajectory" >&2; exit 2; }
fi
export PATH="/usr/bin:/bin:$PATH" ROS_IP=127.0.0.1 ROS_HOME="$ROOT/out/record_bag"
mkdir -p "$ROS_HOME" "$ROOT/test/bags"
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://127.0.0.1:$port"
bag="$ROOT/test/bags/$name"
timeout -s INT -k 10 "$seconds" roslaunch -p "$port" soft_tissue_cutting record_test_bag.launch \
  bag:="$bag" scene:="$scene" speed:="$speed" >"$ROS_HOME/roslaunch.log" 2>&1 || true
rosbag info "$bag"
