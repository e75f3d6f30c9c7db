/*
 * plan.h - decide which pixels get more samples, at which scale, packed
 * into which rectangles, and write that down for anyone to render.
 *
 * The planner works on estimated relative squared errors e_i (see
 * accum_pixel_error()).  Refining pixel i, which has n_i samples, at its
 * next unused resolution scale s gives it m = s^2 new samples; the model is
 * that this divides its error by (n_i + m) / n_i, a gain of
 * e_i m / (n_i + m) for a cost of m samples.  Pixels are taken in order of
 * gain per cost until the predicted image relMSE is below the target (with
 * a margin, so that one pass usually suffices) or the pass's budget is
 * spent.  The chosen pixels are then packed, per scale, into rectangles:
 * first the runs of occupied tiles, then, greedily, any two rectangles
 * whose bounding box costs less than rendering them apart, where a render
 * costs cost_job (one POV-Ray invocation) plus cost_sample for each of its
 * area x s^2 samples.  Every pixel of a rectangle gets the new samples,
 * chosen or not.  POV-Ray renders a region into a whole s W x s H frame, so
 * scales whose frame would exceed 32 Mpixels are not used (at 640x480 the
 * largest scale is 8, at 1920x1080 it is 4); grid renders, twice the
 * image's size, have no such cap.
 */
#ifndef POVPRESS_PLAN_H
#define POVPRESS_PLAN_H

/*
 * The least share of a pass's predicted gain its next estimate shows: a
 * pass plans for the estimate less (estimate - target) / PLAN_REALIZED
 * where that is above target * margin, so that near the target it takes
 * off what is missing and a little more rather than 30% of the estimate.
 * Over 62 refinement passes of the eleven bundled scenes with visible
 * error at 320x240 (targets 3e-3, 1e-3 and 3e-4, one run each, the
 * reports' est_relmse against planned_relmse, 2026-12-04) the estimate
 * fell by 0.89 to 11.7 times the predicted fall: 0.98 to 1.43 but for
 * media's second passes (0.89 to 0.91) and five second passes after a
 * first that found stars and highlights whole (4.7 to 11.7).
 * With the margin alone a pass that began just above the target planned
 * for 0.7 of it, and its rectangles took the pixels around along:
 * glossy_reflection at 640x480, --target 1e-3, began its third pass at an
 * estimate of 1.007e-3, took 26,358 pixels and their neighbours to 220,594
 * at scale 8 and spent 70 CPU s to end at 2.8e-4, after 40 s for the
 * passes before.
 */
#define PLAN_REALIZED 0.8

#include <stddef.h>
#include <stdio.h>

#include "driver/image.h"
#include "driver/povray.h"

struct plan_params {
	double target;		/* image relMSE to reach */
	double margin;		/* plan for target * margin (default 0.7), or
				 * near the target for less (PLAN_REALIZED) */
	double budget;		/* cost this pass may spend, seconds; 0: no limit */
	double cost_job;	/* cost of one POV-Ray invocation, seconds */
	double cost_sample;	/* cost of one sample, seconds */
	int max_regions;	/* at most this many rectangles (default 64),
				 * twice as many after splitting for min_split */
	int tile;		/* packing grid in pixels (default 8) */
	double min_gain;	/* a pixel gaining less than min_gain * target
				 * is not refined (default 0.05) */
	int grid;		/* which of scales 4, 8, 16 are grid renders
				 * (accum.h): PLAN_GRID_* (default NEVER) */
	double grid_frame;	/* under PLAN_GRID_LARGE, the scaled frame, in
				 * pixels, past which a scale is a grid render
				 * (default PLAN_GRID_FRAME) */
	double cost_frame;	/* cost of a render's frame, seconds a pixel of
				 * it (s W x s H; a grid render's 2 W x 2 H),
				 * whatever the region: POV-Ray allocates and
				 * writes it whole (default 0) */
	double fill;		/* when the pixels at their next scales leave
				 * the goal unmet and cost less than this, take
				 * chosen pixels on to later scales until the
				 * samples cost this much (seconds; default 0:
				 * never).  For a pass that may be the last. */
	double min_pass_gain;	/* with a budget, a plan that leaves the goal
				 * unmet and takes less than this share off the
				 * estimate is PLAN_LITTLE_GAIN (default 0) */
	int min_split;		/* split the dearest regions in two, up to
				 * 2 max_regions, until none costs more than the
				 * pass over min_split (the cores that render
				 * it at once; default 0: no splitting) */
	const float *cost_map;	/* w*h or NULL: each pixel's cost a sample
				 * over cost_sample (render.c measures it from
				 * its region renders under a budget).  With a
				 * map, candidates, upgrades and rectangles are
				 * costed by it, and a region is split across
				 * its longer side where its cost halves;
				 * NULL (default): 1 everywhere, split across
				 * the longer side at its middle */
	/* set by the planner from cost_map: its summed-area table,
	 * (w + 1) x (h + 1), and w */
	const double *cost_sat;
	int cost_sat_w;
};

/* A render's fixed cost, seconds, at scale s in an image of px pixels: one
 * invocation and, with cost_frame, its frame. */
double plan_job_cost(const struct plan_params *p, int s, double px);

/*
 * The trace CPU of a whole frame at k times the size of an image of px
 * pixels, with radiosity, on one thread, from a render at the image's size
 * whose trace cost cost_pixel a pixel and shot rays radiosity rays a pixel
 * during the render proper (POV-Ray's "Radiosity (final) rays shot", over
 * px).  Those rays grow far more slowly than the frame's pixels (the
 * samples are reused across more of them), so the cost a pixel at the
 * image's size is too high for a larger frame when they are a large part
 * of it: Debian's radiosity/radiosity2.pov at 160x120 costs 4.1e-6 CPU s a
 * pixel on two threads (109,130 such rays, 5.7 a pixel), at 1280x960
 * 1.3e-6 on one (409,045 rays); so priced, scale 8 was predicted at 6.5 s
 * where it takes 1.6 s.  The trace is split as a (px + PLAN_RAD_RAY_COST
 * R) for R = rays px, and the frame at scale k costs a (k^2 px +
 * PLAN_RAD_RAY_COST R k^PLAN_RAD_RAY_GROWTH).  Fitted on Debian's
 * radiosity2, radiosity3 and radiosity_37 at scales 1 and 8 on one thread
 * (a ray 0.44, 0.60 and 0.82 of a pixel; the rays growing as k^0.63,
 * k^0.66 and k^0.80), it predicts, from a render on two threads, their
 * scale 8 at 0.94, 0.93 and 1.06 times its trace CPU, and rad_def_test_37's
 * and scenes/radiosity_room.pov's (few such rays) at 1.31 and 1.14, Debian's
 * gamma/gamma_showcase.pov's scale 4 at 1.15 (`povray -D +WT2` at scale 1
 * and `+WT1` at the others, 2026-12-04).  Without such rays:
 * cost_pixel k^2 px.
 */
#define PLAN_RAD_RAY_COST 0.5
#define PLAN_RAD_RAY_GROWTH (2.0 / 3.0)
double plan_radiosity_trace(double cost_pixel, double px, double rays, int k);

/* Grid renders: never (resolution scaling), for every scale of 4 or more,
 * or for those whose scaled frame would exceed grid_frame pixels
 * (PLAN_GRID_FRAME, or PLAN_FOCAL_FRAME where render's --sampler auto finds
 * focal blur: POV-Ray's antialiasing converges slowly there); or
 * (PLAN_GRID_ONLY) for every scale of 4 or more with no scale 2 before
 * them, so that every sample added to the base pass is jittered. */
enum { PLAN_GRID_NEVER, PLAN_GRID_ALWAYS, PLAN_GRID_LARGE, PLAN_GRID_ONLY };
#define PLAN_GRID_FRAME (1024.0 * 1024.0)
#define PLAN_FOCAL_FRAME (8.0 * 1024 * 1024)
/* The largest frame a region render may have, pixels (a 4096 x 8192 frame:
 * 320x240 at scale 16, 640x480 at 8, 1920x1080 at 4). */
#define PLAN_MAX_FRAME (32.0 * 1024 * 1024)

/* The --sampler names of PLAN_GRID_NEVER, _ALWAYS, _LARGE and _ONLY:
 * "scale", "grid", "auto", "jitter".  plan_grid_parse() returns the mode
 * a name gives, -1 for another name. */
const char *plan_grid_name(int grid);
int plan_grid_parse(const char *name);

/* Whether scale s of a w x h image is rendered as a grid render. */
int plan_grid_scale(const struct plan_params *p, int w, int h, int s);

/* The scale pixel i of acc is refined at next: accum_next_scale(), but
 * past scale 2 under PLAN_GRID_ONLY. */
int plan_next_scale(const struct plan_params *p, const struct image *acc, size_t i);

void plan_params_init(struct plan_params *p);

struct plan_region {
	int x0, y0, x1, y1;	/* pixels, inclusive */
	int scale;		/* resolution scale of the render */
	long chosen;		/* chosen pixels inside */
	double gain;		/* predicted reduction of the summed error */
	double cost;		/* predicted cost, seconds */
	int frame;		/* the render's size over the image's: 0 for
				 * accum_render_factor(scale), or
				 * ACC_GRID_FRAME for a grid render or, with
				 * scale ACC_AA, an antialiased render in scale
				 * 2's place (+A0.1 +R(depth) rather than +A0.0
				 * +R4; render.c, choose_samplers()) */
	int depth;		/* such a render's POV-Ray depth (+R, 1 to
				 * ACC_AA_DEPTH; 0 for +R4, ACC_AA_DEPTH_V1, as a
				 * regions file without the column), by which it is
				 * folded (accum_merge_aa_file()) */
	int edges;		/* what such a render was taken for,
				 * ACC_AA_FOR_FEW, _EDGES (render.c's edge
				 * rule) or _SPREAD (+AM1, spread_am1()),
				 * folded so (accum_merge_aa_file()) */
};

/* Pixels in r. */
static inline long plan_region_area(const struct plan_region *r)
{
	return (long)(r->x1 - r->x0 + 1) * (r->y1 - r->y0 + 1);
}

/* The cost map's sum over region r of an image w pixels wide (each pixel's
 * cost a sample over cost_sample): r's area without a map.  A region's
 * samples cost cost_sample * scale^2 times this. */
double plan_region_map(const struct plan_params *p, const struct plan_region *r, int w);

enum plan_outcome {
	PLAN_REFINE,		/* regions to render */
	PLAN_TARGET_MET,	/* the estimate is at or below the target */
	PLAN_NO_GAIN,		/* no pixel would gain from more samples */
	PLAN_NO_BUDGET,		/* the budget cannot pay for one region */
	PLAN_LITTLE_GAIN,	/* under min_pass_gain (plan_params) */
};

struct plan {
	int w, h;
	enum plan_outcome outcome;
	float *scale;		/* w*h: the scale each pixel is rendered at, 0: none */
	float *chosen;		/* w*h: 1 where the planner chose the pixel */
	struct plan_region *regions;
	size_t nregions;
	long chosen_pixels;	/* pixels chosen */
	long pixels;		/* pixels inside regions (that lack their scale) */
	double samples;		/* samples the regions add */
	double est_relmse;	/* estimated image relMSE before */
	double est_after;	/* predicted image relMSE after */
	double cost;		/* predicted cost, seconds */
	double budget;		/* the budget the regions were fitted to: p's,
				 * or less where the first fit's splits ran
				 * past it (plan_make_from()); 0: none */
};

/* Short name of an outcome ("refine", "target met", ...); static. */
const char *plan_outcome_name(enum plan_outcome o);

/*
 * Estimated relative error of every pixel (w*h doubles into e) from the
 * analysis (error and fit, as lpr_result or `povpress analyze` give them)
 * and the accumulation, and in *est the image relMSE estimate (their
 * mean); with noise (may be NULL), w*h doubles, each pixel's noise part
 * (accum_pixel_noise()).  Returns 0, or -1 out of memory (err says so).
 */
int plan_pixel_errors(const struct image *acc, const float *press, const float *fit,
		      double *e, double *noise, double *est, char *err, size_t errlen);

/* The same on up to nthreads threads (at most PLAN_MAX_THREADS, bands of 64
 * rows or more): the same values, the estimate summed in pixel order. */
#define PLAN_MAX_THREADS 64
int plan_pixel_errors_threads(const struct image *acc, const float *press, const float *fit,
			      double *e, double *noise, double *est, int nthreads, char *err,
			      size_t errlen);

/*
 * Plan one pass from the pixels' estimated errors e (plan_pixel_errors()).
 * The regions are fitted to p->budget, then the dearest split so that the
 * cores finish together, each part paying its own invocation and, at the
 * scales rendered as whole frames, its frame; where that takes the plan
 * past the budget by more than PLAN_SPLIT_OVER times, the pass is planned
 * again for a budget less by half the excess (out->budget), up to
 * PLAN_SPLIT_TRIES times.
 */
#define PLAN_SPLIT_OVER 1.02
#define PLAN_SPLIT_TRIES 4
int plan_make_from(const struct image *acc, const double *e, const struct plan_params *p,
		   struct plan *out, char *err, size_t errlen);

/* The same from the analysis: press and fit as for plan_pixel_errors(). */
int plan_make(const struct image *acc, const float *press, const float *fit,
	      const struct plan_params *p, struct plan *out, char *err, size_t errlen);

void plan_release(struct plan *pl);

/*
 * The POV-Ray job for region r of a plan, rendering into output: the
 * region at r->scale times base with antialiasing off; for a grid render
 * (r->frame ACC_GRID_FRAME) at twice base with +AM1 +A0.0 +R(scale/2)
 * +J0.75; when r->scale is ACC_AA at scale 1 with POV-Ray's antialiasing,
 * +AM2 +A0.0 +R4 +J, or at twice the size (r->frame ACC_GRID_FRAME) with
 * +AM2 +A0.1 +R3 +J (+R(r->depth) where that is set; taken for spread
 * error, r->edges ACC_AA_FOR_SPREAD, +AM1 +A0.03 +R(2^(depth-1)) +J) (the options
 * appended after the user's, which come from base->extra).
 * base gives the scene,
 * full size, threads, defines, extra options, work directory and binary;
 * the job borrows region (storage for the scaled rectangle) and extra
 * (storage for base->nextra + 4 pointers).
 */
void plan_job(const struct pov_job *base, const struct plan_region *r, const char *output,
	      struct pov_region *region, const char **extra, struct pov_job *job);

/*
 * The regions file: a header line, then per region a tab-separated line
 * "pass x0 y0 x1 y1 scale output depth edges" (the output may hold any
 * byte but a newline; writing fails on one; depth and edges are the
 * region's, 0 0 but for an antialiased render in scale 2's place).
 * plan_regions_read() fills *regions (you free() it and *outputs, an array
 * of strings each to free()); a file whose header line is the old one,
 * ending at "output" (written before depth and edges were recorded), has
 * lines ending at the output, and its regions depth 0 and edges 0; any
 * other file's lines end in depth and edges.
 */
int plan_regions_write(FILE *f, const struct plan *pl, int pass, char *const *outputs);
/* The image region k of a pass renders to: DIR/pPP-rKKK-sS.exr. */
void plan_output_name(char *buf, size_t len, const char *dir, int pass, size_t k, int scale);

/* plan_regions_write() to path, through a temporary file. */
int plan_regions_save(const char *path, const struct plan *pl, int pass, char *const *outputs,
		      char *err, size_t errlen);
int plan_regions_read(const char *path, struct plan_region **regions, char ***outputs,
		      int **passes, size_t *n, char *err, size_t errlen);

/* Fold region g's finished render, the image at path, into acc as pass
 * `pass`: accum_merge_aa_file() at g's depth and edges where it has a
 * depth (an antialiased render in scale 2's place), else
 * accum_merge_file(); *folded the pixels that took samples. */
int plan_merge_file(struct image *acc, const char *path, const struct plan_region *g, int pass,
		    long *folded, char *err, size_t errlen);

/*
 * Whether the estimated errors e (n pixels) sit in a few pixels: the
 * largest PLAN_SPARSE_SHARE of them (at least one) holding half of their
 * sum or more; values not finite or not positive are left out, and 0 is
 * returned when nothing is left or memory runs out.  So it is at
 * highlights seen directly and in mirrors, and at stars smaller than a
 * pixel; not where noise or edges spread over the frame.  After the base
 * pass at 160x120 the share was 0.63 on hdr_highlights (0.66 at 320x240,
 * 0.26 at 80x60, where 0.1% is 4 pixels), 0.97 on starfield, 0.01 to 0.11
 * on the other bundled scenes (radiosity_room 0.26 at 320x240), and 0.01 to
 * 0.09 on 19 of Debian's scenes (README).  render's --sampler auto then
 * renders scale 2 antialiased (render.c, choose_samplers()).
 */
#define PLAN_SPARSE_SHARE 0.001
int plan_sparse_error(const double *e, size_t n);

/*
 * Whether the estimated errors e (n pixels) sit at edges: the largest
 * PLAN_EDGE_SHARE of them (at least one) holding PLAN_EDGE_FRAC of their
 * sum or more, on the same terms as plan_sparse_error().  Where a scene's
 * noise is low and its error is its edges' aliasing, POV-Ray's adaptive
 * antialiasing, which subdivides only where corners differ, does far more
 * for the CPU than scale 2's 4 samples over the rectangles.  After the base
 * pass at 160x120 (2026-12-02, `povpress render S --max-passes 0
 * --error-map M`, the relerror channel): 0.76 to 0.88 on Debian's
 * lights/arealit1, arealit2, arealit3 and advanced/lamppost and 0.77 on
 * still_life (0.93 at 320x240, 0.64 at 80x60: the edges' share of the
 * pixels grows as the image shrinks), 0.91 and 1.00 on hdr_highlights and
 * starfield; 0.11 to 0.58 on the other bundled scenes (soft_shadows 0.54,
 * thin_geometry 0.49) and on Debian's wineglass, woodbox, isosurfaces,
 * blob, bwstripe and whiltile, where the error is noise or texture spread
 * over the frame (radiosity_room 1.00: its radiosity solution's; render.c
 * leaves radiosity scenes out).  The bound sits between the two groups.
 */
#define PLAN_EDGE_SHARE 0.05
#define PLAN_EDGE_FRAC 0.67
int plan_edge_error(const double *e, size_t n);

/* The sum of the largest share of the errors e (n pixels; at least one;
 * values not finite or not positive left out): the top PLAN_EDGE_SHARE's
 * for render.c's edge pass; into *all, unless all is NULL, the sum of all
 * of them.  0 when memory runs out. */
double plan_top_sum(const double *e, size_t n, double share, double *all);

/* Both of the above from one sort of the errors: PLAN_ERROR_FEW if
 * plan_sparse_error(), PLAN_ERROR_EDGES if plan_edge_error(). */
enum { PLAN_ERROR_FEW = 1u, PLAN_ERROR_EDGES = 2u };
unsigned plan_error_where(const double *e, size_t n);

#endif
