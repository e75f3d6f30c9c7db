#!/usr/bin/env bash
# samplers.sh - `povpress render --sampler auto|grid|scale|aa|jitter` side by side.
#
# usage: scripts/samplers.sh [BUILD_DIR] [SCENE ...]
#
# Renders each bundled scene named (default: soft_shadows focal_blur
# hdr_highlights thin_geometry horizon_texture) at 160x120 with each sampler
# at --target 1e-3 and 3e-4, and prints per run the CPU seconds of povpress
# and its POV-Ray children, the relMSE against make sweep's 625-sample
# reference (run `make sweep` first: the references are its cache) and the
# estimated relMSE.  MODES chooses the samplers (default "scale aa"; the
# README's table is MODES="auto grid scale aa").
set -eu

ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-$ROOT/build}
[[ $# -gt 0 ]] && shift
PP=$BUILD/povpress
CACHE=${POVPRESS_CACHE:-$HOME/.cache/povpress}/ref
[[ -x $PP ]] || { echo "samplers.sh: no $PP (make first)" >&2; exit 1; }
scenes=("$@")
[[ ${#scenes[@]} -gt 0 ]] ||
	scenes=(soft_shadows focal_blur hdr_highlights thin_geometry horizon_texture)
T=$(mktemp -d "${TMPDIR:-/tmp}/povpress-samplers.XXXXXX")
trap 'rm -rf "$T"' EXIT

printf '%-17s %-6s %-5s %8s %10s %10s\n' scene target mode "CPU s" relMSE estimated
for sc in "${scenes[@]}"; do
	ref=$(ls "$CACHE/$sc-160x120-j15-"*.exr 2>/dev/null | head -n 1)
	[[ -n $ref ]] || { echo "samplers.sh: no reference for $sc in $CACHE (make sweep)" >&2; exit 1; }
	for t in 1e-3 3e-4; do
		for m in ${MODES:-scale aa}; do
			d=$T/$sc-$t-$m
			"$PP" render "$ROOT/scenes/$sc.pov" -W 160 -H 120 --target $t --sampler $m -q \
				-o "$d.exr" --report "$d.json"
			rel=$("$PP" compare "$d.exr" "$ref" | awk '$1 == "relmse:" { print $2 }')
			cpu=$(grep -o '"all_cpu_s": [0-9.]*' "$d.json" | awk '{ print $2 }')
			est=$(grep -o '"est_relmse": [-0-9.e+]*' "$d.json" | tail -n 1 | awk '{ print $2 }')
			printf '%-17s %-6s %-5s %8.2f %10.3g %10.3g\n' "$sc" $t $m "$cpu" "$rel" "$est"
		done
	done
done
