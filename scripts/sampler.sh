#!/usr/bin/env bash
# How should a region get more samples: POV-Ray's own adaptive antialiasing
# (+AM2), resolution scaling, or grid renders (+AM1 with a threshold of 0)?
# For each scene this takes the region the render loop's first pass
# re-renders (from `povpress render --max-passes 1`)
# and renders that same region each way, one thread, as region renders
# (so each run pays what a real region render pays), then measures the CPU
# seconds of the povray process and the relMSE over the region's pixels
# against the scene's cached reference from `make sweep` (scale 25).
#
# usage: scripts/sampler.sh [BUILD_DIR] [SCENE...]   (default: four scenes)
# Writes BUILD_DIR/sampler/sampler.csv and prints, per scene, both methods'
# lower envelope.  Needs `make sweep` to have cached the 160x120 references.
set -eu

BUILD=${1:-build}
shift || true
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PP="$(cd "$BUILD" && pwd)/povpress"
BOXDOWN="$(cd "$BUILD" && pwd)/tools/boxdown"
CACHE=${POVPRESS_CACHE:-$HOME/.cache/povpress}/ref
W=160
H=120
OUT="$BUILD/sampler"
mkdir -p "$OUT"
T=$(mktemp -d "${TMPDIR:-/tmp}/povpress-sampler.XXXXXX")
trap 'rm -rf "$T"' EXIT
scenes=("$@")
((${#scenes[@]})) || scenes=(soft_shadows focal_blur glossy_reflection hdr_highlights)

# cpu_of COMMAND...: run it, print user + system CPU seconds of its children
cpu_of() {
	local TIMEFORMAT='%3U %3S'
	{ time "$@" >/dev/null 2>&1; } 2>&1 | awk '{ print $1 + $2 }'
}

# region_relmse IMAGE REF X0 Y0 X1 Y1: relMSE over the rectangle
region_relmse() {
	local g="$(($5 - $3 + 1))x$(($6 - $4 + 1))+$3+$4"
	oiiotool "$1" --ch R,G,B --cut "$g" -o "$T/a.exr" &&
		oiiotool "$2" --ch R,G,B --cut "$g" -o "$T/b.exr" &&
		"$PP" compare "$T/a.exr" "$T/b.exr" | awk '$1 == "relmse:" { print $2 }'
}

echo "scene,method,setting,cpu_s,relmse" >"$OUT/sampler.csv"
for name in "${scenes[@]}"; do
	scene="$ROOT/scenes/$name.pov"
	ref=$(ls "$CACHE/$name-${W}x$H-j15-"*.exr 2>/dev/null | head -n 1)
	[[ -n $ref ]] || { echo "sampler: no cached reference for $name (run make sweep)" >&2; continue; }
	"$PP" render "$scene" -o "$T/r.exr" -W $W -H $H --max-passes 1 --jobs 1 -q \
		--workdir "$T/w" --keep-workdir -- +WT1
	# the largest region of pass 1
	read -r x0 y0 x1 y1 < <(awk -F'\t' '!/^#/ { a = ($4 - $2 + 1) * ($5 - $3 + 1)
		if (a > best) { best = a; r = $2 " " $3 " " $4 " " $5 } } END { print r }' "$T/w/regions.tsv")
	echo "sampler: $name: region $x0,$y0-$x1,$y1" >&2
	common=(-D -GA +FE +WT1 "+I\"$scene\"" "+L\"$ROOT/scenes\"")
	for s in 1 2 3 4 6 8; do
		c=$(cpu_of povray "${common[@]}" -A +W$((s * W)) +H$((s * H)) \
			+SC$((x0 * s + 1)) +EC$(((x1 + 1) * s)) +SR$((y0 * s + 1)) +ER$(((y1 + 1) * s)) \
			"+O\"$T/s.exr\"")
		"$BOXDOWN" "$T/s.exr" "$s" "$T/sd.exr" >/dev/null
		e=$(region_relmse "$T/sd.exr" "$ref" "$x0" "$y0" "$x1" "$y1")
		echo "$name,scale,$s,$c,$e" >>"$OUT/sampler.csv"
	done
	# grid renders (render --sampler grid): scale k at twice the size with
	# +AM1 +A0.0 +R(k/2) +J0.75, k^2 + 4 samples per pixel
	for k in 4 8 16; do
		c=$(cpu_of povray "${common[@]}" +AM1 +A0.0 +R$((k / 2)) +J0.75 +W$((2 * W)) \
			+H$((2 * H)) +SC$((x0 * 2 + 1)) +EC$(((x1 + 1) * 2)) +SR$((y0 * 2 + 1)) \
			+ER$(((y1 + 1) * 2)) "+O\"$T/g.exr\"")
		"$BOXDOWN" "$T/g.exr" 2 "$T/gd.exr" >/dev/null
		e=$(region_relmse "$T/gd.exr" "$ref" "$x0" "$y0" "$x1" "$y1")
		echo "$name,grid,$k,$c,$e" >>"$OUT/sampler.csv"
	done
	for a in 0.3 0.1 0.03 0.01 0.0; do
		for r in 2 3 4; do
			c=$(cpu_of povray "${common[@]}" +AM2 +A$a +R$r +J +W$W +H$H \
				+SC$((x0 + 1)) +EC$((x1 + 1)) +SR$((y0 + 1)) +ER$((y1 + 1)) "+O\"$T/a.exr\"")
			e=$(region_relmse "$T/a.exr" "$ref" "$x0" "$y0" "$x1" "$y1")
			echo "$name,am2,+A$a +R$r,$c,$e" >>"$OUT/sampler.csv"
		done
	done
done

# the lower envelope of each method, and each at the other's CPU times
awk -F, 'NR > 1 { n[$1]++; sc[$1, n[$1]] = $1 "," $2 "," $3 "," $4 "," $5 }
END {
	for (k in n) {
		printf "%s:\n", k
		for (i = 1; i <= n[k]; i++) {
			split(sc[k, i], f, ",")
			printf "  %-6s %-12s cpu %6.3f s  relMSE %.3g\n", f[2], f[3], f[4], f[5]
		}
	}
}' "$OUT/sampler.csv"
echo "sampler: $OUT/sampler.csv" >&2
