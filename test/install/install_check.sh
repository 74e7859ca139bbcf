#!/usr/bin/env bash
# Install check (CI, from `./tissue test`): the package builds with CATKIN_ENABLE_TESTING=OFF and
# installs to a temporary prefix; from that install space alone (no source tree, no devel
# space on the ROS path) tissue_node starts on every installed example scene and publishes a
# surface, and trajectory_player.py plays a scalpel into it.
#   install_check.sh WORKDIR [JUNIT.xml]
# WORKDIR gets the release workspace (ws/) and the prefix (prefix/); put it under the ccache
# base dir so the release build reuses the test build's objects.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd -P)"
WORK="$1" JUNIT="${2:-}"
PKG=soft_tissue_cutting
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH" ROS_HOSTNAME=localhost
rm -rf "$WORK/prefix" "$WORK/ws/src"
mkdir -p "$WORK/ws/src" "$WORK/ros_home"
ln -s "$ROOT" "$WORK/ws/src/$PKG"
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cases=() failures=()
record() {  # record NAME SECONDS [FAILURE]
  cases+=("$1|$2|${3:-}")
  if [ -n "${3:-}" ]; then failures+=("$1: $3"); echo "install: FAIL $1: $3"; else echo "install: ok   $1 ($2 s)"; fi
}

t0=$SECONDS
# a plain shell: nothing from the test build's workspace on the paths
if (cd "$WORK/ws" && env -u ROS_PACKAGE_PATH -u CMAKE_PREFIX_PATH -u PYTHONPATH -u LD_LIBRARY_PATH \
      -u PKG_CONFIG_PATH catkin_make -j"${TISSUE_JOBS:-2}" -DCMAKE_BUILD_TYPE=Release \
      "${launcher[@]+"${launcher[@]}"}" -DCATKIN_ENABLE_TESTING=OFF \
      -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
      -DCMAKE_INSTALL_PREFIX="$WORK/prefix" install >"$WORK/build.log" 2>&1); then
  record "release build (CATKIN_ENABLE_TESTING=OFF) + install" $((SECONDS - t0))
else
  tail -30 "$WORK/build.log"
  record "release build (CATKIN_ENABLE_TESTING=OFF) + install" $((SECONDS - t0)) "failed (log: $WORK/build.log)"
fi

# From here on only the install space (a clean environment sourcing prefix/setup.bash).
share="$WORK/prefix/share/$PKG"
if [ -f "$WORK/prefix/setup.bash" ]; then
  run_scene() {  # run_scene SCENE EXTRA_JUDGE
    local scene="$1" t=$SECONDS port log="$WORK/node_$(basename "$1" .yaml).log" out rc=0
    port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])')
    out=$(
      env -i HOME="$HOME" PATH="$PATH" ROS_HOSTNAME=localhost ROS_HOME="$WORK/ros_home" \
        ROS_MASTER_URI="http://localhost:$port" bash -c '
        set +u; source "$1/setup.bash"; set -u
        case "$(rospack find soft_tissue_cutting)" in "$1"/*) ;; *) echo "rospack finds $(rospack find soft_tissue_cutting), not the install space"; exit 1;; esac
        roslaunch -p "$2" soft_tissue_cutting tissue.launch scene:="$3" >"$4" 2>&1 &
        pid=$!
        rc=0
        python3 "$5/test/doc/judge.py" surface || rc=1
        player=""
        if [ "$3" = thigh ] && [ $rc -eq 0 ]; then
          rosrun soft_tissue_cutting trajectory_player.py >>"$4" 2>&1 &
          player=$!
          python3 "$5/test/doc/judge.py" trajectory_player || rc=1
        fi
        # The player outlives its master otherwise (it waits for one, for ever).
        if [ -n "$player" ]; then kill -INT $player 2>/dev/null; wait $player || true; fi
        kill -INT $pid; wait $pid || true
        exit $rc' _ "$WORK/prefix" "$port" "$scene" "$log" "$ROOT" 2>&1) || rc=$?
    local name="installed node on ${scene#"$share"/}"
    if [ $rc -eq 0 ]; then record "$name: $(echo "$out" | sed 's/^judge [a-z_]*: //' | tr '\n' ';')" $((SECONDS - t))
    else record "$name" $((SECONDS - t)) "$(echo "$out" | tail -2 | tr '\n' ' ') (log: $log)"; fi
  }
  run_scene thigh
  for scene in "$share"/config/scenes/*.yaml; do
    case "$(grep -E '^\s*file:' "$scene" || true)" in *test/*) record "installed scene $scene" 0 "points into test/";; esac
    run_scene "$scene"
  done
else
  record "install space" 0 "no $WORK/prefix/setup.bash"
fi

if [ -n "$JUNIT" ]; then
  mkdir -p "$(dirname "$JUNIT")"
  python3 - "$JUNIT" "${cases[@]}" <<'PY'
import sys, xml.etree.ElementTree as ET
suite = ET.Element("testsuite", name="install_check")
for c in sys.argv[2:]:
    name, secs, failure = c.split("|", 2)
    tc = ET.SubElement(suite, "testcase", classname="install_check", name=name, time=secs)
    if failure:
        ET.SubElement(tc, "failure", message=failure).text = failure
suite.set("tests", str(len(sys.argv) - 2))
suite.set("failures", str(sum(1 for c in sys.argv[2:] if c.split("|", 2)[2])))
ET.ElementTree(suite).write(sys.argv[1], encoding="utf-8", xml_declaration=True)
PY
fi
[ ${#failures[@]} -eq 0 ] || { printf 'install: %s\n' "${failures[@]}" >&2; exit 1; }
echo "install: all ${#cases[@]} checks passed"
