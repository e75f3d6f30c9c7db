#!/usr/bin/env bash
# How the radiosity solution depends on the frame POV-Ray computes it on,
# the measurement behind `povpress render`'s radiosity pass (README, "Scene
# consistency").  On scenes/radiosity_room.pov at 160x120:
#   1. solutions saved (+RFO, one thread) by full renders of frames 1, 2, 3,
#      4, 5 and 8 times 160x120, each loaded (+RFI, pretrace skipped) into
#      the same 640x480 render, box-averaged to 160x120: the relMSE each
#      solution leaves;
#   2. the 640x480 render computing its own solution on one thread and, three
#      times, on two threads.
# The reference is the scene at 15 times the resolution (cached in
# ${POVPRESS_CACHE:-~/.cache/povpress}/ref, shared with scripts/sweep.sh).
#
# usage: scripts/radiosity_solution.sh [BUILD_DIR]
set -euo pipefail
BUILD=${1:-build}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PP="$BUILD/povpress"
BOXDOWN="$BUILD/tools/boxdown"
SCENE="$ROOT/scenes/radiosity_room.pov"
CACHE=${POVPRESS_CACHE:-$HOME/.cache/povpress}/ref
W=160
H=120
for tool in "$PP" "$BOXDOWN"; do
	[[ -x $tool ]] || { echo "radiosity_solution.sh: $tool is missing (run make)" >&2; exit 1; }
done
command -v povray >/dev/null || { echo "radiosity_solution.sh: povray is not installed" >&2; exit 1; }
T=$(mktemp -d "${TMPDIR:-/tmp}/povpress-rad.XXXXXX")
trap 'rm -rf "$T"' EXIT
pov() { povray -D -GA +FE -A "+L$ROOT/scenes" "+I$SCENE" "$@" >/dev/null 2>&1; }
relmse() { "$PP" compare "$1" "$2" | awk '$1 == "relmse:" { print $2 }'; }

mkdir -p "$CACHE"
REF="$CACHE/radiosity_room-${W}x${H}-rad15.exr"
if [[ ! -f $REF ]]; then
	echo "# rendering the reference (15x, one thread)..." >&2
	pov +WT1 "+W$((15 * W))" "+H$((15 * H))" "+O$T/ref.exr"
	"$BOXDOWN" "$T/ref.exr" 15 "$T/ref15.exr" >/dev/null
	mv "$T/ref15.exr" "$REF"
fi

echo "solution computed on   relMSE of a 640x480 render loading it"
for s in 1 2 3 4 5 8; do
	pov +WT1 "+W$((s * W))" "+H$((s * H))" "+O$T/sol.exr" +RFO "+RF$T/sol$s.rca" \
		Declare=POVPRESS_PASS=0
	pov +WT1 "+W$((4 * W))" "+H$((4 * H))" "+O$T/load.exr" +RFI "+RF$T/sol$s.rca" \
		Declare=POVPRESS_PASS=1
	"$BOXDOWN" "$T/load.exr" 4 "$T/load4.exr" >/dev/null
	printf '%4dx%-4d (scale %d)    %s\n' $((s * W)) $((s * H)) "$s" "$(relmse "$T/load4.exr" "$REF")"
done
echo
echo "640x480 with its own solution   relMSE"
for wt in 1 2 2 2; do
	pov "+WT$wt" "+W$((4 * W))" "+H$((4 * H))" "+O$T/own.exr"
	"$BOXDOWN" "$T/own.exr" 4 "$T/own4.exr" >/dev/null
	printf '%d thread(s)                      %s\n' "$wt" "$(relmse "$T/own4.exr" "$REF")"
done
