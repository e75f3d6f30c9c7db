#!/usr/bin/env bash
# End-to-end tests of the povpress binary: analyze and compare on synthetic
# EXR images made by tests/gen_image, on bad input, and on a POV-Ray render
# of a bundled scene.  Images are checked with OpenImageIO's tools.
#
# usage: tests/e2e.sh BUILD_DIR
set -u

BUILD=${1:-build}
PP="$BUILD/povpress"
GEN="$BUILD/tests/gen_image"
ROOT=$(cd "$(dirname "$0")/.." && pwd)
T=$(mktemp -d "${TMPDIR:-/tmp}/povpress-e2e.XXXXXX")
trap 'rm -rf "$T"' EXIT

. "$(dirname "$0")/lib.sh"

# stat IMAGE CHANNEL FIELD: one field (Min, Max, Avg, NanCount, InfCount)
# of `oiiotool --printstats` for one channel.
chstat() {
	oiiotool "$1" --ch "$2" --printstats 2>/dev/null |
		awk -v f="$3" '$1 == "Stats" && $2 == f":" { print $3 }'
}
# cutstat IMAGE GEOMETRY CHANNEL FIELD: the same over a region WxH+X+Y.
cutstat() {
	oiiotool "$1" --ch "$3" --cut "$2" --printstats 2>/dev/null |
		awk -v f="$4" '$1 == "Stats" && $2 == f":" { print $3 }'
}
# fraction of pixels whose order is at least N (1 or 2), over a region.
order_frac() { # IMAGE GEOMETRY N
	oiiotool "$1" --ch order --cut "$2" --subc $(($3 - 1)) --clamp:min=0:max=1 \
		--printstats 2>/dev/null | awk '$1 == "Stats" && $2 == "Avg:" { print $3 }'
}
cmpval() { # cmpval OUTPUT KEY: value printed by compare
	awk -v k="$2:" '$1 == k { print $2 }' <<<"$1"
}

echo "# povpress end-to-end tests in $T"

# --- the command line ------------------------------------------------------
check "povpress --help exits 0" quiet "$PP" --help
check "analyze --help exits 0" quiet "$PP" analyze --help
check "compare --help exits 0" quiet "$PP" compare --help
"$PP" analyze --order 7 x.exr -o y.exr 2>/dev/null
check "bad --order is a usage error (2)" test $? -eq 2
"$PP" frobnicate 2>/dev/null
check "unknown command is a usage error (2)" test $? -eq 2

# --- exact quadratic -------------------------------------------------------
"$GEN" quadratic 128 96 "$T/quad.exr"
"$PP" analyze "$T/quad.exr" -o "$T/quad.a.exr"
check "quadratic: analyze succeeds" test -s "$T/quad.a.exr"
oiiotool "$T/quad.a.exr" --ch R,G,B -o "$T/quad.rgb.exr"
check "quadratic: reproduced to 1e-5 relative" \
	idiff -q -fail 4e-6 -failpercent 0 "$T/quad.exr" "$T/quad.rgb.exr"
check "quadratic: error ~ 0" num 'a < 1e-9' "$(chstat "$T/quad.a.exr" error Max)"
f=$(order_frac "$T/quad.a.exr" 112x80+8+8 2)
check "quadratic: order 2 on >= 90% of interior pixels ($f)" num 'a >= 0.9' "$f"
chans=$(iinfo -v "$T/quad.a.exr" | awk -F': ' '/channel list/ { print $2 }')
for c in R G B error order bandwidth dx.R dx.G dx.B dy.R dy.G dy.B; do
	case ", $chans," in
	*", $c,"*) ;;
	*) bad "output channel $c missing ($chans)"; continue ;;
	esac
done
check "analysis is a float EXR" sh -c "iinfo '$T/quad.a.exr' | grep -q 'float openexr'"

# --- noise -----------------------------------------------------------------
"$GEN" noise 128 128 "$T/noise.exr" 3
"$PP" analyze "$T/noise.exr" -o "$T/noise.a.exr"
e=$(chstat "$T/noise.a.exr" error Avg)
check "noise: mean error within 25% of sigma^2 ($e vs 0.0025)" num 'a >= 0.001875 && a <= 0.003125' "$e"
f=$(order_frac "$T/noise.a.exr" 128x128+0+0 1)
check "noise: order 0 on >= 70% of pixels (order>0 on $f)" num 'a <= 0.3' "$f"
oiiotool --pattern constant:color=0.5,0.5,0.5 128x128 3 -d float -o "$T/half.exr"
out=$("$PP" compare "$T/noise.a.exr" "$T/half.exr")
m=$(cmpval "$out" mse)
check "noise: reconstruction MSE <= sigma^2/4 ($m)" num 'a <= 0.000625' "$m"
check "compare prints relmse, mse, psnr" sh -c "printf '%s\n' \"$out\" | awk '\$1==\"relmse:\"{a=1} \$1==\"mse:\"{b=1} \$1==\"psnr:\"{c=1} END{exit !(a&&b&&c)}'"

out=$("$PP" compare "$T/noise.exr" "$T/half.exr" --analysis "$T/noise.a.exr")
check "compare --analysis: estimated relMSE within 25% of the true one on noise" \
	num 'a >= 0.75 * b && a <= 1.25 * b' "$(cmpval "$out" est_relmse)" "$(cmpval "$out" relmse)"
check "compare --analysis: capture and oracle shares in (0, 1], capture <= oracle" \
	num 'a > 0 && b <= 1 && a <= b' "$(cmpval "$out" capture20)" "$(cmpval "$out" oracle20)"
# on pure noise, equal everywhere, knowing where the error lies is knowing
# little: the 3x3 ranking holds far less than the oracle
check "compare --analysis: local20 on noise in (0.2, 0.8 oracle20)" \
	num 'a > 0.2 && a < 0.8 * b' "$(cmpval "$out" local20)" "$(cmpval "$out" oracle20)"

# --- scale invariance --------------------------------------------------------
oiiotool "$T/noise.exr" --mulc 1e4 -d float -o "$T/noise4.exr"
"$PP" analyze "$T/noise4.exr" -o "$T/noise4.a.exr"
oiiotool "$T/noise.a.exr" --ch order,bandwidth -o "$T/ob1.exr"
oiiotool "$T/noise4.a.exr" --ch order,bandwidth -o "$T/ob2.exr"
check "x1e4: no order or bandwidth changes" idiff -q -fail 0 -failpercent 0 "$T/ob1.exr" "$T/ob2.exr"
e4=$(chstat "$T/noise4.a.exr" error Avg)
check "x1e4: error multiplied by 1e8 ($e4 vs $e)" num 'b > 0 && a / b > 0.99e8 && a / b < 1.01e8' "$e4" "$e"

# --- ramp gradients ----------------------------------------------------------
"$GEN" ramp 96 64 "$T/ramp.exr"
"$PP" analyze "$T/ramp.exr" -o "$T/ramp.a.exr"
for s in "dx.R 0.001" "dx.G 0.002" "dx.B 0.003" "dy.R 0.002" "dy.G 0.002" "dy.B 0.002"; do
	set -- $s
	lo=$(cutstat "$T/ramp.a.exr" 80x48+8+8 "$1" Min)
	hi=$(cutstat "$T/ramp.a.exr" 80x48+8+8 "$1" Max)
	check "ramp: $1 = $2 to 1e-5 in the interior ($lo .. $hi)" \
		num 'a >= c - 1e-5 && b <= c + 1e-5' "$lo" "$hi" "$2"
done

# --- holes -------------------------------------------------------------------
"$GEN" holes 96 96 "$T/holes.exr" 5
"$PP" analyze "$T/holes.exr" -o "$T/holes.a.exr"
nan=$(oiiotool "$T/holes.a.exr" --printstats 2>/dev/null | awk '$2 == "NanCount:" || $2 == "InfCount:" { for (i = 3; i <= NF; i++) s += $i } END { print s + 0 }')
check "holes: no NaN or Inf in any output channel ($nan)" test "$nan" -eq 0
oiiotool "$T/holes.a.exr" --ch R,G,B -o "$T/holes.rgb.exr"
"$GEN" quadratic 96 96 "$T/quad96.exr"
check "holes: filled to 1e-3 relative" idiff -q -fail 4e-4 -failpercent 0 "$T/quad96.exr" "$T/holes.rgb.exr"

# --- step edge ---------------------------------------------------------------
"$GEN" step 64 48 "$T/step.exr"
"$PP" analyze "$T/step.exr" -o "$T/step.a.exr"
near=$(cutstat "$T/step.a.exr" 4x48+30+0 error Avg)
far1=$(cutstat "$T/step.a.exr" 12x48+0+0 error Avg)
far2=$(cutstat "$T/step.a.exr" 12x48+52+0 error Avg)
check "step: error near the edge >= 10x the error far from it ($near vs $far1, $far2)" \
	num 'a > 0 && a >= 10 * b && a >= 10 * c' "$near" "$far1" "$far2"

# --- texture and features ------------------------------------------------------
"$GEN" texture 128 128 "$T/tex.exr" 7
"$GEN" texture-feature 128 128 "$T/texf.exr"
"$GEN" texture-clean 128 128 "$T/texc.exr"
"$PP" analyze "$T/tex.exr" --features "$T/texf.exr" -o "$T/tex.f.exr"
"$PP" analyze "$T/tex.exr" -o "$T/tex.n.exr"
ef=$(chstat "$T/tex.f.exr" error Avg)
en=$(chstat "$T/tex.n.exr" error Avg)
m=$(cmpval "$("$PP" compare "$T/tex.f.exr" "$T/texc.exr")" mse)
check "texture+features: mean error within 50% of sigma^2 ($ef vs 0.0004)" num 'a >= 0.0002 && a <= 0.0006' "$ef"
check "texture+features: reconstruction MSE <= sigma^2/2 ($m)" num 'a <= 0.0002' "$m"
check "texture without features: error >= 5x higher ($en vs $ef)" num 'a >= 5 * b' "$en" "$ef"

# --- fixed order and radius ------------------------------------------------------
"$PP" analyze "$T/noise.exr" --order 2 --radius 4 -o "$T/o2r4.exr"
check "--order 2 --radius 4: every pixel has order 2 and bandwidth 4" \
	num 'a == 2 && b == 2 && c == 4' "$(chstat "$T/o2r4.exr" order Min)" \
	"$(chstat "$T/o2r4.exr" order Max)" "$(chstat "$T/o2r4.exr" bandwidth Min)"
check "--radius 4: bandwidth max 4" num 'a == 4' "$(chstat "$T/o2r4.exr" bandwidth Max)"
"$PP" analyze "$T/noise.exr" --radii 3,6 -o "$T/r36.exr"
lo=$(chstat "$T/r36.exr" bandwidth Min)
hi=$(chstat "$T/r36.exr" bandwidth Max)
check "--radii 3,6: bandwidths within 3..6 ($lo..$hi)" num 'a >= 3 && b <= 6' "$lo" "$hi"
"$PP" analyze "$T/noise.exr" --radii 3,x -o "$T/bad.exr" 2>/dev/null
check "bad --radii is a usage error (2)" test $? -eq 2

# --- threads -----------------------------------------------------------------
"$PP" analyze "$T/holes.exr" --threads 1 -o "$T/t1.exr"
"$PP" analyze "$T/holes.exr" --threads 2 -o "$T/t2.exr"
check "--threads 1 and 2: bit-identical files" cmp -s "$T/t1.exr" "$T/t2.exr"

# --- input formats -----------------------------------------------------------------
"$GEN" quadratic-half 64 48 "$T/qh.exr"
check "half-float input" "$PP" analyze "$T/qh.exr" -o "$T/qh.a.exr"
oiiotool "$T/quad.exr" --tile 32 32 -o "$T/tiled.exr"
check "tiled input" "$PP" analyze "$T/tiled.exr" -o "$T/tiled.a.exr"
oiiotool "$T/tiled.a.exr" --ch R,G,B -o "$T/tiled.rgb.exr"
check "tiled input gives the scanline result" idiff -q -fail 0 -failpercent 0 "$T/quad.rgb.exr" "$T/tiled.rgb.exr"
"$GEN" rgba 64 48 "$T/rgba.exr"
check "RGBA input" "$PP" analyze "$T/rgba.exr" -o "$T/rgba.a.exr"

# --- bad input -----------------------------------------------------------------
bad_input() { # DESCRIPTION INPUT
	local d=$1 in=$2 msg rc
	rm -f "$T/out.exr"
	msg=$("$PP" analyze "$in" -o "$T/out.exr" 2>&1)
	rc=$?
	check "$d: non-zero exit" test $rc -ne 0
	check "$d: message names the file" grep -qF -- "$in" <<<"$msg"
	check "$d: no output file" test ! -e "$T/out.exr"
	check "$d: no temporary file left" sh -c "! ls '$T' | grep -q 'out.exr.'"
}
bad_input "missing file" "$T/does-not-exist.exr"
echo "this is not an image" >"$T/text.exr"
bad_input "not an EXR" "$T/text.exr"
head -c $(($(stat -c %s "$T/quad.exr") / 2)) "$T/quad.exr" >"$T/trunc.exr"
bad_input "truncated EXR" "$T/trunc.exr"
"$GEN" nocolour 32 32 "$T/nocol.exr"
bad_input "no colour channels" "$T/nocol.exr"
msg=$("$PP" analyze "$T/quad.exr" --features "$T/noise.exr" -o "$T/out.exr" 2>&1)
check "features of another size: error naming the features file" \
	sh -c "test ! -e '$T/out.exr' && printf '%s' \"\$1\" | grep -qF '$T/noise.exr'" _ "$msg"
msg=$("$PP" analyze "$T/quad.exr" -o "$T/no/such/dir/out.exr" 2>&1)
check "unwritable output: error naming it" grep -qF "$T/no/such/dir/out.exr" <<<"$msg"

msg=$("$PP" compare "$T/quad.exr" "$T/noise.exr" 2>&1)
rc=$?
check "compare: size mismatch is an error naming the file" \
	sh -c "test $rc -ne 0 && printf '%s' \"\$1\" | grep -qF '$T/noise.exr'" _ "$msg"
msg=$("$PP" compare "$T/quad.exr" "$T/nope.exr" 2>&1)
rc=$?
check "compare: unreadable file is an error naming it" \
	sh -c "test $rc -ne 0 && printf '%s' \"\$1\" | grep -qF '$T/nope.exr'" _ "$msg"
out=$("$PP" compare "$T/quad.exr" "$T/quad.exr")
check "compare: an image against itself has relmse 0" num 'a == 0' "$(cmpval "$out" relmse)"

# --- povpress scene: what render reads from a scene file ----------------------
# (tests/render.sh checks that render reads the same gamma, and the bundled
# scenes' keys; here the printing and the errors)
cat >"$T/keys.pov" <<'EOF'
// assumed_gamma 1.5 in a comment; aperture 0.3 too
#declare use_radiosity = 0;
global_settings { assumed_gamma 2.2 }
camera { location <0, 1, -3> look_at 0 aperture 0.3 blur_samples 8 focal_point 0 }
EOF
out=$("$PP" scene "$T/keys.pov" 2>"$T/scene.err")
check "scene: three lines, nothing on stderr" \
	test "$(wc -l <<<"$out")" = 3 -a ! -s "$T/scene.err"
check "scene: the gamma given as a number" grep -qx "assumed_gamma: 2.2" <<<"$out"
check "scene: focal blur from aperture and blur_samples" grep -qx "focal_blur: yes" <<<"$out"
check "scene: radiosity named (in a name)" grep -qx "radiosity: yes" <<<"$out"
sed 's/aperture 0.3 blur/aperture 0 blur/; s/use_radiosity/use_rad/' "$T/keys.pov" >"$T/keys0.pov"
out=$("$PP" scene "$T/keys0.pov")
check "scene: aperture 0 is no focal blur" grep -qx "focal_blur: no" <<<"$out"
check "scene: no radiosity named" grep -qx "radiosity: no" <<<"$out"
scene_fails() { # DESCRIPTION STATUS MESSAGE ARGS...: povpress scene ARGS fails so
	local d=$1 want=$2 m=$3 msg rc
	shift 3
	msg=$("$PP" scene "$@" 2>&1)
	rc=$?
	check "scene: $d: exit $want, saying \"$m\"" \
		sh -c 'test "$1" = "$2" && printf "%s" "$3" | grep -qF -- "$4"' _ "$rc" "$want" "$msg" "$m"
}
scene_fails "a missing file" 1 "cannot read scene '$T/none.pov'" "$T/none.pov"
scene_fails "a directory" 1 "cannot read scene '$T': Is a directory" "$T"
scene_fails "a device" 1 "cannot read scene '/dev/zero': not a regular file" /dev/zero
scene_fails "no file" 2 "no scene file given"
scene_fails "two files" 2 "one scene file" "$T/keys.pov" "$T/keys0.pov"
scene_fails "an unknown option" 2 "unknown option '--gamma'" --gamma "$T/keys.pov"
check "scene: --help, exit 0" \
	bash -c 'set -o pipefail; "$1" scene --help | grep -q "^usage: povpress scene"' _ "$PP"
cp "$T/keys.pov" "$T/-k.pov"
check "scene: a file after --, though it looks like an option" \
	bash -c 'set -o pipefail; cd "$1" && "$2" scene -- -k.pov | grep -qx "assumed_gamma: 2.2"' \
	_ "$T" "$(readlink -f "$PP")"

# --- a POV-Ray render of a bundled scene ---------------------------------------------
cp "$ROOT/scenes/soft_shadows.pov" "$T/scene.pov"
povray -D -GA +W96 +H72 +FE +WT1 "+O$T/render.exr" "+I$T/scene.pov" "+L$ROOT/scenes" \
	>"$T/povray.log" 2>&1
check "povray renders scenes/soft_shadows.pov" test -s "$T/render.exr"
"$PP" analyze "$T/render.exr" -o "$T/render.a.exr"
check "render: analyze succeeds" test -s "$T/render.a.exr"
nan=$(oiiotool "$T/render.a.exr" --printstats 2>/dev/null | awk '$2 == "NanCount:" || $2 == "InfCount:" { for (i = 3; i <= NF; i++) s += $i } END { print s + 0 }')
check "render: every output is finite" test "$nan" -eq 0
e=$(chstat "$T/render.a.exr" error Avg)
check "render: the penumbra noise shows as error ($e)" num 'a > 1e-6' "$e"
povray -D -GA +W96 +H72 +FE +WT1 Declare=AreaN=12 "+O$T/ref.exr" "+I$T/scene.pov" \
	>"$T/povray-ref.log" 2>&1
out=$("$PP" compare "$T/render.exr" "$T/ref.exr")
check "render: compare against a 12x12-light render" num 'a > 0' "$(cmpval "$out" relmse)"

# --- the benchmark's choice among repeated runs -------------------------------
# median_row, as scripts/sweep.sh defines it: of repeated povpress rows, the
# one whose ratio to the scene's POV-Ray envelope (in $CSV.tmp) is the median
eval "$(sed -n '/^awk_envelope() {/,/^}/p; /^median_row() {/,/^}/p' "$ROOT/scripts/sweep.sh")"
CSV=$T/sweep.csv
printf '%s\n' scene,method,setting,cpu_s,wall_s,relmse,psnr,est,cap,orc \
	A,noaa,-,0.1,1,0.01,,,, A,am2,x,1.0,1,0.001,,,, B,am2,x,0.01,1,1e-9,,,, >"$CSV.tmp"
# ratios 0.4 (0.004 over 0.01 at 0.5 s), 2 (0.002 over 0.001), 3 (0.03 over 0.01)
m=$(median_row A A,povpress,t,0.5,1,0.004,,,, A,povpress,t,1.5,1,0.002,,,, \
	A,povpress,t,0.2,1,0.03,,,,)
check "sweep: the median-ratio run of three (not the median relMSE or CPU)" \
	test "$m" = A,povpress,t,1.5,1,0.002,,,,
m=$(median_row A A,povpress,t,0.5,1,0.004,,,, A,povpress,t,1.5,1,0.0005,,,,)
check "sweep: the lower of the middle two of two (0.4 and 0.5)" \
	test "$m" = A,povpress,t,0.5,1,0.004,,,,
m=$(median_row A A,povpress,t,0.05,1,0.001,,,, A,povpress,t,0.5,1,0.02,,,, \
	A,povpress,t,0.5,1,0.01,,,,)
check "sweep: a run cheaper than every POV-Ray run ranks last" \
	test "$m" = A,povpress,t,0.5,1,0.02,,,,
# pp_table: the table row of the median run, its ratio's range over all runs
eval "$(sed -n '/^pp_table() {/,/^}/p' "$ROOT/scripts/sweep.sh")"
CSV=$T/pp.csv RCSV=$T/pp-rep.csv REPEAT=3
printf '%s\n' scene,method,setting,cpu_s,wall_s,relmse,psnr,est,cap,orc \
	A,noaa,-,0.1,1,0.01,,,, A,am2,x,1.0,1,0.001,,,, A,povpress,t,1.5,1,0.002,40,0.001,0.5,0.9 \
	>"$CSV"
printf '%s\n' scene,method,setting,cpu_s,wall_s,relmse,psnr,est,cap,orc \
	A,povpress,t,0.5,1,0.004,,,, A,povpress,t,1.5,1,0.002,,,, A,povpress,t,0.2,1,0.03,,,, \
	>"$RCSV"
row=$(pp_table)
check "sweep: the table's ratio, and the range over the runs (0.40-3.00)" \
	grep -qF "| 2.00 (0.40-3.00) |" <<<"$row"
check "sweep: ... the envelope at the row's CPU and its setting" \
	grep -qF "| 0.001 (am2 x) |" <<<"$row"
REPEAT=1
check "sweep: one run per setting: no range" grep -qF "| 2.00 |" <<<"$(pp_table)"
# goals: the table tallied against issue 4's goals, scenes without visible
# error left out, every budget run's wall time against its budget
eval "$(sed -n '/^goals() {/,/^}/p' "$ROOT/scripts/sweep.sh")"
CSV=$T/g.csv RCSV=$T/g-rep.csv REPEAT=3
printf '%s\n' scene,method,setting,cpu_s,wall_s,relmse A,noaa,-,0.1,1,0.01 Z,noaa,-,0.1,1,1e-9 >"$CSV"
printf '%s\n' scene,method,setting,cpu_s,wall_s,relmse "A,povpress,budget 2,2,1.9,0.002" \
	"A,povpress,budget 2,2,2.1,0.002" "A,povpress,target 1,1,1,0.002" >"$RCSV"
g=$(printf '%s\n' \
	'| A | target 1 | 1 | 1 | 0.002 | 0.004 (x) | 0.50 (0.40-0.60) | - | 1.20 | 1.60 | 0.90 / 1.00 (90%) / 0.95 |' \
	'| A | budget 2 | 2 | 1.9 | 0.002 | 0.0015 (x) | 1.33 | - | 2.00 | - | 0.50 / 1.00 (50%) |' \
	'| Z | target 1 | 1 | 1 | 3e-9 | 1e-9 (x) | 3.00 | - | 9.00 | - | 0.10 / 1.00 (10%) |' | goals)
check "sweep: goals: two runs counted, Z left out" grep -qF "over the 2 runs of the scenes with visible error (Z left out" <<<"$g"
check "sweep: goals: 0.5 met on one, 1.0 and 1.25 passed on one, geometric mean 0.82" \
	grep -qF "at or below 0.5 on 1, above 1.0 on 1, above 1.25 on 1, geometric mean 0.82;" <<<"$g"
check "sweep: goals: the estimate within 1.5x on one, on none less the reference's own" \
	grep -qF "within 1.5x of the true relMSE on 1, and on 0 with the reference's own error taken off" <<<"$g"
check "sweep: goals: capture20 at 90% of the oracle's counts" grep -qF "oracle's on 1." <<<"$g"
check "sweep: goals: budget runs from every run, the longest" \
	grep -qF "within their budgets on 1 of 2 (longest: 2 s budget 2.100 s)" <<<"$g"
check "sweep: goals: the runs above 0.5 named" grep -qxF "Above 0.5: A budget 2 1.33." <<<"$g"
"$ROOT/scripts/sweep.sh" --repeat 0 >"$T/rep.out" 2>&1
check "sweep: --repeat 0 is a usage error (2)" test $? -eq 2
check "sweep: ... naming --repeat" grep -q -- "--repeat '0'" "$T/rep.out"

# --- every bundled scene renders and analyses -------------------------------------
for scene in "$ROOT"/scenes/*.pov; do
	name=$(basename "$scene" .pov)
	if povray -D -GA +W80 +H60 +FE +WT1 "+O$T/s_$name.exr" "+I$scene" "+L$ROOT/scenes" \
		>"$T/s_$name.log" 2>&1 && "$PP" analyze "$T/s_$name.exr" -o "$T/s_$name.a.exr"; then
		nan=$(oiiotool "$T/s_$name.a.exr" --printstats 2>/dev/null | awk '$2 == "NanCount:" || $2 == "InfCount:" { for (i = 3; i <= NF; i++) s += $i } END { print s + 0 }')
		check "scenes/$name.pov renders and analyses to finite values" test "$nan" -eq 0
	else
		bad "scenes/$name.pov renders and analyses ($(tail -3 "$T/s_$name.log" | tr '\n' ' '))"
	fi
done

echo
echo "$passed passed, $failed failed"
test "$failed" -eq 0
