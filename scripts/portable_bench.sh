#!/usr/bin/env bash
# Pack the benchmarks' runtime — this checkout's Python 3.11, bpy 5.0.1 and
# numpy from .venv — into one relocatable tarball, for another Linux x86-64
# machine (a GPU machine, say) whose own Python is another version: bpy
# 5.0.1 exists for Python 3.11 alone. What a benchmark never loads is left
# out (Cycles' GPU kernels, the USD and OpenImageIO Python modules, the CJK
# font, OpenImageDenoise's device back-ends), every shared object is
# stripped, and the system libraries bpy and Python's own modules link
# beyond the C library are carried along (not OpenGL's: the other machine
# needs its own, libEGL.so.1 and libGL.so.1 from glvnd).
#
#   scripts/portable_bench.sh build/portable-bench.tar.xz [PART_MB]
#
# On the other machine, from a checkout of the same commit:
#
#   mkdir -p ../portable && tar xf portable-bench.tar.xz -C ../portable && . ../portable/env.sh
#   PYTHONPATH=$PWD:$PYTHONPATH $PY -m scripts.bench_regions
#
# (About 220 MB with xz -9; packing takes several minutes on two cores.)
# With PART_MB, the tarball is also cut into OUT.part00, OUT.part01, ... of
# at most that many MiB each, for a transfer that limits what one copy may
# carry (a remote machine lent with, say, 64 MiB a call: the parts already
# sent stay there between calls). OUT.sha256 holds the whole tarball's
# checksum; there, join and check before unpacking:
#
#   cat portable-bench.tar.xz.part* > portable-bench.tar.xz && sha256sum -c portable-bench.tar.xz.sha256
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:?usage: scripts/portable_bench.sh OUT.tar.xz [PART_MB]}
part_mb=${2:-}
[[ -z $part_mb || $part_mb =~ ^[1-9][0-9]*$ ]] || { echo "error: PART_MB must be a whole number of MiB, not '$part_mb'" >&2; exit 1; }
site=.venv/lib/python3.11/site-packages
[ -d "$site/bpy" ] || { echo "error: no bpy in .venv (run: make venv)" >&2; exit 1; }
python=$(.venv/bin/python -c 'import sys; print(sys.base_prefix)')

stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/py/bin" "$stage/py/lib" "$stage/site" "$stage/xlib"
cp "$python/bin/python3.11" "$stage/py/bin/"
cp -L "$python"/lib/libpython3.11.so.1.0 "$stage/py/lib/" 2>/dev/null || true
(cd "$python/lib" && tar cf - --exclude=site-packages --exclude=test --exclude=idlelib --exclude=tkinter \
  --exclude=turtledemo --exclude=ensurepip --exclude=lib2to3 --exclude=__pycache__ --exclude='config-3.11*' \
  python3.11) | tar xf - -C "$stage/py/lib"
cp -a "$site/bpy" "$site/numpy" "$site/numpy.libs" "$stage/site/"
bpy=$stage/site/bpy
version=$(ls "$bpy" | grep -E '^[0-9]+\.[0-9]+$')
rm -rf "$bpy"/lib/libOpenImageDenoise_device_* "$bpy/$version/scripts/addons_core/cycles/lib" \
  "$bpy/$version/python/lib/python3.11/site-packages"/{pxr,MaterialX,OpenImageIO,oslquery,openvdb*} \
  "$bpy/lib/usd" "$bpy/$version/datafiles/fonts/Noto Sans CJK Regular.woff2"

# System libraries beyond the C runtime that bpy and Python's modules load;
# not OpenGL's dispatch libraries either, which must be the other machine's
# own, matching its driver.
core='^(libc|libm|libdl|libpthread|librt|libutil|libresolv|ld-linux-x86-64|libgcc_s|libstdc\+\+|libGL|libGLX|libGLdispatch|libEGL|libOpenGL)\.so'
{ ldd "$bpy/__init__.so"; ldd "$stage"/py/lib/python3.11/lib-dynload/*.so; } 2>/dev/null |
  awk '$2 == "=>" && $3 ~ /^\/(usr\/)?lib/ {print $1, $3}' | sort -u |
  while read -r name path; do
    [[ $name =~ $core ]] || cp -L "$path" "$stage/xlib/$name"
  done
find "$stage" -name '*.so*' -type f -exec strip --strip-unneeded {} + 2>/dev/null || true

cat > "$stage/env.sh" <<'EOF'
# Source from the unpacked folder: sets PY and the paths it needs.
B=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
export PYTHONHOME=$B/py PYTHONPATH=$B/site PYTHONNOUSERSITE=1
export LD_LIBRARY_PATH=$B/py/lib:$B/xlib:$B/site/bpy/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
unset VIRTUAL_ENV
PY=$B/py/bin/python3.11
EOF
# Checked here, as the other machine will run it, before the long pack.
(. "$stage/env.sh" && cd "$stage" && "$PY" -c 'import bpy, numpy' 2>/dev/null) ||
  { echo "error: the packed runtime does not import bpy" >&2; exit 1; }
mkdir -p "$(dirname "$out")"
tar cf - -C "$stage" env.sh py xlib site | xz -9 -T0 > "$out"
(cd "$(dirname "$out")" && sha256sum "$(basename "$out")" > "$(basename "$out").sha256")
echo "$out: $(du -h "$out" | cut -f1)"
if [[ -n $part_mb ]]; then
  rm -f "$out".part[0-9]*
  split -b "${part_mb}M" -d -a 2 "$out" "$out.part"
  echo "$(ls "$out".part[0-9]* | wc -l) parts of at most $part_mb MiB: $out.part00 ..."
fi
