#!/usr/bin/env bash
# Runs every unit-test binary, then (unless UNIT_ONLY=1) the integration
# tests against the real daemon, and closes with "N passed, N failed".
# Each test prints "PASS name" or "FAIL name"; this script only counts them.
set -u
BUILD=${BUILD:-build}
BIN=${BIN:-bin}
PYTHON=${PYTHON:-/usr/bin/python3}
log=$(mktemp)
status=0

for t in "$BUILD"/tests/test_*; do
  [ -x "$t" ] || continue
  echo "== $(basename "$t")"
  if ! "$t" 2>&1 | tee -a "$log"; then status=1; fi
  [ "${PIPESTATUS[0]}" -ne 0 ] && status=1
done

if [ "${UNIT_ONLY:-0}" != 1 ] && [ -d tests/integration ]; then
  echo "== integration"
  if ! FDEMD_BIN="$BIN/fdemd" FDEMCTL_BIN="$BIN/fdemctl" "$PYTHON" tests/integration/run.py 2>&1 | tee -a "$log"; then
    status=1
  fi
  [ "${PIPESTATUS[0]}" -ne 0 ] && status=1
fi

passed=$(grep -c '^PASS ' "$log" || true)
failed=$(grep -c '^FAIL ' "$log" || true)
rm -f "$log"
[ "$failed" -ne 0 ] && status=1
[ "$passed" -eq 0 ] && status=1
echo
echo "$passed passed, $failed failed"
exit $status
