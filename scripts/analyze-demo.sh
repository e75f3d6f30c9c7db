#!/usr/bin/env bash
# Render a bundled scene at low quality through POV-Ray, analyse it with
# povpress, and compare both the render and its reconstruction with a
# high-quality render of the same scene.
#
# usage: scripts/analyze-demo.sh [BUILD_DIR] [SCENE.pov] [WIDTH HEIGHT]
# Writes everything to BUILD_DIR/analyze-demo/ (or $DEMO_OUT): base.exr (the render), analysis.exr,
# ref.exr (the reference), and PNG previews of the render, the
# reconstruction, the error maps (without and with the +Q1 feature pass)
# and the order map.
set -euo pipefail

BUILD=${1:-build}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SCENE=${2:-$ROOT/scenes/soft_shadows.pov}
W=${3:-320}
H=${4:-240}
OUT="${DEMO_OUT:-$BUILD/analyze-demo}"
mkdir -p "$OUT"

render() { # OUTPUT [POV-Ray options...]
	local o=$1
	shift
	povray -D -GA +WT1 "+W$W" "+H$H" +FE "+O$o" "+I$SCENE" "+L$(dirname "$SCENE")" "$@" \
		>"$o.log" 2>&1 || { cat "$o.log" >&2; exit 1; }
}

echo "rendering $SCENE at ${W}x$H (low quality)"
render "$OUT/base.exr"
echo "rendering the reference (area light 16x16, antialiasing +AM2 +A0.01 +R3)"
render "$OUT/ref.exr" Declare=AreaN=16 +AM2 +A0.01 +R3 +J
echo "rendering the +Q1 feature pass (quick colours: noise-free texture and geometry)"
render "$OUT/features.exr" +Q1
echo "analysing, without and with features"
"$BUILD/povpress" analyze "$OUT/base.exr" -o "$OUT/analysis.exr" -v
"$BUILD/povpress" analyze "$OUT/base.exr" --features "$OUT/features.exr" \
	-o "$OUT/analysis-features.exr" -v

echo
echo "render against the reference, and how well each error map predicts its error:"
"$BUILD/povpress" compare "$OUT/base.exr" "$OUT/ref.exr" --analysis "$OUT/analysis.exr" |
	sed 's/^/  /'
"$BUILD/povpress" compare "$OUT/base.exr" "$OUT/ref.exr" --analysis "$OUT/analysis-features.exr" |
	sed -n 's/^\(est_relmse\|capture20\):/  with features, \1:/p'
echo "reconstruction against the reference (without, with features):"
"$BUILD/povpress" compare "$OUT/analysis.exr" "$OUT/ref.exr" | sed 's/^/  /'
"$BUILD/povpress" compare "$OUT/analysis-features.exr" "$OUT/ref.exr" | sed 's/^/  /'

oiiotool "$OUT/base.exr" --colorconvert linear sRGB -o "$OUT/base.png"
oiiotool "$OUT/analysis.exr" --ch R,G,B --colorconvert linear sRGB -o "$OUT/reconstruction.png"
# error map: sqrt(error) scaled so that an RMS error of 0.1 is white
oiiotool "$OUT/analysis.exr" --ch error --powc 0.5 --mulc 10 --clamp:min=0:max=1 \
	--ch 0,0,0 -o "$OUT/error.png"
oiiotool "$OUT/analysis-features.exr" --ch error --powc 0.5 --mulc 10 --clamp:min=0:max=1 \
	--ch 0,0,0 -o "$OUT/error-features.png"
oiiotool "$OUT/analysis.exr" --ch order --mulc 0.5 --ch 0,0,0 -o "$OUT/order.png"
echo
echo "previews in $OUT: base.png reconstruction.png error.png error-features.png order.png"
