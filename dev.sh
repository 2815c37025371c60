#!/usr/bin/env bash
# One entry point for a new user: sets up .venv (and, as root, the Debian
# packages) on first use, then runs what was asked.
#   ./dev.sh demo [args]   headless simulator + controller, summary and video
#   ./dev.sh test [args]   the test suite (pytest); no args: every tier, then the tiers where
#                          the robot's name matters as robot miro02; -m unit: the quick tier
#   ./dev.sh bench         simulator, detection and scenario benchmarks
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
  [ ${#want[@]} -eq 0 ] && return 0
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    if sudo -n true 2>/dev/null; then sudo="sudo"; else
      say "missing Debian packages: ${want[*]}"
      say "install them with: sudo apt-get install -y --no-install-recommends ${want[*]}"
      say "(without libegl1/libgl1-mesa-dri the simulator falls back to the slower TinyRenderer)"
      say "(without chromium the browser tests of miro_gui are skipped)"
      say "(without bubblewrap the grader runs only trusted code, with --unsandboxed)"
      return 0
    fi
  fi
  say "installing Debian packages: ${want[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${want[@]}" >/dev/null
}

setup() {
  system_packages
  local stamp="$VENV/.installed"
  if [ ! -f "$stamp" ] || [ setup.py -nt "$stamp" ]; then
    say "creating $VENV and installing miro_ball with ROS 2 Jazzy wheels"
    python3 -m venv "$VENV"
    "$PY" -m pip install -q --upgrade pip
    "$PY" -m pip install -q -e '.[ros,test,scale]'
    touch "$stamp"
  fi
}

cmd=${1:-help}
[ $# -gt 0 ] && shift
case "$cmd" in
  setup) setup ;;
  demo) setup; exec "$PY" -m miro_ball.demo "$@" ;;
  test) setup
    if [ $# -gt 0 ]; then exec "$PY" -m pytest "$@"; fi
    # Every tier, then again under another robot name (the MDK's multi-robot convention)
    # wherever a robot's name is used, so that no test or node leans on the default name.
    "$PY" -m pytest
    MIRO_ROBOT_NAME=miro02 exec "$PY" -m pytest -q -m 'not unit' ;;
  bench) setup; exec "$PY" -m miro_ball.bench.sim_bench "$@" ;;
  soak) setup; exec "$PY" -m miro_ball.bench.soak "$@" ;;
  *) sed -n '2,9p' "$0"; exit 2 ;;
esac
