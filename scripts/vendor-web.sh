#!/usr/bin/env bash
# vendor-web.sh - refreshes the web page's two libraries under web/vendor/
# from the npm registry, at the versions pinned here, with their licences.
#
#   scripts/vendor-web.sh
#
# The page is served by the daemon with nothing fetched from another host
# (contract 6.3), so the libraries are files in the repository; this script
# is the only way they change. Bump a version here, run it, test the page
# (tests/integration/test_web.py), commit web/vendor/ with the script.
#  - three.js: the 3D view (WebGL). Its ES module build and OrbitControls;
#    OrbitControls' bare "three" import is pointed at the file beside it,
#    since the page has no import map (an inline one would need a CSP hash).
#  - uPlot: the plots; small (50 KB) and fast with 1e5 points.
set -euo pipefail
cd "$(dirname "$0")/.."

THREE_VERSION=0.187.0
UPLOT_VERSION=1.6.32

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
(cd "$work" && npm pack --silent "three@$THREE_VERSION" "uplot@$UPLOT_VERSION" >/dev/null)
mkdir -p "$work/three" "$work/uplot"
tar xzf "$work/three-$THREE_VERSION.tgz" -C "$work/three"
tar xzf "$work/uplot-$UPLOT_VERSION.tgz" -C "$work/uplot"

out=web/vendor
rm -rf "$out/three" "$out/uplot"
mkdir -p "$out/three" "$out/uplot"
t=$work/three/package
cp "$t/LICENSE" "$t/build/three.module.js" "$t/build/three.core.js" "$out/three/"
sed "s#^} from 'three';#} from './three.module.js';#" \
  "$t/examples/jsm/controls/OrbitControls.js" >"$out/three/OrbitControls.js"
grep -q "from './three.module.js'" "$out/three/OrbitControls.js" ||
  { echo "vendor-web: OrbitControls.js no longer imports 'three' as expected" >&2; exit 1; }
u=$work/uplot/package
cp "$u/LICENSE" "$u/dist/uPlot.esm.js" "$u/dist/uPlot.min.css" "$out/uplot/"

{
  echo "# What web/vendor/ holds: written by scripts/vendor-web.sh, do not edit."
  echo "three $THREE_VERSION (MIT) https://www.npmjs.com/package/three"
  echo "uplot $UPLOT_VERSION (MIT) https://www.npmjs.com/package/uplot"
  (cd "$out" && sha256sum three/* uplot/*)
} >"$out/VERSIONS.txt"
echo "vendor-web: three $THREE_VERSION and uPlot $UPLOT_VERSION in $out/"
