#!/usr/bin/env bash
# bench/mpi/run.sh - the rank engine's figures (issue 37 item 5), run by
# bench/run.sh when mpicc built them: one and two ranks taking turns on a
# 1e6-element 2D elastic block, a 384k-tetrahedron 3D elastic box (both
# take the split update: border forces only) and a 2D contact pile (the
# replicated update; its discs do not touch yet in the first steps), then
# a pile in contact (900 discs packed a hair apart, neighbours closing at
# 2 m/s: 6-10 k touching pairs a step, the contact walk split between the
# ranks) stepped from its step-180 checkpoint (the machine's load
# printed before each run: on a loaded machine the ratio means little),
# the bytes each rank sends a step, the halo and peak memory per element;
# then METIS on the element dual graph at 2-64 parts (bench_partition.c),
# 1e6 elements and, with 16 GB free, 1e7. Figures only.
set -u
BUILD=${BUILD:-build}
PYTHON=${PYTHON:-/usr/bin/python3}
exe=$BUILD/tests/mpi/rank_compare
STEPS=${RANK_BENCH_STEPS:-20}
ROUNDS=${RANK_BENCH_ROUNDS:-3}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl=self,vader
export OMPI_MCA_btl_vader_single_copy_mechanism=none OMPI_MCA_mpi_yield_when_idle=1
export OMP_NUM_THREADS=1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$PYTHON" - "$tmp" <<'PY'
import json, sys
out = sys.argv[1]
rock = {"density": 2000, "young": 1e8, "poisson": 0.25, "friction": 0.4}
block = {"name": "block-1e6", "materials": {"rock": rock},
         "parts": [{"name": "block", "material": "rock",
                    "rectangle": {"origin": [0, 0], "size": [1, 1], "divisions": [708, 708]},
                    "velocity": [1.0, 0.5]}],
         "time": {"end": 1, "dt": "auto", "safety": 0.5}}
parts = [{"name": "floor", "material": "wall",
          "rectangle": {"origin": [-0.05, -0.05], "size": [2.35, 0.05], "divisions": [47, 1]}}]
for i in range(30):
    for j in range(30):
        parts.append({"name": "d%d-%d" % (i, j), "material": "rock",
                      "disc": {"center": [0.04 + 0.0755 * i, 0.04 + 0.0755 * j],
                               "radius": 0.037, "divisions": 24}})
box = {"name": "box-384k", "dimension": 3, "materials": {"rock": rock},
       "parts": [{"name": "box", "material": "rock",
                  "box": {"origin": [0, 0, 0], "size": [1, 1, 1], "divisions": [40, 40, 40]},
                  "velocity": [1.0, 0.5, 0.2]}],
       "time": {"end": 1, "dt": "auto", "safety": 0.5}}
pile = {"name": "pile", "materials": {"rock": dict(rock, damping=0.2), "wall": rock},
        "parts": parts, "gravity": [0, -9.81],
        "time": {"end": 1, "dt": "auto", "safety": 0.5}}
packed = [parts[0]]
for i in range(30):
    for j in range(30):
        packed.append({"name": "d%d-%d" % (i, j), "material": "rock",
                       "disc": {"center": [0.0372 + 0.0742 * i, 0.0372 + 0.0742 * j],
                                "radius": 0.037, "divisions": 24},
                       "velocity": [1.0 if i % 2 == 0 else -1.0, -1.0 if j % 2 == 0 else 1.0]})
contact = dict(pile, name="pile-contact", parts=packed)
for name, doc in (("block", block), ("box", box), ("pile", pile), ("pile-contact", contact)):
    with open("%s/%s.json" % (out, name), "w") as f:
        json.dump(doc, f)
PY
for c in block box pile; do
  echo "-- $c: $STEPS steps, ranks 1 and 2 taking turns, $ROUNDS rounds"
  for r in $(seq "$ROUNDS"); do
    for n in 1 2; do
      echo "load $(cut -d' ' -f1-3 /proc/loadavg)"
      mpirun -np "$n" --oversubscribe "$exe" "$STEPS" "$STEPS" --figures "$tmp/$c.json" 2>&1 |
        grep -E "^figures|^rank [0-9]+:|failed"
    done
  done
done
# the pile in contact from step 180 (contact from step ~170), one process
"$exe" 180 180 --plain --save-at 180 "$tmp/pile-contact-180.bin" "$tmp/pile-contact.json" >/dev/null
# Two windows: the first 20 steps after the restore, and 100. The restore's
# first step rebuilds the near list and walks every pair (5-7 ms, 2-3 times
# a quiet step, replicated on every rank in part): a fifth of the 20 steps'
# time on 2 ranks, where a running pile rebuilds its list once in 200-400
# steps. The 100 steps are the steady figure (issue 37's goal), the 20 the
# row as it was first printed.
for window in $STEPS ${RANK_BENCH_PILE_STEPS:-100}; do
  end=$((180 + window))
  echo "-- pile-contact: $window steps from step 180, ranks 1 and 2 taking turns, $ROUNDS rounds"
  for r in $(seq "$ROUNDS"); do
    for n in 1 2; do
      echo "load $(cut -d' ' -f1-3 /proc/loadavg)"
      mpirun -np "$n" --oversubscribe "$exe" "$end" "$end" --figures \
        --restore "$tmp/pile-contact-180.bin" "$tmp/pile-contact.json" 2>&1 |
        grep -E "^figures|^rank [0-9]+:|^stages|failed"
    done
  done
done
echo "-- METIS on the element dual graph"
if [ ! -x "$BUILD/bench/mpi/bench_partition" ]; then
  echo "bench_partition is not built: make bench builds it (make mpi does not)"
  exit 0
fi
"$BUILD/bench/mpi/bench_partition" 1e6
free_kb=$(awk '/MemAvailable/ {print $2}' /proc/meminfo)
if [ "${free_kb:-0}" -gt 16000000 ]; then
  "$BUILD/bench/mpi/bench_partition" 1e7
else
  echo "1e7: skipped, under 16 GB available"
fi
