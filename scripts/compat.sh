#!/usr/bin/env bash
# Compatibility run: the test suite against other Blender versions, using the
# bpy wheels on PyPI (Blender as a Python module). Not part of default CI: each
# version is a ~1 GB virtual environment and a full suite run.
#
#   scripts/compat.sh                    # the LTS lines: 4.2 (= blender_version_min) and 4.5
#   scripts/compat.sh 4.2.23 5.0.1       # chosen versions
#   PYTEST_ARGS="tests/test_bad_geometry.py -q" scripts/compat.sh
#
# Environments live in $COMPAT_DIR (default ~/.cache/solidwire-compat), one
# per version, and are reused. Each run's log is $COMPAT_DIR/bpy-VERSION.log;
# a summary line per version is printed at the end. Exit status: 0 when every
# version passed.
#
# The default list must include the manifest's blender_version_min
# (tests/test_security.py checks that it does).
set -uo pipefail
cd "$(dirname "$0")/.."

VERSIONS=("$@")
if [ ${#VERSIONS[@]} -eq 0 ]; then
  VERSIONS=(4.2.23 4.5.15)
fi
PYTHON="${PYTHON:-$(command -v python3.11 || command -v python3)}"
COMPAT_DIR="${COMPAT_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/solidwire-compat}"
PYTEST_ARGS="${PYTEST_ARGS:-tests -q -p no:cacheprovider}"
mkdir -p "$COMPAT_DIR"

summary=()
status=0
for version in "${VERSIONS[@]}"; do
  venv="$COMPAT_DIR/bpy-$version"
  log="$COMPAT_DIR/bpy-$version.log"
  if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c "import bpy" >/dev/null 2>&1; then
    echo "== bpy $version: creating $venv"
    "$PYTHON" -m venv "$venv" &&
      "$venv/bin/python" -m pip install --disable-pip-version-check -q "bpy==$version" pytest hypothesis ||
      { summary+=("bpy $version: could not install"); status=1; continue; }
  fi
  blender="$("$venv/bin/python" -c 'import bpy; print(bpy.app.version_string)' 2>/dev/null | tail -n 1)"
  echo "== bpy $version (Blender $blender): pytest $PYTEST_ARGS"
  start=$(date +%s)
  # shellcheck disable=SC2086
  "$venv/bin/python" -m pytest $PYTEST_ARGS >"$log" 2>&1
  rc=$?
  result="$(grep -E '^(=+ )?[0-9]+ (passed|failed)|[0-9]+ (passed|failed|error)' "$log" | tail -n 1 | tr -d '=')"
  summary+=("bpy $version (Blender $blender): exit $rc,${result:- no result} in $(( $(date +%s) - start )) s (log: $log)")
  [ $rc -eq 0 ] || status=1
done

echo
printf '%s\n' "${summary[@]}"
exit $status
