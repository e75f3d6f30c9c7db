#!/usr/bin/env bash
# What the final image should hold per pixel: `povpress render --final
# samples|blend|auto|reconstruction` on seven bundled scenes at 160x120, target
# 1e-3, --jobs 4 with one POV-Ray thread (so the four runs of a scene render
# the same samples), relMSE against `make sweep`'s scale-25 references.
#
# usage: scripts/final_modes.sh [BUILD_DIR]
set -euo pipefail
BUILD=${1:-build}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PP="$BUILD/povpress"
CACHE=${POVPRESS_CACHE:-$HOME/.cache/povpress}/ref
T=$(mktemp -d "${TMPDIR:-/tmp}/povpress-final.XXXXXX")
trap 'rm -rf "$T"' EXIT
printf '%-18s %-14s %s\n' scene mode relMSE
for name in soft_shadows focal_blur glossy_reflection horizon_texture media thin_geometry \
	hdr_highlights; do
	ref=$(ls "$CACHE/$name-160x120-j15-"*.exr 2>/dev/null | head -n 1)
	[[ -n $ref ]] || { echo "final_modes: no reference for $name (run make sweep)" >&2; exit 1; }
	for mode in samples blend auto reconstruction; do
		"$PP" render "$ROOT/scenes/$name.pov" -o "$T/o.exr" -W 160 -H 120 --target 1e-3 \
			--final "$mode" --jobs 4 -q -- +WT1
		printf '%-18s %-14s %s\n' "$name" "$mode" \
			"$("$PP" compare "$T/o.exr" "$ref" | awk '$1 == "relmse:" { print $2 }')"
	done
done
