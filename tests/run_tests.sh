#!/usr/bin/env bash
# Runs every unit-test binary, then (unless UNIT_ONLY=1) the integration
# tests against the real daemon, and closes with "N passed, N failed".
# Each test prints "PASS name" or "FAIL name" (or "SKIP name (why)", which
# is reported but never counted as passed); this script only counts them.
set -u
BUILD=${BUILD:-build}
BIN=${BIN:-bin}
PYTHON=${PYTHON:-/usr/bin/python3}
log=$(mktemp)
status=0
# OpenMP threads that wait at a barrier spin by default. On a loaded machine
# (CI shares one) the thread they wait for is often descheduled, and the
# spinning burnt the CPU it needed: the 2D Brazilian disc test took 137 s of
# CPU and 247 s of wall time under load 16, against 7.5 s and 12 s with
# passive waiting. The results are the same bits either way.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}

# The source tree's folders form no circle (issue 31): cheap, so first.
echo "== layout"
for args in --self-test "--objects $BUILD"; do
  # shellcheck disable=SC2086
  if ! "$PYTHON" scripts/check_layout.py $args 2>&1 | tee -a "$log"; then status=1; fi
done

# Unit binaries run TEST_JOBS at a time (default: the cores), longest
# first so the pool ends together, each into a file of its own; they are
# then printed in name order as if run one by one. One at a time, the unit
# stage took 427 s of CI's 25 minutes under ASan on 2 cores (test_fracture
# alone 111 s) with one core idle. Each binary is single-threaded unless it
# asks for threads, and writes only under its own mkdtemp directory.
unit_out=$(mktemp -d)
jobs=${TEST_JOBS:-$(nproc 2>/dev/null || echo 1)}
longest="test_fluid_kgd test_fluid_penny test_excavation test_fracture test_contact test_groups test_joint_slip"
ordered=()
for name in $longest; do [ -x "$BUILD/tests/$name" ] && ordered+=("$BUILD/tests/$name"); done
for t in "$BUILD"/tests/test_*; do
  [ -x "$t" ] || continue
  case " $longest " in *" $(basename "$t") "*) continue ;; esac
  ordered+=("$t")
done
running=0
for t in "${ordered[@]}"; do
  name=$(basename "$t")
  (
    t0=$(date +%s)
    "$t" > "$unit_out/$name.out" 2>&1
    echo $? > "$unit_out/$name.rc"
    echo $(( $(date +%s) - t0 )) > "$unit_out/$name.s"
  ) &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then wait -n; running=$((running - 1)); fi
done
wait
for t in "$BUILD"/tests/test_*; do
  [ -x "$t" ] || continue
  name=$(basename "$t")
  echo "== $name"
  tee -a "$log" < "$unit_out/$name.out"
  [ "$(cat "$unit_out/$name.rc" 2>/dev/null || echo 1)" -ne 0 ] && status=1
  echo "   ($name: $(cat "$unit_out/$name.s" 2>/dev/null || echo '?') s)"
done
rm -rf "$unit_out"

if [ "${UNIT_ONLY:-0}" != 1 ] && [ -d tests/integration ]; then
  echo "== integration"
  t0=$(date +%s)
  # modules in $jobs processes side by side (tests/integration/run.py)
  if ! INTEGRATION_JOBS=${INTEGRATION_JOBS:-$jobs} FDEMD_BIN="$BIN/fdemd" FDEMCTL_BIN="$BIN/fdemctl" \
       "$PYTHON" tests/integration/run.py 2>&1 | tee -a "$log"; then
    status=1
  fi
  [ "${PIPESTATUS[0]}" -ne 0 ] && status=1
  echo "   (integration: $(( $(date +%s) - t0 )) s)"
fi

passed=$(grep -c '^PASS ' "$log" || true)
failed=$(grep -c '^FAIL ' "$log" || true)
skipped=$(grep -c '^SKIP ' "$log" || true)
rm -f "$log"
[ "$failed" -ne 0 ] && status=1
[ "$passed" -eq 0 ] && status=1
echo
if [ "$skipped" -ne 0 ]; then echo "($skipped skipped: see the SKIP lines above)"; fi
echo "$passed passed, $failed failed"
exit $status
