#!/usr/bin/env bash
# ./tissue soak: runs tissue_node on a private master for MINUTES minutes under
# scripts/soak_driver.py (random-walk scalpel, service bursts from 4 threads, resets) and
# prints its report. Usage: soak.sh MINUTES SCENE (the workspace's setup.bash sourced).
set -euo pipefail
minutes="${1:-10}"
scene="${2:-thigh}"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
case "$scene" in thigh) ;; /*) ;; *) scene="$(cd "$(dirname "$scene")" && pwd)/$(basename "$scene")" ;; esac

# No name resolution needed: everything on 127.0.0.1, a free port for a private master.
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
export ROS_IP=127.0.0.1 ROS_MASTER_URI="http://127.0.0.1:$port"
unset ROS_HOSTNAME
out="${TISSUE_SOAK_OUT:-${ROS_HOME:-/tmp}/soak}"
mkdir -p "$out"

pids=()
cleanup() {
  local p
  for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done
  sleep 1
  for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null || true; done
}
trap cleanup EXIT

roscore -p "$port" >"$out/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do rosparam list >/dev/null 2>&1 && break; sleep 0.2; done
rosrun soft_tissue_cutting tissue_node __name:=tissue _scene:="$scene" >"$out/node.log" 2>&1 &
node=$!
pids=("$node" "${pids[@]}")
echo "soak: scene $scene for $minutes min, node pid $node, logs in $out"
python3 "$here/soak_driver.py" --minutes "$minutes" --pid "$node" --out "$out"
