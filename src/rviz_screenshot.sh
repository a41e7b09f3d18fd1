#!/usr/bin/env bash
# Reproduce docs/images/rviz_swarm.png: the 20-robot swarm demo in rviz (config/swarm.rviz) on a
# virtual X server, captured after a while so that the trails show.
#
#   src/rviz_screenshot.sh [OUT.png] [WAIT_SECONDS]
#
# Needs the built workspace (./sbot.sh build), Xvfb and ImageMagick (`import`, `convert`; apt-get
# install imagemagick). Starts its own X server (display :99 or the next free one) and its own ROS
# master on a random port, and stops both.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="${1:-$ROOT/docs/images/rviz_swarm.png}"
WAIT="${2:-40}"
export PATH="/usr/bin:$PATH"

for tool in Xvfb import; do
  command -v "$tool" >/dev/null || { echo "rviz_screenshot: $tool is missing (apt-get install xvfb imagemagick)" >&2; exit 1; }
done
CONVERT=/usr/bin/convert; [[ -x $CONVERT ]] || CONVERT=convert
[[ -f "$ROOT/build/ws/devel/setup.bash" ]] || { echo "rviz_screenshot: run ./sbot.sh build first" >&2; exit 1; }

set +u
# shellcheck disable=SC1091
source "$ROOT/build/ws/devel/setup.bash"
set -u
export ROS_HOME="$ROOT/build/ros_home" ROS_LOG_DIR="$ROOT/build/ros_home/log"
mkdir -p "$ROS_LOG_DIR" "$(dirname "$OUT")"

display=99
while [[ -e /tmp/.X11-unix/X$display || -e /tmp/.X$display-lock ]]; do display=$((display + 1)); done
export DISPLAY=":$display"
Xvfb "$DISPLAY" -screen 0 1280x800x24 -nolisten tcp >/dev/null 2>&1 &
xvfb_pid=$!
launch_pid=""
tmp="$(mktemp -d)"
cleanup() {
  [[ -n "$launch_pid" ]] && kill -INT "$launch_pid" 2>/dev/null && wait "$launch_pid" 2>/dev/null || true
  kill "$xvfb_pid" 2>/dev/null || true
  rm -rf "$tmp"
}
trap cleanup EXIT
sleep 2

port=$((11500 + RANDOM % 400))
export ROS_MASTER_URI="http://127.0.0.1:$port"
export LIBGL_ALWAYS_SOFTWARE=1
roslaunch -p "$port" "$ROOT/launch/swarm.launch" headless:=false robots:=20 real_time_factor:=1 duration:=60 \
  >"$tmp/roslaunch.log" 2>&1 &
launch_pid=$!
echo "rviz_screenshot: waiting ${WAIT} s for the swarm to move (display $DISPLAY, master port $port)" >&2
sleep "$WAIT"
kill -0 "$launch_pid" 2>/dev/null || { tail -n 30 "$tmp/roslaunch.log" >&2; echo "rviz_screenshot: roslaunch exited early" >&2; exit 1; }

import -window root "$tmp/full.png"
# The 1280x800 rviz window, reduced to a palette PNG well under 300 KB.
"$CONVERT" "$tmp/full.png" -resize 1024x -colors 256 -strip "PNG8:$OUT"
echo "rviz_screenshot: wrote $OUT ($(du -k "$OUT" | cut -f1) KB)" >&2
