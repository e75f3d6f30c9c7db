/*
 * accum.h - the accumulated render: every sample POV-Ray has produced for a
 * pixel, folded into a running mean, count and variance.
 *
 * An accumulation is an image with these channels (the order of this list
 * in memory; in a file they are matched by name):
 *
 *   R G B          mean of every sample of the pixel so far
 *   samples        how many samples that mean is over
 *   var.R var.G var.B
 *                  unbiased variance of those samples (0 while samples < 2)
 *   pass           the pass that last added samples (0: the base pass)
 *   scales         the resolution scales already sampled, as a bit mask
 *                  (bit s for scale s; the base pass is scale 1; bit 0 an
 *                  antialiased render, ACC_AA)
 *   diff           the error of the mean measured by its last fold: two
 *                  independent estimates of the pixel, the samples before
 *                  (n_a) and the samples added (n_b), differ by d; if each
 *                  has squared error c / n, E[d^2] = c (1/n_a + 1/n_b), so
 *                  the mean of all n_a + n_b has squared error about
 *                  d^2 n_a n_b / (n_a + n_b)^2.  Stored relative (over the
 *                  value^2 + 0.01, mean over R, G, B); NaN before a fold.
 *                  Unlike the sample variance it sees how fast the mean
 *                  really converges (stratified grids, POV-Ray's own
 *                  low-discrepancy sampling of lenses and lights).
 *
 * Samples are added by resolution scaling: a region rendered at s times the
 * resolution gives every pixel s x s new samples on a regular grid of sub-
 * pixel positions.  The grids of scales 1, 2, 4, 8 and 16 share no
 * position, so their samples are new information even for a scene without
 * any randomness; a scale already in a pixel's mask would repeat positions
 * it has, and is skipped.  A grid render (ACC_GRID_FRAME, below) samples
 * the same s x s cells, jittered inside them.
 */
#ifndef POVPRESS_ACCUM_H
#define POVPRESS_ACCUM_H

#include <stddef.h>

#include "driver/image.h"

enum {
	ACC_R, ACC_G, ACC_B, ACC_SAMPLES, ACC_VAR_R, ACC_VAR_G, ACC_VAR_B, ACC_PASS, ACC_SCALES,
	ACC_DIFF, ACC_NCH
};

/* The scales a pixel can be sampled at, in the order they are used. */
#define ACC_NSCALES 5
extern const int accum_scales[ACC_NSCALES];	/* 1, 2, 4, 8, 16 */

/* The "scale" of an antialiased render (at scale 1, +AM2 +A0 +R4 +J; bit 0
 * of the mask): its pixels are folded as as many samples as the render
 * proved to be worth, at most ACC_AA_MAX (see accum_merge_region()). */
#define ACC_AA 0
#define ACC_AA_MAX 289

/*
 * An antialiased render in place of scale 2 (+AM2 +A0.1 +R3 +J at twice the
 * image's size; see render.c's choose_samplers()): a pixel with fewer than
 * 2 samples, whose spread cannot weigh it, takes it as this many samples,
 * and every pixel it is folded into as having had scale 2 (--sampler aa's
 * renders at the image's size are folded as before: a pixel with no spread
 * takes one as 1 sample).  POV-Ray
 * subdivides where corners differ, and at a highlight the render is far
 * closer than the base pass's one sample: on hdr_highlights at 160x120 a
 * weight of 1 ended at relMSE 6.7e-4, 4 at 5.3e-4, 8 at 4.1e-4, 16 at 3.3e-4
 * and 64 at 3.6e-4 (target 1e-3, one run each, with the render then at the
 * image's size, +R4).
 */
#define ACC_AA_FIRST 16
/*
 * The cells such a render taken for a few pixels (highlights, stars: not
 * for edges) stands for at a pixel POV-Ray subdivided: as for edges
 * (ACC_AA_EDGE), the pixel takes the render as the cells its render
 * pixels' colour distance says it was cut into, ramping from ACC_AA_FIRST
 * where they agree to ACC_AA_FEW at the threshold, and is marked
 * ACC_AA_DEEP there (scale 8's bit: after scale 4 such a pixel goes to 16,
 * and finest_scale() counts it as 8, as an edge's).  ACC_AA_FIRST had been
 * measured with the render at the image's size; at twice the size a
 * highlight's subdivided render
 * pixels are far nearer its truth than the later scales' regular grids,
 * which alias it (hdr_highlights at 160x120: the render box-averaged has
 * relMSE 1.1e-4, resolution scaling at 4 7.8e-4), and at 16 the grid at
 * scale 4 pulled the lamps' reflections towards its aliasing (after pass 1
 * 1.6e-4, after pass 2 2.4e-4).  Where the render pixels agree (a star
 * between the corners, unseen) the weight stays ACC_AA_FIRST, so that a
 * base sample holding the star still counts: a flat 256 left starfield at
 * 1.8e-3 where 16 had 5.0e-4 to 6.4e-4.  By turns against a flat 16
 * (scripts/abtest.sh, two runs each, 2026-12-04 01:18 UTC): hdr_highlights
 * relMSE 0.26 to 0.61 times at targets 3e-3 to 1e-4 and budgets 2 to 8 s,
 * starfield 0.33 to 0.93, still_life (edges) the same.  The cells are
 * +R4's (ACC_AA_FEW); a render at +R3, which a budget may take
 * (aa_depth()), was cut into a quarter as many, accum_edge_cells(3), and
 * is merged by accum_merge_aa_file() with its depth.  At +R5 (ACC_AA_DEPTH)
 * the weight stays ACC_AA_FEW: with 1024 cells the later grids moved the
 * lamps' rims too little, and the estimate of hdr_highlights stood at 13
 * to 24 times the truth at 3e-3 and 1e-3 and at 0.37 to 0.41 at 3e-4 and
 * 4 s (by turns, one run each, 2026-12-04 16:30 UTC), where with 256 and
 * the shared-corner rule for these renders (hidden_edge()) it is within
 * 1.5 times at every setting but 3e-3 (see ACC_AA_DEPTH).
 */
#define ACC_AA_FEW 256

/* The bit of the scale mask that marks an antialiased render in scale 2's
 * place (ACC_AA marks either kind; 5 is no scale). */
#define ACC_AA_HALF 5

/* The bit that marks a pixel whose scale-2 bit stands for such a render
 * alone: it has none of scale 2's sub-pixel centre samples, so a grid
 * render takes none of its samples out as repeats (6 is no scale). */
#define ACC_AA_NOGRID 6

/*
 * The bits that mark a pixel folded from such a render taken for edges
 * (render.c's edge rule, accum_merge_aa_file()), and one the render
 * subdivided (its f x f render pixels differ by POV-Ray's threshold,
 * ACC_AA_THRESHOLD, or more).  At an edge the render's corners are half
 * a pixel apart and where they differ by the threshold POV-Ray
 * subdivides, to 1/16 of a pixel at +R4 (ACC_AA_EDGE_DEPTH; +R3 where a
 * budget leaves too little time, render.c's aa_depth()) in the
 * twice-size frame: the pixel is accum_edge_cells(depth) cells' mean (at
 * +R4 2 x 2 render pixels of 8 x 8), and the base pass's one sample at its
 * centre adds nothing the corners lack.  Such a pixel takes the render as
 * that many samples over that one (not ACC_AA_FIRST; with less colour
 * distance as the cells edge_cells() gives, at least ACC_AA_FIRST), their
 * variance the render pixels', its fold is charged their spread over the
 * cells it stands for, a subdivided one counts as scale 8 for
 * the hidden-edge term, and between two such pixels no hidden edge can be
 * larger than the threshold.  Measured against references (scratch
 * script): after the base and edge passes at 160x120 with the render at
 * +R3 (4 x 4 cells a render pixel, 64 a pixel), over pixels whose render
 * pixels differ by 0.1 or more the true squared error was 1/102
 * (still_life), 1/35 (Debian's lights/arealit3) and 1/54 (advanced/
 * lamppost) of that spread; by 0.01 to 0.1 about 1/10 to 1/1, so the
 * division ramps in log from 1 at ACC_AA_THRESHOLD / 10 to the cells at
 * the threshold.  At +R4 the edges' error fell to a quarter (still_life at
 * --target 3e-3: relMSE 1.56e-5 to 4.5e-6, its subdivided pixels' share
 * 1.2e-5 to 2.9e-6, for 1.3 to 1.6 CPU s), as halving the cells' side
 * should, and with 256 cells those pixels' estimate came out 1.5 times
 * their true error.  Not for the few-pixels rule's renders (starfield's
 * stars, hdr_highlights' lamps): a star between corners goes unseen, the
 * base sample may hold it, and there the same folding stopped starfield
 * at --target 3e-3 at relMSE 9.0e-3 on an estimate of 1.7e-4; only their
 * weight and ACC_AA_DEEP are as for edges (ACC_AA_FEW).
 */
#define ACC_AA_EDGE 7
#define ACC_AA_DEEP 8
/*
 * POV-Ray's depth for an antialiased render in scale 2's place taken for a
 * few pixels (highlights, stars), ACC_AA_DEPTH, and for edges,
 * ACC_AA_EDGE_DEPTH (render.c's choose_samplers(); aa_depth() goes down
 * from there to +R3 under a budget that would not fit it).  +R5 cuts the
 * cells' side to 1/32 of a pixel (1/16 at +R4).  By turns against +R4 for both
 * (scripts/abtest.sh, 160x120, one or two runs each; with the few-pixels
 * weight kept at ACC_AA_FEW and the shared-corner rule of hidden_edge()
 * for them as well):
 *   - hdr_highlights: relMSE 9.1e-5 at 3e-3 to 3e-4 became 4.5e-5 to
 *     3.6e-5, for 1.05 to 1.5 times the CPU, where POV-Ray's own best at
 *     twice the size, +AM2 +A0.1 +R4, has 1.06e-4; under 2 and 4 s, 0.87
 *     and 0.99 times the relMSE for the same CPU; its estimate within 1.5
 *     times the truth at every setting but 3e-3;
 *   - starfield: 0.91 to 1.15 times the relMSE for 0.92 to 1.04 times the
 *     CPU;
 *   - still_life's edges: 4.15e-6 became 2.87e-6 at every target, for 1.6
 *     times the CPU (0.57 to 0.92 s);
 *   - but Debian's lights/arealit3, lights/arealit1 and advanced/lamppost,
 *     whose edges are penumbrae: the same relMSE at the targets for 1.3
 *     to 2.4 times the CPU, and under 2 and 4 s 1.0 to 2.7 times the
 *     relMSE (the pass ate the budget).
 * So edges keep +R4.
 */
#define ACC_AA_DEPTH 5
#define ACC_AA_EDGE_DEPTH 4
/* The depth a regions file without the depth column (written before it
 * had one) was rendered at: merged as then. */
#define ACC_AA_DEPTH_V1 4

/* The depth a region's render in scale 2's place is rendered and folded
 * at: its own, or ACC_AA_DEPTH_V1 for depth 0. */
static inline int accum_aa_depth(int depth)
{
	return depth ? depth : ACC_AA_DEPTH_V1;
}

/* The cells a pixel of such a render at POV-Ray's depth d stands for:
 * 2 x 2 render pixels of 2^(d-1) x 2^(d-1) (64 at +R3, 256 at +R4). */
static inline int accum_edge_cells(int d)
{
	return 1 << (2 * d);
}
_Static_assert(ACC_AA_FEW == 1 << (2 * 4), "ACC_AA_FEW is the cells at +R4");
#define ACC_AA_THRESHOLD 0.1

/*
 * What a render in scale 2's place was taken for (struct plan_region's
 * edges, the regions file's last column): a few pixels, edges (both
 * POV-Ray's +AM2), or error spread over the frame of a scene whose samples
 * are cheap (render.c's spread_am1()): there the render is POV-Ray's
 * non-recursive +AM1 +A0.03 +R(2^(depth-1)) +J at twice the size, which
 * gives a render pixel whose colour differs from a neighbour's by the
 * threshold a jittered grid of 2^(depth-1) x 2^(depth-1) samples, so a
 * pixel it subdivided has accum_edge_cells(depth) samples, as +AM2 at that
 * depth has cells.  At 640x480 (one run each, 2026-12-04 21:05 to 21:15 UTC,
 * `--target 1e-3`, CPU of all processes): soft_shadows relMSE 4.1e-5 in
 * 6.5 s where scale 2 had 3.2e-4 in 3.3 s and POV-Ray's own +AM1 +A0.03
 * +R4 at twice the size 4.3e-5 in 5.1 s; thin_geometry 1.4e-4 in 4.3 s
 * against 4.3e-4 in 4.8 s and POV-Ray's 1.7e-4 in 3.2 s.  At +A0.1 both
 * erred more (1.0e-4 and 1.5e-4) for less CPU (5.1 and 4.0 s).  On media
 * (160x120, forced) it did not pay: 5.5e-4 in 8.7 s against 1.3e-4 in
 * 10.3 s, so it is for cheap samples only.
 */
enum {
	ACC_AA_FOR_FEW = 0, ACC_AA_FOR_EDGES = 1, ACC_AA_FOR_SPREAD = 2, ACC_AA_FOR_SPREAD_R3 = 3,
	ACC_AA_FOR_SPREAD_FLOOR = 4, ACC_AA_FOR_SPREAD_R5 = 5, ACC_AA_FOR_SPREAD_R6 = 6
};
#define ACC_AA_SPREAD_DEPTH 3
#define ACC_AA_SPREAD_THRESHOLD 0.03
/*
 * The lighter render for spread error (ACC_AA_FOR_SPREAD_R3), for a budget
 * that +A0.03 +R4 does not fit: +AM1 +A0.1 +R3 +J at twice the size, whose
 * subdivided pixel has 2 x 2 render pixels of 3 x 3 samples (its depth
 * column is ignored).  POV-Ray alone at 1280x960, box-averaged to 640x480
 * (one run each, 2026-12-05 01:30 UTC, CPU s and relMSE against the
 * sweep's references at scale 9), it erred less than +A0.03 +R2, the
 * render's other step down, on every scene tried but soft_shadows, where
 * the two tie: thin_geometry 3.0e-4 in 1.89 s against 7.1e-4 in 1.34 s,
 * hdr_highlights 1.2e-4 in 3.43 against 3.0e-4 in 4.04, Debian's
 * noise_generator 2.2e-5 in 2.67 against 6.7e-5 in 2.38, swirlbox 1.4e-4 in
 * 2.94 against 3.4e-4 in 2.44, var_refl 2.1e-4 in 5.36 against 5.4e-4 in
 * 3.60, soft_shadows 1.4e-4 in 2.51 against 1.5e-4 in 2.08 (+A0.03 +R4:
 * 4.3e-5 in 4.87).  Its threshold is the hidden-edge term's
 * (ACC_AA_THRESHOLD).
 */
#define ACC_AA_SPREAD_R3_THRESHOLD ACC_AA_THRESHOLD
#define ACC_AA_SPREAD_R3_SIDE 3
#define ACC_AA_SPREAD_R3_CELLS (4 * ACC_AA_SPREAD_R3_SIDE * ACC_AA_SPREAD_R3_SIDE)
/*
 * The lightest (ACC_AA_FOR_SPREAD_FLOOR), for a budget that fits none of
 * the others: +AM1 +A0.3 +R2 +J at twice the size (its depth column is
 * ignored), which costs little more than scale 2's plain render at twice
 * the size and on textures errs far less (POV-Ray alone at 1280x960,
 * box-averaged, one run each, 2026-12-05 02:25 UTC: Debian's granite
 * 3.7e-4 in 2.22 s against 1.4e-3 in 1.08 s without antialiasing,
 * noise_generator 7.2e-5 in 1.39 against 2.2e-4 in 1.01, swirlbox 4.2e-4 in
 * 1.74 against 1.8e-3 in 1.12, var_refl 7.8e-4 in 2.56 against 3.2e-3 in
 * 1.41; soft_shadows 4.9e-4 in 1.25 against 7.8e-4 in 0.99).  Its
 * threshold is above the hidden-edge term's cap (ACC_AA_THRESHOLD), which
 * may leave a step of up to 0.3 between two of its pixels charged as 0.1.
 */
#define ACC_AA_SPREAD_FLOOR_THRESHOLD 0.3
#define ACC_AA_SPREAD_FLOOR_SIDE 2
#define ACC_AA_SPREAD_FLOOR_CELLS (4 * ACC_AA_SPREAD_FLOOR_SIDE * ACC_AA_SPREAD_FLOOR_SIDE)
/*
 * The deeper renders for spread error (ACC_AA_FOR_SPREAD_R5 and _R6), for
 * a budget that fits more than +A0.03 +R4: +AM1 +A0.03 +R5 or +R6 +J at
 * twice the size (their depth column is ignored), a subdivided pixel 2 x 2
 * render pixels of 5 x 5 or 6 x 6 samples.  POV-Ray alone at 1280x960,
 * box-averaged to 640x480 against the sweep's references at scale 9 (one
 * run each, CPU s and relMSE, 2026-12-05 12:19 to 12:22 UTC): Debian's
 * noise_generator at +R3 to +R6 2.1e-5 in 4.0 s, 8.8e-6 in 6.3, 4.8e-6 in
 * 9.2, 2.9e-6 in 13.1 (relMSE times CPU falling 8.3e-5, 5.5e-5, 4.4e-5,
 * 3.8e-5), var_refl 1.35e-3 to 8.7e-4 the same way, granite at +R4 and +R5
 * 4.2e-5 in 13.5 and 2.5e-5 in 20.0; soft_shadows and thin_geometry alike
 * at every depth (relMSE times CPU 2.1e-4 to 2.4e-4 and 5.2e-4 to
 * 5.9e-4).  The sweep went no deeper than +R4, where later passes on
 * textures bought little.  README, "Deeper renders for spread error under
 * a larger budget", has the figures.
 */
#define ACC_AA_SPREAD_R5_SIDE 5
#define ACC_AA_SPREAD_R6_SIDE 6

/* Whether a render in scale 2's place was taken for spread error (+AM1). */
static inline int accum_for_spread(int edges)
{
	return edges >= ACC_AA_FOR_SPREAD && edges <= ACC_AA_FOR_SPREAD_R6;
}

/*
 * The render a region taken for spread error stands for, read by the
 * fold, the POV-Ray job and the planner alike: POV-Ray's +AM1 with the
 * threshold option a (the colour distance `threshold`) and the grid option
 * r, so that a pixel it subdivided has `cells` samples (2 x 2 render
 * pixels of r x r).  ACC_AA_FOR_SPREAD is +A0.03 with a grid of
 * 2^(depth-1) a side; the lighter ones (`light`) have their own whatever
 * the depth, and their pixel below the threshold is charged its render
 * pixels' spread whole.
 */
struct accum_spread {
	const char *a, *r;
	double threshold;
	int cells, light;
};
struct accum_spread accum_spread_render(int edges, int depth);
/*
 * Such a render's pixel is charged its render pixels' spread (their mean's
 * variance) divided by its range (the colour distance of its render
 * pixels) over ACC_AA_SPREAD_RANGE, at least 1, not by the cells as for
 * edges: over the subdivided pixels of soft_shadows and thin_geometry at
 * 640x480 (the runs above, pixels binned by range) the true squared error
 * over that spread was 0.22 and 0.16 at ranges 0.03 to 0.1, 0.084 and
 * 0.053 at 0.1 to 0.3, 0.016 and 0.024 at 0.3 to 1 and 0.010 and 0.008
 * above: about 0.012 / range on both, where the cells' 1/64 left the
 * estimate at a quarter of the truth and under (an edge's error grows with
 * its step, not with its square; noise below the threshold is spread the
 * render did not subdivide).  That is at ACC_AA_SPREAD_DEPTH; at another
 * depth the division goes in proportion to the cells (at +R2 it brought
 * thin_geometry's estimate from 0.16 to 0.60 of the truth, soft_shadows'
 * to 0.87).
 */
#define ACC_AA_SPREAD_RANGE 0.012
/*
 * The bit that marks a pixel folded from such a render (ACC_AA_FOR_SPREAD;
 * it has ACC_AA_EDGE too).  Its samples are at the render pixels' centres
 * and shared with no neighbour, so the hidden-edge term does not bound a
 * step beside it by its render pixels' spread (ACC_AA_STEP_SD), only by
 * the threshold: with the bound, soft_shadows at 640x480 and --target 1e-3
 * was estimated at 0.56 times its true relMSE, the pixels whose render
 * pixels agree within 0.03 (noise +AM1 left alone) at 0.02 to 0.39 times
 * theirs; without it 0.95, those 0.73 to 2.4 (without ACC_AA_EDGE at all,
 * 2.8).  thin_geometry stays at 0.57: 40% of its error is in lines no
 * sample of the pixel or its neighbours has seen.
 */
#define ACC_AA_SPREAD_BIT 9

/*
 * How many standard deviations of an edge render's pixel (its samples'
 * spread; after the render's fold onto the base sample, about its render
 * pixels', accum_merge_aa_file()) a step hidden inside it can be: one
 * render pixel of four apart by t gives a sample standard deviation (over
 * n - 1) of t / 2.  Their corners on the pixel's border are shared with
 * its neighbour, so a step between the two that this pixel's render pixels
 * do not show is on the neighbour's side (still_life at --target 3e-3: 477
 * flat pixels beside a ramp were charged 7e-6 for a true 7.9e-7; 191 of
 * them now, 7e-7 for 4.7e-7).
 */
#define ACC_AA_STEP_SD 2.0

/* A region render of scale s is accum_render_factor(s) times the image's
 * size: s, or 1 for an antialiased render. */
static inline int accum_render_factor(int s)
{
	return s == ACC_AA ? 1 : s;
}

/*
 * A grid render of scale s (4, 8 or 16): the region at twice the image's
 * size (ACC_GRID_FRAME) with POV-Ray's non-adaptive antialiasing,
 * +AM1 +A0.0 +R(s/2) +J0.75, which with a threshold of 0 supersamples every
 * pixel of the render with an s/2 x s/2 grid of samples, each jittered
 * inside its cell, besides one at its centre.  A pixel so gets
 * accum_grid_samples(s) = s^2 + 4 samples: an s x s jittered grid, and the
 * 4 positions of scale 2 again.  Where the pixel has had scale 2 those 4
 * repeat samples it has (exactly, in a scene without randomness: counted
 * twice they make the mean worse than its count says and the fold
 * difference smaller than the mean's error, an estimate too low under
 * glossy_reflection's micro-bumps), so they are taken out, the pixel's mean
 * standing in for them, and the pixel gets s^2 new samples.  The jitter
 * spreads a sample over the middle 3/4 of its cell: +J0.5 (half) left the
 * grid regular enough to alias soft_shadows' far checkerboard, and full
 * jitter, +J1.0, made hdr_highlights' lamps 4 times noisier (whole frames
 * at scale 8: 1.8e-4, 9.7e-5 and 9.7e-5 on soft_shadows at +J0.5, 0.75
 * and 1.0; 3.0e-4, 2.6e-4 and 1.2e-3 on hdr_highlights).  (At the image's
 * size, +R(s), the means under focal blur erred twice as much.)
 * POV-Ray holds and writes its whole frame, whose cost grows with the
 * frame's size whatever the region's (at 640x480, scale 8 writes a
 * 5120x3840 frame for about 3 CPU seconds), so a grid render costs what
 * its samples cost.  Its pixels come as 4 means, not as samples; see
 * accum_merge_region().
 */
#define ACC_GRID_FRAME 2

static inline int accum_grid_samples(int s)
{
	return 4 * ((s / 2) * (s / 2) + 1);
}

/* From this finest scale on, a pixel's fold differences are its whole
 * error estimate: its grids have sampled every strip wider than 1/16. */
#define ACC_EDGE_SCALE 8

/* The channel names, in ACC_* order. */
extern const char *const accum_names[ACC_NCH];

/* A new accumulation from a base render (its R, G, B; one sample per
 * pixel at scale 1, pass 0). */
int accum_from_base(const struct image *base, const char *what, struct image *acc, char *err,
		    size_t errlen);

/* Read an accumulation, checking that every channel is there. */
int accum_read(const char *path, struct image *acc, char *err, size_t errlen);

/* The smallest scale pixel i has not been sampled at, or 0 if none is
 * left. */
int accum_next_scale(const struct image *acc, size_t i);

/* Whether pixel i has samples at scale s. */
int accum_has_scale(const struct image *acc, size_t i, int s);

/*
 * Fold s x s samples of pixel i (n of them finite, their mean and sum of
 * squared deviations per channel) into the accumulation, and mark scale s
 * and the pass.  Returns 0 when folded, 1 when the pixel already had scale
 * s (nothing changes).
 */
int accum_fold(struct image *acc, size_t i, int s, int n, const double mean[3],
	       const double m2[3], int pass);

/*
 * Fold a region render at scale s into acc: img holds rows oy.. of the
 * s*W x s*H render (as image_read_exr_rows() returns them), and the
 * pixels of rectangle x0..x1, y0..y1 (inclusive, in acc's pixels) take the
 * mean of their s x s blocks.  A render twice the image's size at scale 4
 * or more is a grid render (ACC_GRID_FRAME): its 2 x 2 blocks are means of
 * s^2 / 4 + 1 samples each (s^2 / 4 where the pixel has scale 2: the
 * centre sample out, see ACC_GRID_FRAME); the pixel takes their mean, the
 * spread between them, and within them the per-sample spread their spread
 * implies for noise, but not more than the pixel's samples had so far
 * (spread between the sub-pixels can be an edge's, not noise).  The
 * fold's difference (the 'diff' channel) is lowered where the new samples'
 * quadrants agree (their mean is closer than independent samples' would
 * be: see struct strat in accum.c).  *folded counts the pixels that took
 * new samples (may be NULL).  Fails on a size mismatch or rows not read.
 */
int accum_merge_region(struct image *acc, const struct image *img, int oy, int s, int x0,
		       int y0, int x1, int y1, int pass, long *folded, char *err,
		       size_t errlen);

/* The same from the render's file at path, reading only the rows the
 * rectangle needs (the render's size is read from the file first). */
int accum_merge_file(struct image *acc, const char *path, int s, int x0, int y0, int x1,
		     int y1, int pass, long *folded, char *err, size_t errlen);

/*
 * A whole frame's s x s samples a pixel folded into pixels that had none (a
 * radiosity pass, accum_merge_region() at scale s onto a fresh
 * accumulation) leave no fold difference, and the error estimate would
 * fall back on their variance over their count, which on a regular grid
 * counts the pixel's detail as noise (Debian's gamma/gamma_showcase.pov at
 * 160x120 after its pass at scale 4: estimated 4.0e-3 for a true 2.5e-4).
 * This sets each such pixel's difference from its samples' two
 * checkerboard halves (x + y even and odd), as accum_fold() would have
 * folding the one onto the other.  img is the frame at s times acc's size;
 * pixels with a sample missing, or not of that render alone (their count
 * other than s x s), are left, and at s = 1 (a sample a pixel) all are.
 * Returns 0, or -1 (the message in err) when img is not such a frame.
 */
int accum_split_diff(struct image *acc, const struct image *img, int s, char *err,
		     size_t errlen);

/* accum_merge_region() and accum_merge_file() of an antialiased render in
 * scale 2's place (s ACC_AA, twice the image's size) at POV-Ray's depth
 * `depth` (+R, 1 to ACC_AA_DEPTH), its subdivided pixels taken as up to
 * accum_edge_cells(depth) cells: taken for edges (edges not 0), folded as
 * ACC_AA_EDGE says; else for a few pixels (ACC_AA_FEW).  Any other render
 * is folded as by the two, which take such a render as for a few pixels at
 * ACC_AA_DEPTH_V1 (+R4). */
int accum_merge_aa_region(struct image *acc, const struct image *img, int oy, int s,
			  int depth, int edges, int x0, int y0, int x1, int y1, int pass,
			  long *folded, char *err, size_t errlen);
int accum_merge_aa_file(struct image *acc, const char *path, int s, int depth, int edges,
			int x0, int y0, int x1, int y1, int pass, long *folded, char *err,
			size_t errlen);

/*
 * accum_merge_region() (depth and edges ignored) or accum_merge_aa_region()
 * (s ACC_AA) of a render that was stopped before it ended: img holds the
 * pixels it finished (povstate.h) and NaN where it did not get to, and a
 * pixel any of whose render pixels is not finite is left as it was, its
 * scale not marked (a whole render's bad pixel is marked as having had the
 * scale, so that it is not planned again).  POV-Ray's blocks are 32 render
 * pixels a side from the region's corner, so a pixel of a render at 1, 2,
 * 4, 8 or 16 times the image's size is rendered whole or not at all (with
 * the user's +BS, a pixel a block's edge cuts is left out).
 */
int accum_merge_partial(struct image *acc, const struct image *img, int oy, int s, int depth,
			int edges, int x0, int y0, int x1, int y1, int pass, long *folded,
			char *err, size_t errlen);

/* What pixel i's relative errors are relative to: the mean over R, G, B
 * of value^2 + 0.01, the value being fit (the regression's, where finite;
 * fit may be NULL) or else the samples' mean. */
double accum_error_scale(const struct image *acc, size_t i, const float fit[3]);

/*
 * The noise part of pixel i's estimated error (below): for a pixel of 4
 * samples or more, diff (the 'diff' channel averaged over the pixel's
 * neighbourhood, NaN when there is none; see plan_pixel_errors()) or,
 * without one, its sample variance over n, relative to value^2 + 0.01 (of
 * an estimate of the true value); NaN for fewer samples.
 */
double accum_pixel_noise(const struct image *acc, size_t i, double diff);

/*
 * The estimated relative squared error of pixel i's mean (a term of
 * relMSE: squared error over value^2 + 0.01; 1 when unknown), the largest
 * of two estimates:
 * - noise: once the pixel has 4 samples, noise, accum_pixel_noise();
 *   before that, the regression's error estimate press (mean over R, G, B
 *   of the squared error, NaN if none; fit is its R, G, B);
 * - edges: an edge between all the sample positions is invisible to both.
 *   Where a pixel differs from a neighbour by more than the two pixels'
 *   own samples spread over, the edge between them may lie in the strip
 *   next to the neighbour that the pixel's finest grid (s x s) has not
 *   sampled, of width 1/(2s): the expected relative squared error of a
 *   uniformly placed edge there (relative to what the value would then be,
 *   so a dark pixel beside a light is not charged the light's brightness
 *   over its own darkness).
 */
double accum_pixel_error(const struct image *acc, size_t i, double press, const float fit[3],
			 double noise);

/* What the final image holds per pixel. */
enum accum_final {
	ACC_FINAL_AUTO,			/* the one predicted to be closer (below) */
	ACC_FINAL_SAMPLES,		/* the mean of the pixel's samples */
	ACC_FINAL_RECONSTRUCTION,	/* the regression's fit */
};

/* The fit is blended in only where it and the samples' mean agree: the
 * squared difference between the mean and the fit without the pixel is at
 * most this many times the sum of their predicted squared errors (3 standard
 * deviations; accum_final_choose()). */
#define ACC_FIT_AGREE 9.0

/* The error a pixel that takes some of the fit is then estimated at: the
 * blend's predicted error, but at least this share of its samples' (of u,
 * in accum_final_choose()).  When the whole fit was taken or none, the
 * prediction of those that took it, chosen for being small, was too small:
 * 0.38 and 0.43 times their true error (media and glossy_reflection at
 * 160x120, target 1e-3, one run each), where their true error fell 3 times
 * from their samples' mean's (media).  With the blend, over the pixels
 * that take all of the fit, 1.3 to 2.5 times on those two scenes. */
#define ACC_FIT_FLOOR 0.25

/*
 * How much of the regression's fit the final image takes per pixel:
 * take[i] in [0, 1] (w*h floats), the pixel being take[i] fit + (1 -
 * take[i]) mean; returns how many pixels take some.  Pixels without samples
 * take the fit, pixels without a finite fit keep their samples.  For
 * ACC_FINAL_AUTO, with u the squared error of the pixel's samples' mean
 * (noise[i], the relative accum_pixel_noise(), times value^2 + 0.01; at
 * most the sample variance over n), H its leverage and press the
 * regression's error estimate there (lpr's error: leave-one-out residuals
 * e^2 / (1 + vloo), smoothed over a neighbourhood, the input's noise plus
 * the fit's bias): the fit is H Y + (1 - H) g, g the fit without the pixel,
 * independent of the mean's error, and b = press - u stands for g's squared
 * error.  The mix Y + k (g - Y) errs by (1 - k)^2 u + k^2 b, least at
 * k = u / (u + b), where it is u b / (u + b): less than either.  (g's
 * error is its bias^2 + vloo sigma^2, vloo below 1 and falling with the
 * radius; b leaves out the second term, and so takes a little more of the
 * fit.  The smoothed PRESS itself, e^2 unscaled, in press's place left the
 * images 0 to 3% further from the reference on media and glossy_reflection
 * and within 1.4% elsewhere: 36 runs, 9 scenes at 160x120, each finished
 * both ways from the same samples.)  So the pixel takes
 * k / (1 - H) of the fit (at most all of it), where all of these hold:
 * - it has 4 samples or more and a fold difference (two independent sample
 *   sets: its noise is measured, not assumed);
 * - g and the mean agree: (g - Y)^2 is at most ACC_FIT_AGREE (u + b).
 *   press is smoothed over a neighbourhood, so at a star or a lamp among
 *   dark pixels b is the dark pixels' and k too large;
 * - its noise is like its neighbours' (within a factor 8 of their
 *   geometric mean): the fit is theirs too.
 * The rule before took the whole fit where its predicted error was below
 * half the mean's, and nothing elsewhere: media's image at 160x120 (one
 * pass of refinement) erred 1.30e-3 so and 8.2e-4 blended,
 * glossy_reflection's at target 1e-3 2.2e-4 and 1.4e-4 (the same samples;
 * without the last two tests 7.1e-4 and 1.3e-4, but hdr_highlights'
 * 3.1e-4 became 4.1e-4 and starfield's 5.6e-4 9.7e-4).
 * The sample variance over n is no measure of a mean's error on stratified
 * samples of deterministic detail (thin rods, a radiosity pass's grid: the
 * mean is 10 to 100 times closer), hence the fold difference and the
 * neighbours.  With e (the pixels' relative error estimates, may be NULL),
 * a pixel that takes some of the fit gets the blend's predicted error (at
 * least ACC_FIT_FLOOR of its samples'), unless e[i] exceeded its noise (an
 * edge between its samples).
 */
long accum_final_choose(const struct image *acc, const float *fit, const float *press,
			const float *leverage, const double *noise, enum accum_final mode,
			float *take, double *e);

/* Fill rgb (w*h*3) with the final image: take[i] of the fit, the rest the
 * samples' mean. */
void accum_final_image(const struct image *acc, const float *fit, const float *take,
		       float *rgb);

/*
 * The variance of the error of pixel i's mean, per channel, into v: its
 * samples' variance over n (from 2 samples on; 0 before), or with 4 samples
 * and a finite noise (accum_pixel_noise(), relative) the smaller of that and
 * noise x (value^2 + 0.01): the fold differences see how fast the mean
 * converges where the spread of stratified samples overstates it.
 */
void accum_noise_var(const struct image *acc, size_t i, double noise, double v[3]);

#endif
