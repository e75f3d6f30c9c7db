#!/usr/bin/env bash
# abtest.sh - two builds of povpress by turns: the same `povpress render`
# settings on the same scenes, run A then B then A ..., each run's relMSE
# against make sweep's cached reference, its CPU (povpress and its POV-Ray
# children, from the report) and its own estimate.  Machines are noisy and
# povpress's plans hang on the timings it measures, so a change is judged by
# turns in one session, never against figures from another.
#
# usage: scripts/abtest.sh [--runs N] [--size WxH] [--ref-scale S] BUILD_A BUILD_B
#                          [SCENE ...]
#
# BUILD_A, BUILD_B: build directories holding povpress and povwait.so (for
# an older commit: git worktree add /tmp/a COMMIT && make -C /tmp/a).
# SCENE: names of bundled scenes, or paths of any .pov files (default: every
# scenes/*.pov but smooth_empty).  SETTINGS (environment) lists the render
# settings, separated by ';' (default "--budget 2;--budget 4;--budget 8"); a
# budget setting also gets --target 1e-6, as in make sweep.  --runs N
# (default 2) runs of each build per setting.  The reference of scene NAME
# is the newest ${POVPRESS_CACHE:-$HOME/.cache/povpress}/ref/NAME-WxH-jS-*.exr
# at the size (default 160x120) and scale S (--ref-scale, default 15): make
# sweep's references (scripts/sweep.sh --quick SCENE.pov makes them at 9, 5
# and 3 for any scene).
#
# Prints a line per run and, per scene and setting, the geometric means of
# both builds' relMSE and CPU and their ratio B/A; at the end the geometric
# mean of those ratios over all rows.  Every run goes to $OUT (default
# build/abtest/runs.csv): scene,setting,build,run,cpu_s,wall_s,relmse,est,
# total_cpu_s.  cpu_s is the report's all_cpu_s (the POV-Ray children and
# povpress while they ran and merged, not its analyses); total_cpu_s adds
# all of povpress's own CPU (cpu_s + own_cpu_s of the report's totals), as
# make sweep counts a run, for ratios to POV-Ray's envelope.  wall_s is the
# report's elapsed_s, the run's whole wall time (a build older than it: its
# passes' wall_s, which leave out the final image and error map).
set -euo pipefail

usage() {
	sed -n 's/^# \{0,1\}//; 9,10p' "$0"
}

ROOT=$(cd "$(dirname "$0")/.." && pwd)
CACHE=${POVPRESS_CACHE:-$HOME/.cache/povpress}/ref
runs=2
size=160x120
rscale=15
args=()
while (($#)); do
	case $1 in
	--runs)
		[[ $# -ge 2 ]] || { echo "abtest: --runs needs a count" >&2; exit 2; }
		runs=$2
		shift
		;;
	--size)
		[[ $# -ge 2 ]] || { echo "abtest: --size needs WxH" >&2; exit 2; }
		size=$2
		shift
		;;
	--ref-scale)
		[[ $# -ge 2 ]] || { echo "abtest: --ref-scale needs a scale" >&2; exit 2; }
		rscale=$2
		shift
		;;
	-h | --help) usage; exit 0 ;;
	-*) echo "abtest: unknown option '$1'" >&2; usage >&2; exit 2 ;;
	*) args+=("$1") ;;
	esac
	shift
done
((${#args[@]} >= 2)) || { usage >&2; exit 2; }
[[ $runs =~ ^[1-9]$ ]] || { echo "abtest: invalid --runs '$runs': expected 1 to 9" >&2; exit 2; }
[[ $rscale =~ ^[1-9][0-9]?$ ]] || { echo "abtest: invalid --ref-scale '$rscale'" >&2; exit 2; }
[[ $size =~ ^([1-9][0-9]{0,4})x([1-9][0-9]{0,4})$ ]] ||
	{ echo "abtest: invalid size '$size': expected WxH, as 160x120" >&2; exit 2; }
W=${BASH_REMATCH[1]}
H=${BASH_REMATCH[2]}
A=${args[0]}
B=${args[1]}
scenes=("${args[@]:2}")
for b in "$A" "$B"; do
	[[ -x $b/povpress && -f $b/povwait.so ]] ||
		{ echo "abtest: no povpress and povwait.so in '$b' (make there first)" >&2; exit 1; }
done
if ((${#scenes[@]} == 0)); then
	for f in "$ROOT"/scenes/*.pov; do
		n=$(basename "$f" .pov)
		[[ $n == smooth_empty ]] || scenes+=("$n")
	done
fi
IFS=';' read -r -a settings <<<"${SETTINGS:---budget 2;--budget 4;--budget 8}"

declare -A refs=() paths=()
names=()
for sc in "${scenes[@]}"; do
	if [[ $sc == *.pov ]]; then
		path=$sc
		sc=$(basename "$sc" .pov)
	else
		path=$ROOT/scenes/$sc.pov
	fi
	[[ -f $path && -r $path ]] || { echo "abtest: cannot read scene '$path'" >&2; exit 1; }
	# the newest reference at the size (an edited scene gets a new one)
	ref=$(ls -t "$CACHE/$sc-${W}x$H-j$rscale-"*.exr 2>/dev/null | head -n 1 || true)
	[[ -n $ref ]] || { echo "abtest: no scale-$rscale reference for $sc at ${W}x$H in $CACHE (make sweep)" >&2; exit 1; }
	refs[$sc]=$ref
	paths[$sc]=$path
	names+=("$sc")
done
scenes=("${names[@]}")

OUT=${OUT:-$ROOT/build/abtest}
mkdir -p "$OUT"
T=$(mktemp -d "${TMPDIR:-/tmp}/povpress-abtest.XXXXXX")
trap 'rm -rf "$T"' EXIT
csv=$OUT/runs.csv
echo "scene,setting,build,run,cpu_s,wall_s,relmse,est,total_cpu_s" >"$csv.tmp"

field() { # REPORT KEY: the last number under KEY in a JSON report
	grep -o "\"$2\": [-0-9.e+]*" "$1" | tail -n 1 | awk '{ print $2 }'
}

printf '%-18s %-12s %-2s %4s %8s %8s %10s %10s\n' scene setting ab run "CPU s" "wall s" relMSE estimate
for sc in "${scenes[@]}"; do
	for set in "${settings[@]}"; do
		read -r -a opt <<<"$set"
		[[ $set == *--budget* ]] && opt+=(--target 1e-6)
		for ((k = 1; k <= runs; k++)); do
			for ab in A B; do
				b=$A
				[[ $ab == B ]] && b=$B
				d=$T/run
				"$b/povpress" render "${paths[$sc]}" -W "$W" -H "$H" -q -o "$d.exr" \
					--report "$d.json" "${opt[@]}"
				rel=$("$b/povpress" compare "$d.exr" "${refs[$sc]}" | awk '$1 == "relmse:" { print $2 }')
				cpu=$(field "$d.json" all_cpu_s)
				# the run's whole wall (a build before elapsed_s: its
				# passes' only)
				wall=$(field "$d.json" elapsed_s)
				[[ -n $wall ]] || wall=$(field "$d.json" wall_s)
				est=$(field "$d.json" est_relmse)
				tot=$(awk -v a="$(field "$d.json" cpu_s)" -v b="$(field "$d.json" own_cpu_s)" \
					'BEGIN { printf "%.3f", a + b }')
				printf '%-18s %-12s %-2s %4d %8.3f %8.3f %10.3g %10.3g\n' \
					"$sc" "$set" $ab $k "$cpu" "$wall" "$rel" "$est"
				echo "$sc,$set,$ab,$k,$cpu,$wall,$rel,$est,$tot" >>"$csv.tmp"
			done
		done
	done
done
mv "$csv.tmp" "$csv"

echo
echo "geometric means over the runs, B over A"
awk -F, 'NR > 1 {
	key = $1 "," $2
	if (!(key in seen)) { seen[key] = 1; order[++n] = key }
	lr[key, $3] += log($7); lc[key, $3] += log($5); cnt[key, $3]++
} END {
	printf "%-18s %-12s %10s %10s %6s %7s %7s %6s\n", "scene", "setting", "A relMSE", "B relMSE", "B/A", "A CPU", "B CPU", "B/A"
	for (i = 1; i <= n; i++) {
		k = order[i]; split(k, p, ",")
		ra = exp(lr[k, "A"] / cnt[k, "A"]); rb = exp(lr[k, "B"] / cnt[k, "B"])
		ca = exp(lc[k, "A"] / cnt[k, "A"]); cb = exp(lc[k, "B"] / cnt[k, "B"])
		printf "%-18s %-12s %10.3g %10.3g %6.2f %7.2f %7.2f %6.2f\n", p[1], p[2], ra, rb, rb / ra, ca, cb, cb / ca
		g += log(rb / ra); gc += log(cb / ca); m++
	}
	if (m) printf "all %d rows: relMSE B/A %.2f, CPU B/A %.2f (geometric means)\n", m, exp(g / m), exp(gc / m)
}' "$csv"
