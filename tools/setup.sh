#!/usr/bin/env bash
# Set up (or bring up to date) the development environment of EasyNav for Python:
#   .venv/ at the repository root with every package installed (editable), the ROS 2 message
#   packages built from their .msg files, and the test tools.
# Idempotent and quick when nothing changed (a stamp per step). Needs Python 3.10-3.13 and, as root,
# nothing else: every Python dependency comes from PyPI (ROS 2 Jazzy wheels included).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
VENV=$ROOT/.venv
STAMPS=$VENV/.easynav-stamps

log() { printf '\033[1m[setup]\033[0m %s\n' "$*"; }

# The interpreter: $PYTHON if given, else the first of these that is 3.10 to 3.13 (the versions
# ROS 2 Jazzy's rclpy wheels exist for).
find_python() {
  for candidate in ${PYTHON:-} python3.11 python3.12 python3.13 python3.10 python3 python; do
    if command -v "$candidate" >/dev/null 2>&1 &&
       "$candidate" -c 'import sys; sys.exit(0 if (3, 10) <= sys.version_info[:2] <= (3, 13) else 1)' 2>/dev/null; then
      command -v "$candidate"; return 0
    fi
  done
  return 1
}

# System packages: none are needed by the packages themselves. (The benchmark's optional open3d
# comparison needs libusb-1.0-0; it prints a note instead of a figure when it is missing.)

if [ ! -x "$VENV/bin/python" ]; then
  PY=$(find_python) || { echo "setup: Python 3.10 to 3.13 is required (none found; set PYTHON=...)" >&2; exit 1; }
  log "creating $VENV with $PY"
  "$PY" -m venv "$VENV"
fi
mkdir -p "$STAMPS"
# pip_install ARGS: quiet pip, without the machine's notes about absent local index folders.
pip_install() {
  "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check "$@" 2>&1 |
    { grep -v "is ignored: it is neither a file nor a directory" || true; }
  return "${PIPESTATUS[0]}"
}

hash_of() { cat "$@" 2>/dev/null | sha256sum | cut -c1-16; }

# 1. Build tools (a new venv has setuptools 65, too old for the message build).
step=$(hash_of packages/easynav-interfaces/tools/build_requirements.txt requirements-dev.txt)
if [ "$(cat "$STAMPS/tools" 2>/dev/null)" != "$step" ]; then
  log "installing build and test tools"
  pip_install --upgrade pip "setuptools>=77" wheel hatchling editables
  pip_install -r packages/easynav-interfaces/tools/build_requirements.txt -r requirements-dev.txt
  echo "$step" > "$STAMPS/tools"
fi

# 2. The ROS message packages (CMake build of .msg files; about a minute). The wheel is kept in
#    $WHEELS: the packaging tests install it into their fresh environments instead of building
#    it again.
WHEELS=$VENV/.easynav-wheels
step=$(cd packages/easynav-interfaces && find . -path ./build -prune -o -type f \
  \( -name '*.msg' -o -name 'CMakeLists.txt' -o -name 'package.xml' -o -name 'setup.py' \
  -o -name 'pyproject.toml' -o -name '*.cmake' \) -print | sort | xargs cat | sha256sum | cut -c1-16)
if [ "$(cat "$STAMPS/interfaces" 2>/dev/null)" != "$step" ] ||
   ! "$VENV/bin/python" -c 'import easynav_interfaces.msg, tf2_msgs.msg, vision_msgs.msg' 2>/dev/null; then
  log "building the ROS message packages (easynav_interfaces, tf2_msgs, vision_msgs)"
  rm -rf "$WHEELS"
  "$VENV/bin/python" -m pip wheel --quiet --disable-pip-version-check --no-deps \
    --no-build-isolation ./packages/easynav-interfaces -w "$WHEELS"
  wheel=$(ls "$WHEELS"/easynav_interfaces-*.whl)
  # Reinstalled even at the same version (the messages changed); then its dependencies.
  pip_install --force-reinstall --no-deps "$wheel"
  pip_install "$wheel"
  echo "$step" > "$STAMPS/interfaces"
fi

# 3. Every Python package, editable, with its dependencies.
step=$(hash_of packages/*/pyproject.toml)
if [ "$(cat "$STAMPS/packages" 2>/dev/null)" != "$step" ]; then
  log "installing the EasyNav packages (editable)"
  args=()
  for pkg in packages/*/; do
    name=$(basename "$pkg")
    [ "$name" = easynav-interfaces ] && continue
    # Every optional extra the test suite exercises: "all" (OMPL, GTSAM, numba, ...), "ros" (what
    # a plugin distribution needs inside the runtime) and "test".
    extras=()
    for extra in all ros test; do
      grep -q "^$extra = " "$pkg/pyproject.toml" && extras+=("$extra")
    done
    if [ ${#extras[@]} -gt 0 ]; then
      args+=(-e "$pkg[$(IFS=,; echo "${extras[*]}")]")
    else
      args+=(-e "$pkg")
    fi
  done
  pip_install --no-build-isolation "${args[@]}"
  echo "$step" > "$STAMPS/packages"
fi
log "environment ready: $VENV"
