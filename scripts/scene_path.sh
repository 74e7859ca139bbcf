# Sourced by scripts that take a scene argument (demo.sh, record_test_bag.sh):
# scene_path NAME ROOT prints `thigh` (the built-in scene), the absolute path of a scene YAML,
# or of config/scenes/NAME.yaml; returns 1 (printing nothing) for anything else.
scene_path() {
  local scene="$1" root="$2"
  if [ "$scene" = thigh ]; then
    echo thigh
  elif [ -f "$scene" ]; then
    echo "$(cd "$(dirname "$scene")" && pwd)/$(basename "$scene")"
  elif [ -f "$root/config/scenes/$scene.yaml" ]; then
    echo "$root/config/scenes/$scene.yaml"
  else
    return 1
  fi
}
