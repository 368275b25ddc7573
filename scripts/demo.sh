#!/usr/bin/env bash
# demo.sh - the "first five minutes" of fdemd, run by `make demo`.
#
# Starts a private daemon on a free loopback port (data in out/demo-data,
# emptied first so every demo starts clean), submits a bundled example,
# follows its progress, fetches result.h5 + result.xdmf into out/, draws a
# PNG and stops the daemon with SIGTERM, the way a user would.
#
#   scripts/demo.sh [examples/CASE.json [PLOT OPTIONS]]   (default examples/collision.json)
#
# PLOT OPTIONS go to plot_result.py as they are (--field, --component,
# --view ELEV,AZIM): a 3D result is drawn as the outside of its bodies, so
# a box with spheres in it needs --view 75,-60 to show them. OUT (default
# out) is where the files go.
set -euo pipefail
cd "$(dirname "$0")/.."

BIN=${BIN:-bin}
PYTHON=${PYTHON:-/usr/bin/python3}
EXAMPLE=${1:-examples/collision.json}
[ $# -gt 0 ] && shift
PLOT_ARGS=("$@")
OUT=${OUT:-out}
DATA=$OUT/demo-data
LOG=$OUT/demo-fdemd.log

say() { printf '\n== %s\n' "$*"; }
die() { printf 'demo: %s\n' "$*" >&2; exit 1; }

if [ ! -x "$BIN/fdemd" ] || [ ! -x "$BIN/fdemctl" ]; then die "build first: make"; fi
[ -f "$EXAMPLE" ] || die "no such example: $EXAMPLE"

rm -rf "$DATA"
mkdir -p "$DATA"

say "starting $BIN/fdemd on a free port (log: $LOG)"
# the log exists before the daemon does: the loop below may read it before
# the background shell has opened it (sed then failed the demo on a busy
# machine)
: >"$LOG"
"$BIN/fdemd" --listen 127.0.0.1:0 --data "$DATA" >>"$LOG" 2>&1 &
daemon=$!
# Whatever goes wrong below, the daemon must not outlive the demo.
trap 'kill -TERM "$daemon" 2>/dev/null || true; wait "$daemon" 2>/dev/null || true' EXIT

port=
for _ in $(seq 100); do
  port=$(sed -n 's/^listening on 127\.0\.0\.1:\([0-9][0-9]*\)$/\1/p' "$LOG" | head -n 1)
  [ -n "$port" ] && break
  kill -0 "$daemon" 2>/dev/null || { cat "$LOG" >&2; die "fdemd exited before listening"; }
  sleep 0.1
done
[ -n "$port" ] || die "fdemd did not print its port within 10 s (see $LOG)"
export FDEMD_URL="http://127.0.0.1:$port"
echo "fdemd listening at $FDEMD_URL"

name=$("$PYTHON" -c 'import json, sys; print(json.load(open(sys.argv[1])).get("name", "demo"))' "$EXAMPLE")

say "fdemctl submit $EXAMPLE --start"
id=$("$BIN/fdemctl" submit "$EXAMPLE" --start)
echo "case id: $id"

say "fdemctl wait $id"
"$BIN/fdemctl" wait "$id"

say "fdemctl status $id"
"$BIN/fdemctl" status "$id"

say "fdemctl fetch $id -o $OUT/$name.h5 --force"
"$BIN/fdemctl" fetch "$id" -o "$OUT/$name.h5" --force   # the demo replaces its own output

say "plot_result.py -> $OUT/$name.png"
"$PYTHON" clients/python/plot_result.py "$OUT/$name.h5" -o "$OUT/$name.png" ${PLOT_ARGS[@]+"${PLOT_ARGS[@]}"}
dimension=$("$PYTHON" -c 'import json, sys; print(json.load(open(sys.argv[1])).get("dimension", 2))' "$EXAMPLE")
if [ "$dimension" = 3 ] && [ ${#PLOT_ARGS[@]} -eq 0 ]; then
  echo "(3D: the outside of the bodies, seen from --view 25,-60; to look into a box from above:"
  echo " scripts/demo.sh $EXAMPLE --view 75,-60)"
fi

say "stopping fdemd (SIGTERM)"
kill -TERM "$daemon"
wait "$daemon" || die "fdemd exited with status $? on SIGTERM"
trap - EXIT

cat <<TXT

Done. Files:
  $OUT/$name.h5     the result (HDF5, layout in docs/results.md)
  $OUT/$name.xdmf   open this one in ParaView: File > Open, Apply, then play the time series
  $OUT/$name.png    the last snapshot, drawn by clients/python/plot_result.py

Read it from Python:
  /usr/bin/python3 -c "import h5py; f = h5py.File('$OUT/$name.h5'); print(f['/snapshots/time'][:])"

Run another example:  scripts/demo.sh examples/bar-wave.json
TXT
