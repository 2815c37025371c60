#!/usr/bin/env bash
# One entry point for a new user: sets up .venv (and, as root, the Debian
# packages) on first use, then runs what was asked.
#   ./dev.sh lab [args]    the lab, headless: simulator + controller, summary and video
#   ./dev.sh test [args]   the test suite (pytest); no args: every tier once, three test files
#                          at a time, as robot miro02; -m unit: the quick tier
#   ./dev.sh bench         simulator, detection and scenario benchmarks
#   ./dev.sh speed [args]  the simulator side by side with the previous landing (.ci/landed)
#   ./dev.sh soak [args]   long free run: memory, open files, speed per minute (--minutes N)
#   ./dev.sh setup         only the set-up
set -euo pipefail
cd "$(dirname "$0")"
VENV=${VENV:-.venv}
PY="$VENV/bin/python"

say() { printf '[dev.sh] %s\n' "$*" >&2; }

have_egl() { compgen -G '/usr/lib/*/libEGL.so.1' >/dev/null && compgen -G '/usr/lib/*/dri/swrast_dri.so' >/dev/null; }

system_packages() {
  local want=()
  python3 -c 'import ensurepip' 2>/dev/null || want+=(python3-venv)
  have_egl || want+=(libegl1 libgl1-mesa-dri)
  command -v chromium >/dev/null || want+=(chromium)  # the GUI's browser tests
  command -v bwrap >/dev/null || want+=(bubblewrap)  # the grader's sandbox
  # miro2_msg and tf2_msgs are compiled at set-up (python -m miro_ball.build_interfaces)
  local tool
  for tool in gcc g++ cmake make; do command -v $tool >/dev/null || want+=($tool); done
  python3 -c 'import sysconfig, os, sys; sys.exit(not os.path.isfile(os.path.join(sysconfig.get_paths()["include"], "Python.h")))' \
    || want+=(python3-dev)
  [ ${#want[@]} -eq 0 ] && return 0
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    if sudo -n true 2>/dev/null; then sudo="sudo"; else
      say "missing Debian packages: ${want[*]}"
      say "install them with: sudo apt-get install -y --no-install-recommends ${want[*]}"
      say "(without libegl1/libgl1-mesa-dri the simulator falls back to the slower TinyRenderer)"
      say "(without chromium the browser tests of miro_gui are skipped)"
      say "(without bubblewrap the grader runs only trusted code, with --unsandboxed)"
      say "(without gcc, g++, cmake, make, python3-dev there is no miro2_msg and no tf2_msgs)"
      return 0
    fi
  fi
  say "installing Debian packages: ${want[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${want[@]}" >/dev/null
}

# setup [EXTRAS]: the venv with miro_ball and the ROS 2 wheels; EXTRAS (e.g. test,cluster) for
# the tests' tools. A student's set-up leaves them out: Ray and Playwright are most of a
# full venv's size.
setup() {
  system_packages
  local extras="ros,msgs${1:+,$1}"
  local stamp="$VENV/.installed-${extras//,/-}"
  if [ ! -f "$stamp" ] || [ setup.py -nt "$stamp" ]; then
    say "installing miro_ball[$extras] with ROS 2 Jazzy wheels into $VENV"
    [ -x "$PY" ] || python3 -m venv "$VENV"
    "$PY" -m pip install -q --upgrade pip
    # setuptools says "Editable installation ... be careful with folders ... with the same
    # name as your package" as a warning on every editable install: filtered, nothing else.
    PYTHONWARNINGS="${PYTHONWARNINGS:+$PYTHONWARNINGS,}ignore:Editable installation" \
      "$PY" -m pip install -q -e ".[$extras]"
    touch "$stamp"
  fi
  # MiRo's messages: built once, again only when their sources change (a second or less
  # otherwise); without a compiler it says what is missing and the rest runs.
  "$PY" -m miro_ball.build_interfaces || say "going on without miro2_msg/tf2_msgs"
}

cmd=${1:-help}
[ $# -gt 0 ] && shift
case "$cmd" in
  setup) setup ;;
  lab) setup; exec "$PY" -m miro_ball.lab "$@" ;;
  test) setup test,scale
    if [ $# -gt 0 ]; then exec "$PY" -m pytest "$@"; fi
    # Every tier once, under a robot name other than the default (the MDK's multi-robot
    # convention), so that no test or node leans on the name 'miro'; a test file's tests
    # run in one process (each on a ROS domain of its own), TEST_JOBS files at a time: three
    # on two cores, as the tests wait on processes and discovery about as much as they compute.
    MIRO_ROBOT_NAME=miro02 exec "$PY" -m pytest -n "${TEST_JOBS:-3}" --dist loadfile \
      --durations=15 ;;
  bench) setup; exec "$PY" -m miro_ball.bench.sim_bench "$@" ;;
  speed) setup; exec "$PY" -m miro_ball.bench.sim_bench --against landed --cases egl \
      --runs 5 --seconds 20 --batches 0 "$@" ;;
  soak) setup; exec "$PY" -m miro_ball.bench.soak "$@" ;;
  *) sed -n '2,10p' "$0"; exit 2 ;;
esac
