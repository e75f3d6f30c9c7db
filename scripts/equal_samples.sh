#!/usr/bin/env bash
# The render loop against uniform resolution scaling at equal samples per
# pixel, which, unlike CPU time, does not vary from run to run: for each
# scene at 80x60, `povpress render --target 1e-3 --jobs 4 -- +WT1` (one
# POV-Ray thread: the same samples every run), its samples per pixel, its
# relMSE and estimate, and the relMSE uniform scaling s = 1..10 would reach
# with that many samples (interpolated in log-log between the two nearest
# scales).  References: the scale-25 ones tests/render.sh caches (run
# `make check` first).
#
# usage: scripts/equal_samples.sh [BUILD_DIR] [SCENE_NAME...]
set -euo pipefail
BUILD=${1:-build}
shift || true
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PP="$BUILD/povpress"
BOXDOWN="$BUILD/tools/boxdown"
CACHE=${POVPRESS_CACHE:-$HOME/.cache/povpress}/testref
W=80
H=60
T=$(mktemp -d "${TMPDIR:-/tmp}/povpress-eqs.XXXXXX")
trap 'rm -rf "$T"' EXIT
names=("$@")
((${#names[@]})) || names=(soft_shadows focal_blur glossy_reflection media thin_geometry
	hdr_highlights horizon_texture radiosity_room)
relmse() { "$PP" compare "$1" "$2" | awk '$1 == "relmse:" { print $2 }'; }

printf '%-18s %7s %10s %10s %7s %9s\n' scene spp povpress uniform ratio est/true
for name in "${names[@]}"; do
	scene="$ROOT/scenes/$name.pov"
	ref=$(ls "$CACHE/$name-${W}x$H-j15-"*.exr 2>/dev/null | head -n 1)
	[[ -n $ref ]] || { echo "equal_samples: no reference for $name (run make sweep)" >&2; exit 1; }
	: >"$T/uni"
	for s in 1 2 3 4 5 6 7 8 9 10; do
		povray -D -GA +FE -A +WT1 +W$((s * W)) +H$((s * H)) "+I\"$scene\"" \
			"+L\"$ROOT/scenes\"" "+O\"$T/u.exr\"" 2>/dev/null
		"$BOXDOWN" "$T/u.exr" "$s" "$T/ud.exr" >/dev/null
		echo "$((s * s)) $(relmse "$T/ud.exr" "$ref")" >>"$T/uni"
	done
	"$PP" render "$scene" -o "$T/o.exr" -W $W -H $H --target 1e-3 -q --report "$T/r.json" \
		--jobs 4 -- +WT1
	spp=$(grep -o '"samples_per_pixel": [0-9.e+]*' "$T/r.json" | awk '{ print $2 }')
	est=$(grep -o '"est_relmse": [0-9.e+-]*' "$T/r.json" | tail -n 1 | awk '{ print $2 }')
	ours=$(relmse "$T/o.exr" "$ref")
	uni=$(awk -v q="$spp" '{ x[NR] = log($1); y[NR] = log($2) }
		END { lq = log(q)
			for (i = 1; i < NR; i++) if (lq >= x[i] && lq <= x[i + 1]) {
				t = (lq - x[i]) / (x[i + 1] - x[i]); print exp(y[i] + t * (y[i + 1] - y[i])); exit }
			print "nan" }' "$T/uni")
	awk -v n="$name" -v s="$spp" -v o="$ours" -v u="$uni" -v e="$est" 'BEGIN {
		printf "%-18s %7.1f %10.3g %10s %7s %9.2f\n", n, s, o,
			u == "nan" ? "beyond" : sprintf("%.3g", u), u == "nan" ? "-" : sprintf("%.2f", o / u), e / o }'
done
