#!/usr/bin/env bash
# Re-records test/bags/thigh_cut.bag (used by test/ros/rostest_bag_replay): the thigh's
# scripted scalpel at half speed (2 s), /scalpel/pose only. Run with the workspace sourced.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export PATH="/usr/bin:/bin:$PATH" ROS_IP=127.0.0.1 ROS_HOME="$ROOT/out/record_bag"
mkdir -p "$ROS_HOME" "$ROOT/test/bags"
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://127.0.0.1:$port"
bag="$ROOT/test/bags/thigh_cut.bag"
timeout -s INT -k 10 "${1:-8}" roslaunch -p "$port" soft_tissue_cutting record_test_bag.launch \
  bag:="$bag" >"$ROS_HOME/roslaunch.log" 2>&1 || true
rosbag info "$bag"
