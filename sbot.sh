#!/usr/bin/env bash
# swarmbot3d developer entry point. Every subcommand is idempotent and quick when nothing changed.
#
#   ./sbot.sh demo     install deps, build, run the headless swarm demo (rosbag + printed summary)
#   ./sbot.sh test     install deps, build, run every test (gtest, rostest, python); non-zero on failure
#   ./sbot.sh bench    install deps, build, print the benchmark figures (RTM, step time, memory)
#   ./sbot.sh build    install deps and build only
#   ./sbot.sh deps     install the Debian packages only
#   ./sbot.sh shell    a bash with the workspace sourced (for rosrun/roslaunch by hand)
#
# The catkin workspace lives in build/ws (git-ignored); its src/ links each package of this
# repository separately, because catkin stops descending at the first package.xml it meets.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
WS="$ROOT/build/ws"
PACKAGES=(sbot_msgs sbot_description sbot_sim sbot_controllers)
# ROS Python lives in the system interpreter; a python3 earlier on PATH may lack rospy/rosbag.
export PATH="/usr/bin:$PATH"
PY=/usr/bin/python3

APT_PACKAGES=(
  build-essential cmake catkin ros-core-dev ros-robot-dev libroscpp-dev ros-message-generation
  libtf2-ros-dev libimage-transport-dev libcv-bridge-dev libvisualization-msgs-dev libnav-msgs-dev
  libsensor-msgs-dev libgeometry-msgs-dev libstd-srvs-dev ros-robot-state-publisher rviz
  python3-rosbag python3-rostest python3-roslaunch python3-rostopic python3-rosnode python3-rosservice
  python3-nav-msgs python3-std-srvs python3-geometry-msgs python3-sensor-msgs python3-rospkg python3-tf2-ros
  rosbash libode-dev liburdfdom-dev liburdfdom-tools libopencv-dev libeigen3-dev libyaml-cpp-dev
  libgtest-dev python3-yaml python3-numpy python3-matplotlib xvfb xauth
)

log() { printf '\033[1m[sbot]\033[0m %s\n' "$*" >&2; }

deps() {
  local missing=()
  for p in "${APT_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if ((${#missing[@]})); then
    log "installing ${#missing[@]} Debian packages: ${missing[*]}"
    local sudo=""; [[ $(id -u) -ne 0 ]] && sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  fi
}

# What of the repository root belongs to the root package `swarmbot3d`. It is linked item by item:
# a link to the root itself would contain build/ws/src/swarmbot3d again, and roslaunch/rosrun, which
# walk a package's folder following links, would loop through it.
ROOT_PACKAGE_ITEMS=(package.xml CMakeLists.txt src launch config test datasets docs)

workspace() {
  mkdir -p "$WS/src"
  for p in "${PACKAGES[@]}"; do ln -sfn "$ROOT/$p" "$WS/src/$p"; done
  [[ -L "$WS/src/swarmbot3d" ]] && rm "$WS/src/swarmbot3d"
  mkdir -p "$WS/src/swarmbot3d"
  for item in "${ROOT_PACKAGE_ITEMS[@]}"; do
    [[ -e "$ROOT/$item" ]] && ln -sfn "$ROOT/$item" "$WS/src/swarmbot3d/$item"
  done
  return 0
}

build() {
  deps
  workspace
  # URDFs are generated from one parameter table; the committed files are checked by a test.
  "$PY" "$ROOT/sbot_description/scripts/generate_urdf.py" --out "$ROOT/sbot_description/urdf" --quiet
  log "building (Release) in $WS"
  (cd "$WS" && catkin_make -j"$(nproc)" -DCMAKE_BUILD_TYPE=Release -DCATKIN_ENABLE_TESTING=ON \
      -DPYTHON_EXECUTABLE="$PY" -DPython3_EXECUTABLE="$PY" ${SBOT_CMAKE_ARGS:-} >"$ROOT/build/catkin_make.log" 2>&1) \
    || { tail -n 60 "$ROOT/build/catkin_make.log"; log "build failed (full log: build/catkin_make.log)"; exit 1; }
}

ws_env() {
  set +u
  # shellcheck disable=SC1091
  source "$WS/devel/setup.bash"
  set -u
  export ROS_HOME="$ROOT/build/ros_home"
  export ROS_LOG_DIR="$ROOT/build/ros_home/log"
  mkdir -p "$ROS_LOG_DIR"
}

demo() {
  build
  ws_env
  local out="$ROOT/build/demo"
  mkdir -p "$out"
  log "running the headless swarm demo (scenario flat_swarm, 20 robots, 30 s simulated)"
  # Our own master on a free port: never assume one is running, never disturb one that is.
  local port=$((11400 + RANDOM % 500))
  export ROS_MASTER_URI="http://127.0.0.1:$port"
  # Real-time factor 2 and 20 Hz state topics: as fast as possible, rosbag on a shared 2-core
  # machine cannot keep up with 20 robots' topics and drops messages.
  roslaunch -p "$port" "$ROOT/launch/swarm.launch" headless:=true record:=true duration:=30 \
      real_time_factor:=2 publish_rate:=20 bag:="$out/demo.bag" robots:=20 >"$out/roslaunch.log" 2>&1 || true
  grep -h "simulator: " "$out/roslaunch.log" | sed -e 's/^.*simulator: /simulator: /' -e 's/\x1b\[[0-9;]*m//g' || true  # without the log's colour codes
  [[ -f "$out/demo.bag" ]] || { tail -n 40 "$out/roslaunch.log"; log "demo failed: no bag written"; exit 1; }
  "$PY" "$ROOT/src/bag_summary.py" "$out/demo.bag"
}

run_tests() {
  build
  ws_env
  log "building test binaries"
  (cd "$WS" && catkin_make -j"$(nproc)" tests >>"$ROOT/build/catkin_make.log" 2>&1) \
    || { tail -n 60 "$ROOT/build/catkin_make.log"; log "test build failed"; exit 1; }
  log "running the test suite (ctest; rostests start their own master)"
  cd "$WS/build"
  # ctest runs each gtest binary, rostest file and python test; its last line is the summary.
  ctest --output-on-failure --timeout 900 ${SBOT_CTEST_ARGS:-}
}

bench() {
  build
  ws_env
  rosrun sbot_sim sbot_bench "$@"
}

case "${1:-}" in
  deps) deps ;;
  build) build ;;
  demo) demo ;;
  test) run_tests ;;
  bench) shift; bench "$@" ;;
  shell) build; ws_env; exec bash -i ;;
  *) sed -n '2,10p' "$0"; exit 2 ;;
esac
