#!/usr/bin/env bash
# End-to-end tests of `povpress render`, `plan` and `merge` through POV-Ray
# on the bundled scenes, at small sizes: errors and faults, the loop's
# accuracy against cached high-sample references, determinism, the plan ->
# xargs -> merge route, interruption and --resume, and awkward paths.
#
# usage: tests/render.sh BUILD_DIR
#
# References (resolution scale 25: 625 samples per pixel, antialiasing off,
# box-averaged) are rendered once and cached in
# ${POVPRESS_CACHE:-$HOME/.cache/povpress}/testref, keyed by the scene's
# contents, the size and POV-Ray's version.
set -u

BUILD=${1:-build}
PP="$(cd "$BUILD" && pwd)/povpress"
BOXDOWN="$(cd "$BUILD" && pwd)/tools/boxdown"
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SC="$ROOT/scenes"
T=$(mktemp -d "${TMPDIR:-/tmp}/povpress-render.XXXXXX")
CACHE=${POVPRESS_CACHE:-$HOME/.cache/povpress}/testref
trap 'rm -rf "$T"' EXIT
W=80
H=60

. "$(dirname "$0")/lib.sh"
relmse() { # relmse IMAGE REF
	"$PP" compare "$1" "$2" | awk '$1 == "relmse:" { print $2 }'
}
jget() { # jget REPORT KEY: the last value of "KEY": in a JSON report
	grep -o "\"$2\": [-0-9.e+a-z]*" "$1" | tail -n 1 | awk '{ print $2 }'
}
est_relmse() { # est_relmse IMAGE REF: the relMSE IMAGE's error map (IMAGE less .exr, .errors.exr) predicts
	"$PP" compare "$1" "$2" --analysis "${1%.exr}.errors.exr" | awk '$1 == "est_relmse:" { print $2 }'
}
valid_exr() { # a complete, readable EXR with R, G, B
	oiiotool "$1" --ch R,G,B --printstats >/dev/null 2>&1
}
no_povray_left() { # no povray process whose command line mentions $1
	! pgrep -f -- "$1" >/dev/null 2>&1 || { sleep 2; ! pgrep -f -- "$1" >/dev/null 2>&1; }
}

POV_VERSION=$(povray --version 2>&1 | head -n 1)
# The reference is scale 25: its sample positions include none of scales 2,
# 4, 8 and 16's (scale 24's include scale 8's, which then err against it by
# less than they do against the image).  It renders on one thread, so it is
# the same on every machine: on several, POV-Ray computes another radiosity
# solution every render (the radiosity test's ratio was 0.84 against one
# such reference, 0.48 to 0.60 against three others).
reference() { # reference SCENE: print the cached reference's path, rendering it if need be (S: the scale, default 25)
	local scene=$1 s=${S:-25} key dest tmp
	key=$({
		echo "povpress test reference 2 ${W}x$H s$s +WT1"
		echo "$POV_VERSION"
		sha256sum <"$scene"
	} | sha256sum | cut -c1-16)
	dest="$CACHE/$(basename "$scene" .pov)-${W}x$H-s$s-$key.exr"
	if [[ ! -f $dest ]]; then
		mkdir -p "$CACHE" || return 1
		tmp=$(mktemp -d "$T/ref.XXXXXX")
		povray -D -GA +FE -A +WT1 +W$((s * W)) +H$((s * H)) "+I\"$scene\"" \
			"+L\"$(dirname "$scene")\"" "+O\"$tmp/hi.exr\"" 2>"$tmp/log" ||
			{ tail -5 "$tmp/log" >&2; return 1; }
		"$BOXDOWN" "$tmp/hi.exr" "$s" "$tmp/ref.exr" >/dev/null || return 1
		mv "$tmp/ref.exr" "$dest"
		rm -rf "$tmp"
	fi
	echo "$dest"
}

# uniform SCENE CPU REF: the relMSE of the finest uniform resolution-scaled
# render (antialiasing off, one thread) that costs at most CPU seconds,
# printed as "SCALE CPU RELMSE"; scale 1 if even that costs more.
# Scales up to 10.
uniform() {
	local scene=$1 budget=$2 ref=$3 s best="" t
	for s in 1 2 3 4 5 6 7 8 9 10; do
		local TIMEFORMAT='%3U %3S'
		t=$({ time povray -D -GA +FE -A +WT1 +W$((s * W)) +H$((s * H)) "+I\"$scene\"" \
			"+L\"$(dirname "$scene")\"" "+O\"$T/u.exr\"" 2>/dev/null; } 2>&1 |
			awk '{ print $1 + $2 }')
		if ((s > 1)) && num 'a > b' "$t" "$budget"; then
			break
		fi
		"$BOXDOWN" "$T/u.exr" "$s" "$T/ud.exr" >/dev/null
		best="$s $t $(relmse "$T/ud.exr" "$ref")"
	done
	echo "$best"
}

echo "# povpress render tests in $T"

# --- usage -------------------------------------------------------------------
for c in render plan merge; do
	check "$c --help exits 0" quiet "$PP" $c --help
done
"$PP" render 2>/dev/null
check "render without a scene is a usage error (2)" test $? -eq 2
"$PP" render "$SC/smooth_empty.pov" -o "$T/x.exr" --target nope 2>/dev/null
check "render with a bad --target is a usage error (2)" test $? -eq 2
msg=$("$PP" render "$SC/smooth_empty.pov" -o "$T/x.exr" --radiosity-scale 3 2>&1)
rc=$?
check "render with --radiosity-scale 3 (not 0, 1, 2, 4 or 8) is a usage error (2)" \
	test $rc -eq 2
check "... whose message names the option" grep -q -- "--radiosity-scale" <<<"$msg"

# --- bad input: a clear message, non-zero, no output --------------------------
fault() { # fault DESCRIPTION PATTERN OUTPUT COMMAND...: fails, says PATTERN, no OUTPUT
	local d=$1 pat=$2 out=$3 rc
	shift 3
	"$@" >"$T/f.out" 2>"$T/f.err"
	rc=$?
	if ((rc != 0)) && grep -q -- "$pat" "$T/f.err" && [[ ! -e $out ]]; then
		ok "$d"
	else
		bad "$d (exit $rc, stderr: $(head -c 300 "$T/f.err"))"
	fi
}
fault "missing scene: named, exit != 0, no output" "cannot read scene '$T/none.pov'" "$T/o.exr" \
	"$PP" render "$T/none.pov" -o "$T/o.exr" -W 32 -H 24
printf 'camera { location <0, 1, -3> look_at 0 }\nlight_source { <2, 4, -3> rgb 1 }\n\nsphere { 0, 1 pigment { rgb 1 }\nbox { 0 }\n' >"$T/syntax.pov"
fault "syntax error: POV-Ray's file and line, no output" "syntax.pov' line 5" "$T/o.exr" \
	"$PP" render "$T/syntax.pov" -o "$T/o.exr" -W 32 -H 24
[[ ! -e "$T/o.exr.work" ]]
check "syntax error: no work directory left behind" test $? -eq 0
fault "missing povray binary: named, no output" "cannot run '/nonexistent/povray'" "$T/o.exr" \
	env POVPRESS_POVRAY=/nonexistent/povray "$PP" render "$SC/smooth_empty.pov" -o "$T/o.exr" -W 32 -H 24
fault "output in a missing directory: named, no output" "cannot write output '$T/no/o.exr'" \
	"$T/no/o.exr" "$PP" render "$SC/smooth_empty.pov" -o "$T/no/o.exr" -W 32 -H 24
mkdir -p "$T/ro" && chmod 555 "$T/ro"
if [[ $(id -u) != 0 ]]; then
	fault "unwritable output directory: named, no output" "cannot write output" "$T/ro/o.exr" \
		"$PP" render "$SC/smooth_empty.pov" -o "$T/ro/o.exr" -W 32 -H 24
fi
fault "output path that is a directory: named" "is a directory" "$T/ro/none" \
	"$PP" render "$SC/smooth_empty.pov" -o "$T/ro" -W 32 -H 24

# --- the loop on bundled scenes: better than the base pass and, on the
# scenes of RENDER_WIN_SCENES, than a uniform render of the same CPU cost ----
for name in ${RENDER_TEST_SCENES:-soft_shadows glossy_reflection thin_geometry}; do
	scene="$SC/$name.pov"
	ref=$(reference "$scene") || { bad "$name: reference render failed"; continue; }
	"$PP" render "$scene" -o "$T/$name.exr" -W $W -H $H --target 1e-3 -q \
		--report "$T/$name.json" --workdir "$T/$name.work" --keep-workdir
	if (($? != 0)); then
		bad "$name: render failed"
		continue
	fi
	final=$(relmse "$T/$name.exr" "$ref")
	base=$(relmse "$T/$name.work/base.exr" "$ref")
	cpu=$(jget "$T/$name.json" all_cpu_s)
	est=$(jget "$T/$name.json" est_relmse)
	read -r us ucpu urel <<<"$(uniform "$scene" "$cpu" "$ref")"
	echo "# $name: base $base, final $final (estimated $est) in $cpu CPU s;" \
		"uniform scale $us ($ucpu CPU s) $urel"
	check "$name: final relMSE below the base pass's" num 'a < b' "$final" "$base"
	# each refinement pass's plan predicted a fall from the estimate before
	# it (planned_relmse); the base pass has no plan (null)
	check "$name: the report's planned_relmse: null for pass 0, below the estimate before each pass" \
		awk '/"pass": [0-9]/ { n++; match($0, /"est_relmse": [^,]*/); e = substr($0, RSTART + 14, RLENGTH - 14)
			match($0, /"planned_relmse": [^,]*/); p = substr($0, RSTART + 18, RLENGTH - 18)
			if (n == 1) { if (p != "null") b = 1 } else if (p == "null" || !(p + 0 < prev + 0)) b = 1
			prev = e } END { exit b || n < 2 }' "$T/$name.json"
	# asserted where the loop is clearly ahead; on glossy_reflection it ties
	# with uniform scale 8 or 9 (measured 1.03 and 0.85 against the 625-sample
	# reference), and which of them fits the CPU is a matter of timing noise.
	# soft_shadows at 80x60 neither: the loop stops at the target after one
	# pass, 2.9e-4 in 0.37 to 0.45 CPU s, where uniform scale 7 has 4.4e-4 in
	# 0.28 s and scale 8 1.4e-4 in 0.39 s (its regular grids alias on the
	# checkerboard, scale 10 2.5e-4, scale 12 6.3e-4)
	case " ${RENDER_WIN_SCENES:-thin_geometry} " in
	*" $name "*)
		check "$name: final relMSE below a uniform render of the same CPU cost" \
			num 'a < b' "$final" "$urel"
		;;
	esac
	check "$name: report has a pass list and totals" \
		grep -q '"passes": \[' "$T/$name.json"
	# elapsed_s counts the final image's and error map's writes, which the
	# passes' wall_s (summed in totals) leave out
	check "$name: the report's elapsed_s above its passes' wall_s" \
		num 'a > b' "$(jget "$T/$name.json" elapsed_s)" "$(jget "$T/$name.json" wall_s)"
	check "$name: error map has error, samples, order and pass channels" \
		oiiotool "$T/$name.errors.exr" --ch error,samples,order,pass -o "$T/em.exr"
done

# --- the final image: the samples' mean blended with the fit ---------------
# glossy_reflection's work directory finished again with --final samples
# (--target 1 renders nothing more): the blend is closer on the same samples
# (measured 2.5e-4 against 4.2e-4 with the hidden edges charged whole, 1.6e-4
# against 3.6e-4 with them weighed; taking the whole fit where it was
# predicted twice as close, or nothing, 3.6e-4 on the first), and some
# pixels take part of the fit (the error map's fit channel strictly between
# 0 and 1).
if [[ -d $T/glossy_reflection.work && -f $T/glossy_reflection.exr ]]; then
	ref=$(reference "$SC/glossy_reflection.pov")
	cp -r "$T/glossy_reflection.work" "$T/gs.work"
	"$PP" render "$SC/glossy_reflection.pov" -o "$T/gs.exr" -W $W -H $H --target 1 \
		--final samples -q --workdir "$T/gs.work" --resume
	check "final samples: the work directory finished again" test $? -eq 0
	auto=$(relmse "$T/glossy_reflection.exr" "$ref")
	samples=$(relmse "$T/gs.exr" "$ref")
	echo "# glossy_reflection: --final auto $auto, samples $samples"
	check "final auto: both images measured" test -n "$auto" -a -n "$samples"
	check "final auto: under 0.75 x the samples' mean's relMSE on the same samples" \
		num 'a < 0.75 * b' "${auto:-1}" "${samples:-0}"
	# the blend unfiltered (--final blend): the filter of --final auto
	# (driver/denoise.c) takes a share of its error on the same samples
	# (0.76 to 0.78 of it on glossy_reflection at 160x120, 4 runs; 0.88 at
	# this test's 80x60, 3 runs)
	cp -r "$T/glossy_reflection.work" "$T/gb.work"
	"$PP" render "$SC/glossy_reflection.pov" -o "$T/gb.exr" -W $W -H $H --target 1 \
		--final blend -q --workdir "$T/gb.work" --resume
	check "final blend: the work directory finished again" test $? -eq 0
	blend=$(relmse "$T/gb.exr" "$ref")
	echo "# glossy_reflection: --final blend $blend"
	check "final auto: under 0.95 x the unfiltered blend's relMSE on the same samples" \
		num 'a < 0.95 * b' "${auto:-1}" "${blend:-0}"
	check "final blend: under the samples' mean's relMSE" \
		num 'a < b' "${blend:-1}" "${samples:-0}"
	partial=$(oiiotool "$T/glossy_reflection.errors.exr" --ch fit --mulc 2 --subc 1 --abs \
		--printstats 2>/dev/null | awk '/Stats Min/ { print $3 }')
	check "final auto: some pixels blend the fit and their mean" num 'a < 1' "${partial:-1}"
else
	bad "final auto: no glossy_reflection run to finish again (RENDER_TEST_SCENES?)"
fi

# --- radiosity: the solution from a frame 480+ pixels wide ------------------
# At 80x60 the radiosity pass renders 320x240 on one thread; without it the
# region renders reuse the base pass's solution from an 80-pixel frame.  One
# POV-Ray thread throughout: a solution computed on several is another every
# run.
scene="$SC/radiosity_room.pov"
if ref=$(reference "$scene"); then
	for mode in pass none; do
		opt=()
		[[ $mode == none ]] && opt=(--radiosity-scale 0)
		"$PP" render "$scene" -o "$T/rad-$mode.exr" -W $W -H $H --target 1e-3 --max-passes 2 \
			-q --report "$T/rad-$mode.json" "${opt[@]}" -- +WT1 || bad "radiosity ($mode): render failed"
	done
	with=$(relmse "$T/rad-pass.exr" "$ref")
	without=$(relmse "$T/rad-none.exr" "$ref")
	echo "# radiosity_room: relMSE $with with the radiosity pass, $without without"
	check "radiosity: the report names the radiosity pass's scale (4)" \
		grep -q '"radiosity_scale": 4' "$T/rad-pass.json"
	check "radiosity: --radiosity-scale 0 renders no radiosity pass" \
		grep -q '"radiosity_scale": 1' "$T/rad-none.json"
	# (0.46 against the reference; with the reference rendered on several
	# threads, whose radiosity solution differs from render to render, 0.48
	# to 0.84 against four of them)
	check "radiosity: the radiosity pass lowers the relMSE by a fifth or more" \
		num 'a <= 0.8 * b' "$with" "$without"
else
	bad "radiosity_room: reference render failed"
fi

# --- --sampler: grid renders, resolution scaling, POV-Ray's antialiasing ----
msg=$("$PP" render "$SC/smooth_empty.pov" -o "$T/x.exr" --sampler random 2>&1)
rc=$?
check "render with --sampler random (not auto, grid, scale, aa or jitter) is a usage error (2)" \
	test $rc -eq 2
check "... whose message names the option" grep -q -- "--sampler" <<<"$msg"
scene="$SC/soft_shadows.pov"
if ref=$(reference "$scene"); then
	for m in scale aa grid jitter; do
		"$PP" render "$scene" -o "$T/smp-$m.exr" -W $W -H $H --target 3e-4 --sampler $m -q \
			--keep-workdir --report "$T/smp-$m.json" -- +WT1 ||
			bad "--sampler $m: render failed"
	done
	sc=$(relmse "$T/smp-scale.exr" "$ref")
	aa=$(relmse "$T/smp-aa.exr" "$ref")
	echo "# soft_shadows --target 3e-4: relMSE $sc with --sampler scale, $aa with aa"
	check "--sampler aa: the report says so" grep -q '"sampler": "aa"' "$T/smp-aa.json"
	check "--sampler aa: a region was rendered antialiased" \
		test -n "$(compgen -G "$T/smp-aa.exr.work/p*-aa.exr")"
	check "--sampler scale: no region was" \
		test -z "$(compgen -G "$T/smp-scale.exr.work/p*-aa.exr")"
	# (measured 2.4e-5 and 2.6e-5; a fold that trusted the antialiased render
	# beyond what it proved worth was 5.5e-3)
	check "--sampler aa: relMSE at most twice --sampler scale's" num 'a <= 2 * b' "$aa" "$sc"
	gr=$(relmse "$T/smp-grid.exr" "$ref")
	echo "# ... and $gr with --sampler grid"
	check "--sampler grid: the report says so" grep -q '"sampler": "grid"' "$T/smp-grid.json"
	# a grid render is twice the image's size whatever its scale; scaling's
	# scale-4 render is four times
	g4=$(compgen -G "$T/smp-grid.exr.work/p*-s4.exr" | head -n 1)
	s4=$(compgen -G "$T/smp-scale.exr.work/p*-s4.exr" | head -n 1)
	check "--sampler grid: a scale-4 region rendered at twice the width" \
		grep -q "$((2 * W)) x *$((2 * H))" <(iinfo "$g4" 2>&1)
	check "--sampler scale: at four times the width" \
		grep -q "$((4 * W)) x *$((4 * H))" <(iinfo "$s4" 2>&1)
	# (measured 1.2e-4, in a quarter of scaling's CPU time: at 80x60
	# scaling's frames cost little, and its regular grids' fold differences
	# at the horizon keep the loop going to scale 16, to 2.5e-5)
	check "--sampler grid: relMSE within the target" num 'a <= 3e-4' "$gr"
	ji=$(relmse "$T/smp-jitter.exr" "$ref")
	echo "# ... and $ji with --sampler jitter"
	check "--sampler jitter: the report says so" grep -q '"sampler": "jitter"' "$T/smp-jitter.json"
	check "--sampler jitter: no scale-2 region" \
		test -z "$(compgen -G "$T/smp-jitter.exr.work/p*-s2.exr")"
	j4=$(compgen -G "$T/smp-jitter.exr.work/p01-*-s4.exr" | head -n 1)
	check "--sampler jitter: the first pass renders scale 4, at twice the width" \
		grep -q "$((2 * W)) x *$((2 * H))" <(iinfo "$j4" 2>&1)
	check "--sampler jitter: relMSE within the target" num 'a <= 3e-4' "$ji"
else
	bad "soft_shadows: reference render failed"
fi

# --- --sampler auto with focal blur: resolution scaling to larger frames -----
# POV-Ray's antialiasing converges slowly on focal blur (each sub-sample
# draws its blur offsets from a position-keyed table), so auto keeps scaling
# up to 8 Mpixel frames there: at 320x240 scale 4 (1280x960) is four times
# the width rather than a grid render at twice it.  The keywords count only
# outside comments and strings, and "aperture 0" not at all.
cat >"$T/focal.pov" <<'EOF'
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 1, -3> look_at <0, 0.5, 0>
	aperture 0.4 blur_samples 2 focal_point <0, 0.5, 0> }
light_source { <2, 4, -3> rgb 1 }
plane { y, 0 pigment { checker rgb 0.1 rgb 0.9 } }
sphere { <0, 0.5, 0>, 0.5 pigment { rgb <1, 0.3, 0.2> } }
EOF
sed 's|^\taperture.*|\taperture 0 blur_samples 2 // aperture 0.4\n\t/* aperture */ #debug "aperture 1" }|' \
	"$T/focal.pov" >"$T/nofocal.pov"
"$PP" render "$T/focal.pov" -o "$T/focal.exr" -W 320 -H 240 --target 2e-3 --max-passes 2 -q \
	--keep-workdir --report "$T/focal.json" -- +WT1 || bad "focal blur: render failed"
check "focal blur: the report says the scene has it" grep -q '"focal_blur": true' "$T/focal.json"
f4=$(compgen -G "$T/focal.exr.work/p02-*-s4.exr" | head -n 1)
check "focal blur: scale 4 at 320x240 by resolution scaling, four times the width" \
	grep -q "1280 x *960" <(iinfo "$f4" 2>&1)
for f in nofocal:"$T/nofocal.pov" bundled:"$SC/focal_blur.pov"; do
	"$PP" render "${f#*:}" -o "$T/${f%%:*}.exr" -W 40 -H 30 --max-passes 0 -q \
		--report "$T/${f%%:*}.json" -- +WT1 || bad "focal blur (${f%%:*}): render failed"
done
check "focal blur: 'aperture 0', or aperture in comments and strings, is not focal blur" \
	grep -q '"focal_blur": false' "$T/nofocal.json"
check "focal blur: scenes/focal_blur.pov has it" grep -q '"focal_blur": true' "$T/bundled.json"
"$PP" render "$SC/focal_blur.pov" -o "$T/fb-grid.exr" -W 40 -H 30 --max-passes 0 -q --sampler grid \
	--report "$T/fb-grid.json" -- +WT1 || bad "focal blur, --sampler grid: render failed"
check "focal blur: only --sampler auto looks for it" grep -q '"focal_blur": false' "$T/fb-grid.json"

# --- --sampler auto with assumed_gamma other than 1: resolution scaling only --
# POV-Ray's antialiasing averages its samples in the scene's gamma encoding,
# resolution scaling's box average linearly: under auto such a scene gets no
# grid render and no antialiased render.  A checkerboard whose squares are
# finer than the pixels has error everywhere (at 320x240 auto would render
# scale 4 as a grid render, 640x480, and may take the jittered first step).
cat >"$T/gamma.pov" <<'EOF'
#version 3.7;
global_settings { assumed_gamma 1.8 }
camera { location <0, 1, -3> look_at <0, 0.5, 0> }
light_source { <2, 4, -3> rgb 1 }
plane { y, 0 pigment { checker rgb 0.05 rgb 0.95 scale 0.02 } }
sphere { <0, 0.5, 0>, 0.5 pigment { rgb <1, 0.3, 0.2> } finish { specular 0.8 roughness 0.002 } }
EOF
sed 's|assumed_gamma 1.8|assumed_gamma 1.0 // assumed_gamma 1.8\n#debug "assumed_gamma 2.2"|' \
	"$T/gamma.pov" >"$T/gamma1.pov"
"$PP" render "$T/gamma.pov" -o "$T/gamma.exr" -W 320 -H 240 --target 1e-3 --max-passes 2 -v \
	--keep-workdir --report "$T/gamma.json" -- +WT1 2>"$T/gamma.log" || bad "gamma: render failed"
check "gamma: the report gives the scene's assumed_gamma" grep -q '"assumed_gamma": 1.8,' "$T/gamma.json"
check "gamma: auto chooses resolution scaling" grep -q '"sampler_chosen": "scale"' "$T/gamma.json"
check "gamma: -v says so" grep -q "assumed_gamma is 1.8" "$T/gamma.log"
g4=$(compgen -G "$T/gamma.exr.work/p0[12]-*-s4.exr" | head -n 1)
check "gamma: a scale-4 render, by resolution scaling (1280x960)" \
	grep -q "1280 x *960" <(iinfo "$g4" 2>&1)
check "gamma: no antialiased render" \
	test -z "$(compgen -G "$T/gamma.exr.work/p0*-aa.exr")"
"$PP" render "$T/gamma1.pov" -o "$T/gamma1.exr" -W 40 -H 30 --max-passes 0 -q \
	--report "$T/gamma1.json" -- +WT1 || bad "gamma 1: render failed"
check "gamma: 1, or a value in comments and strings, is not another gamma" \
	grep -q '"assumed_gamma": 1,' "$T/gamma1.json"
"$PP" render "$T/gamma.pov" -o "$T/gamma-grid.exr" -W 40 -H 30 --max-passes 0 -q --sampler grid \
	--report "$T/gamma-grid.json" -- +WT1 || bad "gamma, --sampler grid: render failed"
check "gamma: --sampler grid is kept" grep -q '"sampler_chosen": "grid"' "$T/gamma-grid.json"
# povpress scene prints what render reads from the scene file (and the
# benchmark reads a scene's gamma through it: such a scene's references are
# rendered without antialiasing).  The last gamma given as a number counts,
# not one in a comment or a string, nor an expression.
cat >"$T/gamma2.pov" <<'EOF'
#version 3.7;
#declare G = 1.5;
global_settings { assumed_gamma
  2.0 }
global_settings { assumed_gamma G } // assumed_gamma 1.9
/* assumed_gamma 2.2 */
#declare S = "assumed_gamma 1.7 // not a comment";
#declare my_assumed_gamma = 2.4;
camera { location <0, 1, -3> look_at <0, 0.5, 0> }
light_source { <2, 4, -3> rgb 1 }
sphere { <0, 0.5, 0>, 0.5 pigment { rgb <1, 0.3, 0.2> } }
EOF
"$PP" render "$T/gamma2.pov" -o "$T/gamma2.exr" -W 40 -H 30 --max-passes 0 -q \
	--report "$T/gamma2.json" -- +WT1 || bad "gamma 2: render failed"
check "gamma: the last gamma given as a number (2.0)" grep -q '"assumed_gamma": 2,' "$T/gamma2.json"
scene_key() { "$PP" scene "$1" | sed -n "s/^$2: //p"; }
# bundled KEY: "NAME.pov VALUE" for each bundled scene
bundled() { for sc in "$SC"/*.pov; do echo "$(basename "$sc") $(scene_key "$sc" "$1")"; done; }
check "scene: 1.8 where render reads 1.8" test "$(scene_key "$T/gamma.pov" assumed_gamma)" = 1.8
check "scene: 1 where render reads 1" test "$(scene_key "$T/gamma1.pov" assumed_gamma)" = 1
check "scene: 2 where render reads 2.0" test "$(scene_key "$T/gamma2.pov" assumed_gamma)" = 2
check "scene: 2.2 in scenes/legacy_gamma.pov and no other gamma in the bundled scenes" \
	test "$(bundled assumed_gamma | awk '$2 != 1')" = "legacy_gamma.pov 2.2"
check "scene: focal blur in scenes/focal_blur.pov alone" \
	test "$(bundled focal_blur | awk '$2 == "yes" { print $1 }')" = "focal_blur.pov"
check "scene: radiosity named in scenes/radiosity_room.pov alone" \
	test "$(bundled radiosity | awk '$2 == "yes" { print $1 }')" = "radiosity_room.pov"

# --- --sampler auto where the error sits in a few pixels: antialiasing first -
# hdr_highlights' lamps and their reflections hold half the base pass's
# estimated error in 0.1% of the pixels at 160x120 (at 80x60, 0.1% is 4
# pixels and they hold a quarter); soft_shadows' is spread.
# auto_and_scale TAG SCENE: SCENE at 160x120 and --target 3e-3 with --sampler
# auto and scale, into $T/TAG-auto.exr and $T/TAG-scale.exr (their work
# directories kept, the -v logs in $T/TAG-auto.log and $T/TAG-scale.log)
auto_and_scale() {
	local m
	for m in auto scale; do
		"$PP" render "$2" -o "$T/$1-$m.exr" -W 160 -H 120 --target 3e-3 --sampler $m \
			-v --keep-workdir -- +WT1 2>"$T/$1-$m.log" ||
			bad "$(basename "$2" .pov), --sampler $m: render failed"
	done
}
# auto_beats_scale TAG SCENE REF FACTOR WHAT: check WHAT, that auto_and_scale
# TAG SCENE's relMSE against REF with auto is at most FACTOR times scale's
# (both printed)
auto_beats_scale() {
	local au sc
	au=$(relmse "$T/$1-auto.exr" "$3")
	sc=$(relmse "$T/$1-scale.exr" "$3")
	echo "# $(basename "$2" .pov) 160x120 --target 3e-3: relMSE $au with --sampler auto, $sc with scale"
	check "$5" num "a <= $4 * b" "$au" "$sc"
}
scene="$SC/hdr_highlights.pov"
if ref=$(W=160 H=120 reference "$scene"); then
	auto_and_scale hl "$scene"
	check "highlights: the first pass renders antialiased regions in scale 2's place" \
		test -n "$(compgen -G "$T/hl-auto.exr.work/p01-*-aa.exr")"
	check "... and no scale-2 region" test -z "$(compgen -G "$T/hl-auto.exr.work/p01-*-s2.exr")"
	a1=$(compgen -G "$T/hl-auto.exr.work/p01-*-aa.exr" | head -n 1)
	check "... at twice the image's size" grep -q "320 x *240" <(iinfo "$a1" 2>&1)
	check "... and says so, at depth 5" grep -q "error sits in few pixels: .* depth 5" "$T/hl-auto.log"
	check "--sampler scale: no antialiased region" \
		test -z "$(compgen -G "$T/hl-scale.exr.work/p*-aa.exr")"
	# (measured 3.3e-4 against 1.8e-3; a weight of 1 for the antialiased
	# render, as --sampler aa gives a pixel with no spread, ended at 6.7e-4)
	auto_beats_scale hl "$scene" "$ref" 0.5 "highlights: relMSE at most half of scale 2's"
else
	bad "hdr_highlights: reference render failed"
fi
# past_share TAG SCENE BUDGET COST KEPT WHAT: one pass of SCENE at 160x120
# under --budget BUDGET with a sample costing COST s, where +R3 over all of
# the pass's antialiased regions is priced past its share; check that the
# log says so, with KEPT (a grep pattern) of them at +R3, and that no render
# was lost at the deadline; the work directory is $T/TAG.exr.work
past_share() {
	local tag=$1 scene=$2 budget=$3 cost=$4 kept=$5 what=$6
	"$PP" render "$scene" -o "$T/$tag.exr" -W 160 -H 120 --budget "$budget" --target 1e-6 -v \
		--max-passes 1 --cost-sample "$cost" --keep-workdir -- +WT1 2>"$T/$tag.log" ||
		bad "$what: render failed"
	check "$what: +R3 priced past the pass's share, and it says so" \
		grep -q "would not fit the budget even at +R3 (about [0-9.]* core-s): $kept at +R3, the rest at scale 2" \
		"$T/$tag.log"
	check "... and no render lost at the deadline" \
		test "$(grep -c "stopped at the budget's end" "$T/$tag.log")" -eq 0
}
# still_life's error is its edges: after the base pass at 160x120 the
# largest 5% of the pixels' estimates hold 0.77 of it, and the first pass
# renders POV-Ray's antialiasing in scale 2's place there too, at depth 4
# (+R4; measured 2.8e-5 at +R3 against 5.2e-4 with --sampler scale);
# radiosity_room's error sits in as few pixels, but it is the radiosity
# solution's: no antialiasing.
scene="$SC/still_life.pov"
if ref=$(S=9 W=160 H=120 reference "$scene"); then
	auto_and_scale sl "$scene"
	check "still_life: the first pass renders antialiased regions in scale 2's place" \
		test -n "$(compgen -G "$T/sl-auto.exr.work/p01-*-aa.exr")"
	check "... and says why, at depth 4" grep -q "error sits at edges: .* depth 4" "$T/sl-auto.log"
	auto_beats_scale sl "$scene" "$ref" 0.25 "still_life: relMSE at most a quarter of scale 2's"
	# under a budget that +R4 would not fit twice over, depth 3 (its edge
	# pass by the cost model about 2.2 core-s at +R4 and 1.4 at +R3,
	# printed by a scratch build, against the pass's share of 2.2 s, about
	# 3.2 core-s by render.c's formula, which +R3 fits 1.5 times over).
	# The cost of a sample is pinned at 2^-17 s: measured, it is rounded to
	# a power of two, and a faster machine's 2^-19 (3 runs of 10 here,
	# 2026-12-03; 2^-18 in the rest) made +R4 fit.  Pinned, the pass is at
	# depth 3 at 2.0 and 2.2 s (three runs each) and at 4 at 4 s (two).
	# (At 1.6 s, a share of 1.9 core-s, +R3 no longer fits 1.5 times over:
	# scale 2, below.)
	"$PP" render "$scene" -o "$T/sl-b2.exr" -W 160 -H 120 --budget 2.2 --target 1e-6 -v \
		--cost-sample 7.62939453125e-06 -- +WT1 2>"$T/sl-b2.log" ||
		bad "still_life --budget 2.2: render failed"
	check "still_life --budget 2.2: the edge pass at depth 3" \
		grep -q "error sits at edges: .* depth 3" "$T/sl-b2.log"
	# the pass's expected duration counts its antialiased renders at their
	# price (edge_render_cost()), not the scale 2 they were planned as
	# (which read 0.1 s for a pass priced at 1.4 core-s)
	price=$(sed -n 's/^pass 1: its antialiased renders took [0-9.]* CPU s, priced at \([0-9.]*\)$/\1/p' \
		"$T/sl-b2.log")
	about=$(sed -n 's/^pass 1: [0-9]* regions\{0,1\}, .* samples, about \([0-9.]*\) s$/\1/p' \
		"$T/sl-b2.log")
	check "... its renders' CPU printed against their price ($price core-s)" \
		num 'a > 0.5' "${price:-0}"
	check "... the pass expected to take their price over the cores (about $about s)" \
		num "a >= 0.5 * b / $(nproc)" "${about:-0}" "${price:-1}"
	# where +R3's price 1.5 times over is more than the pass may spend, the
	# pass renders the scale 2 it was planned as (EDGE_R3_MARGIN; Debian's
	# advanced/bwstripe at 640x480 under --budget 3, every pixel an edge:
	# +R3 priced at 8.2 core-s for a share of 3.7 ran anyway, was stopped
	# at the deadline, and the image was the base pass's, relMSE 0.40 where
	# scale 2 then scale 4 have 0.026); pinned at 2^-15 s a sample, +R3 at
	# 3.9 core-s for 1.1
	past_share sl-b1 "$scene" 1.2 3.0517578125e-05 0 \
		"still_life --budget 1.2, 2^-15 s a sample (no region kept at +R3)"
	check "... its regions file: pass 1 at scale 2 alone" \
		awk -F'\t' '$1 == 1 { k++; if ($6 != 2) b = 1 } END { exit b || !k }' \
		"$T/sl-b1.exr.work/regions.tsv"
	check "... its renders at scale 2, none antialiased" \
		test -n "$(compgen -G "$T/sl-b1.exr.work/p01-*-s2.exr")" -a \
		-z "$(compgen -G "$T/sl-b1.exr.work/p01-*-aa.exr")"
	# folded as taken for edges, the pass's estimate is near the truth
	# (measured 3.1e-5 for 1.4e-5 against this reference; at +R3, the
	# cells' variance the base sample's, 7.5e-5 for 2.8e-5; charged the
	# render pixels' whole spread and every hidden edge, 1.7e-3 for 3.4e-5)
	sle=$("$PP" compare "$T/sl-auto.exr" "$ref" --analysis "$T/sl-auto.errors.exr" |
		awk '$1 == "est_relmse:" { print $2 }')
	slt=$(relmse "$T/sl-auto.exr" "$ref")
	echo "# still_life 160x120 --target 3e-3: estimated relMSE $sle, true $slt"
	check "still_life: the estimate within 4 times the true relMSE" num "a <= 4 * b" "$sle" "$slt"
	check "... and not below a third of it" num "3 * a >= b" "$sle" "$slt"
else
	bad "still_life: reference render failed"
fi
# ... and where +R3 over all the regions would not fit but over some it
# would, those whose +R3 costs least more than their scale 2 keep it, the
# rest go back to scale 2, folded before them (hdr_highlights at 160x120,
# 3e-5 s a sample, 2 s: its lamps and a strip at +R3, its floor at scale 2;
# at 640x480 under --budget 3, unpinned, relMSE 7.2e-4 in three runs, where
# all at scale 2 had 1.1e-3 and all at +R3 1.6e-3, renders lost)
past_share hs "$SC/hdr_highlights.pov" 2 3e-5 "[1-9][0-9]*" \
	"hdr_highlights --budget 2, 3e-5 s a sample (some regions kept at +R3)"
check "... its regions file: pass 1 at scale 2 and at +R3 (scale 0, depth 3), those last" \
	awk -F'\t' '$1 == 1 { if ($6 == 2) { s++; if (a) b = 1 } else if ($6 == 0 && $8 == 3) a++;
		else b = 1 } END { exit b || !s || !a }' "$T/hs.exr.work/regions.tsv"
"$PP" render "$SC/radiosity_room.pov" -o "$T/rr1.exr" -W 160 -H 120 --target 1e-6 \
	--max-passes 1 -v --keep-workdir -- +WT1 2>"$T/rr1.log" || bad "radiosity_room: render failed"
check "radiosity_room: no antialiased region in the first pass" \
	test -z "$(compgen -G "$T/rr1.exr.work/p01-*-aa.exr")"
# starfield's error sits in a few pixels too, but as stars smaller than a
# pixel: the render is twice the image's size so that, where POV-Ray does
# not subdivide, its corners are scale 2's density. At the image's size it
# missed the stars between corners, each such pixel stood at 17 samples all
# dark, estimated 0, and the loop stopped at 1.5e-3 (estimate 5.2e-4).
scene="$SC/starfield.pov"
if ref=$(W=160 H=120 reference "$scene"); then
	"$PP" render "$scene" -o "$T/sf.exr" -W 160 -H 120 --target 3e-4 -v -- +WT1 \
		2>"$T/sf.log" || bad "starfield: render failed"
	check "starfield: antialiasing in scale 2's place" grep -q "error sits in few pixels" "$T/sf.log"
	sf=$(relmse "$T/sf.exr" "$ref")
	echo "# starfield 160x120 --target 3e-4: relMSE $sf"
	check "starfield: relMSE at most 3 times the target (no dark pixel left at 17 samples)" \
		num 'a <= 9e-4' "$sf"
else
	bad "starfield: reference render failed"
fi
# where the error is spread, auto goes straight to scale 4, jittered, when the
# frame at scale 4 takes less than 0.7 s on the cores (samples
# taken as free here), and by scale 2 otherwise (samples taken as dear)
for c in free dear; do
	cs=1e-9
	[[ $c == dear ]] && cs=1e-3
	"$PP" render "$SC/soft_shadows.pov" -o "$T/sp-$c.exr" -W 160 -H 120 --max-passes 1 -v \
		--cost-sample $cs --keep-workdir --report "$T/sp-$c.json" -- +WT1 \
		2>"$T/sp-$c.log" || bad "soft_shadows 160x120 ($c samples): render failed"
done
check "soft_shadows (error spread): no antialiased region either way" \
	test -z "$(compgen -G "$T/sp-*.exr.work/p*-aa.exr")"
check "... samples free: the first pass renders no scale 2" \
	test -z "$(compgen -G "$T/sp-free.exr.work/p*-s2.exr")"
j4=$(compgen -G "$T/sp-free.exr.work/p01-*-s4.exr" | head -n 1)
check "... but scale 4, at twice the size (jittered)" \
	grep -q "320 x *240" <(iinfo "$j4" 2>&1)
check "... and says so" grep -q "no scale 2, scale 4 and up jittered" "$T/sp-free.log"
check "... in the report too" grep -q '"sampler_chosen": "jitter"' "$T/sp-free.json"
check "... the report's sampler is still the option's" grep -q '"sampler": "auto"' "$T/sp-free.json"
check "... samples dear: the first pass renders scale 2" \
	test -n "$(compgen -G "$T/sp-dear.exr.work/p01-*-s2.exr")"
check "... and the report says auto" grep -q '"sampler_chosen": "auto"' "$T/sp-dear.json"
# the choice holds for the run: a resumed run goes on without scale 2
rs=(render "$SC/soft_shadows.pov" -o "$T/rs.exr" -W $W -H $H --cost-sample 1e-9 --target 1e-5
	-q --keep-workdir --report "$T/rs.json")
"$PP" "${rs[@]}" --max-passes 1 -- +WT1 &&
	"$PP" "${rs[@]}" --max-passes 2 --resume -- +WT1 || bad "soft_shadows, resumed: render failed"
check "... resumed, the second pass renders no scale 2 either" \
	test -n "$(compgen -G "$T/rs.exr.work/p02-*.exr")" -a \
	-z "$(compgen -G "$T/rs.exr.work/p*-s2.exr")"
check "... and the report says jitter" grep -q '"sampler_chosen": "jitter"' "$T/rs.json"
"$PP" "${rs[@]}" --max-passes 3 --resume --sampler scale -- +WT1 ||
	bad "soft_shadows, resumed with --sampler scale: render failed"
check "... resumed with --sampler scale, the run goes by it" \
	grep -q '"sampler_chosen": "scale"' "$T/rs.json"
# a run whose first plan renders nothing (the target met) has chosen nothing
"$PP" render "$SC/soft_shadows.pov" -o "$T/tm.exr" -W 48 -H 36 --target 0.5 --cost-sample 1e-9 \
	-v --report "$T/tm.json" -- +WT1 2>"$T/tm.log" || bad "soft_shadows, target 0.5: render failed"
check "... no pass, no choice: the report says auto" grep -q '"sampler_chosen": "auto"' "$T/tm.json"
check "... and no line says otherwise" test "$(grep -c 'no scale 2' "$T/tm.log")" -eq 0
# price LOG NAME: the price -v printed for the render level NAME of a pass
# whose error is spread, and spend LOG what the pass may spend, on the last
# such line (a pass that planned twice, its renders started early not
# matching, prints two)
price() { grep -o "[0-9.]*\( core-s\)\? at $2[,;]" "$1" | tail -n 1 | awk '{ print $1 }'; }
spend() { sed -n 's/.*the pass may spend \([0-9.]*\)$/\1/p' "$1" | tail -n 1; }
# ere TEXT: TEXT as an extended regular expression matching it alone
ere() { printf '%s' "$1" | sed 's/[]\\.+*?(){}|^$[]/\\&/g'; }

# spread_level SCENE TAG LOW HIGH: the first refinement pass of SCENE at
# 320x240 on one core, the cost of a sample pinned at 1e-6 s (spread error,
# its scale-2 regions rendered by POV-Ray's +AM1 at twice the size), under
# a budget that fits the render level LOW (as -v names it) but not the one
# tried before it, HIGH, their prices taken with render.c's SPREAD_MARGIN
# (spread_margin; MARGIN, a fifth argument, for levels of another): a run
# under 30 s
# ($T/TAG-30.exr) prints each level's price and what the pass may spend,
# (budget - elapsed - latency - reserve) x 0.9 core-s on one core, and the
# budget is moved so that the pass may spend the geometric middle of the
# two prices with the margin ($T/TAG.exr, its
# log TAG.log and report TAG.json; moved again, up to three times, where
# it missed).  Checks that the pass so took LOW (on some regions, HIGH on
# the rest),
# rendered at twice the size, marked its pixels and ended within the
# budget; fails when a run fails.
spread_margin=1.25
spread_level() {
	local scene=$1 tag=$2 lo=$3 hi=$4 m=${5:-$spread_margin} b plo phi may m2 a1 try
	local sp=(taskset -c 0 "$PP" render "$scene" -W 320 -H 240 --target 1e-6 --max-passes 1
		--cost-sample 1e-6 --cost-job 0.05 -v --keep-workdir)
	"${sp[@]}" -o "$T/$tag-30.exr" --budget 30 -- +WT1 2>"$T/$tag-30.log" ||
		{ bad "$(basename "$scene") 320x240 --budget 30: render failed"; return 1; }
	plo=$(price "$T/$tag-30.log" "$lo")
	phi=$(price "$T/$tag-30.log" "$hi")
	may=$(spend "$T/$tag-30.log")
	check "$(basename "$scene") under 30 s: the pass's prices at $hi ($phi) and $lo ($plo), $hi the dearer" \
		num 'a > b && b > 0' "${phi:-0}" "${plo:-0}"
	b=30
	# more tries, each moved by what the one before missed by, where the
	# times of the base pass and the analysis moved between the runs or
	# the pass's plan (and so the prices) moved with the budget (a
	# sanitized build's slower analysis leaves the plan less time)
	for try in 1 2 3 4; do
		b=$(awk -v b="$b" -v h="${phi:-1}" -v l="${plo:-1}" -v m="${may:-1}" -v x="$m" \
			-v y="$m" 'BEGIN { printf "%.2f", b - (m - sqrt(x * l * y * h)) / 0.9 }')
		"${sp[@]}" -o "$T/$tag.exr" --budget "$b" --report "$T/$tag.json" -- +WT1 \
			2>"$T/$tag.log" ||
			{ bad "$(basename "$scene") 320x240 --budget $b: render failed"; return 1; }
		plo=$(price "$T/$tag.log" "$lo")
		phi=$(price "$T/$tag.log" "$hi")
		m2=$(spend "$T/$tag.log")
		may=$m2
		num "a >= $m * b && a < $m * c" "${m2:-0}" "${plo:-1}" "${phi:-0}" && break
	done
	check "... under $b s the pass may spend $m2, between $m times $lo's $plo and $m times $hi's $phi" \
		num "a >= $m * b && a < $m * c" "${m2:-0}" "${plo:-1}" "${phi:-0}"
	# the lighter level whole, or on some regions and the dearer on the
	# rest, as far as it fits (spread_mix())
	check "... so $lo in scale 2's place (on some regions, $hi on the rest)" grep -Eq \
		"\(\+AM1\) in place of scale 2, ([0-9]+ at )?$(ere "$lo")( and [0-9]+ at $(ere "$hi"))?\$" \
		"$T/$tag.log"
	check "... no region of scale 2" \
		awk -F'\t' '$1 == 1 && $6 == 2 { f = 1 } END { exit f }' "$T/$tag.exr.work/regions.tsv"
	a1=$(compgen -G "$T/$tag.exr.work/p01-*-aa.exr" | head -n 1)
	check "... at twice the image's size" grep -q "640 x *480" <(iinfo "$a1" 2>&1)
	check "... its pixels marked (scales bit 9)" \
		num 'a >= 512 && a < 1024' "$(oiiotool "$T/$tag.errors.exr" --ch scales \
			--printstats 2>/dev/null | awk '/Max:/ { print $3; exit }')"
	check "... within the budget, the final image and error map included" \
		num 'a <= b' "$(jget "$T/$tag.json" elapsed_s)" "$b"
}

# spread error where the frame at scale 4 is dearer than 0.7 s on the cores
# but a sample costs at most 1.5 microseconds (thin_geometry at 320x240 on
# one core, the cost of a sample pinned at 1e-6 s): the first pass renders
# scale 2's regions as POV-Ray's +AM1 +A0.03 +R4 at twice the size (at
# 640x480 on two cores, unpinned, relMSE 1.4e-4 where scale 2 had 4.3e-4;
# here, one pass against scale 2's one, 2.4e-4 against 6.1e-3)
scene="$SC/thin_geometry.pov"
if ref=$(W=320 H=240 reference "$scene"); then
	for m in auto scale; do
		taskset -c 0 "$PP" render "$scene" -o "$T/am1-$m.exr" -W 320 -H 240 --target 3e-3 \
			--max-passes 1 --sampler $m --cost-sample 1e-6 -v --keep-workdir -- +WT1 \
			2>"$T/am1-$m.log" ||
			bad "thin_geometry 320x240 --sampler $m: render failed"
	done
	check "thin_geometry (spread, cheap samples, a dear frame): +AM1 in scale 2's place" \
		grep -q "error is spread and samples are cheap: .* (+AM1) in place of scale 2, depth 3" \
		"$T/am1-auto.log"
	check "... its regions file says so (scale 0, depth 3, edges 2)" \
		awk -F'\t' '$1 == 1 && $6 == 0 && $8 == 3 && $9 == 2 { f = 1 } END { exit !f }' \
		"$T/am1-auto.exr.work/regions.tsv"
	check "... and no scale-2 region" test -z "$(compgen -G "$T/am1-auto.exr.work/p01-*-s2.exr")"
	a1=$(compgen -G "$T/am1-auto.exr.work/p01-*-aa.exr" | head -n 1)
	check "... at twice the image's size" grep -q "640 x *480" <(iinfo "$a1" 2>&1)
	# one pass: no scale above 2, so bit 9 is the largest a pixel can have
	check "... its pixels marked (scales bit 9)" \
		num 'a >= 512 && a < 1024' "$(oiiotool "$T/am1-auto.errors.exr" --ch scales \
			--printstats 2>/dev/null | awk '/Max:/ { print $3; exit }')"
	sc=$(relmse "$T/am1-scale.exr" "$ref")
	# judge IMAGE WHAT: a one-pass render's relMSE, at most half of scale
	# 2's, and its estimate, within 4 times (measured with +R4 9.3e-5 for
	# 2.4e-4: thin lines no sample touched, see ACC_AA_SPREAD_BIT; against
	# a reference at scale 9, whose own error is of that size here, 4.8e-4)
	judge() {
		local rel est
		rel=$(relmse "$1" "$ref")
		est=$(est_relmse "$1" "$ref")
		echo "# thin_geometry 320x240, one pass, one core: relMSE $rel $2 (estimated $est), $sc with scale 2"
		check "... relMSE at most half of scale 2's" num 'a <= 0.5 * b' "$rel" "$sc"
		check "... its estimate within 4 times the true relMSE" \
			num 'a <= 4 * b && 4 * a >= b' "$est" "$rel"
	}
	judge "$T/am1-auto.exr" "with +AM1 +A0.03 +R4"
	check "--sampler scale: no antialiased region" \
		test -z "$(compgen -G "$T/am1-scale.exr.work/p*-aa.exr")"
	# a sample at 1.8 microseconds: dear for a run without a budget (its
	# cost rounded to 2^-19, above SPREAD_SAMPLE_S), cheap under one
	# (measured, at most SPREAD_SAMPLE_BUDGET_S)
	for m in target budget; do
		opt=(--target 3e-3)
		[[ $m == budget ]] && opt=(--target 1e-6 --budget 30)
		taskset -c 0 "$PP" render "$scene" -o "$T/am1-$m.exr" -W 320 -H 240 "${opt[@]}" \
			--max-passes 1 --cost-sample 1.8e-6 -v --keep-workdir -- +WT1 \
			2>"$T/am1-$m.log" || bad "thin_geometry 320x240, 1.8e-6 s a sample, $m: render failed"
	done
	check "thin_geometry at 1.8e-6 s a sample, without a budget: scale 2, no +AM1" \
		test -n "$(compgen -G "$T/am1-target.exr.work/p01-*-s2.exr")" -a \
		-z "$(compgen -G "$T/am1-target.exr.work/p01-*-aa.exr")"
	check "... under a budget: +AM1 in scale 2's place" \
		grep -q "error is spread and samples are cheap: .* (+AM1) in place of scale 2" \
		"$T/am1-budget.log"
	# under a budget that +A0.03 +R4 does not fit but the lighter +A0.1 +R3
	# does (ACC_AA_FOR_SPREAD_R3), that one (spread_level, above)
	if spread_level "$scene" r3 "+A0.1 +R3" "+A0.03 +R4"; then
		check "... its regions file says so (scale 0, edges 3)" \
			awk -F'\t' '$1 == 1 && $6 == 0 && $9 == 3 { f = 1 } END { exit !f }' \
			"$T/r3.exr.work/regions.tsv"
		judge "$T/r3.exr" "with +AM1 +A0.1 +R3"
		check "... above that of the run under 30 s (+R6)" num 'a > b' \
			"$(relmse "$T/r3.exr" "$ref")" "$(relmse "$T/r3-30.exr" "$ref")"
	fi
	# under a budget that fits +A0.03 +R5 but not +R6 (ACC_AA_FOR_SPREAD_R5
	# and _R6, render.c's SPREAD_DEEP_MARGIN), +R5 (on some regions +R6),
	# which errs less than +R4 without a budget (measured 1.2e-4 against
	# 1.7e-4)
	if spread_level "$scene" r5 "+A0.03 +R5" "+A0.03 +R6" 1.4; then
		check "... its regions file says so (scale 0, edges 5, or 6 on some)" \
			awk -F'\t' '$1 == 1 && $6 == 0 && $9 == 5 { f = 1 }
				$1 == 1 && $6 == 0 && ($9 < 5 || $9 > 6) { g = 1 }
				END { exit !(f && !g) }' "$T/r5.exr.work/regions.tsv"
		judge "$T/r5.exr" "with +AM1 +A0.03 +R5"
		check "... below +R4's" num 'a < b' "$(relmse "$T/r5.exr" "$ref")" \
			"$(relmse "$T/am1-auto.exr" "$ref")"
	fi
else
	bad "thin_geometry 320x240: reference render failed"
fi
# ... and where neither +A0.1 +R3 nor +A0.03 +R2 fits, the lightest, +A0.3
# +R2 (ACC_AA_FOR_SPREAD_FLOOR), on a texture: horizon_texture.  Against
# the run under 30 s (+R4, several times less error than either) it errs
# less than scale 2 in the same pass under the same budget (measured 2.1e-3
# against 6.1e-3; on soft_shadows, no texture, the two erred alike).
scene="$SC/horizon_texture.pov"
if spread_level "$scene" floor "+A0.3 +R2" "+A0.03 +R2"; then
	check "... its regions file says so (scale 0, edges 4)" \
		awk -F'\t' '$1 == 1 && $6 == 0 && $9 == 4 { f = 1 } END { exit !f }' \
		"$T/floor.exr.work/regions.tsv"
	b=$(jget "$T/floor.json" budget)
	taskset -c 0 "$PP" render "$scene" -o "$T/floor-s2.exr" -W 320 -H 240 --target 1e-6 \
		--max-passes 1 --cost-sample 1e-6 --cost-job 0.05 --sampler scale --budget "$b" \
		-q -- +WT1 || bad "horizon_texture 320x240 --sampler scale --budget $b: render failed"
	fl=$(relmse "$T/floor.exr" "$T/floor-30.exr")
	s2=$(relmse "$T/floor-s2.exr" "$T/floor-30.exr")
	echo "# horizon_texture 320x240, one pass, one core, against +R4: relMSE $fl at +A0.3 +R2, $s2 at scale 2"
	check "... relMSE at most 0.6 of scale 2's under the same budget" num 'a <= 0.6 * b' "$fl" "$s2"
fi

# --- under a budget the cost map starts from the base pass's progress lines --
# (base_cost_map()): glossy_reflection's reflecting floor, the lower half of
# the frame, costs 8 to 14 times its sky and wall a sample (the halves at
# 320x240 on one thread, 0.53 and 0.067 CPU s); the error map's cost channel
# is the map.  Without a budget, or with --cost-sample, it is 1 everywhere.
cost_avg() { # cost_avg ERRORMAP CUT: the cost channel's mean over CUT (WxH+X+Y)
	oiiotool "$1" --ch cost --cut "$2" --printstats 2>/dev/null | awk '/Avg:/ { print $3; exit }'
}
cost_range() { # cost_range ERRORMAP: the cost channel's min and max
	oiiotool "$1" --ch cost --printstats 2>/dev/null |
		awk '/Min:/ { lo = $3 } /Max:/ { hi = $3 } END { print lo, hi }'
}
"$PP" render "$SC/glossy_reflection.pov" -o "$T/cm.exr" -W 640 -H 480 --budget 30 \
	--max-passes 0 -v 2>"$T/cm.log" || bad "glossy_reflection 640x480 --budget 30: render failed"
check "glossy_reflection under a budget: a cost map from the base pass's progress lines" \
	grep -q "a sample's cost from its progress lines" "$T/cm.log"
up=$(cost_avg "$T/cm.errors.exr" 640x192+0+0)
dn=$(cost_avg "$T/cm.errors.exr" 640x192+0+288)
echo "# glossy_reflection 640x480: the cost map's mean $up over the upper rows, $dn over the lower"
check "... the floor's samples at least 3 times as dear as the sky's and wall's" \
	num 'a >= 3 * b && b > 0' "${dn:-0}" "${up:-0}"
check "... the map's mean 1" num 'a > 0.95 && a < 1.05' "$(cost_avg "$T/cm.errors.exr" 640x480+0+0)"
"$PP" render "$SC/glossy_reflection.pov" -o "$T/cm1.exr" -W 160 -H 120 --max-passes 0 -q ||
	bad "glossy_reflection 160x120: render failed"
check "... without a budget, cost 1 everywhere" num 'a == 1 && b == 1' $(cost_range "$T/cm1.errors.exr")
"$PP" render "$SC/glossy_reflection.pov" -o "$T/cm2.exr" -W 640 -H 480 --budget 30 \
	--max-passes 0 --cost-sample 1e-6 -v 2>"$T/cm2.log" ||
	bad "glossy_reflection --cost-sample: render failed"
check "... nor with --cost-sample" num 'a == 1 && b == 1' $(cost_range "$T/cm2.errors.exr")
check "... which says none" test "$(grep -c 'from its progress lines' "$T/cm2.log")" -eq 0

# --- a smooth, nearly empty scene costs almost nothing beyond the base pass --
"$PP" render "$SC/smooth_empty.pov" -o "$T/smooth.exr" -W $W -H $H -q --report "$T/smooth.json"
px=$(awk '/"pass": [1-9]/ { for (i = 1; i <= NF; i++) if ($i == "\"pixels\":") s += $(i + 1) }
	END { print s + 0 }' "$T/smooth.json")
check "smooth scene: at most 2% of the pixels re-rendered ($px)" num 'a <= 0.02 * b' "$px" $((W * H))
check "--sampler auto is the default" grep -q '"sampler": "auto"' "$T/smooth.json"

# --- determinism: one job, one POV-Ray thread -------------------------------
# The cost model is given: soft_shadows' measured costs sit on a rounding
# boundary on some machines (1.9e-6 and 3.8e-6 s a sample, 0.031 and 0.062 s
# a job, from run to run on one of them, under load), and the plan follows it.
for k in 1 2; do
	"$PP" render "$SC/soft_shadows.pov" -o "$T/det$k.exr" -W 48 -H 36 --jobs 1 -q \
		--max-passes 2 --target 1e-4 --cost-job 0.05 --cost-sample 2e-6 -- +WT1
done
check "--jobs 1 with +WT1: bit-identical output run to run" cmp -s "$T/det1.exr" "$T/det2.exr"
check "--jobs 1 with +WT1: bit-identical error map run to run" \
	cmp -s "$T/det1.errors.exr" "$T/det2.errors.exr"

# --- plan, the job list by xargs -P 2, merge == one pass of render ----------
scene="$SC/soft_shadows.pov"
"$PP" render "$scene" -o "$T/one.exr" -W 48 -H 36 --jobs 1 --max-passes 1 --target 1e-4 \
	--sampler scale --final samples -q --workdir "$T/one.work" --keep-workdir --report "$T/one.json" -- +WT1
cj=$(jget "$T/one.json" job_s)
cs=$(jget "$T/one.json" sample_s)
mkdir -p "$T/farm"
(
	cd "$T/farm" &&
	"$PP" merge --init "$T/one.work/base.exr" -o acc0.exr &&
	"$PP" analyze acc0.exr -o an0.exr &&
	"$PP" plan an0.exr --state acc0.exr --scene "$scene" -o jobs --target 1e-4 \
		--sampler scale --cost-job "$cj" --cost-sample "$cs" -- +WT1 >/dev/null &&
	xargs -P 2 -d '\n' -n 1 sh -c <jobs/jobs.txt &&
	"$PP" merge acc0.exr jobs/regions.tsv -o acc1.exr >/dev/null
) 2>"$T/farm.err"
check "plan -> xargs -P 2 -> merge runs" test $? -eq 0
check "plan wrote a mask with samples per pixel" \
	oiiotool "$T/farm/jobs/mask.exr" --ch samples -o "$T/m.exr"
check "plan's regions are render's regions" \
	cmp -s <(cut -f1-6 "$T/farm/jobs/regions.tsv") <(cut -f1-6 "$T/one.work/regions.tsv")
oiiotool "$T/farm/acc1.exr" --ch R,G,B -o "$T/farm/img1.exr" 2>/dev/null
check "plan -> xargs -> merge gives render's image, bit for bit" \
	same "$T/farm/img1.exr" "$T/one.exr"

# --- merge folds grid renders (scale 4 and up) as render does ---------------
gm=(render "$scene" -o "$T/gm.exr" -W 48 -H 36 --jobs 1 --target 1e-4 -q --keep-workdir
	--workdir "$T/gm.work" --sampler grid)
"$PP" "${gm[@]}" --max-passes 1 -- +WT1 && cp "$T/gm.work/accum.exr" "$T/gm-acc1.exr" &&
	"$PP" "${gm[@]}" --max-passes 2 --resume -- +WT1 &&
	"$PP" merge "$T/gm-acc1.exr" "$T/gm.work/regions.tsv" -o "$T/gm-acc2.exr" >/dev/null
check "render, --resume a pass further, merge its regions.tsv: runs" test $? -eq 0
check "... the pass rendered a grid region (scale 4)" \
	awk -F'\t' '$1 == 2 && $6 == 4 { f = 1 } END { exit !f }' "$T/gm.work/regions.tsv"
for f in gm-acc2 gm.work/accum; do
	oiiotool "$T/$f.exr" --ch R,G,B,samples,var.R,diff -o "$T/${f//\//-}-ch.exr" 2>/dev/null
done
check "... merge folds it to render's accumulation, bit for bit" \
	idiff -fail 0 -failpercent 0 "$T/gm-acc2-ch.exr" "$T/gm.work-accum-ch.exr"

# --- merge folds an antialiased first pass (twice the size) as render does ---
"$PP" render "$SC/starfield.pov" -o "$T/af.exr" -W 80 -H 60 --jobs 1 --max-passes 1 -q \
	--keep-workdir --workdir "$T/af.work" -- +WT1 &&
	"$PP" merge --init "$T/af.work/base.exr" -o "$T/af-acc0.exr" &&
	"$PP" merge "$T/af-acc0.exr" "$T/af.work/regions.tsv" -o "$T/af-acc1.exr" >/dev/null
check "starfield, one pass: render, then merge its regions.tsv: runs" test $? -eq 0
check "... the pass was antialiased (scale 0 in regions.tsv)" \
	grep -qP '^1\t(\d+\t){4}0\t' "$T/af.work/regions.tsv"
for f in af-acc1 af.work/accum; do
	oiiotool "$T/$f.exr" --ch R,G,B,samples,scales,diff -o "$T/${f//\//-}-ch.exr" 2>/dev/null
done
check "... merge folds it to render's accumulation, bit for bit" \
	idiff -fail 0 -failpercent 0 "$T/af-acc1-ch.exr" "$T/af.work-accum-ch.exr"

# --- ... and one taken for edges, at +R4 and at +R3 (regions.tsv's depth and
# edges columns), as render does; a file without them still merges ------------
# still_life at 160x120 takes its first pass for edges; costing a sample at
# 2e-5 s under a 4 s budget, +R3 (+R4 at 1e-5 s, +R3 at 2e-5 and 2.5e-5 s,
# scale 2 from 3e-5 s, where +R3's price 1.5 times over passes the share,
# by hand, 2026-12-04)
# one_pass TAG SCENE [OPTION ...]: render SCENE's base pass and one pass at
# 160x120 into $T/TAG.work, then merge its regions.tsv onto the base pass
# into $T/TAG-acc1.exr
one_pass() {
	local tag=$1 scene=$2
	shift 2
	"$PP" render "$scene" -o "$T/$tag.exr" -W 160 -H 120 --jobs 1 --max-passes 1 \
		-q "$@" --keep-workdir --workdir "$T/$tag.work" -- +WT1 &&
		"$PP" merge --init "$T/$tag.work/base.exr" -o "$T/$tag-acc0.exr" &&
		"$PP" merge "$T/$tag-acc0.exr" "$T/$tag.work/regions.tsv" -o "$T/$tag-acc1.exr" \
			>/dev/null
}
# folds_alike TAG [ACCUM]: check that one_pass TAG's merge, $T/TAG-acc1.exr,
# equals render's accumulation, $T/ACCUM.exr (default TAG.work/accum)
folds_alike() {
	local f acc=${2:-$1.work/accum}
	for f in "$1-acc1" "$acc"; do
		oiiotool "$T/$f.exr" --ch R,G,B,samples,scales,diff,var.R -o "$T/${f//\//-}-ch.exr" \
			2>/dev/null
	done
	check "... merge folds it to render's accumulation, bit for bit" \
		same "$T/$1-acc1-ch.exr" "$T/${acc//\//-}-ch.exr"
}
for n in r4 r3; do
	o=()
	[[ $n == r3 ]] && o=(--budget 4 --cost-job 0.05 --cost-sample 2e-5)
	one_pass "ae$n" "$SC/still_life.pov" "${o[@]}"
	check "still_life, one pass ($n): render, then merge its regions.tsv: runs" test $? -eq 0
	check "... every region antialiased for edges at ${n/r/+R} (scale 0, depth ${n#r}, edges 1)" \
		awk -F'\t' -v d="${n#r}" '!/^#/ { k++; if ($6 != 0 || $8 != d || $9 != 1) b = 1 }
			END { exit b || !k }' "$T/ae$n.work/regions.tsv"
	folds_alike "ae$n"
done
# ... and one taken for a few pixels, at +R5 (hdr_highlights' lamps): depth 5,
# edges 0, and merge folds it as render does
one_pass af5 "$SC/hdr_highlights.pov"
check "hdr_highlights, one pass: render, then merge its regions.tsv: runs" test $? -eq 0
check "... its antialiased regions for a few pixels at +R5 (scale 0, depth 5, edges 0)" \
	awk -F'\t' '!/^#/ && $6 == 0 { k++; if ($8 != 5 || $9 != 0) b = 1 } END { exit b || !k }' \
	"$T/af5.work/regions.tsv"
folds_alike af5
# ... and the deeper render for spread error of spread_level's r5 run above
# (+A0.03 +R5, edges 5; +R6, 6, on any region moved up)
if [[ -f $T/r5.exr.work/regions.tsv ]]; then
	"$PP" merge --init "$T/r5.exr.work/base.exr" -o "$T/r5m-acc0.exr" &&
		"$PP" merge "$T/r5m-acc0.exr" "$T/r5.exr.work/regions.tsv" -o "$T/r5m-acc1.exr" \
			>/dev/null
	check "thin_geometry's pass at +R5 (320x240): merge its regions.tsv: runs" test $? -eq 0
	folds_alike r5m r5.exr.work/accum
else
	bad "thin_geometry's pass at +R5: no work directory to merge"
fi
differ() { ! idiff -fail 0 -failpercent 0 "$@" >/dev/null; }
# the same regions in the format before depth and edges: folded as +R4 for a few
# pixels, which differs (so the columns are what made the fold above right)
{
	echo "# povpress regions: pass x0 y0 x1 y1 scale output (pixels 0-based, inclusive)"
	grep -v '^#' "$T/aer3.work/regions.tsv" | cut -f1-7
} >"$T/ae-old.tsv"
"$PP" merge "$T/aer3-acc0.exr" "$T/ae-old.tsv" -o "$T/ae-old.exr" >/dev/null
check "a regions file without depth and edges merges" test $? -eq 0
oiiotool "$T/ae-old.exr" --ch R,G,B,samples,scales,diff,var.R -o "$T/ae-old-ch.exr" 2>/dev/null
check "... as +R4 for a few pixels, not as render folded it" \
	differ "$T/ae-old-ch.exr" "$T/aer3.work-accum-ch.exr"
awk -F'\t' -v OFS='\t' '!/^#/ && !d++ { $8 = 6 } 1' "$T/aer3.work/regions.tsv" >"$T/ae-bad.tsv"
fault "merge: a depth out of range: file and line named, no output" \
	"ae-bad.tsv' line 2: expected \"pass x0 y0 x1 y1 scale output depth edges\"" \
	"$T/ae-bad.exr" "$PP" merge "$T/aer3-acc0.exr" "$T/ae-bad.tsv" -o "$T/ae-bad.exr"
awk -F'\t' -v OFS='\t' '!/^#/ && !d++ { $6 = 4 } 1' "$T/aer3.work/regions.tsv" >"$T/ae-bad.tsv"
fault "merge: depth and edges on a scaled region: an error, no output" \
	"ae-bad.tsv' line 2: expected" \
	"$T/ae-bad.exr" "$PP" merge "$T/aer3-acc0.exr" "$T/ae-bad.tsv" -o "$T/ae-bad.exr"

# --- the edge pass takes the edges whole, even just above a loose target -----
# still_life at 320x240: the base pass's estimate 4.4e-3; at --target 3e-3 the
# pass planned for the target alone took 1342 pixels and left 4.2e-4 (by hand,
# 2026-12-04), with the edges whole about 3.4e-6.  At --target 5e-3 the base
# pass meets the target: no pass.
det=(--cost-job 0.05 --cost-sample 4e-6 --jobs 1)
"$PP" render "$SC/still_life.pov" -o "$T/ew.exr" -W 320 -H 240 --target 3e-3 --max-passes 1 \
	"${det[@]}" --report "$T/ew.json" -v -- +WT1 2>"$T/ew.err"
check "still_life at 320x240, --target 3e-3, one pass: runs" test $? -eq 0
check "... its pass was antialiased for edges" grep -q "estimated error sits at edges" "$T/ew.err"
check "... and planned for the edges whole, below the target" \
	grep -q "pass 1 plans for an estimated relMSE of .*, the edges whole" "$T/ew.err"
check "... and took the edges whole: estimated relMSE below 3e-5 ($(jget "$T/ew.json" est_relmse))" \
	num 'a < 3e-5' "$(jget "$T/ew.json" est_relmse)"
"$PP" render "$SC/still_life.pov" -o "$T/ew5.exr" -W 320 -H 240 --target 5e-3 "${det[@]}" -q \
	--report "$T/ew5.json" -- +WT1
met_at_base() { grep -q '"stop": "target met"' "$1" && test "$(jget "$1" pass)" = 0; }
check "... at --target 5e-3 the base pass meets it: no pass" met_at_base "$T/ew5.json"

# --- a region job that crashes or hangs: retried, reported, image valid -----
cat >"$T/fakepov" <<'EOF'
#!/bin/sh
# POV-Ray, except that region renders crash (FAKE=crash) or hang (FAKE=hang)
for a in "$@"; do
	case $a in
	+SC*)
		echo x >>"$FAKE_LOG"
		[ "$FAKE" = hang ] && exec sleep 60
		kill -SEGV $$
		;;
	esac
done
exec povray "$@"
EOF
chmod +x "$T/fakepov"
for mode in crash hang; do
	what=$([ $mode = crash ] && echo crashes || echo hangs)
	: >"$T/fake.log"
	FAKE=$mode FAKE_LOG="$T/fake.log" POVPRESS_POVRAY="$T/fakepov" "$PP" render \
		"$SC/soft_shadows.pov" -o "$T/$mode.exr" -W 48 -H 36 --max-passes 1 --timeout 2 \
		--report "$T/$mode.json" 2>"$T/$mode.err"
	rc=$?
	attempts=$(wc -l <"$T/fake.log")
	regions=$(awk '/"pass": 1/ { for (i = 1; i <= NF; i++) if ($i == "\"failed\":") print $(i + 1) + 0 }' "$T/$mode.json")
	check "region job that $what: exit 0 and a valid image" \
		test $rc -eq 0 -a -n "$regions"
	valid_exr "$T/$mode.exr"
	check "region job that $what: the image is valid" test $? -eq 0
	check "region job that $what: tried twice per region ($attempts runs, $regions failed)" \
		test "$attempts" -eq $((2 * ${regions:-0})) -a "${regions:-0}" -ge 1
	check "region job that $what: reported on stderr" grep -q "$( [ $mode = crash ] && echo crashed || echo 'timed out')" "$T/$mode.err"
done

# --- povwait.so: POV-Ray's polling waits cut, nothing else --------------------
# tests/povray_waits runs 4 rounds of four 50 ms waits of the kinds POV-Ray
# polls with (800 ms), then a 300 ms sleep, and prints how long each took
WAITS="$BUILD/tests/povray_waits"
PW="$BUILD/povwait.so"
read -r cut long < <(LD_PRELOAD="$PW" "$WAITS" 4)
check "povwait.so: 50 ms polling waits cut (4 rounds of four in $cut ms, not 800)" \
	num 'a > 0 && a < 400' "$cut"
check "povwait.so: a 300 ms sleep is not a poll and stays ($long ms)" num 'a >= 299' "$long"
cp "$WAITS" "$T/waits"
read -r other _ < <(LD_PRELOAD="$PW" "$T/waits" 4)
check "povwait.so: a program not named povray* keeps its waits ($other ms)" \
	num 'a >= 799' "$other"
# povpress preloads it into POV-Ray (a wrapper standing in for POV-Ray logs
# its LD_PRELOAD), says so in the report, and the image is the same without
printf '#!/bin/sh\necho "${LD_PRELOAD:-none}" >>"$ENV_LOG"\nexec povray "$@"\n' >"$T/envpov"
chmod +x "$T/envpov"
pw=(render "$SC/soft_shadows.pov" -W 80 -H 60 --max-passes 2 --jobs 1 --cost-job 0.05
	--cost-sample 2e-6 -q)
: >"$T/env.log"
ENV_LOG="$T/env.log" POVPRESS_POVRAY="$T/envpov" "$PP" "${pw[@]}" -o "$T/pw-on.exr" \
	--report "$T/pw-on.json" -- +WT1 || bad "povwait: render failed"
POVPRESS_POVWAIT=0 "$PP" "${pw[@]}" -o "$T/pw-off.exr" --report "$T/pw-off.json" -- +WT1 ||
	bad "povwait: render with POVPRESS_POVWAIT=0 failed"
check "povwait: every POV-Ray run had it preloaded ($(sort -u "$T/env.log" | tr '\n' ' '))" \
	test "$(sort -u "$T/env.log")" = "$(cd "$BUILD" && pwd -P)/povwait.so"
check "povwait: the report says so" grep -q '"povwait": true' "$T/pw-on.json"
check "povwait: POVPRESS_POVWAIT=0 turns it off, and the report says so" \
	grep -q '"povwait": false' "$T/pw-off.json"
check "povwait: the same image with and without it (--jobs 1 +WT1, fixed costs)" \
	cmp -s "$T/pw-on.exr" "$T/pw-off.exr"
if POVPRESS_POVWAIT=/nonexistent/povwait.so "$PP" render "$SC/smooth_empty.pov" -W 32 -H 24 \
	--max-passes 0 -q -o "$T/pw-none.exr" --report "$T/pw-none.json"; then
	check "povwait: a POVPRESS_POVWAIT that does not exist: rendered without it" \
		grep -q '"povwait": false' "$T/pw-none.json"
else
	bad "povwait: a POVPRESS_POVWAIT that does not exist stopped the render"
fi

# --- a budget is a deadline: a pass planned far over it is stopped in time ----
# --cost-sample 1e-9: the planner thinks samples free and plans a pass that
# would take many times the budget (--prelaunch off: a pass that takes
# renders started early leaves its dearer regions to the next).  One pass
# at 480x360 after a base pass of about 1 s: the frame at scale 4,
# 2,764,800 samples, about 30 CPU s on one POV-Ray process at the base
# pass's 1.1e-5 s a sample (2026-12-03), which a machine ten times as fast
# would not finish in the 3 s left.  (At 80x60 the pass planned free was the
# second; a machine fast enough to finish it did not start a third within
# the reserve, and nothing was stopped: one make check of five here.)
t0=$EPOCHREALTIME
"$PP" render "$SC/media.pov" -o "$T/dl.exr" -W 480 -H 360 --budget 4 --target 1e-6 \
	--cost-sample 1e-9 --prelaunch off --max-passes 1 --workdir "$T/dl work" -v \
	--report "$T/dl.json" 2>"$T/dl.err"
rc=$?
dt=$(awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.2f", b - a }')
check "budget deadline: a run whose pass is planned as free succeeds" test $rc -eq 0
check "... its region renders are stopped at the budget's end" \
	grep -q "stopped at the budget's end" "$T/dl.err"
# the blocks the stopped render finished are folded in from its state file
dlk=$(sed -n "s/.*stopped at the budget's end (done: .*; \([0-9]*\) pixels kept)/\1/p" "$T/dl.err")
check "... the pixels it finished are kept (${dlk:-none})" num 'a >= 64' "${dlk:-0}"
check "... and the pass counts them" \
	grep -q "\"pass\": 1, .*\"pixels\": ${dlk:-x}, " "$T/dl.json"
check "... and it ends within the 4 s budget ($dt s)" num 'a <= 4.3' "$dt"
check "... the output is a complete image" valid_exr "$T/dl.exr"
check "... no POV-Ray child left" no_povray_left "$T/dl work"

# --- under a budget the planner learns each pixel's cost from its renders ----
# glossy_reflection's floor costs many times its sky a sample: the first
# pass's region renders (scale 2 over the frame, split for the cores) teach
# the cost map, whose mean the report gives; without a budget there is none
"$PP" render "$SC/glossy_reflection.pov" -o "$T/cm.exr" -W 160 -H 120 --budget 3 \
	--target 1e-6 -v --report "$T/cm.json" 2>"$T/cm.err"
check "cost map: a budget run succeeds" test $? -eq 0
cml=$(jget "$T/cm.json" learnt)
cms=$(grep -o '"scale": [-0-9.e+]*, "learnt"' "$T/cm.json" | awk '{ print $2 }' | tr -d ,)
check "... it learnt from region renders ($cml)" num 'a >= 1' "${cml:-0}"
check "... and says so" grep -q "times their planned CPU, their pixels' costs so scaled" "$T/cm.err"
check "... the map moved off the base pass's mean ($cms)" num 'a != 1' "${cms:-1}"
check "... a run without a budget learns nothing" grep -q '"scale": 1, "learnt": 0}' "$T/one.json"

# a base pass longer than the budget (media at 1280x960: 64 times its
# 160x120 base pass, 0.37 CPU s in the sweep, so some 23 CPU s) is stopped
# at the budget's end: an error naming the budget, no image, nothing left
# running
t0=$EPOCHREALTIME
"$PP" render "$SC/media.pov" -o "$T/bb.exr" -W 1280 -H 960 --budget 1 --workdir "$T/bb work" \
	2>"$T/bb.err"
rc=$?
dt=$(awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.2f", b - a }')
check "base pass past the budget: the run fails" test $rc -ne 0
check "... saying so: $(head -c 150 "$T/bb.err")" \
	grep -q "base pass .* did not finish within the budget of 1 s" "$T/bb.err"
# how far it got, from POV-Ray's progress lines, and what the frame would
# take at that rate: more than the budget
need=$(sed -n 's/.*of its pixels in [0-9.]* s; at that rate the frame alone takes about \([0-9]*\) s).*/\1/p' \
	"$T/bb.err")
check "... saying how far it got and what the frame would take (about ${need:-?} s)" \
	num 'a > 1' "${need:-0}"
check "... stopped at the budget's end, not the pass's ($dt s)" num 'a <= 2.5' "$dt"
check "... no output file" test ! -e "$T/bb.exr"
check "... no POV-Ray child left" no_povray_left "$T/bb work"

# --- --prelaunch: renders started a pass early, taken or stopped -----------
# auto starts them only without povwait.so (POVPRESS_POVWAIT=0: "noWait").
# The first pass takes the early renders when they cost no more than its plan
# and half the latency a core (prelaunch_cover()): with povwait.so the base
# pass measures a latency of 0.01 to 0.07 s, and where it measured under the
# 0.031 s a job it costed and planned one region, the two early bands (a job
# more) were rightly left (2 of 30 runs, with this build and aa4a1fe alike):
# a job costed at 2 ms keeps the test off that edge
for m in on off auto noWait; do
	pm=$m envs=(env)
	[[ $m = noWait ]] && pm=auto envs=(env POVPRESS_POVWAIT=0)
	"${envs[@]}" "$PP" render "$SC/soft_shadows.pov" -o "$T/pl-$m.exr" -W $W -H $H --budget 3 \
		--target 1e-6 --prelaunch $pm --cost-job 0.001953125 --workdir "$T/pl $m" --keep-workdir \
		--report "$T/pl-$m.json" -v 2>"$T/pl-$m.log"
	eval "rc_$m=$?"
done
taken=$(grep '"pass": 1,' "$T/pl-on.json" | grep -o '"prelaunched": [0-9]*' | awk '{ print $2 }')
check "--prelaunch on under a budget: the run succeeds" test "$rc_on" -eq 0
check "... its first pass takes renders started with the base pass ($taken)" \
	test "${taken:-0}" -ge 1
check "... and says so" grep -q "started with the base pass" "$T/pl-on.log"
check "... the report names the mode" grep -q '"prelaunch": "on"' "$T/pl-on.json"
check "... no gate left in the work directory" \
	test -z "$(find "$T/pl on" -name 'gate-*')"
check "... no POV-Ray child left" no_povray_left "$T/pl on"
check "... the output is a complete image" valid_exr "$T/pl-on.exr"
for m in off auto; do
	check "--prelaunch $m (povwait.so on): the run succeeds" test "$(eval echo \$rc_$m)" -eq 0
	check "... and no pass takes an early render" \
		test "$(grep -o '"prelaunched": [1-9]' "$T/pl-$m.json" | wc -l)" -eq 0
done
check "... the report names auto" grep -q '"prelaunch": "auto"' "$T/pl-auto.json"
taken=$(grep '"pass": 1,' "$T/pl-noWait.json" | grep -o '"prelaunched": [0-9]*' | awk '{ print $2 }')
check "--prelaunch auto without povwait.so under a budget: the run succeeds" \
	test "$rc_noWait" -eq 0
check "... its report says povwait off" grep -q '"povwait": false' "$T/pl-noWait.json"
check "... its first pass takes renders started with the base pass ($taken)" \
	test "${taken:-0}" -ge 1
"$PP" render "$SC/soft_shadows.pov" -o "$T/pl-bad.exr" --prelaunch maybe 2>"$T/pl-bad.log"
check "--prelaunch maybe is a usage error (2)" test $? -eq 2
check "... whose message names the option" grep -q -- "--prelaunch" "$T/pl-bad.log"
# a header of the user's own (+HI): no gate takes its place
mkdir -p "$T/hi"
printf '#declare User_Colour = rgb <1, 0.5, 0.2>;\n' >"$T/hi/user.inc"
cat >"$T/hi/s.pov" <<'SCENE'
#version 3.7;
global_settings { assumed_gamma 1.0 }
camera { location <0, 1, -4> look_at 0 }
light_source { <-3, 5, -4> color rgb 1 area_light x, z, 4, 4 jitter }
plane { y, -1 pigment { checker color rgb 1 color rgb 0.2 } }
sphere { 0, 1 pigment { color User_Colour } }
SCENE
"$PP" render "$T/hi/s.pov" -o "$T/hi/out.exr" -W $W -H $H --budget 3 --target 1e-6 \
	--report "$T/hi/r.json" -q -- "+HI$T/hi/user.inc" 2>"$T/hi/err"
check "a scene needing the user's +HI header renders under a budget" test $? -eq 0
check "... and no early render took the header's place" \
	test "$(grep -o '"prelaunched": [1-9]' "$T/hi/r.json" | wc -l)" -eq 0
# a radiosity scene under a budget: its radiosity pass is started with the
# base pass and taken from its gate (--prelaunch on); with off it starts afresh
for m in on off; do
	"$PP" render "$SC/radiosity_room.pov" -o "$T/rp-$m.exr" -W 80 -H 60 --budget 4 \
		--target 1e-6 --max-passes 0 --prelaunch $m --workdir "$T/rp $m" --keep-workdir \
		--report "$T/rp-$m.json" -v 2>"$T/rp-$m.log"
	eval "rprc_$m=$?"
done
check "radiosity under a budget, --prelaunch on: the run succeeds" test "$rprc_on" -eq 0
check "... its radiosity pass was started early" \
	grep -q "the radiosity pass was started early" "$T/rp-on.log"
check "... the base pass's record counts it" \
	grep -q '"pass": 0,.*"prelaunched": 1' "$T/rp-on.json"
check "... no gate left in the work directory" test -z "$(find "$T/rp on" -name 'gate-*')"
check "... no POV-Ray child left" no_povray_left "$T/rp on"
check "... the output is a complete image" valid_exr "$T/rp-on.exr"
check "... its radiosity pass ran at scale 8 (a frame 640 wide, which the budget fits)" \
	grep -q '"radiosity_scale": 8' "$T/rp-on.json"
check "radiosity under a budget, --prelaunch off: the run succeeds" test "$rprc_off" -eq 0
check "... and no render was started early" \
	test "$(grep -o '"prelaunched": [1-9]' "$T/rp-off.json" | wc -l)" -eq 0
check "... the same image either way (one thread, the same solution)" \
	test "$("$PP" compare "$T/rp-on.exr" "$T/rp-off.exr" | sed -n 's/^relmse: //p')" = 0
# a sample costed at 2e-5 s: the pass at scale 8 (about 6 s) would not fit
# the budget, and the one at the usual scale, 4 (about 1.5 s), does
"$PP" render "$SC/radiosity_room.pov" -o "$T/r4.exr" -W 80 -H 60 --budget 4 --target 1e-6 \
	--max-passes 0 --cost-sample 2e-5 --report "$T/r4.json" -v 2>"$T/r4.log"
check "radiosity: a larger frame that would not fit the budget: the run succeeds" test $? -eq 0
check "... it says why" grep -q "radiosity pass not at scale 8: it would take about" "$T/r4.log"
check "... its radiosity pass ran at scale 4" grep -q '"radiosity_scale": 4' "$T/r4.json"
# a radiosity pass that one thread would not finish within the budget (a
# sample costed at 2.2e-4 s: scale 2 at 80x60 about 4.3 s of the 4) runs on
# every core where that fits (about 2.5 s on two), else not at all; a
# wrapper standing in for POV-Ray logs the arguments of every render (no
# renders started early, whose arguments it would log too)
printf '#!/bin/sh\necho "$*" >>"$ARGS_LOG"\nexec povray "$@"\n' >"$T/argpov"
chmod +x "$T/argpov"
: >"$T/rt.args"
ARGS_LOG="$T/rt.args" POVPRESS_POVRAY="$T/argpov" "$PP" render "$SC/radiosity_room.pov" \
	-o "$T/rt.exr" -W 80 -H 60 --budget 4 --cost-sample 2.2e-4 --prelaunch off \
	--report "$T/rt.json" -q 2>"$T/rt.err"
rtrc=$?
ncores=$(env -u OMP_NUM_THREADS nproc)	# as povpress counts them: the affinity mask
check "radiosity pass that one thread would not fit in the budget: the run succeeds" \
	test "$rtrc" -eq 0
check "... the wrapper logged the base pass (80x60, saving the radiosity data)" \
	grep -q -- "+W80 +H60 .*+RFO" "$T/rt.args"
if ((ncores > 1)); then
	check "... on $ncores cores: the pass at scale 2 runs on all of them (+WT$ncores)" \
		grep -q -- "+W160 +H120 +WT$ncores .*+RFO" "$T/rt.args"
	check "... and the report names its scale" grep -q '"radiosity_scale": 2' "$T/rt.json"
else
	check "... on one core: no radiosity pass (no 160x120 render saving a solution)" \
		test "$(grep -c -- '+W160 +H120 .*+RFO' "$T/rt.args")" -eq 0
fi
check "... the output is a complete image" valid_exr "$T/rt.exr"
# a radiosity pass at scale 1, on one thread after a base pass on every core
# (on one core there is none): a sample a pixel
"$PP" render "$SC/radiosity_room.pov" -o "$T/r1.exr" -W 480 -H 360 --max-passes 0 \
	--radiosity-scale 1 --report "$T/r1.json" -q 2>"$T/r1.err"
check "radiosity at 480x360 (a radiosity pass at scale 1): the run succeeds" test $? -eq 0
check "... the output is a complete image" valid_exr "$T/r1.exr"
# without a budget the solution's frame is 1280 pixels wide or more, at most 4
# times the image and 1280x960 pixels: 960x720 at 480x360, 1280x960 at
# 320x240 (a wrapper logs the arguments; no region renders)
for v in 480x360:960x720 320x240:1280x960; do
	sz=${v%%:*} fr=${v#*:}
	: >"$T/rs.args"
	ARGS_LOG="$T/rs.args" POVPRESS_POVRAY="$T/argpov" "$PP" render "$SC/radiosity_room.pov" \
		-o "$T/rs.exr" -W "${sz%x*}" -H "${sz#*x}" --max-passes 0 --prelaunch off -q \
		2>"$T/rs.err"
	check "radiosity at $sz, no budget: the run succeeds" test $? -eq 0
	check "... its radiosity pass renders $fr on one thread, saving the solution" \
		grep -q -- "+W${fr%x*} +H${fr#*x} +WT1 .*+RFO" "$T/rs.args"
done
# on one core under a budget, with the larger frame (960x720) costed past the
# budget and scale 1 within it: no pass at scale 1, which would repeat the
# base pass (a sample costed at 2e-5 s: 960x720 about 14 s, 480x360 3.5 s)
: >"$T/r1c.args"
ARGS_LOG="$T/r1c.args" POVPRESS_POVRAY="$T/argpov" taskset -c 0 "$PP" render \
	"$SC/radiosity_room.pov" -o "$T/r1c.exr" -W 480 -H 360 --budget 8 --target 1e-6 \
	--max-passes 0 --cost-sample 2e-5 --prelaunch off -q 2>"$T/r1c.err"
check "radiosity at 480x360 on one core under a budget: the run succeeds" test $? -eq 0
check "... one render saved a radiosity solution: the base pass" \
	test "$(grep -c -- '+W480 +H360 .*+RFO' "$T/r1c.args")" -eq 1
check "... and none at 960x720" test "$(grep -c -- '+W960 +H720' "$T/r1c.args")" -eq 0
# interrupted while the early renders wait at their gates
"$PP" render "$SC/focal_blur.pov" -o "$T/pl-int.exr" -W $W -H $H --budget 5 --target 1e-6 \
	--prelaunch on -q --workdir "$T/pl int" &
pid=$!
sleep 0.2
kill -INT $pid
wait $pid
check "SIGINT during the base pass: exits 130" test $? -eq 130
check "... no POV-Ray child left, waiting or not" no_povray_left "$T/pl int"

# --- SIGINT: children stopped, output absent or valid, --resume finishes ----
mkdir -p "$T/int"
"$PP" render "$SC/glossy_reflection.pov" -o "$T/int/out.exr" -W 160 -H 120 --target 1e-5 \
	--jobs 2 -q --workdir "$T/int/work" --report "$T/int/r.json" &
pid=$!
for _ in $(seq 1 100); do	# wait for the first refinement pass to start
	[[ -f "$T/int/work/regions.tsv" ]] && break
	sleep 0.1
done
sleep 0.5
kill -INT $pid
t0=$EPOCHREALTIME
wait $pid
rc=$?
dt=$(awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN { print b - a }')
check "SIGINT: exits non-zero (130) within 5 s ($dt s)" test $rc -eq 130 -a "${dt%.*}" -lt 5
check "SIGINT: no POV-Ray child left" no_povray_left "$T/int/work"
if [[ -e "$T/int/out.exr" ]]; then
	check "SIGINT: the output is a complete image" valid_exr "$T/int/out.exr"
else
	ok "SIGINT: no output (interrupted before one existed)"
fi
"$PP" render "$SC/glossy_reflection.pov" -o "$T/int/out.exr" -W 160 -H 120 --target 3e-3 \
	--jobs 2 -q --workdir "$T/int/work" --resume --report "$T/int/r.json"
check "--resume finishes the interrupted run" test $? -eq 0
check "--resume: the output is a complete image" valid_exr "$T/int/out.exr"
first=$(grep -o '"pass": [0-9]*' "$T/int/r.json" | head -n 1 | awk '{ print $2 }')
check "--resume: the report keeps the passes before the interruption (from pass $first)" \
	test "$first" = 0
"$PP" render "$SC/soft_shadows.pov" -o "$T/int/out.exr" -W 160 -H 120 -q \
	--workdir "$T/int/work" --resume 2>"$T/int/err"
check "--resume with another scene is refused" grep -q "another scene" "$T/int/err"

# --- paths with spaces and quotes --------------------------------------------
D="$T/my \"odd\" dir"
mkdir -p "$D"
cp "$SC/radiosity_room.pov" "$D/scene one's.pov"
"$PP" render "$D/scene one's.pov" -o "$D/out \"1\".exr" -W 48 -H 36 --max-passes 2 -q
check "scene and output paths with spaces and quotes" test $? -eq 0
check "... the output exists and is valid" valid_exr "$D/out \"1\".exr"
check "... and the work directory is gone" test ! -e "$D/out \"1\".exr.work"

echo "# $passed passed, $failed failed"
((failed == 0))
