/*
 * accum.c - the accumulated render (see accum.h).
 *
 * Sample sets are combined with the pairwise update of Chan, Golub and
 * LeVeque: means and sums of squared deviations, never sums of squares,
 * so a bright, nearly constant pixel keeps its variance digits.
 */
#include "driver/accum.h"
#include "driver/errbuf.h"
#include "driver/metrics.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

const int accum_scales[ACC_NSCALES] = { 1, 2, 4, 8, 16 };

const char *const accum_names[ACC_NCH] = {
	"R", "G", "B", "samples", "var.R", "var.G", "var.B", "pass", "scales", "diff",
};

static uint32_t scale_mask(const struct image *acc, size_t i)
{
	float m = acc->px[i * ACC_NCH + ACC_SCALES];
	return m >= 0.0f && m < 4294967296.0f ? (uint32_t)m : 0;
}

int accum_has_scale(const struct image *acc, size_t i, int s)
{
	return s >= 0 && s < 32 && (scale_mask(acc, i) >> s & 1u);
}

int accum_next_scale(const struct image *acc, size_t i)
{
	for (int k = 0; k < ACC_NSCALES; k++)
		if (!accum_has_scale(acc, i, accum_scales[k]))
			return accum_scales[k];
	return 0;
}

int accum_from_base(const struct image *base, const char *what, struct image *acc, char *err,
		    size_t errlen)
{
	struct image rgb = {0};
	if (image_rgb(base, what, &rgb, err, errlen))
		return -1;
	if (image_init(acc, rgb.w, rgb.h, ACC_NCH, accum_names, err, errlen)) {
		image_release(&rgb);
		return -1;
	}
	size_t n = (size_t)rgb.w * rgb.h;
	for (size_t i = 0; i < n; i++) {
		float *o = acc->px + i * ACC_NCH;
		int ok = 1;
		for (int c = 0; c < 3; c++) {
			o[c] = rgb.px[i * 3 + c];
			ok &= isfinite(o[c]) != 0;
		}
		/* a pixel POV-Ray could not shade counts as no sample */
		o[ACC_SAMPLES] = ok ? 1.0f : 0.0f;
		o[ACC_SCALES] = 2.0f;	/* bit 1: scale 1 */
		o[ACC_DIFF] = NAN;
	}
	image_release(&rgb);
	return 0;
}

int accum_read(const char *path, struct image *acc, char *err, size_t errlen)
{
	struct image raw = {0};
	if (image_read_exr(path, &raw, err, errlen))
		return -1;
	int idx[ACC_NCH];
	for (int c = 0; c < ACC_NCH; c++) {
		idx[c] = image_channel(&raw, accum_names[c]);
		if (idx[c] < 0) {
			errbuf_printf(err, errlen, "'%s' is not an accumulation: it has no '%s' "
				      "channel (write one with 'povpress merge --init')", path,
				      accum_names[c]);
			image_release(&raw);
			return -1;
		}
	}
	if (image_init(acc, raw.w, raw.h, ACC_NCH, accum_names, err, errlen)) {
		image_release(&raw);
		return -1;
	}
	size_t n = (size_t)raw.w * raw.h;
	for (size_t i = 0; i < n; i++)
		for (int c = 0; c < ACC_NCH; c++)
			acc->px[i * ACC_NCH + c] = raw.px[i * raw.nch + idx[c]];
	image_release(&raw);
	return 0;
}

/* The merged mean's squared error from a fold of nb samples onto na whose
 * means differ by d2 (relative; see ACC_DIFF in accum.h). */
static double fold_diff(double d2, double na, double nb)
{
	const double nt = na + nb;
	return d2 * na * nb / (nt * nt);
}

int accum_fold(struct image *acc, size_t i, int s, int n, const double mean[3],
	       const double m2[3], int pass)
{
	float *o = acc->px + i * ACC_NCH;
	if (accum_has_scale(acc, i, s))
		return 1;
	o[ACC_SCALES] = (float)(scale_mask(acc, i) | 1u << s);
	if (n <= 0)
		return 0;
	double na = o[ACC_SAMPLES], nb = n, nt = na + nb;
	double d2 = 0.0;
	for (int c = 0; c < 3; c++) {
		double ma = na > 0 ? o[c] : 0.0;
		double m2a = na > 1 ? (double)o[ACC_VAR_R + c] * (na - 1.0) : 0.0;
		double d = mean[c] - ma;
		double mt = ma + d * nb / nt;
		double m2t = m2a + m2[c] + d * d * na * nb / nt;
		o[c] = (float)mt;
		o[ACC_VAR_R + c] = nt > 1 ? (float)(m2t / (nt - 1.0)) : 0.0f;
		d2 += d * d / (mt * mt + METRICS_RELMSE_EPS) / 3.0;
	}
	if (na > 0)
		o[ACC_DIFF] = (float)fold_diff(d2, na, nb);
	o[ACC_SAMPLES] = (float)nt;
	o[ACC_PASS] = (float)pass;
	return 0;
}

/* The mean over R, G, B of v[c] / (m[c]^2 + 0.01): squared errors v relative
 * to the values m, a pixel's term of relMSE. */
static double rel3(const float *m, const double v[3])
{
	double r = 0.0;
	for (int c = 0; c < 3; c++)
		r += v[c] / ((double)m[c] * m[c] + METRICS_RELMSE_EPS) / 3.0;
	return r;
}

/*
 * What new samples of a region were worth: over the pixels that had two
 * samples or more and lacked the scale, the sum a of their relative sample
 * variances (per sample) and the sum d of the relative squared differences
 * between the new samples' mean and the pixels' means.  If the new mean of
 * each pixel has the squared error of n samples, E[d] = a / n + (the old
 * means' squared error), so a / d is a lower bound on n.
 */
struct accum_worth {
	double a, d;
	long pixels;
};

/*
 * Add pixel i's terms to w for new samples of mean mean[3] (see
 * struct accum_worth): its relative sample variance A_i and the relative
 * squared difference D_i between the new mean and its mean.  A pixel
 * without two samples, or that already has scale s, does not count.
 */
static void worth_add(const struct image *acc, size_t i, int s, const double mean[3],
		      struct accum_worth *w)
{
	const float *o = acc->px + i * ACC_NCH;
	if (!(o[ACC_SAMPLES] >= 2.0f) || accum_has_scale(acc, i, s))
		return;
	double var[3], e2[3];
	for (int c = 0; c < 3; c++) {
		var[c] = o[ACC_VAR_R + c];
		e2[c] = (mean[c] - o[c]) * (mean[c] - o[c]);
	}
	double a = rel3(o, var), d = rel3(o, e2);
	if (!isfinite(a) || !isfinite(d))
		return;
	w->a += a;
	w->d += d;
	w->pixels++;
}

/* a / d of w, at least 1 and at most ACC_AA_MAX; 0 when a is 0. */
static double worth_samples(const struct accum_worth *w)
{
	if (!(w->a > 0.0))
		return 0.0;
	if (w->d * ACC_AA_MAX <= w->a)
		return ACC_AA_MAX;	/* also d == 0 */
	return w->a / w->d < 1.0 ? 1.0 : w->a / w->d;
}

/* Pixel (x, y)'s value in an antialiased render f times the image's size
 * (1, or ACC_GRID_FRAME in scale 2's place): the mean of its f x f render
 * pixels, into mean, and, if var is not NULL, that mean's variance (their
 * sample variance over f^2; 0 for f = 1) and into *range their colour
 * distance as POV-Ray measures it for its threshold (each channel's
 * largest less smallest, summed); 0 if one is not finite. */
static int aa_pixel(const struct image *img, int oy, const int ch[3], int f, int x, int y,
		    double mean[3], double var[3], double *range)
{
	int ok = 1;
	double sq[3] = { 0.0, 0.0, 0.0 }, lo[3], hi[3];
	for (int c = 0; c < 3; c++) {
		mean[c] = 0.0;
		lo[c] = INFINITY;
		hi[c] = -INFINITY;
	}
	for (int j = 0; j < f; j++)
		for (int l = 0; l < f; l++) {
			const float *p = img->px + ((size_t)(y * f + j - oy) * img->w +
						    (size_t)x * f + l) * img->nch;
			for (int c = 0; c < 3; c++) {
				mean[c] += p[ch[c]] / (double)(f * f);
				sq[c] += (double)p[ch[c]] * p[ch[c]] / (double)(f * f);
				ok &= isfinite(p[ch[c]]) != 0;
				lo[c] = p[ch[c]] < lo[c] ? p[ch[c]] : lo[c];
				hi[c] = p[ch[c]] > hi[c] ? p[ch[c]] : hi[c];
			}
		}
	if (var) {	/* the f x f pixels' sample variance over f^2 */
		for (int c = 0; c < 3; c++) {
			double v = f > 1 ? (sq[c] - mean[c] * mean[c]) / (f * f - 1) : 0.0;
			var[c] = v > 0.0 ? v : 0.0;
		}
		*range = (hi[0] - lo[0]) + (hi[1] - lo[1]) + (hi[2] - lo[2]);
	}
	return ok;
}

/* The worth of an antialiased render of a region (worth_samples()),
 * rounded. */
static int aa_worth(const struct image *acc, const struct image *img, int oy, const int ch[3],
		    int f, int x0, int y0, int x1, int y1)
{
	struct accum_worth w = {0};
	for (int y = y0; y <= y1; y++)
		for (int x = x0; x <= x1; x++) {
			double mean[3];
			aa_pixel(img, oy, ch, f, x, y, mean, NULL, NULL);
			worth_add(acc, (size_t)y * acc->w + x, ACC_AA, mean, &w);
		}
	return (int)lround(worth_samples(&w));
}

/* What the spread of a pixel's render pixels is divided by for the error
 * of their mean, in a render taken for edges of that many cells whose
 * render pixels' colour distance is range (see ACC_AA_EDGE). */
static double edge_cells(double range, double cells)
{
	const double lo = ACC_AA_THRESHOLD / 10.0;
	if (!(range > lo))
		return 1.0;
	return range >= ACC_AA_THRESHOLD ? cells : pow(cells, log10(range / lo));
}

struct accum_spread accum_spread_render(int edges, int depth)
{
	/* ACC_AA_FOR_SPREAD's grid side for the same samples as +AM2's
	 * cells at each depth */
	static const char *const side[] = { "+R1", "+R2", "+R4", "+R8", "+R16" };
	_Static_assert(ACC_AA_DEPTH == 5, "a side for every depth");
	if (edges == ACC_AA_FOR_SPREAD_R3)
		return (struct accum_spread){ "+A0.1", "+R3", ACC_AA_SPREAD_R3_THRESHOLD,
					      ACC_AA_SPREAD_R3_CELLS, 1 };
	if (edges == ACC_AA_FOR_SPREAD_FLOOR)
		return (struct accum_spread){ "+A0.3", "+R2", ACC_AA_SPREAD_FLOOR_THRESHOLD,
					      ACC_AA_SPREAD_FLOOR_CELLS, 1 };
	if (edges == ACC_AA_FOR_SPREAD_R5 || edges == ACC_AA_FOR_SPREAD_R6) {
		const int r6 = edges == ACC_AA_FOR_SPREAD_R6,
			  n = r6 ? ACC_AA_SPREAD_R6_SIDE : ACC_AA_SPREAD_R5_SIDE;
		return (struct accum_spread){ "+A0.03", r6 ? "+R6" : "+R5", ACC_AA_SPREAD_THRESHOLD,
					      4 * n * n, 0 };
	}
	const int d = accum_aa_depth(depth), dd = d >= 1 && d <= ACC_AA_DEPTH ? d : ACC_AA_DEPTH_V1;
	return (struct accum_spread){ "+A0.03", side[dd - 1], ACC_AA_SPREAD_THRESHOLD,
				      accum_edge_cells(dd), 0 };
}

/* What the spread of a pixel's render pixels is divided by for the error
 * of their mean, in a render taken for spread error (+AM1), sp, whose
 * render pixels' colour distance is range (see ACC_AA_SPREAD_RANGE):
 * range / ACC_AA_SPREAD_RANGE at ACC_AA_SPREAD_DEPTH's cells, in
 * proportion to them at another depth or render, at least 1; 1 below a
 * lighter render's threshold. */
static double spread_division(double range, const struct accum_spread *sp)
{
	if (sp->light && range < sp->threshold)
		return 1.0;
	const double k = range / ACC_AA_SPREAD_RANGE * sp->cells /
			 (double)accum_edge_cells(ACC_AA_SPREAD_DEPTH);
	return k > 1.0 ? k : 1.0;
}

/* Fold an antialiased render f times the image's size (see aa_worth()),
 * in scale 2's place at POV-Ray's depth `depth` (0: ACC_AA_DEPTH_V1, as a regions
 * file without the depth column was rendered), taken
 * for edges (ACC_AA_EDGE) or else for a few pixels (ACC_AA_FEW). */
static long merge_aa(struct image *acc, const struct image *img, int oy, const int ch[3],
		     int f, int x0, int y0, int x1, int y1, int pass, int depth, int edges,
		     int holes)
{
	const struct accum_spread sp = accum_spread_render(edges, depth);
	int cells = accum_for_spread(edges) ? sp.cells : accum_edge_cells(accum_aa_depth(depth));
	if (!edges && cells > ACC_AA_FEW)
		cells = ACC_AA_FEW;	/* see ACC_AA_FEW */
	int n = aa_worth(acc, img, oy, ch, f, x0, y0, x1, y1);
	long count = 0;
	for (int y = y0; y <= y1; y++)
		for (int x = x0; x <= x1; x++) {
			size_t i = (size_t)y * acc->w + x;
			const float *o = acc->px + i * ACC_NCH;
			double mean[3], old[3], m2[3] = { 0.0, 0.0, 0.0 };
			double v[3], range = 0.0;
			int ok = aa_pixel(img, oy, ch, f, x, y, mean, v, &range);
			for (int c = 0; c < 3; c++)
				old[c] = o[c];
			if (!ok) {
				if (!holes)	/* a render's bad pixel: not again */
					accum_fold(acc, i, ACC_AA, 0, mean, m2, pass);
				continue;
			}
			/* the render's samples spread as the pixel's do; no pixel
			 * takes it as more than its own a / d (a bias where the
			 * pixel's spread is small would be weighted as the region's
			 * noisier pixels prove it worth).  A pixel with no spread
			 * to weigh it by (the base pass's one sample) takes it as
			 * ACC_AA_FIRST samples, or taken for edges as the cells
			 * its colour distance says POV-Ray subdivided it into
			 * (edge_cells(), at least ACC_AA_FIRST: where it did
			 * not subdivide, the pixel is the mean of 9 corners).
			 * All pixels of a +R4 render at 256 left Debian's
			 * lights/arealit1 at --budget 2 at 4.2e-5 twice, its
			 * penumbrae at the render's area-light pattern, later
			 * samples outweighed; so 2.4e-5 and 2.7e-5 (4 s: 1.6e-5,
			 * 1.1e-5 and 1.2e-5) */
			struct accum_worth one = {0};
			worth_add(acc, i, ACC_AA, mean, &one);
			double own = worth_samples(&one);
			const int half = f == ACC_GRID_FRAME;	/* in scale 2's place */
			const int first = half && !(o[ACC_SAMPLES] >= 2.0f);
			const int edge = half && edges;
			/* the cells its colour distance says POV-Ray subdivided
			 * the pixel into, taken for edges or for a few pixels
			 * (ACC_AA_FEW at +R4); only for edges is the spread over
			 * them */
			const double ec = first ? edge_cells(range, cells) : 1.0;
			const double ek = !edge ? 1.0
				: !accum_for_spread(edges) ? ec
				: spread_division(range, &sp);
			int k = first ? (ec > ACC_AA_FIRST ? (int)lround(ec) : ACC_AA_FIRST)
				      : own < 1.0 ? 1 : own < n ? (int)lround(own) : n;
			/* taken for edges, the cells vary as the render pixels
			 * do (v is their mean's variance): a shading ramp
			 * across the pixel shows in its variance as a ramp
			 * does, which hidden_edge() takes off the difference to
			 * its neighbours (with the base sample's variance, the
			 * ramps of still_life's shaded objects were charged as
			 * edges hidden between the render's corners: 5.4e-5 of
			 * its estimate of 6.9e-5 after the pass, for a true
			 * relMSE of 1.6e-6 over those pixels; so 1.6e-5) */
			for (int c = 0; c < 3; c++)
				m2[c] = k < 2 ? 0.0
					: first && edge ? 4.0 * v[c] * (k - 1)
							: (double)o[ACC_VAR_R + c] * (k - 1);
			double na = o[ACC_SAMPLES], prev = o[ACC_DIFF];
			if (accum_fold(acc, i, ACC_AA, k, mean, m2, pass))
				continue;
			count++;
			/* in scale 2's place the render stands in for scale 2: the
			 * planner moves on to scale 4 (a pixel planned at scale 2
			 * again would get no new render: its jitter is the same
			 * every run), and ACC_AA_HALF marks it for finest_scale(),
			 * ACC_AA_NOGRID for grid_pixel() where it had no scale 2,
			 * ACC_AA_EDGE and ACC_AA_DEEP for hidden_edge() */
			if (half) {
				const uint32_t m = scale_mask(acc, i);
				uint32_t add = 1u << 2 | 1u << ACC_AA_HALF;
				if (!(m >> 2 & 1u))
					add |= 1u << ACC_AA_NOGRID;
				if (edge)
					add |= 1u << ACC_AA_EDGE;
				if (accum_for_spread(edges))
					add |= 1u << ACC_AA_SPREAD_BIT;
				if ((edge || first) && range >= ACC_AA_THRESHOLD)
					add |= 1u << ACC_AA_DEEP;
				acc->px[i * ACC_NCH + ACC_SCALES] = (float)(m | add);
			}
			if (!(na > 0.0))
				continue;
			/* the error of the new mean, not knowing which of the two
			 * the difference between them belongs to (the render holds
			 * POV-Ray's antialiasing bias: its threshold test and
			 * area-light patterns converge to their own answer; the old
			 * mean can hold a sample grid's aliasing): each one's
			 * weight squared times it, or for the old mean its own
			 * error if larger */
			double e2[3];
			for (int c = 0; c < 3; c++)
				e2[c] = (mean[c] - old[c]) * (mean[c] - old[c]);
			double d = rel3(o, e2), wa = na / (na + k), wb = k / (na + k);
			double em = isfinite(prev) && prev > d ? prev : d;
			double diff = wb * wb * d + wa * wa * em;
			/* Over the base pass's one sample the difference is mostly
			 * that sample's own error: at an edge it is on one side or
			 * the other, and the antialiased mean is far nearer the
			 * truth.  There the new mean is charged no more than its
			 * f x f render pixels' spread shows (their mean's
			 * variance; at an edge the render subdivided, so its
			 * pixels are means of many samples and the bound is high
			 * if anything).  Without it, after the pass, still_life's
			 * estimate at 160x120 stood at over 100 times the truth
			 * and arealit3's (Debian's) at 320x240 at 55 times, and a
			 * run at --target 1e-3 took a second pass that bought
			 * nothing (2.8e-5 in 35 CPU s against 2.6e-5 in 9 s).
			 * Taken for edges, the spread is over the cells the render
			 * pixels stand for (edge_cells()). */
			if (first) {
				double rv = rel3(o, v) / ek;
				if (isfinite(rv) && rv < diff)
					diff = rv;
			}
			acc->px[i * ACC_NCH + ACC_DIFF] = (float)diff;
		}
	return count;
}

/*
 * The twist of four quadrant means q (in the order top-left, top-right,
 * bottom-left, bottom-right): (q0 - q1 - q2 + q3) / 4 per channel,
 * squared, relative to mean^2 + 0.01, mean over R, G, B.  The samples of a
 * region render are stratified by quadrant, so their mean's error is the
 * mean of the quadrants' errors; the twist has the same variance under
 * noise and no part of a linear change across the pixel (an edge or a
 * curve through it adds to it, so it errs high).  NaN when not finite.
 */
static double quad_twist(double q[4][3], const double mean[3])
{
	double v[3];
	for (int c = 0; c < 3; c++) {
		double t = (q[0][c] - q[1][c] - q[2][c] + q[3][c]) / 4.0;
		v[c] = t * t;
	}
	double r = 0.0;
	for (int c = 0; c < 3; c++)
		r += v[c] / (mean[c] * mean[c] + METRICS_RELMSE_EPS) / 3.0;
	return isfinite(r) ? r : NAN;
}

/*
 * The 'diff' of a fold of nb new samples onto na (accum_fold()) takes both
 * means as independent samples' (each of variance sigma^2 / n), so the
 * difference between them d2 gives the merged mean's sigma^2 / (na + nb).
 * A region render's samples are stratified: where the pixel varies across
 * its area (an edge, a texture, a penumbra's slope) their mean is far
 * closer than sigma^2 / nb, and the base pass's one sample at the centre
 * is the one that differs.  With vb, the new mean's own squared error
 * (quad_twist() averaged over the 3 x 3 pixels around that have one: one
 * pixel's is one number's square, about a degree of freedom), the old
 * mean's is d2 - vb, and the merged mean's (na^2 (d2 - vb) + nb^2 vb) /
 * (na + nb)^2.
 *
 * Both err high where the pixel has structure (the independent one where
 * the base sample stands apart from a stratified mean, the lowered one
 * where an edge twists the quadrants) and are each about right on noise.
 * Per pixel each is a handful of squared numbers, and the smaller of the
 * two noisy values is biased low: the image mean of that per-pixel minimum
 * was half the true error of the merged means (scripts/fold_check.py: full
 * frames of the base pass and a scale-4 grid render at 160x120, against
 * the references: soft_shadows 0.51, focal_blur 0.47, glossy_reflection
 * 0.54, media 0.51, thin_geometry 0.66, horizon_texture 0.94, still_life
 * 0.75; independent alone 1.82, 1.04, 1.08, 1.01, 2.57, 1.66, 1.80;
 * lowered alone 1.20, 1.15, 1.08, 1.02, 1.60, 1.74, 3.70).  So the choice
 * is made on their means over the 5 x 5 pixels around: where one is more
 * than STRAT_APART times the other, the smaller one's value, else the mean
 * of the two (0.89, 0.93, 0.96, 0.98, 1.39, 1.43, 1.35).
 *
 * Only onto the base pass's one sample (fewer than 4: the base pass's, or
 * scale 2's with some missing), or onto 5, that and scale 2's four at fixed
 * positions (a scale-4 render after a scale-2 pass): strat_onto().  Onto 5,
 * whole frames of the base pass and scale 2 with a scale-4 render by
 * resolution scaling (scripts/fold_check.py --onto 5 --scaling) gave the
 * independent figure at 0.99 to 6.20 of the truth on seven scenes
 * (soft_shadows 6.20, horizon_texture 2.23, still_life 1.77,
 * thin_geometry 1.47) and 0.57 to 0.79 on starfield and hdr_highlights;
 * the rule 0.86 to 2.41, and 0.52 and 0.66.  Onto 4 (a radiosity pass at
 * scale 2, whose samples share the solution of every later render, so
 * that their fold difference already reads low) and onto 6 or more,
 * stratified themselves at jittered positions, not: there d2 is no longer
 * mostly the old mean's, and the twist of the new samples' quadrants
 * understates their error where the sub-pixels of one render share a
 * pattern (POV-Ray's area-light and blur sampling), so the lowered diff
 * put the estimate of long runs at a third to a half of the truth.  At
 * 160x120, every fold lowered against only those onto the base pass's
 * sample (2026-12-01, the smaller of the two figures then, one run each,
 * estimated over true relMSE): soft_shadows --budget 4 0.47 against 1.20,
 * thin_geometry --target 3e-4 0.53 against 0.74, --budget 4 0.59 against
 * 0.74, starfield --target 3e-4 0.83 against 1.00, glossy_reflection
 * --target 3e-4 0.66 against 0.86 (README).
 *
 * A region's merge notes each pixel it folds (strat_note()), and once all
 * have folded strat_end() sets their diffs.  Without the memory
 * (strat_begin() returns 0) the diffs stay the independent samples'.
 */
#define STRAT_APART 2.0
struct strat {
	int x0, y0, rw, rh;
	double *tw;		/* the twist of the new samples, NaN where none */
	double *d2, *na, *nb;	/* the fold's difference and counts; nb 0: no fold */
	double *ind, *lo;	/* the two figures, NaN where there is no choice */
};

/* Whether a fold onto na samples gets the choice (above). */
static int strat_onto(double na)
{
	return na > 0.0 && (na < 4.0 || na == 5.0);
}

static int strat_begin(struct strat *st, int x0, int y0, int x1, int y1)
{
	st->x0 = x0;
	st->y0 = y0;
	st->rw = x1 - x0 + 1;
	st->rh = y1 - y0 + 1;
	const size_t rn = (size_t)st->rw * st->rh;
	st->tw = malloc(6 * rn * sizeof(*st->tw));
	if (!st->tw)
		return 0;
	st->d2 = st->tw + rn;
	st->na = st->d2 + rn;
	st->nb = st->na + rn;
	st->ind = st->nb + rn;
	st->lo = st->ind + rn;
	for (size_t k = 0; k < rn; k++) {
		st->tw[k] = st->ind[k] = st->lo[k] = NAN;
		st->nb[k] = 0.0;
	}
	return 1;
}

/* Pixel (x, y) (index i) has folded nb new samples of mean `mean`, with
 * quadrant means q (NULL: not all four), onto na of mean old. */
static void strat_note(struct strat *st, const struct image *acc, size_t i, int x, int y,
		       const double old[3], double na, const double mean[3], double nb,
		       double q[4][3])
{
	if (!st->tw)
		return;
	const size_t k = (size_t)(y - st->y0) * st->rw + (x - st->x0);
	double e2[3];
	for (int c = 0; c < 3; c++)
		e2[c] = (mean[c] - old[c]) * (mean[c] - old[c]);
	st->tw[k] = q ? quad_twist(q, mean) : NAN;
	st->d2[k] = rel3(acc->px + i * ACC_NCH, e2);
	st->na[k] = na;
	st->nb[k] = nb;
}

/* The means of u and of v over the 5 x 5 pixels of the region around
 * (x, y) where both are finite, into *mu and *mv (NaN where none is). */
static void strat_around(const struct strat *st, const double *u, const double *v, int x, int y,
			 double *mu, double *mv)
{
	double su = 0.0, sv = 0.0;
	int n = 0;
	for (int j = y - 2; j <= y + 2; j++)
		for (int l = x - 2; l <= x + 2; l++) {
			if (j < 0 || j >= st->rh || l < 0 || l >= st->rw)
				continue;
			const size_t k = (size_t)j * st->rw + l;
			if (isfinite(u[k]) && isfinite(v[k])) {
				su += u[k];
				sv += v[k];
				n++;
			}
		}
	*mu = n ? su / n : NAN;
	*mv = n ? sv / n : NAN;
}

static void strat_end(struct strat *st, struct image *acc)
{
	if (!st->tw)
		return;
	for (int y = 0; y < st->rh; y++)
		for (int x = 0; x < st->rw; x++) {
			const size_t k = (size_t)y * st->rw + x;
			const float *o = acc->px + ((size_t)(st->y0 + y) * acc->w + st->x0 + x) * ACC_NCH;
			const double na = st->na[k], nb = st->nb[k], d2 = st->d2[k];
			if (!isfinite(st->tw[k]) || !strat_onto(na) || !(nb > 0.0) ||
			    !isfinite(o[ACC_DIFF]))
				continue;
			double sum = 0.0;
			int n = 0;
			for (int j = y - 1; j <= y + 1; j++)
				for (int l = x - 1; l <= x + 1; l++)
					if (j >= 0 && j < st->rh && l >= 0 && l < st->rw &&
					    isfinite(st->tw[(size_t)j * st->rw + l])) {
						sum += st->tw[(size_t)j * st->rw + l];
						n++;
					}
			const double vb = sum / n, nt = na + nb;
			const double st_d = (na * na * (d2 > vb ? d2 - vb : 0.0) + nb * nb * vb) / (nt * nt);
			if (isfinite(st_d)) {
				st->ind[k] = o[ACC_DIFF];
				st->lo[k] = st_d;
			}
		}
	const double *ind = st->ind, *lo = st->lo;
	for (int y = 0; y < st->rh; y++)
		for (int x = 0; x < st->rw; x++) {
			const size_t k = (size_t)y * st->rw + x;
			if (!isfinite(lo[k]))
				continue;
			double ai, as;
			strat_around(st, ind, lo, x, y, &ai, &as);
			const double big = ai > as ? ai : as, small = ai > as ? as : ai;
			const double d = big > STRAT_APART * small ? (as < ai ? lo[k] : ind[k])
								   : 0.5 * (ind[k] + lo[k]);
			acc->px[((size_t)(st->y0 + y) * acc->w + st->x0 + x) * ACC_NCH + ACC_DIFF] = (float)d;
		}
	free(st->tw);
	st->tw = NULL;
}

/* Pixel (x, y) of a grid render: its sub-pixels' values (sub, nq of them
 * finite; in the quadrant order of quad_twist() when all 4 are), their
 * mean, sum of squared deviations m2 and count of samples each (*g). */
static int grid_pixel(const struct image *acc, const struct image *img, int oy, const int ch[3],
		      int s, int x, int y, double sub[4][3], double mean[3], double m2[3], int *g)
{
	const int f = ACC_GRID_FRAME, g0 = accum_grid_samples(s) / 4;	/* per sub-pixel */
	size_t i = (size_t)y * acc->w + x;
	const float *o = acc->px + i * ACC_NCH;
	int nq = 0;
	/* a sub-pixel's centre sample repeats scale 2's where the pixel has
	 * it: taken out, by the pixel's mean in its place.  Not where scale
	 * 2's bit stands for an antialiased render alone (ACC_AA_NOGRID): its
	 * samples are at corners, none at those centres, and taking the mean
	 * out would bias the fold by a quarter of the centres' difference
	 * from it, at an edge a large one */
	const int dup = accum_has_scale(acc, i, 2) && !accum_has_scale(acc, i, ACC_AA_NOGRID) &&
			o[ACC_SAMPLES] > 0.0f;
	*g = dup ? g0 - 1 : g0;
	for (int c = 0; c < 3; c++)
		mean[c] = 0.0;
	for (int j = 0; j < f; j++)
		for (int l = 0; l < f; l++) {
			const float *p = img->px +
				((size_t)(y * f + j - oy) * img->w + (size_t)x * f + l) * img->nch;
			if (!isfinite(p[ch[0]]) || !isfinite(p[ch[1]]) || !isfinite(p[ch[2]]))
				continue;
			for (int c = 0; c < 3; c++) {
				sub[nq][c] = dup ? (g0 * (double)p[ch[c]] - o[c]) / *g : p[ch[c]];
				mean[c] += sub[nq][c];
			}
			nq++;
		}
	for (int c = 0; c < 3; c++) {
		mean[c] = nq ? mean[c] / nq : 0.0;
		double b = 0.0;
		for (int q = 0; q < nq; q++)
			b += (sub[q][c] - mean[c]) * (sub[q][c] - mean[c]);
		/* per sample: what the sub-pixels' spread means for noise,
		 * capped by the pixel's own sample variance */
		double v = nq > 1 ? *g * b / (nq - 1) : NAN;
		double own = o[ACC_SAMPLES] >= 2.0f ? (double)o[ACC_VAR_R + c] : NAN;
		if (!isfinite(v) || (isfinite(own) && own < v))
			v = own;
		m2[c] = *g * b + (isfinite(v) ? nq * (*g - 1) * v : 0.0);
	}
	return nq;
}

/* Fold a grid render (ACC_GRID_FRAME; see accum_merge_region()). */
static long merge_grid(struct image *acc, const struct image *img, int oy, const int ch[3],
		       int s, int x0, int y0, int x1, int y1, int pass, int holes)
{
	struct strat st;
	strat_begin(&st, x0, y0, x1, y1);
	long count = 0;
	for (int y = y0; y <= y1; y++)
		for (int x = x0; x <= x1; x++) {
			size_t i = (size_t)y * acc->w + x;
			const float *o = acc->px + i * ACC_NCH;
			double sub[4][3], mean[3], m2[3], old[3] = { o[0], o[1], o[2] };
			double na = o[ACC_SAMPLES];
			int g, nq = grid_pixel(acc, img, oy, ch, s, x, y, sub, mean, m2, &g);
			if ((holes && nq < 4) || accum_fold(acc, i, s, nq * g, mean, m2, pass) || !nq)
				continue;
			count++;
			strat_note(&st, acc, i, x, y, old, na, mean, (double)nq * g,
				   nq == 4 ? sub : NULL);
		}
	strat_end(&st, acc);
	return count;
}

/* Whether a region render of scale s may come at twice the image's size
 * (ACC_GRID_FRAME): a grid render (scale 4 or more) or an antialiased
 * render in scale 2's place. */
static int may_double(int s)
{
	return s >= 4 || s == ACC_AA;
}

/* A region render of scale s, render_w pixels wide, of an image image_w
 * wide: its size over the image's, ACC_GRID_FRAME for one at twice the width
 * (may_double()), else accum_render_factor(s). */
static int render_frame(int s, int render_w, int image_w)
{
	return may_double(s) && render_w == image_w * ACC_GRID_FRAME ? ACC_GRID_FRAME
								     : accum_render_factor(s);
}

/* Pixel (x, y) of a render s times the image's size: the mean of its
 * s x s finite samples, their sum of squared deviations m2, and for an even
 * s the means of its four (s/2) x (s/2) quadrants q (in quad_twist()'s
 * order; meaningful when all samples are finite).  Returns the count. */
static int scaled_pixel(const struct image *img, int oy, const int ch[3], int s, int x, int y,
			double mean[3], double m2[3], double q[4][3])
{
	double sum[3] = { 0.0, 0.0, 0.0 };
	int n = 0;
	for (int k = 0; k < 4; k++)
		for (int c = 0; c < 3; c++)
			q[k][c] = 0.0;
	for (int pass2 = 0; pass2 < 2; pass2++) {
		for (int j = 0; j < s; j++) {
			const float *row = img->px +
				((size_t)(y * s + j - oy) * img->w + (size_t)x * s) * img->nch;
			for (int k = 0; k < s; k++) {
				const float *p = row + (size_t)k * img->nch;
				if (!isfinite(p[ch[0]]) || !isfinite(p[ch[1]]) || !isfinite(p[ch[2]]))
					continue;
				const int quad = (2 * j >= s) * 2 + (2 * k >= s);
				for (int c = 0; c < 3; c++) {
					if (!pass2) {
						sum[c] += p[ch[c]];
						q[quad][c] += p[ch[c]] * 4.0 / ((double)s * s);
					} else {
						double d = p[ch[c]] - mean[c];
						m2[c] += d * d;
					}
				}
				n += !pass2;
			}
		}
		if (!pass2)
			for (int c = 0; c < 3; c++) {
				mean[c] = n ? sum[c] / n : 0.0;
				m2[c] = 0.0;
			}
	}
	return n;
}

/* A render's R, G and B channels, into ch; -1 (the message in err) when it
 * lacks one. */
static int render_rgb(const struct image *img, int ch[3], char *err, size_t errlen)
{
	static const char *const name[3] = { "R", "G", "B" };
	for (int c = 0; c < 3; c++)
		if ((ch[c] = image_channel(img, name[c])) < 0) {
			errbuf_printf(err, errlen, "the render has no R, G and B channels");
			return -1;
		}
	return 0;
}

static int merge_region(struct image *acc, const struct image *img, int oy, int s, int x0,
			int y0, int x1, int y1, int pass, int depth, int edges, int holes,
			long *folded, char *err, size_t errlen)
{
	if (folded)
		*folded = 0;
	if (s != ACC_AA && s != 3 && (s < 1 || s > 16 || (s & (s - 1)) != 0)) {
		errbuf_printf(err, errlen, "scale %d is not one of 0 (antialiased), 1, 2, 3 (a "
			      "radiosity pass), 4, 8, 16", s);
		return -1;
	}
	if (x0 < 0 || y0 < 0 || x1 >= acc->w || y1 >= acc->h || x0 > x1 || y0 > y1) {
		errbuf_printf(err, errlen, "region %d,%d-%d,%d lies outside the %dx%d image", x0,
			      y0, x1, y1, acc->w, acc->h);
		return -1;
	}
	const int f = render_frame(s, img->w, acc->w), grid = f != accum_render_factor(s);
	if (img->w != acc->w * f) {
		if (may_double(s))
			errbuf_printf(err, errlen,
				      "the render is %d pixels wide, not %d (%d x %d) or %d (%s)",
				      img->w, acc->w * f, acc->w, f, acc->w * ACC_GRID_FRAME,
				      s == ACC_AA ? "antialiased in scale 2's place" : "a grid render");
		else
			errbuf_printf(err, errlen, "the render is %d pixels wide, not %d (%d x %d)",
				      img->w, acc->w * f, acc->w, f);
		return -1;
	}
	if (oy > y0 * f || oy + img->h < (y1 + 1) * f) {
		errbuf_printf(err, errlen, "the render lacks rows %d..%d", y0 * f,
			      (y1 + 1) * f - 1);
		return -1;
	}
	int ch[3];
	if (render_rgb(img, ch, err, errlen))
		return -1;
	if (s == ACC_AA || grid) {
		long c = s == ACC_AA
				 ? merge_aa(acc, img, oy, ch, f, x0, y0, x1, y1, pass, depth, edges,
					    holes)
				 : merge_grid(acc, img, oy, ch, s, x0, y0, x1, y1, pass, holes);
		if (folded)
			*folded = c;
		return 0;
	}
	/* as merge_grid()'s, with the quadrants of an even scale's s x s */
	struct strat st = { 0 };
	if (s % 2 == 0)
		strat_begin(&st, x0, y0, x1, y1);
	long count = 0;
	for (int y = y0; y <= y1; y++) {
		for (int x = x0; x <= x1; x++) {
			double mean[3], m2[3], q[4][3];
			int n = scaled_pixel(img, oy, ch, s, x, y, mean, m2, q);
			if (holes && n < s * s)
				continue;
			size_t i = (size_t)y * acc->w + x;
			const float *o = acc->px + i * ACC_NCH;
			double old[3] = { o[0], o[1], o[2] }, na = o[ACC_SAMPLES];
			if (accum_fold(acc, i, s, n, mean, m2, pass) || !n)
				continue;
			count++;
			strat_note(&st, acc, i, x, y, old, na, mean, n, n == s * s ? q : NULL);
		}
	}
	strat_end(&st, acc);
	if (folded)
		*folded = count;
	return 0;
}

int accum_split_diff(struct image *acc, const struct image *img, int s, char *err,
		     size_t errlen)
{
	int ch[3];
	if (render_rgb(img, ch, err, errlen))
		return -1;
	if (s < 1 || img->w != acc->w * s || img->h != acc->h * s) {
		errbuf_printf(err, errlen, "the render is %dx%d, not %dx%d at scale %d",
			      img->w, img->h, acc->w * s, acc->h * s, s);
		return -1;
	}
	if (s == 1)	/* one sample a pixel: no halves */
		return 0;
	/* the halves' counts: (j + k) even, then odd, over the s x s */
	const double na = (s * s + 1) / 2, nb = s * s / 2;
	for (int y = 0; y < acc->h; y++)
		for (int x = 0; x < acc->w; x++) {
			float *o = acc->px + ((size_t)y * acc->w + x) * ACC_NCH;
			if (o[ACC_SAMPLES] != (float)(na + nb))
				continue;
			double sum[2][3] = { { 0.0, 0.0, 0.0 }, { 0.0, 0.0, 0.0 } };
			int ok = 1;
			for (int j = 0; j < s; j++)
				for (int k = 0; k < s; k++) {
					const float *p = img->px +
						(((size_t)y * s + j) * img->w + (size_t)x * s + k) * img->nch;
					for (int c = 0; c < 3; c++) {
						ok &= isfinite(p[ch[c]]) != 0;
						sum[(j + k) & 1][c] += p[ch[c]];
					}
				}
			if (!ok)
				continue;
			/* as accum_fold() would have it, the second half folded
			 * onto the first */
			double e2[3];
			for (int c = 0; c < 3; c++) {
				const double d = sum[1][c] / nb - sum[0][c] / na;
				e2[c] = d * d;
			}
			o[ACC_DIFF] = (float)fold_diff(rel3(o, e2), na, nb);
		}
	return 0;
}

int accum_merge_region(struct image *acc, const struct image *img, int oy, int s, int x0,
		       int y0, int x1, int y1, int pass, long *folded, char *err,
		       size_t errlen)
{
	return merge_region(acc, img, oy, s, x0, y0, x1, y1, pass, 0, 0, 0, folded, err, errlen);
}

/* Whether depth is not one an antialiased render in scale 2's place may
 * have (the message in err). */
static int bad_depth(int depth, char *err, size_t errlen)
{
	if (depth >= 1 && depth <= ACC_AA_DEPTH)
		return 0;
	errbuf_printf(err, errlen, "antialiasing depth %d is not 1 to %d", depth, ACC_AA_DEPTH);
	return 1;
}

int accum_merge_aa_region(struct image *acc, const struct image *img, int oy, int s,
			  int depth, int edges, int x0, int y0, int x1, int y1, int pass,
			  long *folded, char *err, size_t errlen)
{
	if (bad_depth(depth, err, errlen))
		return -1;
	return merge_region(acc, img, oy, s, x0, y0, x1, y1, pass, depth, edges, 0, folded, err,
			    errlen);
}

int accum_merge_partial(struct image *acc, const struct image *img, int oy, int s, int depth,
			int edges, int x0, int y0, int x1, int y1, int pass, long *folded,
			char *err, size_t errlen)
{
	if (s == ACC_AA && bad_depth(depth, err, errlen))
		return -1;
	return merge_region(acc, img, oy, s, x0, y0, x1, y1, pass, s == ACC_AA ? depth : 0,
			    s == ACC_AA ? edges : 0, 1, folded, err, errlen);
}

static int merge_file(struct image *acc, const char *path, int s, int x0, int y0, int x1,
		      int y1, int pass, int depth, int edges, long *folded, char *err,
		      size_t errlen)
{
	struct image img = {0};
	int oy = 0;
	if (folded)
		*folded = 0;
	int f = accum_render_factor(s), w, h;
	if (may_double(s)) {	/* twice the size or not: the render's width says */
		if (image_exr_size(path, &w, &h, err, errlen))
			return -1;
		f = render_frame(s, w, acc->w);
	}
	int rc = image_read_exr_rows(path, y0 * f, (y1 + 1) * f - 1, &img, &oy, err, errlen) ||
		 merge_region(acc, &img, oy, s, x0, y0, x1, y1, pass, depth, edges, 0, folded, err,
			      errlen);
	image_release(&img);
	return rc ? -1 : 0;
}

int accum_merge_file(struct image *acc, const char *path, int s, int x0, int y0, int x1,
		     int y1, int pass, long *folded, char *err, size_t errlen)
{
	return merge_file(acc, path, s, x0, y0, x1, y1, pass, 0, 0, folded, err, errlen);
}

int accum_merge_aa_file(struct image *acc, const char *path, int s, int depth, int edges,
			int x0, int y0, int x1, int y1, int pass, long *folded, char *err,
			size_t errlen)
{
	if (bad_depth(depth, err, errlen))
		return -1;
	return merge_file(acc, path, s, x0, y0, x1, y1, pass, depth, edges, folded, err, errlen);
}

/* The finest scale pixel i has been sampled at; an antialiased render of
 * --sampler aa (+A0, subdividing to 1/16 of a pixel where corners differ at
 * all) counts as 8.  In scale 2's place (+A0.1, ACC_AA_HALF) it counts as 2:
 * where the corners differ by less than the threshold its samples are half
 * a pixel apart; where it subdivided (ACC_AA_DEEP: taken for edges, or as
 * its base sample's first fold for a few pixels, ACC_AA_FEW), as 8. */
static int finest_scale(const struct image *acc, size_t i)
{
	int best = 1;
	for (int k = 0; k < ACC_NSCALES; k++)
		if (accum_has_scale(acc, i, accum_scales[k]))
			best = accum_scales[k];
	if (accum_has_scale(acc, i, ACC_AA) && best < 8 &&
	    (!accum_has_scale(acc, i, ACC_AA_HALF) || accum_has_scale(acc, i, ACC_AA_DEEP)))
		best = 8;
	return best;
}

/* Pixel i's eight neighbours inside the image (row by row), into q; returns
 * how many. */
static int neighbours8(const struct image *acc, size_t i, const float *q[8])
{
	const int w = acc->w, h = acc->h, x = (int)(i % (size_t)w), y = (int)(i / (size_t)w);
	int k = 0;
	for (int dy = -1; dy <= 1; dy++)
		for (int dx = -1; dx <= 1; dx++)
			if ((dx || dy) && x + dx >= 0 && x + dx < w && y + dy >= 0 && y + dy < h)
				q[k++] = acc->px + ((size_t)(y + dy) * w + (x + dx)) * ACC_NCH;
	return k;
}

/*
 * Whether a step of squared height h2 in channel c between a pixel and its
 * diagonal neighbour shows in the samples of either pixel beside both
 * (side, NULL for an edge-on neighbour): 12 times its sample variance, a
 * ramp's, reaches h2.  An edge parting the two diagonal pixels crosses
 * their 2 x 2 block through those two (or exactly at its centre); where one
 * holds it, the part of it in this pixel's unsampled corner is small.
 * hdr_highlights at --target 3e-3: the dark pixels diagonal to a lamp's
 * fully lit pixels, the lamp's rim in the pixels between, were charged
 * 0.48 each for a true error of 0 (twelve pixels held 2/3 of the estimate's
 * hidden-edge part; est/true 2.38, 1.35 without them).  A side pixel that
 * POV-Ray subdivided in an antialiased render (ACC_AA_DEEP) shows it too:
 * its render pixels differed by the threshold.  (Once the lamps' rims took
 * that render as up to ACC_AA_FEW cells, the grid's spread after it no
 * longer showed in their variance, and at 3e-3 the estimate stood at 10
 * times the truth; 5 times with this.)
 */
static int step_beside(const float *const side[2], int c, double h2)
{
	for (int k = 0; k < 2; k++)
		if (side[k] && ((side[k][ACC_SAMPLES] >= 4.0f && 12.0 * side[k][ACC_VAR_R + c] >= h2) ||
				((uint32_t)side[k][ACC_SCALES] >> ACC_AA_DEEP & 1u)))
			return 1;
	return 0;
}

/*
 * The expected relative squared error of pixel i from an edge hidden
 * between its samples and its neighbours': for each neighbour and channel,
 * the part d of their difference that neither pixel's own samples show
 * (d^2 less 12 times each one's sample variance, a ramp of height d having
 * variance d^2 / 12), an edge at an unknown place in the unsampled strip
 * of width 1/(2s) next to the neighbour moves the pixel's value v by
 * alpha d, alpha uniform in [0, 1/(2s)]: the mean over alpha of
 * (alpha d)^2 / ((v + alpha d)^2 + 0.01), by the midpoint rule on 4
 * points.  The edge lies in the gap between the two pixels' samples, the
 * neighbour's strip 1/(2 s_j) wide (s_j its finest scale): on this pixel's
 * side with probability s_j / (s + s_j), which weighs the term.  (Charged
 * in full to each of the two, an edge between two pixels of equal scale
 * counted twice: hdr_highlights' estimate at --target 3e-3 was 3.1 times
 * its true relMSE, 1.9 with the weight, the dark pixels beside its lamps
 * near 1 each; the plans of nine scenes at targets 3e-3 to 3e-4 took 0 to
 * 24% fewer samples to errors from 3% lower to 11% higher, a fixed cost
 * model and one job making them deterministic.)  Between two pixels of
 * an antialiased render taken for edges (ACC_AA_EDGE) the part hidden is
 * at most the render's threshold over the channels (ACC_AA_THRESHOLD / 3
 * each): where their shared corners differed by more, POV-Ray subdivided
 * (uncapped, the term held 0.9 of still_life's estimate after that pass,
 * 7.8e-4 for a true relMSE of 1.6e-5; capped, 5e-5), and a pixel of such a
 * render that POV-Ray did not subdivide is charged nothing towards one it
 * did (ACC_AA_DEEP): the edge is there, and with the weight above 8 / 10
 * of it fell on this side (at --target 3e-3 still_life's 403 such pixels
 * held 1.1e-5 of its estimate of 2.55e-5, for a true 4e-7; with this
 * exemption the estimate is 1.66e-5 for a true 4.28e-6, the same image).
 * The exemption holds for a render taken for a few pixels as well (both
 * pixels ACC_AA_HALF; measured at +R5, see below), at whatever depth a
 * budget gave it, and for a neighbour refined at scale 8 later, whose bit
 * ACC_AA_DEEP shares, though there no cap bounded the term it loses.
 * The largest over the eight neighbours, mean over R, G, B.
 */
static double hidden_edge(const struct image *acc, size_t i, int s)
{
	const float *o = acc->px + i * ACC_NCH, *nb[8];
	const int own = o[ACC_SAMPLES] >= 4.0f, nn = neighbours8(acc, i, nb);
	/* whether its samples' spread bounds a step it shares with a
	 * neighbour of a render taken for edges (below): not for +AM1's
	 * (ACC_AA_SPREAD_BIT), which shares no corners with its neighbours */
	const int bounds = own && !accum_has_scale(acc, i, ACC_AA_SPREAD_BIT);
	const int w = acc->w, px = (int)(i % (size_t)w), py = (int)(i / (size_t)w);
	double best = 0.0;
	for (int j = 0; j < nn; j++) {
		const float *q = nb[j];
		if (!(q[ACC_SAMPLES] > 0.0f))
			continue;
		const int theirs = q[ACC_SAMPLES] >= 4.0f;
		const size_t qi = (size_t)(q - acc->px) / ACC_NCH;
		/* two pixels of a render taken for edges: their corners
		 * between them differed by less than the threshold, or POV-Ray
		 * subdivided there (ACC_AA_EDGE) */
		const int seen = accum_has_scale(acc, i, ACC_AA_EDGE) &&
				 accum_has_scale(acc, qi, ACC_AA_EDGE);
		/* ... and where POV-Ray subdivided the neighbour and not this
		 * pixel, both of such a render (for edges or, since +R5, for a
		 * few pixels: ACC_AA_HALF), the edge is the neighbour's: the two
		 * share the corners on their border, and an edge crossing into
		 * this pixel's render pixels would have parted their corners
		 * too.  (ACC_AA_DEEP is scale 8's bit: a neighbour of the render
		 * refined at scale 8 later counts too; for edges it loses only
		 * the capped term for a step below the threshold, which its
		 * corners' agreement with this pixel's bounded already.)  For a
		 * few pixels: hdr_highlights' dark pixels beside its lamps were
		 * charged 0.6 to 1.0 each for a true error of 0, and held 0.8 of
		 * the estimate at --target 3e-3 (est/true 5.2).  At +R4 the rule
		 * left the estimate at 0.5 times the truth at 1e-3 (the charges
		 * had stood in for rims the render got wrong); at +R5 it is 1.31
		 * at 1e-3 to 1e-4 and 0.73 to 1.46 under 2 and 4 s (see
		 * ACC_AA_DEPTH). */
		if (accum_has_scale(acc, i, ACC_AA_HALF) && accum_has_scale(acc, qi, ACC_AA_HALF) &&
		    accum_has_scale(acc, qi, ACC_AA_DEEP) && !accum_has_scale(acc, i, ACC_AA_DEEP))
			continue;
		/* a diagonal neighbour: the two pixels beside both */
		const float *side[2] = { NULL, NULL };
		const int qx = (int)(qi % (size_t)w), qy = (int)(qi / (size_t)w);
		if (qx != px && qy != py) {
			side[0] = acc->px + ((size_t)py * w + qx) * ACC_NCH;
			side[1] = acc->px + ((size_t)qy * w + px) * ACC_NCH;
		}
		double e = 0.0;
		for (int c = 0; c < 3; c++) {
			double d = (double)q[c] - o[c], v = o[c];
			double h2 = d * d - 12.0 * ((own ? o[ACC_VAR_R + c] : 0.0) +
						    (theirs ? q[ACC_VAR_R + c] : 0.0));
			if (!(h2 > 0.0) || step_beside(side, c, h2))
				continue;
			double dh = d > 0.0 ? sqrt(h2) : -sqrt(h2);
			/* between two pixels of a render taken for edges, at most
			 * the threshold, and at most what this pixel's samples
			 * spread over (ACC_AA_STEP_SD of their deviation: after
			 * the render's fold, about its render pixels') where that
			 * bounds it (`bounds`, above) */
			double cap = ACC_AA_THRESHOLD / 3.0;
			if (seen && bounds && ACC_AA_STEP_SD * sqrt(o[ACC_VAR_R + c]) < cap)
				cap = ACC_AA_STEP_SD * sqrt(o[ACC_VAR_R + c]);
			if (seen && fabs(dh) > cap)
				dh = d > 0.0 ? cap : -cap;
			for (int k = 0; k < 4; k++) {
				double m = (k + 0.5) / (8.0 * s) * dh;
				e += m * m / ((v + m) * (v + m) + METRICS_RELMSE_EPS) / 12.0;
			}
		}
		if (!(e > 0.0))
			continue;
		/* the edge lies in the gap between the two pixels' samples, our
		 * strip 1/(2s) wide and theirs 1/(2 s_j): on our side with
		 * probability s_j / (s + s_j) */
		const int sj = finest_scale(acc, qi);
		e *= (double)sj / (s + sj);
		if (e > best)
			best = e;
	}
	return isfinite(best) ? best : 1.0;
}

double accum_error_scale(const struct image *acc, size_t i, const float fit[3])
{
	const float *o = acc->px + i * ACC_NCH;
	double den = 0.0;
	for (int c = 0; c < 3; c++) {
		double f = fit && isfinite(fit[c]) ? fit[c] : o[c];
		den += (f * f + METRICS_RELMSE_EPS) / 3.0;
	}
	return den;
}

/*
 * An error relative to the pixel's mean m, value^2 + 0.01 with m for the
 * value, is relative to the true value x by the factor this returns:
 * (m^2 + 0.01) / (x^2 + 0.01) per channel (mean over R, G, B of each), with
 * x^2 estimated as m^2 - var / n (E[m^2] = x^2 + sigma^2 / n), kept at least
 * m^2 / 4.  A rare bright sample (a firefly: one of 5 samples on a
 * highlight) lifts m far above x, and the error relative to m hid it
 * (hdr_highlights at --target 1e-3 stopped at a true relMSE of 1.5e-3 on an
 * estimate of 4.6e-4, one pixel 0.18 estimated and 12.5 true).  Without the
 * floor, an estimate x^2 of about 0 from a handful of samples multiplied
 * errors by up to 100: hdr_highlights' estimate after its first
 * refinement pass was 16 times the true relMSE; with it, 0.98 times.
 */
static double value_bias(const float *o)
{
	double n = o[ACC_SAMPLES], m = 0.0, x = 0.0;
	for (int c = 0; c < 3; c++) {
		double m2 = (double)o[c] * o[c], x2 = m2 - (double)o[ACC_VAR_R + c] / n;
		if (!(x2 >= 0.25 * m2))
			x2 = 0.25 * m2;
		m += m2 + METRICS_RELMSE_EPS;
		x += x2 + METRICS_RELMSE_EPS;
	}
	return isfinite(m / x) ? m / x : 1.0;
}

/* Whether POV-Ray subdivided pixel i in a render taken for edges
 * (ACC_AA_DEEP is scale 8's bit too: a grid render of scale 8 alone sets
 * it, and its spread is the pixel's noise). */
static int subdivided(const struct image *acc, size_t i)
{
	return accum_has_scale(acc, i, ACC_AA_EDGE) && accum_has_scale(acc, i, ACC_AA_DEEP);
}

/*
 * The largest relative squared error pixel i's mean can have if its true
 * value lies within the range of the means of its 3x3 neighbourhood (itself
 * included): per channel, (m - r)^2 / (r^2 + 0.01) at r the range's lower or
 * upper end (it falls from either end towards m), mean over R, G, B.  A
 * detail that no sample of the nine pixels has seen is beyond it, as it is
 * beyond PRESS; the hidden-edge part of the estimate is for those.  A
 * neighbour POV-Ray subdivided for an edge (ACC_AA_DEEP) counts as the
 * nearest value of its mean +- its samples' spread: its mean is a mix of
 * the edge's two sides (still_life at --target 3e-3: the 42 one-sample
 * pixels beside a subdivided row, whose mean the dark side two rows up had
 * lowered by 0.035, were estimated up to 0.008 each by PRESS, the range
 * bound no lower, for a true 2e-8: 3.8e-6 of the image's 1.66e-5 in all;
 * now 5e-9).
 */
static double range_bound(const struct image *acc, size_t i)
{
	const int w = acc->w, h = acc->h, x = (int)(i % (size_t)w), y = (int)(i / (size_t)w);
	const float *o = acc->px + i * ACC_NCH;
	double lo[3] = { o[0], o[1], o[2] }, hi[3] = { o[0], o[1], o[2] };
	for (int dy = -1; dy <= 1; dy++)
		for (int dx = -1; dx <= 1; dx++) {
			if (x + dx < 0 || x + dx >= w || y + dy < 0 || y + dy >= h)
				continue;
			const size_t qi = (size_t)(y + dy) * w + (x + dx);
			const float *q = acc->px + qi * ACC_NCH;
			if (!(q[ACC_SAMPLES] > 0.0f))
				continue;
			/* a neighbour POV-Ray subdivided for an edge: its mean
			 * mixes the edge's two sides, and the values beside this
			 * pixel are among its samples: the nearest of its mean
			 * +- its samples' spread */
			const int mixed = q[ACC_SAMPLES] >= 4.0f && subdivided(acc, qi);
			for (int c = 0; c < 3; c++) {
				if (!isfinite(q[c]))
					continue;
				double v = q[c];
				const double sd = sqrt(q[ACC_VAR_R + c]);
				if (mixed && isfinite(sd))
					v = o[c] < v - sd ? v - sd : o[c] > v + sd ? v + sd : o[c];
				lo[c] = v < lo[c] ? v : lo[c];
				hi[c] = v > hi[c] ? v : hi[c];
			}
		}
	double b = 0.0;
	for (int c = 0; c < 3; c++) {
		const double dl = o[c] - lo[c], dh = hi[c] - o[c];
		const double fl = dl * dl / (lo[c] * lo[c] + METRICS_RELMSE_EPS),
			     fh = dh * dh / (hi[c] * hi[c] + METRICS_RELMSE_EPS);
		b += (fl > fh ? fl : fh) / 3.0;
	}
	return isfinite(b) ? b : 1.0;
}

double accum_pixel_noise(const struct image *acc, size_t i, double diff)
{
	const float *o = acc->px + i * ACC_NCH;
	double n = o[ACC_SAMPLES];
	if (!(n >= 4.0))
		return NAN;
	if (isfinite(diff))
		return diff * value_bias(o);
	/* samples from a single render with no split of them to compare (a
	 * radiosity pass whose pixels had a sample missing; one at scale 1
	 * has a sample a pixel): the variance of their mean */
	double v[3];
	for (int c = 0; c < 3; c++)
		v[c] = o[ACC_VAR_R + c] / n;
	return rel3(o, v) * value_bias(o);
}

double accum_pixel_error(const struct image *acc, size_t i, double press, const float fit[3],
			 double noise)
{
	const float *o = acc->px + i * ACC_NCH;
	double n = o[ACC_SAMPLES], e = noise;
	if (!(n >= 4.0)) {
		/* no estimate (a hole the regression could not reach): assume
		 * the worst a pixel of this brightness can plausibly be off by */
		e = isfinite(press) ? press / accum_error_scale(acc, i, fit) : 1.0;
		/* PRESS is smoothed over a neighbourhood: a lamp's residual
		 * spread onto the dark pixels around it, relative to their
		 * darkness (hdr_highlights' base pass was estimated at 0.96
		 * for a true relMSE of 0.018; with the bound 0.040) */
		double rb = range_bound(acc, i);
		if (rb < e)
			e = rb;
	}
	/* an edge or a detail between every sample position so far */
	int fs = finest_scale(acc, i);
	double edge = fs < ACC_EDGE_SCALE ? hidden_edge(acc, i, fs) : 0.0;
	if (edge > e)
		e = edge;
	if (n <= 0.0)
		e = 1.0;
	return e;
}

/*
 * Whether pixel i's noise is like its neighbours': the geometric mean over
 * its 3x3 neighbours with 2 samples or more of their mean's variance over
 * its own (mean over R, G, B) lies within a factor ACC_FIT_ALIKE.  The fit
 * averages the neighbours; where a pixel is far noisier than they (a
 * highlight's pixel among dark ones) or far smoother, it is not of their
 * kind, and a fit pulled to them misses it by more than its own noise can
 * show (hdr_highlights: a highlight's mean 1.41, the fit 0.25, the truth
 * 1.34, the fit within two of the mean's standard deviations).  With the
 * blend's agreement test beside it, a factor 8 rather than 4 took 14% off
 * media's error at 2 s, 9% off glossy_reflection's, 5% off focal_blur's at
 * 3e-3 (a factor 16: 16, 12 and 7.5%), and left thin_geometry's at 3e-3
 * 1.7% worse (16: 2.8%), hdr_highlights and starfield within 0.1% (the 36
 * runs of the README, finished each way from the same samples).
 */
#define ACC_FIT_ALIKE 8.0

/* The variance of pixel o's mean: its sample variance over n, mean over
 * R, G, B. */
static double mean_variance(const float *o)
{
	return ((double)o[ACC_VAR_R] + o[ACC_VAR_G] + o[ACC_VAR_B]) / 3.0 / o[ACC_SAMPLES];
}

static int noise_alike(const struct image *acc, size_t i)
{
	const float *nb[8];
	const double vi = mean_variance(acc->px + i * ACC_NCH);
	const int nn = neighbours8(acc, i, nb);
	double sl = 0.0;
	int k = 0;
	for (int j = 0; j < nn; j++) {
		if (!(nb[j][ACC_SAMPLES] >= 2.0f))
			continue;
		sl += log((mean_variance(nb[j]) + 1e-30) / (vi + 1e-30));
		k++;
	}
	return k > 0 && isfinite(sl) && fabs(sl / k) <= log(ACC_FIT_ALIKE);
}

long accum_final_choose(const struct image *acc, const float *fit, const float *press,
			const float *leverage, const double *noise, enum accum_final mode,
			float *take, double *e)
{
	size_t npx = (size_t)acc->w * acc->h;
	long took = 0;
	for (size_t i = 0; i < npx; i++) {
		const float *o = acc->px + i * ACC_NCH;
		const float *f = fit + 3 * i;
		double n = o[ACC_SAMPLES];
		int fin = isfinite(f[0]) && isfinite(f[1]) && isfinite(f[2]);
		double w = 0.0;
		if (n <= 0.0)
			w = 1.0;
		else if (!fin || mode == ACC_FINAL_SAMPLES)
			w = 0.0;
		else if (mode == ACC_FINAL_RECONSTRUCTION)
			w = 1.0;
		else if (n >= 4.0 && isfinite(o[ACC_DIFF]) && isfinite(noise[i])) {
			double h = leverage[i], p = press[i];
			double sc = accum_error_scale(acc, i, NULL);
			double v = mean_variance(o);
			double u = noise[i] * sc < v ? noise[i] * sc : v;
			if (isfinite(h) && isfinite(p) && h >= 0.0 && h < 1.0 && u > 0.0) {
				/* b: the error of the fit without the pixel,
				 * g = (fit - h Y) / (1 - h), as press's noise
				 * estimate leaves it (see accum.h) */
				double b = p - u > 0.0 ? p - u : 0.0;
				double d2 = 0.0;
				for (int c = 0; c < 3; c++)
					d2 += ((double)f[c] - o[c]) * ((double)f[c] - o[c]) / 3.0;
				double g2 = d2 / ((1.0 - h) * (1.0 - h));
				if (g2 <= ACC_FIT_AGREE * (u + b) && noise_alike(acc, i)) {
					w = u / (u + b) / (1.0 - h);
					if (w > 1.0)
						w = 1.0;
				}
				/* the blend's error, unless an edge between its
				 * samples was the larger part; at least a quarter
				 * of the samples' (see ACC_FIT_FLOOR) */
				if (w > 0.0 && e && !(e[i] > noise[i])) {
					double k = w * (1.0 - h);
					double pred = (1.0 - k) * (1.0 - k) * u + k * k * b;
					e[i] = (pred > ACC_FIT_FLOOR * u ? pred : ACC_FIT_FLOOR * u) / sc;
				}
			}
		}
		take[i] = (float)w;
		took += take[i] > 0.0f;
	}
	return took;
}

void accum_final_image(const struct image *acc, const float *fit, const float *take,
		       float *rgb)
{
	size_t npx = (size_t)acc->w * acc->h;
	for (size_t i = 0; i < npx; i++)
		for (int c = 0; c < 3; c++) {
			double w = take[i], f = fit[3 * i + c], m = acc->px[i * ACC_NCH + c];
			rgb[3 * i + c] = (float)(w >= 1.0 ? f : w > 0.0 ? w * f + (1.0 - w) * m : m);
		}
}

void accum_noise_var(const struct image *acc, size_t i, double noise, double v[3])
{
	const float *o = acc->px + i * ACC_NCH;
	const double n = o[ACC_SAMPLES];
	for (int c = 0; c < 3; c++) {
		double vs = n >= 2.0 ? (double)o[ACC_VAR_R + c] / n : 0.0;
		if (n >= 4.0 && isfinite(noise)) {
			double vn = noise * ((double)o[c] * o[c] + METRICS_RELMSE_EPS);
			if (vn < vs)
				vs = vn;
		}
		v[c] = isfinite(vs) && vs > 0.0 ? vs : 0.0;
	}
}
