#!/usr/bin/env bash
# The main job on a bundled scene: `povpress render` renders it adaptively
# through POV-Ray, then the result, the base pass and the error estimate are
# compared with a high-quality render of the same scene.
#
# usage: scripts/demo.sh [BUILD_DIR] [SCENE.pov] [WIDTH HEIGHT] [TARGET]
# Writes everything to BUILD_DIR/demo/ (or $DEMO_OUT): render.exr (the
# result), render.errors.exr (the error map), render.json (the report),
# work/ (the base pass and the accumulation), ref.exr (the reference: the
# scene at 15x the resolution, box-averaged, cached in ~/.cache/povpress), and
# PNG previews: render.png, base.png, samples.png (samples per pixel) and
# error.png (estimated error).
set -euo pipefail

BUILD=${1:-build}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SCENE=${2:-$ROOT/scenes/soft_shadows.pov}
W=${3:-320}
H=${4:-240}
TARGET=${5:-1e-3}
OUT="${DEMO_OUT:-$BUILD/demo}"
PP="$BUILD/povpress"
mkdir -p "$OUT"

echo "povpress render $SCENE at ${W}x$H, target relMSE $TARGET"
"$PP" render "$SCENE" -o "$OUT/render.exr" -W "$W" -H "$H" --target "$TARGET" -v \
	--report "$OUT/render.json" --workdir "$OUT/work" --keep-workdir

# The reference: the scene at 15 times the resolution with antialiasing off,
# box-averaged (225 samples per pixel; an odd scale, so that none of its
# samples falls where povpress's scales 2, 4, 8, 16 sample), cached outside
# the repository.
S=15
CACHE=${POVPRESS_CACHE:-$HOME/.cache/povpress}/demo
key=$({ echo "povpress demo reference 1 ${W}x$H s$S"; povray --version 2>&1 | head -n 1
	sha256sum <"$SCENE"; } | sha256sum | cut -c1-16)
REF="$CACHE/$(basename "$SCENE" .pov)-${W}x$H-s$S-$key.exr"
if [[ ! -f $REF ]]; then
	echo
	echo "rendering the reference once: ${S}x the resolution, no antialiasing, box-averaged"
	mkdir -p "$CACHE"
	povray -D -GA "+W$((S * W))" "+H$((S * H))" +FE -A "+O$OUT/ref-hi.exr" "+I$SCENE" \
		"+L$(dirname "$SCENE")" >"$OUT/ref.log" 2>&1 || { cat "$OUT/ref.log" >&2; exit 1; }
	"$BUILD/tools/boxdown" "$OUT/ref-hi.exr" "$S" "$OUT/ref.exr" >/dev/null
	rm -f "$OUT/ref-hi.exr"
	mv "$OUT/ref.exr" "$REF.tmp" && mv "$REF.tmp" "$REF"
fi
cp "$REF" "$OUT/ref.exr"

val() { awk -v k="$2:" '$1 == k { print $2 }' <<<"$1"; }
jget() { grep -o "\"$2\": [-0-9.e+]*" "$1" | tail -n 1 | awk '{ print $2 }'; }
final=$("$PP" compare "$OUT/render.exr" "$OUT/ref.exr")
base=$("$PP" compare "$OUT/work/base.exr" "$OUT/ref.exr")
echo
echo "against the reference:"
printf '  base pass (1 sample per pixel)   relMSE %-10s PSNR %s dB\n' \
	"$(val "$base" relmse)" "$(val "$base" psnr)"
printf '  povpress render                  relMSE %-10s PSNR %s dB\n' \
	"$(val "$final" relmse)" "$(val "$final" psnr)"
printf '  its own estimate of that relMSE  %s\n' "$(jget "$OUT/render.json" est_relmse)"
# the POV-Ray children's CPU and povpress's own process's (analyses and writes
# included)
pov_cpu=$(jget "$OUT/render.json" cpu_s)
own_cpu=$(jget "$OUT/render.json" own_cpu_s)
printf '  cost: %s CPU s (POV-Ray %s, povpress %s), %s s wall, %s samples per pixel\n' \
	"$(awk -v a="$pov_cpu" -v b="$own_cpu" 'BEGIN { printf "%.3f", a + b }')" \
	"$pov_cpu" "$own_cpu" "$(jget "$OUT/render.json" elapsed_s)" \
	"$(jget "$OUT/render.json" samples_per_pixel)"

oiiotool "$OUT/render.exr" --colorconvert linear sRGB -o "$OUT/render.png"
oiiotool "$OUT/work/base.exr" --colorconvert linear sRGB -o "$OUT/base.png"
# samples per pixel on a log scale: 1 black, 341 white
oiiotool "$OUT/render.errors.exr" --ch samples --powc 0.171 --subc 1 --divc 1.71 \
	--clamp:min=0:max=1 --ch 0,0,0 -o "$OUT/samples.png"
# estimated relative error: sqrt scaled so that 0.1 is white
oiiotool "$OUT/render.errors.exr" --ch relerror --powc 0.5 --mulc 3.16 --clamp:min=0:max=1 \
	--ch 0,0,0 -o "$OUT/error.png"
echo
echo "previews in $OUT: render.png base.png samples.png error.png"
