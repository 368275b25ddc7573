#!/usr/bin/env bash
# make bench: every bench binary built from bench/*.c, then the HTTP load
# bench against the real daemon. Figures only; nothing here passes or fails
# a build. Single-threaded figures unless OMP_NUM_THREADS says otherwise.
set -u
BUILD=${BUILD:-build}
BIN=${BIN:-bin}
PYTHON=${PYTHON:-/usr/bin/python3}
cores=$(nproc --all)
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
cd "$(dirname "$0")/.."
echo "# fdemd bench on $(uname -m), $cores cores, $(date -u +%Y-%m-%dT%H:%MZ), commit $(git rev-parse --short HEAD 2>/dev/null || echo '?')"
for b in "$BUILD"/bench/*; do
  [ -x "$b" ] && [ -f "$b" ] || continue
  echo
  echo "==== $(basename "$b")"
  "$b" || echo "(exit $?)"
done
if [ -x "$BUILD/tests/mpi/rank_compare" ] && [ -x "$BUILD/bench/mpi/bench_partition" ]; then
  echo
  echo "==== bench/mpi/run.sh (the engine on MPI ranks)"
  BUILD="$BUILD" PYTHON="$PYTHON" bash bench/mpi/run.sh || echo "(exit $?)"
fi
echo
echo "==== bench_http.py"
FDEMD_BIN="$BIN/fdemd" "$PYTHON" bench/bench_http.py || echo "(exit $?)"
