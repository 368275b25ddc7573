#!/usr/bin/env bash
# Builds the libFuzzer harnesses with clang + ASan/UBSan against the core,
# proto and server sources they need, seeds their corpora and runs each for
# its share of FUZZ_SECONDS (default 60 in all; the case parser gets a
# half, JSON Patch a sixth, the HTTP request path a third, so CI time does
# not grow):
#   fuzz_case  case_build() and gmsh_read() on any bytes; seeds: examples,
#              tests/data/*.msh (raw and wrapped as gmsh parts), inline docs;
#   fuzz_json_patch  a document, a newline and a JSON Patch (RFC 6902): a
#              result or 422 problems, the target never changed; seeds: the
#              RFC's examples and the bundled example patch;
#   fuzz_http  a raw request: header block, framing checks, ?fields=, and the
#              body as POST /cases; seeds: inline requests.
# Exits non-zero on a crash, leak or timeout; the reproducer is left in
# build/fuzz/.
set -euo pipefail
cd "$(dirname "$0")/../.."

seconds=${FUZZ_SECONDS:-60}
case_seconds=$(( seconds / 2 > 0 ? seconds / 2 : 1 ))
patch_seconds=$(( seconds / 6 > 0 ? seconds / 6 : 1 ))
http_seconds=$(( seconds - case_seconds - patch_seconds > 0 ? seconds - case_seconds - patch_seconds : 1 ))
out=build/fuzz
corpus=$out/corpus
http_corpus=$out/corpus-http
patch_corpus=$out/corpus-json-patch
mkdir -p "$out" "$corpus" "$http_corpus" "$patch_corpus"

# core/ without the OpenMP pragmas' runtime: -fopenmp is not needed for
# correctness and libFuzzer + libomp threads only slow the fuzzer down.
cflags="-std=c11 -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE -g -O1 -fno-omit-frame-pointer
        -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -Wno-unknown-pragmas"
pkg=$(pkg-config --cflags --libs jansson hdf5 zlib)
# Every source of core/ and proto/, whatever folder it sits in, compiled
# once, two at a time, for the harnesses that link the engine: a clang call
# with them all compiles one file after another, and twice that was ~2.5
# of CI's 25 minutes.
obj=$out/obj
rm -rf "$obj"
mkdir -p "$obj"
find core proto -name '*.c' -print0 | sort -z | \
    FUZZ_CC_FLAGS="$cflags $(pkg-config --cflags jansson hdf5 zlib)" FUZZ_OBJ=$obj \
    xargs -0 -n1 -P2 sh -c \
      'clang $FUZZ_CC_FLAGS -Icore -Iproto -c "$0" -o "$FUZZ_OBJ/$(echo "${0%.c}" | tr / _).o"'
engine=$(find "$obj" -name '*.o' | sort)
# shellcheck disable=SC2086
clang $cflags -Icore -Iproto tests/fuzz/fuzz_case.c $engine $pkg -lm \
      -o "$out/fuzz_case"
# shellcheck disable=SC2086
clang $cflags -Iproto tests/fuzz/fuzz_json_patch.c proto/json/*.c $pkg -lm \
      -o "$out/fuzz_json_patch"
# shellcheck disable=SC2086
clang $cflags -Icore -Iproto -Iserver tests/fuzz/fuzz_http.c server/http/http_frame.c $engine \
      $pkg -lm -o "$out/fuzz_http"

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
if "cube" in sys.argv[1]:  # the tetrahedral files: a 3D case
    doc["dimension"] = 3
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
cat > "$corpus/inline-tets.json" <<'JSON'
{"dimension": 3, "materials": {"r": {"density": 2700, "young": 3e10, "poisson": 0.25, "fracture":
  {"tensile_strength": 5e6, "cohesion": 2e7, "friction_angle": 30, "energy_I": 20, "energy_II": 100}}},
 "parts": [{"material": "r", "fracture": true, "mesh": {"nodes": [[0,0,0],[1,0,0],[0,1,0],[0,0,1],[1,1,1]],
   "tetrahedra": [[0,1,2,3],[1,2,3,4]]}},
  {"material": "r", "sphere": {"center": [3, 0, 0], "radius": 1, "divisions": 8}, "velocity": [-1, 0, 0]},
  {"material": "r", "cylinder": {"axis": "y", "radius": 0.5, "length": 1, "divisions": [8, 1]}, "velocity": [0, 0, 1]}],
 "constraints": [{"box": [-1, -1, -1, 0.1, 2, 0.1], "fix": ["x", "z"]}, {"box": [2, -2, -2, 4, 2, 2], "force": [1, 0, 0]}],
 "gravity": [0, 0, -9.81], "time": {"end": 1e-3, "dt": 1e-7}, "output": {"interval": 1e-4}}
JSON
printf '{"time": {"end": 1e999}}' > "$corpus/inline-overflow.json"
printf '[[[[[[[[[[' > "$corpus/inline-deep.json"

# JSON Patch seeds: a document, a newline, a patch (RFC 6902 appendix A).
printf '%s\n%s' '{"foo":["bar","baz"],"a/b":1,"m~n":{"x":[1,2]}}' \
    '[{"op":"add","path":"/foo/1","value":"qux"},{"op":"remove","path":"/a~1b"},{"op":"test","path":"/m~0n/x/1","value":2.0}]' \
    > "$patch_corpus/ops"
printf '%s\n%s' '{"foo":{"bar":"baz","waldo":"fred"},"qux":{"corge":"grault"}}' \
    '[{"op":"move","from":"/foo/waldo","path":"/qux/thud"},{"op":"copy","from":"/qux","path":"/foo/-"},{"op":"replace","path":"","value":[]}]' \
    > "$patch_corpus/move-copy"
{ head -c 2000 "$corpus/inline-mesh.json" | tr -d '\n'; printf '\n'; tr -d '\n' < examples/uniaxial-compression.weaker.json-patch; } \
    > "$patch_corpus/case"

# HTTP seeds: well-formed requests and each framing the gate refuses.
body=$(cat "$corpus/inline-rect.json")
printf 'POST /cases?start=true HTTP/1.1\r\nHost: x\r\nContent-Length: %d\r\n\r\n%s' \
    "${#body}" "$body" > "$http_corpus/post-rect"
printf 'GET /cases/0123456789abcdef/state?fields=position,velocity HTTP/1.1\r\nHost: x\r\n\r\n' \
    > "$http_corpus/get-state"
printf 'POST /cases HTTP/1.1\r\nContent-Length: -1\r\n\r\n' > "$http_corpus/cl-negative"
printf 'POST /cases HTTP/1.1\r\nContent-Length: 2\r\nContent-Length: 3\r\n\r\n{}' > "$http_corpus/cl-two"
printf 'POST /cases HTTP/1.1\r\nTransfer-Encoding: identity\r\nContent-Length: 2\r\n\r\n{}' \
    > "$http_corpus/te-identity"
printf '\r\nPOST /cases HTTP/1.1\nContent-Length:\n 2\n\n{}' > "$http_corpus/folded-lf"

# run TARGET SECONDS CORPUS [extra libFuzzer flags]
run() {
  local target=$1 secs=$2 dir=$3 status=0
  shift 3
  "$out/$target" "$dir" "$@" -max_total_time="$secs" -max_len=65536 -timeout=10 \
      -rss_limit_mb=2048 -malloc_limit_mb=512 -print_final_stats=1 \
      -artifact_prefix="$out/$target-" 2>&1 | tail -n 25 || status=$?
  if [ "$status" -ne 0 ]; then
    echo "fuzz: $target FAILED (exit $status); reproducer in $out/" >&2
    exit "$status"
  fi
  echo "fuzz: $target: no crash in ${secs}s"
}
run fuzz_case "$case_seconds" "$corpus" -dict=tests/fuzz/case.dict
run fuzz_json_patch "$patch_seconds" "$patch_corpus" -dict=tests/fuzz/case.dict
run fuzz_http "$http_seconds" "$http_corpus" -dict=tests/fuzz/http.dict
