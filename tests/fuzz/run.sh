#!/usr/bin/env bash
# Builds tests/fuzz/fuzz_case.c with clang + libFuzzer + ASan/UBSan against
# the core and proto sources directly, seeds a corpus from examples/*.json,
# tests/data/*.msh (wrapped as gmsh parts) and a few inline documents, and
# fuzzes case_build() for FUZZ_SECONDS (default 60). Exits non-zero on a
# crash, leak or timeout; the reproducer is left in build/fuzz/.
set -euo pipefail
cd "$(dirname "$0")/../.."

seconds=${FUZZ_SECONDS:-60}
out=build/fuzz
corpus=$out/corpus
mkdir -p "$out" "$corpus"

# core/ without the OpenMP pragmas' runtime: -fopenmp is not needed for
# correctness and libFuzzer + libomp threads only slow the fuzzer down.
cflags="-std=c11 -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE -g -O1 -fno-omit-frame-pointer
        -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -Wno-unknown-pragmas"
pkg=$(pkg-config --cflags --libs jansson hdf5)
# shellcheck disable=SC2086
clang $cflags -Icore -Iproto tests/fuzz/fuzz_case.c core/*.c proto/*.c $pkg -lm \
      -o "$out/fuzz_case"

# Seeds: the bundled examples, every gmsh test file as a part, small docs.
for f in examples/*.json; do [ -e "$f" ] && cp "$f" "$corpus/"; done
for f in tests/data/*.msh; do
  [ -e "$f" ] || continue
  cp "$f" "$corpus/"
  /usr/bin/python3 - "$f" "$corpus/$(basename "$f").json" <<'PY'
import json, sys
text = open(sys.argv[1]).read()
doc = {"materials": {"m": {"density": 1000, "young": 1e9, "poisson": 0.2}},
       "parts": [{"material": "m", "gmsh": text}], "time": {"end": 0.01}}
open(sys.argv[2], "w").write(json.dumps(doc))
PY
done
cat > "$corpus/inline-rect.json" <<'JSON'
{"materials": {"m": {"density": 1000, "young": 1e9, "poisson": 0.2}},
 "parts": [{"name": "a", "material": "m", "rectangle": {"size": [1, 1], "divisions": [2, 2]}}],
 "constraints": [{"part": "a", "fix": ["x"]}, {"box": [0, 0, 1, 0], "velocity": [null, 0]}],
 "time": {"end": 0.01, "dt": "auto"}, "output": {"fields": ["stress"]}}
JSON
cat > "$corpus/inline-mesh.json" <<'JSON'
{"materials": {"r": {"density": 2700, "young": 3e10, "poisson": 0.25, "fracture":
  {"tensile_strength": 5e6, "cohesion": 2e7, "friction_angle": 30, "energy_I": 20, "energy_II": 100}}},
 "parts": [{"material": "r", "fracture": true, "mesh": {"nodes": [[0,0],[1,0],[0,1],[1,1]],
   "triangles": [[0,1,2],[1,3,2]]}}, {"material": "r", "disc": {"center": [3, 0], "radius": 1, "divisions": 12}}],
 "constraints": [{"box": [2, -2, 4, 2], "force": [1, 0]}], "gravity": [0, -9.81],
 "time": {"end": 1e-3, "dt": 1e-7, "safety": 0.9}, "output": {"interval": 1e-4}}
JSON
printf '{"time": {"end": 1e999}}' > "$corpus/inline-overflow.json"
printf '[[[[[[[[[[' > "$corpus/inline-deep.json"

status=0
"$out/fuzz_case" "$corpus" -dict=tests/fuzz/case.dict -max_total_time="$seconds" -max_len=65536 -timeout=10 \
    -rss_limit_mb=2048 -malloc_limit_mb=512 -print_final_stats=1 \
    -artifact_prefix="$out/" 2>&1 | tail -n 25 || status=$?
if [ "$status" -ne 0 ]; then
  echo "fuzz: FAILED (exit $status); reproducer in $out/" >&2
  exit "$status"
fi
echo "fuzz: no crash in ${seconds}s"
