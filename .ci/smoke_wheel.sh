#!/usr/bin/env bash
# The wheel a user installs (issue 31): build it, install it with no extras into a clean venv (not
# the source tree), check the package data is in it, and run the core commands from outside the
# source tree.  The first command meets an empty numba cache, as on a fresh install: it must say
# in one line that the kernels compile in the background and answer on the Python engine; the
# background compilation is then stopped (the tests need the cores) and the other commands run on
# the Python engine (SPATIALMECH_PURE=1: the wheel is under test here, not the compiler).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT="$PWD"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
"${PYTHON:-.venv/bin/python}" -m build --wheel --outdir "$WORK/dist" . >"$WORK/build.log" 2>&1 \
  || { cat "$WORK/build.log"; exit 1; }
WHEEL="$(ls "$WORK"/dist/spatialmech-*-py3-none-any.whl)"   # pure: py3-none-any
# Package data in the wheel: catalog data, JSON schemas, the studio's static files, py.typed.
for f in spatialmech/catalog/data/five_cs.json spatialmech/interfaces/schemas/fk.schema.json \
         spatialmech/interfaces/studio/static/index.html spatialmech/py.typed; do
  python3 -c "import sys, zipfile; sys.exit(sys.argv[2] not in zipfile.ZipFile(sys.argv[1]).namelist())" "$WHEEL" "$f" \
    || { echo "smoke: $f is missing from $WHEEL" >&2; exit 1; }
done
python3 -m venv "$WORK/venv"
"$WORK/venv/bin/pip" install -q "$WHEEL"
SM="$WORK/venv/bin/spatialmech"
cd "$WORK"   # not the source tree
"$SM" --version | grep -q "spatialmech, version" 
export NUMBA_CACHE_DIR="$WORK/numba-cache"; mkdir -p "$NUMBA_CACHE_DIR"
"$SM" fk four-sps-cu --actuators 0.2167,0.2390,0.2273,0.2069 --all 2>"$WORK/first.err" >/dev/null
grep -q "compiling in the background" "$WORK/first.err" || { cat "$WORK/first.err"; echo "smoke: no first-run line" >&2; exit 1; }
for lock in "$NUMBA_CACHE_DIR"/spatialmech-kernels-*.lock; do
  [ -e "$lock" ] && kill -- "-$(head -n1 "$lock")" 2>/dev/null || true
done
export SPATIALMECH_PURE=1
"$SM" mobility four-sps-cu >/dev/null
"$SM" ik four-sps-cu --xyz 0 0 0.12 --euler ZYX 34.38 -5.73 11.46 --json >/dev/null
"$SM" fk rssr --actuators 30 --all >/dev/null
"$SM" defects five-cs-1 --json >/dev/null
"$SM" synth rccc --json >/dev/null
# an extra that is not installed: one line naming it, exit code 2, nothing written (the viewer:
# plot; a CAD export: cad); in Python, the notebook widget: a MissingExtraError naming notebook
for cmd in "view four-sps-cu --out v.html:plot" "export rssr part.stl:cad"; do
  extra="${cmd##*:}"
  set +e; "$SM" ${cmd%:*} 2>"$WORK/extra.err"; rc=$?; set -e
  [ "$rc" -eq 2 ] && grep -q "pip install 'spatialmech\[$extra\]'" "$WORK/extra.err" && [ ! -e v.html ] \
    && [ -z "$(ls part.* 2>/dev/null)" ] \
    || { cat "$WORK/extra.err"; echo "smoke: a missing extra must exit 2 naming it ($cmd: got $rc)" >&2; exit 1; }
done
"$WORK/venv/bin/python" -c "
import spatialmech as sm
from spatialmech.errors import MissingExtraError
try:
    sm.studio('rssr')
except MissingExtraError as e:
    assert e.extra == 'notebook', e
else:
    raise SystemExit('smoke: sm.studio without anywidget did not name the notebook extra')
"
echo "smoke: the wheel $(basename "$WHEEL") installs with no extras and runs the core commands"
cd "$ROOT"
