/*
 * test_plan.c - unit tests for driver/accum.c (the accumulated render) and
 * driver/plan.c (the pass planner and its regions file), with the row-band
 * reader image_read_exr_rows() they rely on.
 *
 * Expected statistics are computed here directly, in double, by two passes
 * over every sample a pixel has; expected planner numbers come from the
 * model in plan.h and accum.h.  Files go in a fresh mkdtemp() directory.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "driver/accum.h"
#include "driver/metrics.h"
#include "driver/image.h"
#include "driver/plan.h"
#include "driver/povray.h"
#include "tests/testutil.h"

static const char *const rgb_names[] = { "R", "G", "B" };
static const char *const bgr_names[] = { "B", "G", "R" };

static int setup_dir(void **state)
{
	(void)state;
	snprintf(scratch_dir, sizeof(scratch_dir), "/tmp/povpress-test-plan.XXXXXX");
	return mkdtemp(scratch_dir) ? 0 : -1;
}

static int teardown_dir(void **state)
{
	(void)state;
	return run("rm -rf '%s'", scratch_dir) == 0 ? 0 : -1;
}

static float *accpx(const struct image *acc, size_t i)
{
	return acc->px + i * ACC_NCH;
}

/* Mean and unbiased variance of v[0..n-1], two passes in double. */
static void stats2(const double *v, int n, double *mean, double *var)
{
	double s = 0.0, m2 = 0.0;

	for (int k = 0; k < n; k++)
		s += v[k];
	*mean = s / n;
	for (int k = 0; k < n; k++)
		m2 += (v[k] - *mean) * (v[k] - *mean);
	*var = n > 1 ? m2 / (n - 1) : 0.0;
}

static void assert_close(double got, double want, double rel, double abs_tol, const char *what)
{
	if (!(fabs(got - want) <= abs_tol + rel * fabs(want)))
		fail_msg("%s: got %.9g, want %.9g", what, got, want);
}

/* An accumulation of w x h pixels whose base render is value(x, y, c). */
static void make_acc(struct image *acc, int w, int h, double (*value)(int, int, int))
{
	struct image base;
	char err[256];

	assert_int_equal(image_init(&base, w, h, 3, rgb_names, err, sizeof(err)), 0);
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++)
			for (int c = 0; c < 3; c++)
				base.px[((size_t)y * w + x) * 3 + c] = (float)value(x, y, c);
	assert_int_equal(accum_from_base(&base, "base", acc, err, sizeof(err)), 0);
	image_release(&base);
}

static double base_value(int x, int y, int c)
{
	return 0.3 + 0.02 * x + 0.01 * y + 0.05 * c;
}

static double flat_value(int x, int y, int c)
{
	(void)x;
	(void)y;
	(void)c;
	return 0.5;
}

/* The sub-sample of a render at scale s at render pixel (X, Y). */
static double sub_value(int X, int Y, int c, int s)
{
	return 0.2 + 0.1 * c + 0.01 * ((X * 7 + Y * 13 + c * 5) % 17) + 0.001 * X + 0.003 * s;
}

/* Rows oy..oy+h-1 of a w-wide render, channels B, G, R. */
static void make_render(struct image *img, int w, int oy, int h, int s)
{
	char err[256];

	assert_int_equal(image_init(img, w, h, 3, bgr_names, err, sizeof(err)), 0);
	for (int r = 0; r < h; r++)
		for (int X = 0; X < w; X++)
			for (int k = 0; k < 3; k++)
				img->px[((size_t)r * w + X) * 3 + k] =
					(float)sub_value(X, oy + r, 2 - k, s);
}

/* The R, G, B (c = 0, 1, 2) of render pixel (X, Y) of img (rows from oy). */
static float render_at(const struct image *img, int oy, int X, int Y, int c)
{
	return img->px[((size_t)(Y - oy) * img->w + X) * 3 + (2 - c)];
}

/* ------------------------------------------------------------------ */

/* deviations from 1e4: the 5 of base + first set average to a value a
 * float holds exactly, so only the algorithm is under test */
static const double base_dev[3] = { 1.0, -0.5, 0.25 };

static double fold_base(int x, int y, int c)
{
	return x == 0 && y == 0 ? 1e4 + base_dev[c] : 0.5;
}

/* 1. accum_fold against a direct two-pass computation over all 21 samples. */
static void test_fold(void **state)
{
	static const double set2[4][3] = {
		{ -0.5, 0.75, -1.5 }, { 0.25, -1.0, 0.5 }, { 0.75, 0.5, -0.75 },
		{ -0.25, 0.25, -1.0 },
	};
	const double off = 1e4;
	double all[3][21], mean[3], m2[3];
	struct image acc;
	int n = 0;

	(void)state;
	make_acc(&acc, 2, 1, fold_base);
	for (int c = 0; c < 3; c++)
		all[c][0] = off + base_dev[c];
	n = 1;
	assert_true(accpx(&acc, 0)[ACC_SAMPLES] == 1.0f);
	assert_true(accpx(&acc, 0)[ACC_PASS] == 0.0f);
	assert_true(accpx(&acc, 0)[ACC_VAR_G] == 0.0f);
	assert_true(accum_has_scale(&acc, 0, 1));
	assert_int_equal(accum_next_scale(&acc, 0), 2);

	/* 4 samples at scale 2, then 16 at scale 4 */
	for (int set = 0; set < 2; set++) {
		int s = set ? 4 : 2, m = s * s;
		double v[16][3];

		for (int k = 0; k < m; k++)
			for (int c = 0; c < 3; c++)
				v[k][c] = off + (set ? 0.0625 * ((k * 7 + c * 3) % 16) - 0.4 + 0.3 * c
						     : set2[k][c]);
		for (int c = 0; c < 3; c++) {
			mean[c] = m2[c] = 0.0;
			for (int k = 0; k < m; k++)
				mean[c] += v[k][c] / m;
			for (int k = 0; k < m; k++)
				m2[c] += (v[k][c] - mean[c]) * (v[k][c] - mean[c]);
			for (int k = 0; k < m; k++)
				all[c][n + k] = v[k][c];
		}
		n += m;
		assert_int_equal(accum_fold(&acc, 0, s, m, mean, m2, 3 + set), 0);
		assert_true(accpx(&acc, 0)[ACC_SAMPLES] == (float)n);
		assert_true(accpx(&acc, 0)[ACC_PASS] == (float)(3 + set));
		assert_true(accum_has_scale(&acc, 0, s));
		for (int c = 0; c < 3; c++) {
			double em, ev;
			char what[64];

			stats2(all[c], n, &em, &ev);
			snprintf(what, sizeof(what), "n=%d channel %d mean", n, c);
			/* within a couple of float ulps at 1e4 */
			assert_close(accpx(&acc, 0)[c], em, 0.0, 2e-3, what);
			snprintf(what, sizeof(what), "n=%d channel %d variance", n, c);
			assert_close(accpx(&acc, 0)[ACC_VAR_R + c], ev, 1e-5, 0.0, what);
		}
	}
	assert_int_equal(accum_next_scale(&acc, 0), 8);

	/* scale 2 again: nothing changes */
	float before[ACC_NCH];
	memcpy(before, accpx(&acc, 0), sizeof(before));
	assert_int_equal(accum_fold(&acc, 0, 2, 4, mean, m2, 9), 1);
	assert_memory_equal(before, accpx(&acc, 0), sizeof(before));

	/* pixel 1 walks through every scale */
	double c0[3] = { 0.5, 0.5, 0.5 }, z[3] = { 0.0, 0.0, 0.0 };
	for (int k = 1; k < ACC_NSCALES; k++) {
		int s = accum_scales[k];

		assert_int_equal(accum_next_scale(&acc, 1), s);
		assert_false(accum_has_scale(&acc, 1, s));
		assert_int_equal(accum_fold(&acc, 1, s, s * s, c0, z, k), 0);
		assert_true(accum_has_scale(&acc, 1, s));
	}
	assert_int_equal(accum_next_scale(&acc, 1), 0);
	assert_true(accpx(&acc, 1)[ACC_SAMPLES] == 1.0f + 4 + 16 + 64 + 256);
	assert_true(accpx(&acc, 1)[ACC_PASS] == (float)(ACC_NSCALES - 1));
	image_release(&acc);
}

/* What pixel (x, y) of make_acc(base_value) should hold after the renders
 * r2 (scale 2, rows from oy2, rectangle a2) and r4 (scale 4, from oy4, a4). */
static int expected_pixel(int x, int y, const struct image *r2, int oy2, const int a2[4],
			  const struct image *r4, int oy4, const int a4[4], double mean[3],
			  double var[3])
{
	double v[3][1 + 4 + 16];
	int n = 0;

	for (int c = 0; c < 3; c++)
		v[c][0] = (float)base_value(x, y, c);
	n = 1;
	for (int pass = 0; pass < 2; pass++) {
		const struct image *r = pass ? r4 : r2;
		const int *a = pass ? a4 : a2;
		int s = pass ? 4 : 2, oy = pass ? oy4 : oy2;

		if (!r || x < a[0] || x > a[2] || y < a[1] || y > a[3])
			continue;
		for (int j = 0; j < s; j++)
			for (int k = 0; k < s; k++, n++)
				for (int c = 0; c < 3; c++)
					v[c][n] = render_at(r, oy, x * s + k, y * s + j, c);
	}
	for (int c = 0; c < 3; c++)
		stats2(v[c], n, &mean[c], &var[c]);
	return n;
}

/*
 * What pixel b (an accumulation pixel before a fold) becomes when folded
 * with nb samples of mean m and squared deviations m2: the pooled count,
 * mean and variance.
 */
static void expect_fold(const float *b, double nb, const double m[3], const double m2[3],
			double *n, double mean[3], double var[3])
{
	double na = b[ACC_SAMPLES];
	*n = na + nb;
	for (int c = 0; c < 3; c++) {
		double d = m[c] - b[c];
		mean[c] = b[c] + d * nb / *n;
		var[c] = ((double)b[ACC_VAR_R + c] * (na - 1.0) + m2[c] + d * d * na * nb / *n) /
			 (*n - 1.0);
	}
}

/* A whole render img merged over all of acc, antialiased (s ACC_AA, at depth
 * and for edges) or at scale s; the pixels it folded. */
static long merge_whole(struct image *acc, const struct image *img, int s, int depth,
			int edges)
{
	char err[256];
	long folded = -1;

	if (s == ACC_AA)
		assert_int_equal(accum_merge_aa_region(acc, img, 0, s, depth, edges, 0, 0,
						       acc->w - 1, acc->h - 1, 1, &folded, err,
						       sizeof(err)), 0);
	else
		assert_int_equal(accum_merge_region(acc, img, 0, s, 0, 0, acc->w - 1, acc->h - 1,
						    1, &folded, err, sizeof(err)), 0);
	return folded;
}

/*
 * accum_merge_partial: a render stopped before it ended, its pixels not
 * rendered NaN.  A pixel with a render pixel missing is left as it was,
 * its scale not marked (accum_merge_region marks a whole render's bad
 * pixel, not to plan it again); the others fold as from the whole render
 * (at scale 2 but for the quadrant twist's neighbourhood, diff; antialiased
 * in scale 2's place, whole).
 */
static void test_merge_partial(void **state)
{
	const int W = 8, H = 4;
	struct image acc, whole, cut, aa;
	char err[256];
	long folded = -1;

	(void)state;
	make_acc(&acc, W, H, base_value);
	make_render(&whole, 2 * W, 0, 2 * H, 5);
	make_render(&cut, 2 * W, 0, 2 * H, 5);
	/* pixel (2, 1) not rendered, and one render pixel of (5, 2) */
	for (int j = 0; j < 2; j++)
		for (int l = 0; l < 2; l++)
			for (int c = 0; c < 3; c++)
				cut.px[((size_t)(2 + j) * cut.w + 4 + l) * 3 + c] = NAN;
	cut.px[((size_t)5 * cut.w + 11) * 3 + 0] = NAN;
	const size_t npx = (size_t)W * H, bytes = npx * ACC_NCH * sizeof(float);
	const size_t hole[2] = { 1 * (size_t)W + 2, 2 * (size_t)W + 5 };
	for (int mode = 0; mode < 2; mode++) {
		/* mode 0: scale 2; mode 1: antialiased in scale 2's place, the
		 * render at twice the size taken for spread error */
		const int s = mode ? ACC_AA : 2, depth = mode ? 3 : 0,
			  edges = mode ? ACC_AA_FOR_SPREAD : 0;
		float *ref = malloc(bytes), *part = malloc(bytes), *marked = malloc(bytes);
		assert_non_null(ref);
		assert_non_null(part);
		assert_non_null(marked);
		struct image a = acc;
		a.px = ref;
		memcpy(ref, acc.px, bytes);
		folded = merge_whole(&a, &whole, s, depth, edges);
		assert_int_equal(folded, (long)npx);
		a.px = part;
		memcpy(part, acc.px, bytes);
		assert_int_equal(accum_merge_partial(&a, &cut, 0, s, depth, edges, 0, 0, W - 1,
						     H - 1, 1, &folded, err, sizeof(err)), 0);
		assert_int_equal(folded, (long)npx - 2);
		for (size_t i = 0; i < npx; i++) {
			if (i == hole[0] || i == hole[1]) {
				assert_memory_equal(part + i * ACC_NCH, acc.px + i * ACC_NCH,
						    ACC_NCH * sizeof(float));
				assert_false(accum_has_scale(&a, i, s));
				continue;
			}
			assert_true(accum_has_scale(&a, i, s));
			for (int c = 0; c < ACC_NCH; c++)
				if (c != ACC_DIFF || mode)
					assert_true(part[i * ACC_NCH + c] == ref[i * ACC_NCH + c]);
		}
		/* the whole-render merge of the same image marks the hole */
		a.px = marked;
		memcpy(marked, acc.px, bytes);
		merge_whole(&a, &cut, s, depth, edges);
		assert_true(accum_has_scale(&a, hole[0], s));
		free(ref);
		free(part);
		free(marked);
	}
	/* a bad depth is an error, as for a whole render */
	make_render(&aa, 2 * W, 0, 2 * H, 6);
	assert_int_equal(accum_merge_partial(&acc, &aa, 0, ACC_AA, ACC_AA_DEPTH + 1, 2, 0, 0,
					     W - 1, H - 1, 1, &folded, err, sizeof(err)), -1);
	assert_non_null(strstr(err, "depth"));
	image_release(&aa);
	image_release(&cut);
	image_release(&whole);
	image_release(&acc);
}

/*
 * accum_merge_region of grid renders, twice the image's width: 2 x 2
 * sub-pixels of (s/2)^2 + 1 samples, less the centre one where the pixel
 * has scale 2 (which it repeats), replaced by the pixel's mean (their mean, their spread and the
 * within spread it implies, capped by the pixel's sample variance; a
 * sub-pixel that is not finite left out), pooled with the pixel's samples
 * (scale 16, then 8).  A scale is taken once; a width that fits neither
 * way is an error naming both.
 */
static void test_merge_grid(void **state)
{
	const int W = 6, H = 4;
	struct image acc, r2, g, g8, bad;
	char err[256];
	long folded = -1;

	(void)state;
	make_acc(&acc, W, H, base_value);
	make_render(&r2, 2 * W, 0, 2 * H, 2);
	assert_int_equal(accum_merge_region(&acc, &r2, 0, 2, 0, 0, W - 1, H - 1, 1, &folded, err,
					    sizeof(err)), 0);
	make_render(&g, 2 * W, 0, 2 * H, 7);
	/* one sub-pixel of pixel (4, 2) not finite; pixel (1, 1) flat inside
	 * (its sub-pixels equal): no spread of its own to add */
	g.px[((size_t)(2 * 2) * g.w + 2 * 4 + 1) * 3 + 1] = NAN;
	for (int j = 0; j < 2; j++)
		for (int l = 0; l < 2; l++)
			for (int k = 0; k < 3; k++)
				g.px[((size_t)(2 + j) * g.w + 2 + l) * 3 + k] = 0.4f;
	make_render(&g8, 2 * W, 0, 2 * H, 9);
	size_t npx = (size_t)W * H, bytes = npx * ACC_NCH * sizeof(float);
	float *before = malloc(bytes);
	assert_non_null(before);
	for (int step = 0; step < 2; step++) {
		const int s = step ? 8 : 16, f = 2;
		const struct image *r = step ? &g8 : &g;
		/* per sub-pixel (s/2)^2 + 1 samples, the centre one scale 2's
		 * again: every pixel has scale 2, so it is taken out */
		const double g0 = step ? 17.0 : 65.0, gs = g0 - 1.0;
		memcpy(before, acc.px, bytes);
		assert_int_equal(accum_merge_region(&acc, r, 0, s, 1, 1, 4, 2, 2 + step, &folded,
						    err, sizeof(err)), 0);
		assert_int_equal(folded, 8);
		for (int y = 0; y < H; y++)
			for (int x = 0; x < W; x++) {
				size_t i = (size_t)y * W + x;
				const float *o = accpx(&acc, i), *b = before + i * ACC_NCH;
				char what[64];
				if (x < 1 || x > 4 || y < 1 || y > 2) {
					assert_memory_equal(o, b, ACC_NCH * sizeof(float));
					continue;
				}
				double sub[4][3], m[3] = { 0.0, 0.0, 0.0 }, m2[3], n, em[3], ev[3];
				int nq = 0;
				for (int j = 0; j < f; j++)
					for (int l = 0; l < f; l++) {
						if (!step && x == 4 && y == 2 && j == 0 && l == 1)
							continue;
						for (int c = 0; c < 3; c++) {
							sub[nq][c] = (g0 * render_at(r, 0, f * x + l,
										     f * y + j, c) -
								      b[c]) / gs;
							m[c] += sub[nq][c];
						}
						nq++;
					}
				for (int c = 0; c < 3; c++) {
					double bs = 0.0;
					m[c] /= nq;
					for (int q = 0; q < nq; q++)
						bs += (sub[q][c] - m[c]) * (sub[q][c] - m[c]);
					double v = b[ACC_VAR_R + c];
					if (nq > 1 && gs * bs / (nq - 1) < v)
						v = gs * bs / (nq - 1);
					m2[c] = gs * bs + nq * (gs - 1.0) * v;
				}
				expect_fold(b, nq * gs, m, m2, &n, em, ev);
				snprintf(what, sizeof(what), "s%d (%d,%d) samples", s, x, y);
				assert_close(o[ACC_SAMPLES], n, 1e-5, 0.0, what);
				assert_true(o[ACC_SCALES] ==
					    (float)(2 + 4 + 65536 + (step ? 256 : 0)));
				assert_true(o[ACC_PASS] == (float)(2 + step));
				for (int c = 0; c < 3; c++) {
					snprintf(what, sizeof(what), "s%d (%d,%d) c%d mean", s, x, y,
						 c);
					assert_close(o[c], em[c], 1e-5, 0.0, what);
					snprintf(what, sizeof(what), "s%d (%d,%d) c%d variance", s,
						 x, y, c);
					assert_close(o[ACC_VAR_R + c], ev[c], 1e-4, 1e-12, what);
				}
			}
	}
	/* the same scale again: nothing */
	memcpy(before, acc.px, bytes);
	assert_int_equal(accum_merge_region(&acc, &g8, 0, 8, 1, 1, 4, 2, 4, &folded, err,
					    sizeof(err)), 0);
	assert_int_equal(folded, 0);
	assert_memory_equal(before, acc.px, bytes);
	/* three times the width at scale 8: neither 8 x W nor a grid render */
	make_render(&bad, 3 * W, 0, 3 * H, 8);
	err[0] = '\0';
	assert_int_equal(accum_merge_region(&acc, &bad, 0, 8, 0, 0, 1, 1, 4, &folded, err,
					    sizeof(err)), -1);
	assert_non_null(strstr(err, "48"));
	assert_non_null(strstr(err, "12 (a grid render)"));
	assert_memory_equal(before, acc.px, bytes);
	image_release(&bad);
	free(before);
	image_release(&g8);
	image_release(&g);
	image_release(&r2);
	image_release(&acc);
}

/*
 * The fold difference of a region render's stratified samples: onto one
 * base sample at 0.5, pixels whose four sub-pixels agree at 0.3 (no
 * twist: the new mean exact) have the old sample's difference charged at
 * its own weight, d2 / nt^2, not the independent samples' d2 nb / nt^2;
 * The choice between the two figures is made on their means over the 5 x 5
 * pixels around: the pixels whose window holds no twist (x <= 4 of 9) take
 * the lowered one; pixel 5, whose window reaches pixel 7 (its 3 x 3 mean
 * takes a third of pixel 8's twist, crosswise 0.5 and 0.1, which weighed
 * by nb^2 outweighs d2), has the two means within a factor 2 at scale 4
 * and takes the mean of its two figures.  Grid renders (scale 4, 5 samples
 * a sub-pixel) and resolution scaling (scale 2, one sample a quadrant)
 * alike.  Onto 5 samples (the base pass's and scale 2's) the same, where
 * the lowered figure is more than twice below; onto 4 (a radiosity pass at
 * scale 2) and onto 21 every pixel keeps the independent figure.
 */
static void test_merge_stratified(void **state)
{
	const int W = 9, H = 1;
	(void)state;
	static const double onto[4] = { 1.0, 5.0, 4.0, 21.0 };
	for (int kind = 0; kind < 8; kind++) {
		const int s = kind % 2 ? 2 : 4;
		/* kinds 2 and 3: onto 5 samples (the base pass's and scale
		 * 2's), still mostly the old mean's difference; 4 and 5: onto
		 * a radiosity pass's 4; 6 and 7: onto 21, where it no longer is */
		const double nb = kind % 2 ? 4.0 : 20.0, na = onto[kind / 2], nt = nb + na;
		struct image acc, r;
		char err[256];
		long folded = -1;
		make_acc(&acc, W, H, flat_value);
		for (int x = 0; x < W; x++)
			accpx(&acc, (size_t)x)[ACC_SAMPLES] = (float)na;
		assert_int_equal(image_init(&r, 2 * W, 2 * H, 3, rgb_names, err, sizeof(err)), 0);
		for (int x = 0; x < W; x++)
			for (int j = 0; j < 2; j++)
				for (int l = 0; l < 2; l++) {
					double v = x == W - 1 ? (j == l ? 0.5 : 0.1) : 0.3;
					for (int c = 0; c < 3; c++)
						r.px[((size_t)j * r.w + 2 * x + l) * 3 + c] = (float)v;
				}
		assert_int_equal(accum_merge_region(&acc, &r, 0, s, 0, 0, W - 1, 0, 1, &folded,
						    err, sizeof(err)),
				 0);
		assert_int_equal(folded, W);
		for (int x = 0; x < W; x++) {
			const float *o = accpx(&acc, (size_t)x);
			double mt = (na * 0.5 + nb * 0.3) / nt, d2 = 0.04 / (mt * mt + 0.01);
			double iid = d2 * na * nb / (nt * nt), own = d2 * na * na / (nt * nt);
			char what[64];
			snprintf(what, sizeof(what), "scale %d onto %g: pixel %d diff", s, na, x);
			/* the twisted pixel's mean is 0.3 too; the pixels whose
			 * 5 x 5 has no twist (x <= 4) take the lowered diff
			 * where it is nb / na times below the other, more than
			 * twice (twenty and four times onto 1, four times
			 * scale 4's onto 5), and the mean of the two where not
			 * (scale 2's 4 onto 5); onto 4 and 21 every pixel
			 * keeps the independent one */
			if (na == 4.0 || na > 6.0)
				assert_close(o[ACC_DIFF], iid, 1e-4, 0.0, what);
			else if (x <= 4)
				assert_close(o[ACC_DIFF], nb > 2.0 * na ? own : 0.5 * (iid + own),
					     1e-4, 0.0, what);
			else if (x == 5 && s == 4 && na < 2.0)
				assert_close(o[ACC_DIFF], 0.5 * (iid + own), 1e-4, 0.0, what);
		}
		image_release(&r);
		image_release(&acc);
	}

	/* noise: quadrants 0.3 +- t in a twist, the base sample 0.3 + sqrt(3) t,
	 * so that at scale 2 the two diffs are alike (d2 = 3 vb, 1.5 apart): the mean of
	 * the two, not the smaller (the smaller of two noisy values is biased
	 * low) */
	struct image acc, r;
	char err[256];
	long folded = -1;
	const double t = 0.02, base = 0.3 + sqrt(3.0) * t;
	make_acc(&acc, 5, 1, flat_value);
	for (int x = 0; x < 5; x++) {
		float *o = accpx(&acc, (size_t)x);
		o[ACC_SAMPLES] = 1.0f;
		for (int c = 0; c < 3; c++)
			o[c] = (float)base;
	}
	assert_int_equal(image_init(&r, 10, 2, 3, rgb_names, err, sizeof(err)), 0);
	for (int x = 0; x < 5; x++)
		for (int j = 0; j < 2; j++)
			for (int l = 0; l < 2; l++)
				for (int c = 0; c < 3; c++)
					r.px[((size_t)j * r.w + 2 * x + l) * 3 + c] =
						(float)(0.3 + (j == l ? t : -t));
	assert_int_equal(accum_merge_region(&acc, &r, 0, 2, 0, 0, 4, 0, 1, &folded, err,
					    sizeof(err)), 0);
	const double mt = (base + 4.0 * 0.3) / 5.0;
	const double d2 = (base - 0.3) * (base - 0.3) / (mt * mt + 0.01);
	const double vb = t * t / (0.3 * 0.3 + 0.01);
	const double iid = d2 * 4.0 / 25.0, low = (d2 - vb + 16.0 * vb) / 25.0;
	assert_true(iid < 2.0 * low && low < 2.0 * iid);
	for (int x = 0; x < 5; x++)
		assert_close(accpx(&acc, (size_t)x)[ACC_DIFF], 0.5 * (iid + low), 1e-3, 0.0,
			     "noise: the mean of the two diffs");
	image_release(&r);
	image_release(&acc);
}

/* 2. accum_merge_region: block statistics, untouched outside, errors. */
static void test_merge_region(void **state)
{
	const int W = 10, H = 20;
	const int a2[4] = { 3, 10, 7, 13 }, a4[4] = { 5, 12, 9, 15 };	/* x0 y0 x1 y1 */
	const int oy2 = 2 * a2[1] - 16, oy4 = 4 * a4[1] - 16;
	struct image acc, r2, r4, bad;
	size_t npx = (size_t)W * H, bytes = npx * ACC_NCH * sizeof(float);
	char err[256];
	long folded = -1;

	(void)state;
	make_acc(&acc, W, H, base_value);
	float *orig = malloc(bytes), *snap = malloc(bytes);
	assert_non_null(orig);
	assert_non_null(snap);
	memcpy(orig, acc.px, bytes);

	make_render(&r2, 2 * W, oy2, 2 * (a2[3] + 1) - oy2 + 3, 2);
	make_render(&r4, 4 * W, oy4, 4 * (a4[3] + 1) - oy4 + 5, 4);
	assert_int_equal(accum_merge_region(&acc, &r2, oy2, 2, a2[0], a2[1], a2[2], a2[3], 1,
					    &folded, err, sizeof(err)), 0);
	assert_int_equal(folded, 5 * 4);
	assert_int_equal(accum_merge_region(&acc, &r4, oy4, 4, a4[0], a4[1], a4[2], a4[3], 2,
					    &folded, err, sizeof(err)), 0);
	assert_int_equal(folded, 5 * 4);

	for (int y = 0; y < H; y++)
		for (int x = 0; x < W; x++) {
			size_t i = (size_t)y * W + x;
			int in2 = x >= a2[0] && x <= a2[2] && y >= a2[1] && y <= a2[3];
			int in4 = x >= a4[0] && x <= a4[2] && y >= a4[1] && y <= a4[3];
			const float *o = accpx(&acc, i);
			double em[3], ev[3];
			char what[64];

			if (!in2 && !in4) {
				assert_memory_equal(o, orig + i * ACC_NCH, ACC_NCH * sizeof(float));
				continue;
			}
			int n = expected_pixel(x, y, &r2, oy2, a2, &r4, oy4, a4, em, ev);
			assert_true(o[ACC_SAMPLES] == (float)n);
			assert_true(o[ACC_PASS] == (in4 ? 2.0f : 1.0f));
			assert_true(o[ACC_SCALES] == (float)(2 + (in2 ? 4 : 0) + (in4 ? 16 : 0)));
			for (int c = 0; c < 3; c++) {
				snprintf(what, sizeof(what), "(%d,%d) c%d mean", x, y, c);
				assert_close(o[c], em[c], 1e-6, 0.0, what);
				snprintf(what, sizeof(what), "(%d,%d) c%d variance", x, y, c);
				assert_close(o[ACC_VAR_R + c], ev[c], 1e-5, 1e-12, what);
			}
		}

	/* scale 2 again over the same pixels: no new samples */
	memcpy(snap, acc.px, bytes);
	assert_int_equal(accum_merge_region(&acc, &r2, oy2, 2, a2[0], a2[1], a2[2], a2[3], 5,
					    &folded, err, sizeof(err)), 0);
	assert_int_equal(folded, 0);
	assert_memory_equal(snap, acc.px, bytes);

	/* failures change nothing */
	make_render(&bad, 2 * W - 2, oy2, r2.h, 2);
	err[0] = '\0';
	assert_int_equal(accum_merge_region(&acc, &bad, oy2, 2, 0, 10, 9, 11, 6, &folded, err,
					    sizeof(err)), -1);
	assert_true(err[0] != '\0');
	image_release(&bad);
	/* the first needed row (20) is not there / the last (31) is not */
	assert_int_equal(accum_merge_region(&acc, &r2, 21, 2, 0, 10, 9, 11, 6, &folded, err,
					    sizeof(err)), -1);
	assert_int_equal(accum_merge_region(&acc, &r2, oy2, 2, 0, 10, 9, 15, 6, &folded, err,
					    sizeof(err)), -1);
	/* outside the image */
	assert_int_equal(accum_merge_region(&acc, &r2, oy2, 2, 0, 10, W, 11, 6, &folded, err,
					    sizeof(err)), -1);
	assert_int_equal(accum_merge_region(&acc, &r2, oy2, 2, -1, 10, 3, 11, 6, &folded, err,
					    sizeof(err)), -1);
	/* scale 5, with a render of the matching width */
	make_render(&bad, 5 * W, 0, 5 * H, 5);
	err[0] = '\0';
	assert_int_equal(accum_merge_region(&acc, &bad, 0, 5, 0, 0, 1, 1, 6, &folded, err,
					    sizeof(err)), -1);
	assert_non_null(strstr(err, "scale 5 is not one of"));
	assert_int_equal(folded, 0);
	image_release(&bad);
	assert_memory_equal(snap, acc.px, bytes);
	/* scale 3 (a radiosity pass under a budget): 9 samples a pixel */
	struct image a3;
	make_acc(&a3, 4, 2, flat_value);
	make_render(&bad, 12, 0, 6, 3);
	assert_int_equal(accum_merge_region(&a3, &bad, 0, 3, 0, 0, 3, 1, 1, &folded, err,
					    sizeof(err)), 0);
	assert_int_equal(folded, 8);
	assert_true(accpx(&a3, 5)[ACC_SAMPLES] == 10.0f);
	assert_true(accum_has_scale(&a3, 5, 3));
	image_release(&bad);
	image_release(&a3);

	free(orig);
	free(snap);
	image_release(&r2);
	image_release(&r4);
	image_release(&acc);
}

/* A radiosity pass's frame folded into a fresh accumulation: its pixels'
 * difference from their samples' two checkerboard halves. */
static void test_split_diff(void **state)
{
	const int W = 3, H = 1, S = 4;
	struct image acc, img, bad;
	char err[256];
	long folded = 0;

	(void)state;
	assert_int_equal(image_init(&acc, W, H, ACC_NCH, accum_names, err, sizeof(err)), 0);
	for (size_t i = 0; i < (size_t)W * H; i++)
		accpx(&acc, i)[ACC_DIFF] = NAN;
	assert_int_equal(image_init(&img, W * S, H * S, 3, rgb_names, err, sizeof(err)), 0);
	for (int y = 0; y < S; y++)
		for (int X = 0; X < W * S; X++)
			for (int c = 0; c < 3; c++) {
				const int x = X / S, k = X % S, odd = (y + k) & 1;
				/* pixel 0: 1 on even, 0.5 on odd positions;
				 * pixel 1: flat 0.25; pixel 2: one missing */
				float v = x == 0 ? (odd ? 0.5f : 1.0f) : 0.25f;
				if (x == 2 && y == 1 && k == 2)
					v = NAN;
				img.px[((size_t)y * img.w + X) * 3 + c] = v;
			}
	assert_int_equal(accum_merge_region(&acc, &img, 0, S, 0, 0, W - 1, H - 1, 0, &folded,
					    err, sizeof(err)), 0);
	assert_int_equal(folded, 3);
	assert_true(isnan(accpx(&acc, 0)[ACC_DIFF]));	/* no fold onto samples */
	assert_int_equal(accum_split_diff(&acc, &img, S, err, sizeof(err)), 0);
	/* 8 samples onto 8: d^2 / (m^2 + 0.01) x 8 x 8 / 16^2, d = -0.5,
	 * m = 0.75 */
	assert_close(accpx(&acc, 0)[ACC_DIFF], 0.25 / (0.5625 + METRICS_RELMSE_EPS) / 4.0, 1e-6,
		     0.0, "checkerboard pixel");
	assert_true(accpx(&acc, 1)[ACC_DIFF] == 0.0f);
	assert_true(accpx(&acc, 2)[ACC_SAMPLES] == 15.0f);
	assert_true(isnan(accpx(&acc, 2)[ACC_DIFF]));	/* a sample missing: left */
	/* a pixel that had samples before is not the render's alone */
	accpx(&acc, 1)[ACC_SAMPLES] = 17.0f;
	accpx(&acc, 1)[ACC_DIFF] = 0.5f;
	assert_int_equal(accum_split_diff(&acc, &img, S, err, sizeof(err)), 0);
	assert_true(accpx(&acc, 1)[ACC_DIFF] == 0.5f);
	/* not a frame at that scale: an error, nothing changed */
	make_render(&bad, W * S - 1, 0, H * S, S);
	err[0] = '\0';
	assert_int_equal(accum_split_diff(&acc, &bad, S, err, sizeof(err)), -1);
	assert_non_null(strstr(err, "not 12x4 at scale 4"));
	assert_true(accpx(&acc, 1)[ACC_DIFF] == 0.5f);
	image_release(&bad);
	/* scale 1 (a radiosity pass on a frame 480 pixels wide or more): one
	 * sample a pixel, no halves, nothing changed and no error */
	struct image a1, one;
	assert_int_equal(image_init(&a1, W, H, ACC_NCH, accum_names, err, sizeof(err)), 0);
	for (size_t i = 0; i < (size_t)W * H; i++)
		accpx(&a1, i)[ACC_DIFF] = NAN;
	make_render(&one, W, 0, H, 1);
	assert_int_equal(accum_merge_region(&a1, &one, 0, 1, 0, 0, W - 1, H - 1, 0, &folded,
					    err, sizeof(err)), 0);
	assert_int_equal(accum_split_diff(&a1, &one, 1, err, sizeof(err)), 0);
	for (size_t i = 0; i < (size_t)W * H; i++)
		assert_true(isnan(accpx(&a1, i)[ACC_DIFF]));
	image_release(&one);
	image_release(&a1);
	/* scale 3 (a radiosity pass under a budget): halves of 5 and 4 */
	struct image a3, three;
	assert_int_equal(image_init(&a3, 1, 1, ACC_NCH, accum_names, err, sizeof(err)), 0);
	accpx(&a3, 0)[ACC_DIFF] = NAN;
	assert_int_equal(image_init(&three, 3, 3, 3, rgb_names, err, sizeof(err)), 0);
	for (int k = 0; k < 9; k++)
		for (int c = 0; c < 3; c++)	/* even positions 1, odd 0.1 c */
			three.px[k * 3 + c] = (k % 2 == 0) ? 1.0f : 0.1f * (float)c;
	assert_int_equal(accum_merge_region(&a3, &three, 0, 3, 0, 0, 0, 0, 0, &folded, err,
					    sizeof(err)), 0);
	assert_int_equal(accum_split_diff(&a3, &three, 3, err, sizeof(err)), 0);
	double want = 0.0;
	for (int c = 0; c < 3; c++) {
		const double m = (5.0 + 4.0 * 0.1 * c) / 9.0, d = 0.1 * c - 1.0;
		want += d * d / (m * m + METRICS_RELMSE_EPS) / 3.0;
	}
	assert_close(accpx(&a3, 0)[ACC_DIFF], want * 5.0 * 4.0 / 81.0, 1e-5, 0.0, "scale 3");
	image_release(&three);
	image_release(&a3);
	image_release(&img);
	image_release(&acc);
}

/* 3. A non-finite sub-sample is skipped; a block of them adds nothing. */
static void test_merge_nonfinite(void **state)
{
	struct image acc, r;
	char err[256];
	long folded = -1;
	double v[3][4], em, ev;
	int n = 0;

	(void)state;
	make_acc(&acc, 4, 4, base_value);
	make_render(&r, 8, 0, 8, 2);
	/* pixel (0,0): G of sub-sample (1,0) is NaN; channel index 1 is G */
	r.px[(0 * 8 + 1) * 3 + 1] = NAN;
	/* pixel (1,0): every sub-sample has a NaN or an infinity */
	r.px[(0 * 8 + 2) * 3 + 0] = NAN;
	r.px[(0 * 8 + 3) * 3 + 2] = INFINITY;
	r.px[(1 * 8 + 2) * 3 + 1] = -INFINITY;
	r.px[(1 * 8 + 3) * 3 + 0] = NAN;
	float before1[ACC_NCH];
	memcpy(before1, accpx(&acc, 1), sizeof(before1));

	assert_int_equal(accum_merge_region(&acc, &r, 0, 2, 0, 0, 3, 3, 1, &folded, err,
					    sizeof(err)), 0);
	assert_int_equal(folded, 15);

	for (int c = 0; c < 3; c++)
		v[c][0] = (float)base_value(0, 0, c);
	n = 1;
	for (int j = 0; j < 2; j++)
		for (int k = 0; k < 2; k++) {
			if (j == 0 && k == 1)
				continue;
			for (int c = 0; c < 3; c++)
				v[c][n] = render_at(&r, 0, k, j, c);
			n++;
		}
	assert_true(accpx(&acc, 0)[ACC_SAMPLES] == 4.0f);
	for (int c = 0; c < 3; c++) {
		stats2(v[c], n, &em, &ev);
		assert_close(accpx(&acc, 0)[c], em, 1e-6, 0.0, "mean without the NaN");
		assert_close(accpx(&acc, 0)[ACC_VAR_R + c], ev, 1e-5, 1e-12,
			     "variance without the NaN");
	}
	/* no finite sub-sample: the pixel keeps its sample, scale 2 is spent */
	assert_true(accpx(&acc, 1)[ACC_SAMPLES] == 1.0f);
	for (int c = 0; c < 3; c++) {
		assert_true(accpx(&acc, 1)[c] == before1[c]);
		assert_true(isfinite(accpx(&acc, 1)[ACC_VAR_R + c]));
	}
	assert_true(accum_has_scale(&acc, 1, 2));
	image_release(&r);
	image_release(&acc);
}

/* The cells an edge render's spread is divided over (ACC_AA_EDGE), as the
 * header gives them: 1 up to a tenth of the threshold, `cells` from it,
 * geometric between. */
static double edge_cells_want(double range, double cells)
{
	if (range <= ACC_AA_THRESHOLD / 10.0)
		return 1.0;
	if (range >= ACC_AA_THRESHOLD)
		return cells;
	return pow(cells, log10(range / (ACC_AA_THRESHOLD / 10.0)));
}

/* 3b. An antialiased render (ACC_AA) is folded as the samples it proves to
 * be worth: n = sum A / sum D over the region, and per pixel at most its
 * own A / D (accum.c, aa_worth(), merge_aa()). */
static double aa_mean(int i, int c)
{
	return 0.2 + 0.1 * i + 0.05 * c;
}

static void test_merge_aa(void **state)
{
	struct image acc, r;
	char err[256];
	long folded = -1;
	const double var[3] = { 0.04, 0.02, 0.01 }, dev[4] = { 0.03, -0.05, 0.02, 0.06 };

	(void)state;
	make_acc(&acc, 4, 2, flat_value);
	/* row 0: four pixels with 16 samples each (pixel 2 has a fold
	 * difference); row 1 keeps its one base sample */
	for (int i = 0; i < 4; i++) {
		float *o = accpx(&acc, (size_t)i);
		for (int c = 0; c < 3; c++) {
			o[c] = (float)aa_mean(i, c);
			o[ACC_VAR_R + c] = (float)var[c];
		}
		o[ACC_SAMPLES] = 16.0f;
		o[ACC_DIFF] = i == 2 ? 1e-3f : NAN;
	}
	assert_int_equal(image_init(&r, 4, 2, 3, rgb_names, err, sizeof(err)), 0);
	double sa = 0.0, sd = 0.0, pa[4] = {0}, pd[4] = {0};
	for (int i = 0; i < 8; i++)
		for (int c = 0; c < 3; c++) {
			double m = accpx(&acc, (size_t)i)[c];
			r.px[i * 3 + c] = (float)(i < 4 ? m + dev[i] : m + 0.1);
			if (i < 4) {
				double den = m * m + 0.01, d = r.px[i * 3 + c] - m;
				pa[i] += var[c] / den / 3.0;
				pd[i] += d * d / den / 3.0;
			}
		}
	for (int i = 0; i < 4; i++) {
		sa += pa[i];
		sd += pd[i];
	}
	int pool = (int)lround(sa / sd), k[4], capped = 0;
	assert_true(pool > 1 && pool < ACC_AA_MAX);
	/* no pixel takes it as more than its own a / d */
	for (int i = 0; i < 4; i++) {
		k[i] = pa[i] / pd[i] < pool ? (int)lround(pa[i] / pd[i]) : pool;
		capped += k[i] < pool;
	}
	assert_true(capped >= 1 && capped <= 3);
	accpx(&acc, 7)[ACC_SCALES] = (float)(1u << 1 | 1u << 4);
	float before[8][ACC_NCH];
	for (int i = 0; i < 8; i++)
		memcpy(before[i], accpx(&acc, (size_t)i), sizeof(before[i]));

	assert_int_equal(accum_merge_region(&acc, &r, 0, ACC_AA, 0, 0, 3, 1, 4, &folded, err,
					    sizeof(err)), 0);
	assert_int_equal(folded, 8);
	for (int i = 0; i < 4; i++) {
		const float *o = accpx(&acc, (size_t)i);
		const int n = k[i];
		double wa = 16.0 / (16 + n), wb = n / (16.0 + n), d = 0.0;
		assert_true(o[ACC_SAMPLES] == (float)(16 + n));
		assert_true(accum_has_scale(&acc, (size_t)i, ACC_AA));
		assert_true(o[ACC_PASS] == 4.0f);
		for (int c = 0; c < 3; c++) {
			double m = before[i][c], a = r.px[i * 3 + c], mt = wa * m + wb * a;
			assert_close(o[c], mt, 1e-6, 0.0, "weighted mean");
			/* the render's samples spread as the pixel's do */
			double m2 = var[c] * 15 + var[c] * (n - 1) + (a - m) * (a - m) * 16.0 * n /
				    (16 + n);
			assert_close(o[ACC_VAR_R + c], m2 / (15 + n), 1e-5, 0.0, "variance");
			d += (a - m) * (a - m) / (mt * mt + 0.01) / 3.0;
		}
		/* either may hold the difference: the old mean's share is the
		 * larger of it and the old mean's own error (pixel 2's) */
		double em = i == 2 && 1e-3 > d ? 1e-3 : d;
		double want = wb * wb * d + wa * wa * em;
		assert_close(o[ACC_DIFF], want, 1e-5, 0.0, "difference over the weights");
	}
	/* a pixel with one sample has no spread to weigh the render by: the
	 * render counts as one sample; and a render at the image's size does
	 * not stand in for scale 2 */
	for (int i = 0; i < 8; i++) {
		const float *o = accpx(&acc, (size_t)i);
		assert_true(accum_has_scale(&acc, (size_t)i, ACC_AA));
		assert_false(accum_has_scale(&acc, (size_t)i, 2));
		assert_false(accum_has_scale(&acc, (size_t)i, ACC_AA_HALF));
		assert_true(accum_next_scale(&acc, (size_t)i) == 2);
		if (i < 4)
			continue;
		assert_true(o[ACC_SAMPLES] == 2.0f);
		assert_close(o[0], (before[i][0] + r.px[i * 3]) / 2.0, 1e-6, 0.0, "two samples");
	}
	/* once per pixel: the same render again changes nothing */
	float after[ACC_NCH];
	memcpy(after, accpx(&acc, 0), sizeof(after));
	assert_int_equal(accum_merge_region(&acc, &r, 0, ACC_AA, 0, 0, 3, 1, 5, &folded, err,
					    sizeof(err)), 0);
	assert_int_equal(folded, 0);
	assert_memory_equal(after, accpx(&acc, 0), sizeof(after));
	/* the render is at the image's size or twice it: 3x is the wrong size */
	struct image big;
	make_render(&big, 12, 0, 6, 3);
	assert_int_equal(accum_merge_region(&acc, &big, 0, ACC_AA, 0, 0, 3, 1, 5, &folded, err,
					    sizeof(err)), -1);
	assert_non_null(strstr(err, "12 pixels wide, not 4"));
	image_release(&big);
	image_release(&acc);

	/* in scale 2's place the render is twice the size: a pixel takes the
	 * mean of its 2 x 2 render pixels, as ACC_AA_FIRST samples where it
	 * has one; and every pixel folded has scale 2 after it (planned at
	 * scale 2 again, it would get the same render, which it refuses) */
	make_acc(&acc, 4, 2, flat_value);
	int bound = 0, heavier = 0, deeps = 0;
	float *o3 = accpx(&acc, 3);
	for (int c = 0; c < 3; c++)
		o3[ACC_VAR_R + c] = (float)var[c];
	o3[ACC_SAMPLES] = 9.0f;
	accpx(&acc, 6)[ACC_SCALES] = (float)(1u << 1 | 1u << 4);
	make_render(&big, 8, 0, 4, 2);
	/* pixel 0's render pixels agree (a star between the corners would
	 * look so): it keeps ACC_AA_FIRST */
	for (int j = 0; j < 2; j++)
		for (int l = 0; l < 2; l++)
			memcpy(big.px + ((size_t)j * 8 + l) * 3, big.px, 3 * sizeof(float));
	assert_int_equal(accum_merge_region(&acc, &big, 0, ACC_AA, 0, 0, 3, 1, 1, &folded, err,
					    sizeof(err)), 0);
	assert_int_equal(folded, 8);
	for (int i = 0; i < 8; i++) {
		const int x = i % 4, y = i / 4;
		const float *o = accpx(&acc, (size_t)i);
		assert_true(accum_has_scale(&acc, (size_t)i, 2));
		assert_true(accum_has_scale(&acc, (size_t)i, ACC_AA_HALF));
		/* the colour distance of its 2 x 2 render pixels, as POV-Ray's
		 * threshold measures it: the weight of a one-sample pixel ramps
		 * from ACC_AA_FIRST to ACC_AA_FEW cells, and at the threshold
		 * the pixel is marked subdivided (scale 8's bit) */
		double range = 0.0;
		for (int c = 0; c < 3; c++) {
			double lo = INFINITY, hi = -INFINITY;
			for (int j = 0; j < 2; j++)
				for (int l = 0; l < 2; l++) {
					const double t = render_at(&big, 0, 2 * x + l, 2 * y + j, c);
					lo = t < lo ? t : lo;
					hi = t > hi ? t : hi;
				}
			range += hi - lo;
		}
		const int deep = i != 3 && range >= ACC_AA_THRESHOLD;
		deeps += deep;
		assert_int_equal(accum_has_scale(&acc, (size_t)i, ACC_AA_DEEP), deep);
		assert_true(accum_next_scale(&acc, (size_t)i) == (i == 6 ? (deep ? 16 : 8) : 4));
		if (i == 3) {	/* 9 samples: weighed as before */
			assert_true(o[ACC_SAMPLES] > 9.0f && o[ACC_SAMPLES] != 9.0f + ACC_AA_FIRST);
			continue;
		}
		const double ef = edge_cells_want(range, ACC_AA_FEW);
		const int kw = ef > ACC_AA_FIRST ? (int)lround(ef) : ACC_AA_FIRST;
		if (kw > ACC_AA_FIRST)
			heavier++;
		double m = 0.0;
		for (int j = 0; j < 2; j++)
			for (int l = 0; l < 2; l++)
				m += render_at(&big, 0, 2 * x + l, 2 * y + j, 0) / 4.0;
		assert_true(o[ACC_SAMPLES] == (float)(1 + kw));
		assert_close(o[0], (flat_value(x, y, 0) + kw * m) / (1 + kw),
			     1e-6, 0.0, "the base sample and the 2 x 2 mean");
		/* the new mean's error: the difference from the base sample
		 * over the weights, but no more than the 2 x 2 mean's variance */
		double d = 0.0, v = 0.0;
		for (int c = 0; c < 3; c++) {
			double mc = 0.0, vc = 0.0;
			for (int j = 0; j < 2; j++)
				for (int l = 0; l < 2; l++)
					mc += render_at(&big, 0, 2 * x + l, 2 * y + j, c) / 4.0;
			for (int j = 0; j < 2; j++)
				for (int l = 0; l < 2; l++) {
					double t = render_at(&big, 0, 2 * x + l, 2 * y + j, c) - mc;
					vc += t * t / 12.0;
				}
			double den = (double)o[c] * o[c] + METRICS_RELMSE_EPS;
			d += (mc - flat_value(x, y, c)) * (mc - flat_value(x, y, c)) / den / 3.0;
			v += vc / den / 3.0;
		}
		const double full = ((double)kw * kw + 1.0) / ((1.0 + kw) * (1.0 + kw)) * d;
		assert_close(o[ACC_DIFF], full < v ? full : v, 1e-4, 1e-12,
			     "the first fold's error: the difference, at most the 2 x 2 spread");
		bound += v < full;
	}
	assert_true(bound > 0);	/* the spread bound acted somewhere */
	assert_true(heavier > 0 && heavier < 7);	/* both weights were taken */
	assert_true(deeps > 0);
	image_release(&big);
	image_release(&acc);

	/* a render equal to the means is worth ACC_AA_MAX samples, no more */
	make_acc(&acc, 4, 2, flat_value);
	for (int i = 0; i < 8; i++) {
		float *o = accpx(&acc, (size_t)i);
		for (int c = 0; c < 3; c++) {
			o[ACC_VAR_R + c] = (float)var[c];
			r.px[i * 3 + c] = o[c];
		}
		o[ACC_SAMPLES] = 9.0f;
	}
	assert_int_equal(accum_merge_region(&acc, &r, 0, ACC_AA, 0, 0, 3, 1, 1, &folded, err,
					    sizeof(err)), 0);
	assert_true(accpx(&acc, 5)[ACC_SAMPLES] == (float)(9 + ACC_AA_MAX));
	image_release(&r);
	image_release(&acc);
}

/* The hidden-edge term of a pixel of value v whose neighbour differs by d
 * (grey, no spread), its finest scale s, before the share: the mean of
 * (alpha d)^2 / ((v + alpha d)^2 + 0.01) over alpha in [0, 1/(2s)], by the
 * midpoint rule on 4 points. */
static double edge_strip(double v, double d, int s)
{
	double e = 0.0;
	for (int k = 0; k < 4; k++) {
		double m = (k + 0.5) / (8.0 * s) * d;
		e += m * m / ((v + m) * (v + m) + METRICS_RELMSE_EPS) / 4.0;
	}
	return e;
}


/* 3c. An antialiased render in scale 2's place taken for edges at depth
 * d (5, ACC_AA_DEPTH, 4 and 3): over a pixel's one sample it counts as
 * the cells POV-Ray subdivided it into (4^d where its render pixels' colour
 * distance reaches the threshold, at least ACC_AA_FIRST), whose variance
 * is its 2 x 2 render pixels', its fold is
 * charged their spread over the cells their colour distance says POV-Ray
 * subdivided into, the pixels are marked (edge; subdivided where the
 * distance reaches the threshold); taken for a few pixels, as many cells
 * but at most ACC_AA_FEW (+R4's); a depth outside 1 to 5 is refused; a
 * later grid render takes none of its samples out as scale 2's repeats;
 * and between two such pixels no hidden edge is larger than the
 * threshold. */
static void test_merge_aa_edges(void **state)
{
	struct image acc, big, plain, few;
	char err[256];
	long folded = -1;
	/* per pixel of row 0, the spread of its 2 x 2 render pixels in each
	 * channel: colour distances 0, 0.03, 0.06, 0.3 and 0.9 */
	const double spread[5] = { 0.0, 0.01, 0.02, 0.1, 0.3 };
	const double pat[4] = { -0.5, 0.5, 0.5, -0.5 };	/* TL, TR, BL, BR */

	(void)state;
	assert_int_equal(image_init(&big, 10, 2, 3, rgb_names, err, sizeof(err)), 0);
	for (int X = 0; X < 10; X++)
		for (int Y = 0; Y < 2; Y++)
			for (int c = 0; c < 3; c++)
				big.px[((size_t)Y * 10 + X) * 3 + c] =
					(float)(0.4 + 0.1 * c + spread[X / 2] * pat[Y * 2 + X % 2]);
	assert_int_equal(accum_edge_cells(ACC_AA_DEPTH), 1024);
	assert_int_equal(accum_edge_cells(ACC_AA_DEPTH_V1), 256);
	assert_int_equal(accum_edge_cells(3), 64);
	make_acc(&plain, 5, 1, flat_value);
	assert_int_equal(accum_merge_region(&plain, &big, 0, ACC_AA, 0, 0, 4, 0, 1, &folded, err,
					    sizeof(err)), 0);
	for (int depth = 3; depth <= ACC_AA_DEPTH; depth++) {
		make_acc(&acc, 5, 1, flat_value);
		assert_int_equal(accum_merge_aa_region(&acc, &big, 0, ACC_AA, depth, 1, 0, 0, 4, 0,
							 1, &folded, err, sizeof(err)), 0);
		assert_int_equal(folded, 5);
		make_acc(&few, 5, 1, flat_value);
		assert_int_equal(accum_merge_aa_region(&few, &big, 0, ACC_AA, depth, 0, 0, 0, 4, 0,
							1, &folded, err, sizeof(err)), 0);
		assert_int_equal(folded, 5);
		const int cells = accum_edge_cells(depth);
		double full_x[5], v_x[5];	/* each pixel's, for the spread fold below */
		for (int x = 0; x < 5; x++) {
			const float *o = accpx(&acc, (size_t)x), *q = accpx(&plain, (size_t)x);
			const double range = 3.0 * spread[x];
			/* the samples it stands for: the cells it was subdivided
			 * into, at least ACC_AA_FIRST */
			const double ek = edge_cells_want(range, cells);
			const int k = ek > ACC_AA_FIRST ? (int)lround(ek) : ACC_AA_FIRST;
			assert_true(o[ACC_SAMPLES] == (float)(1 + k));
			if (range >= ACC_AA_THRESHOLD)
				assert_int_equal(k, cells);
			/* taken for a few pixels, the same ramp to ACC_AA_FEW
			 * (+R4's cells), or at this depth to its cells */
			const double ef = edge_cells_want(range, ACC_AA_FEW);
			const int kf = ef > ACC_AA_FIRST ? (int)lround(ef) : ACC_AA_FIRST;
			assert_true(q[ACC_SAMPLES] == (float)(1 + kf));
			if (range >= ACC_AA_THRESHOLD)
				assert_int_equal(kf, ACC_AA_FEW);
			const float *fd = accpx(&few, (size_t)x);
			const double ec = edge_cells_want(range, cells < ACC_AA_FEW ? cells : ACC_AA_FEW);
			const int kc = ec > ACC_AA_FIRST ? (int)lround(ec) : ACC_AA_FIRST;
			assert_true(fd[ACC_SAMPLES] == (float)(1 + kc));
			if (depth <= ACC_AA_DEPTH_V1)
				assert_int_equal(kc, k);
			assert_true(fd[ACC_SCALES] == q[ACC_SCALES]);
			double d = 0.0, v = 0.0;
			for (int c = 0; c < 3; c++) {
				const double m = 0.4 + 0.1 * c;	/* the 2 x 2 mean */
				assert_close(o[c], (0.5 + k * m) / (1 + k), 1e-6, 0.0,
					     "the base sample and the mean, 1 to the cells");
				const double den = (double)o[c] * o[c] + METRICS_RELMSE_EPS;
				d += (m - 0.5) * (m - 0.5) / den / 3.0;
				/* four values +-spread/2: variance spread^2/3, over 4 */
				v += spread[x] * spread[x] / 3.0 / 4.0 / den / 3.0;
				/* the cells vary as the render pixels, spread^2/3, and
				 * the base sample 0.5 adds its difference */
				const double m2 = spread[x] * spread[x] / 3.0 * (k - 1) +
						  (m - 0.5) * (m - 0.5) * k / (1.0 + k);
				assert_close(o[ACC_VAR_R + c], m2 / k, 1e-4, 1e-9,
					     "the cells' variance: the render pixels'");
			}
			const double w = k, full = (w * w + 1.0) / ((1.0 + w) * (1.0 + w)) * d;
			full_x[x] = full;
			v_x[x] = v;
			const double bound = v / edge_cells_want(range, cells);
			assert_close(o[ACC_DIFF], full < bound ? full : bound, 1e-4, 1e-12,
				     "the edge fold's error: the spread over its cells");
			if (x >= 3)	/* the bound acts where the pixel differs */
				assert_true(o[ACC_DIFF] < full);
			if (x == 2)	/* between a tenth of the threshold and it */
				assert_true(edge_cells_want(range, cells) > 1.0 &&
					    edge_cells_want(range, cells) < cells);
			assert_true(accum_has_scale(&acc, (size_t)x, ACC_AA_HALF));
			assert_true(accum_has_scale(&acc, (size_t)x, ACC_AA_NOGRID));
			assert_true(accum_has_scale(&acc, (size_t)x, ACC_AA_EDGE));
			assert_int_equal(accum_has_scale(&acc, (size_t)x, ACC_AA_DEEP),
					 range >= ACC_AA_THRESHOLD);
			assert_false(accum_has_scale(&plain, (size_t)x, ACC_AA_EDGE));
			assert_int_equal(accum_has_scale(&plain, (size_t)x, ACC_AA_DEEP),
					 range >= ACC_AA_THRESHOLD);
			assert_true(accum_has_scale(&plain, (size_t)x, ACC_AA_NOGRID));
		}
		/* from +R4 (ACC_AA_DEPTH_V1, the plain one's) on, the few
		 * pixels' fold is the plain one in every channel (samples,
		 * variance, difference, scales): their cells stop at ACC_AA_FEW */
		if (depth >= ACC_AA_DEPTH_V1)
			for (size_t i = 0; i < (size_t)5 * ACC_NCH; i++)
				assert_true(memcmp(&few.px[i], &plain.px[i], sizeof(float)) == 0);
		/* taken for spread error (+AM1): folded as for edges but for
		 * its error, the spread over range / ACC_AA_SPREAD_RANGE (at
		 * least 1), and marked ACC_AA_SPREAD_BIT besides */
		struct image spr;
		make_acc(&spr, 5, 1, flat_value);
		assert_int_equal(accum_merge_aa_region(&spr, &big, 0, ACC_AA, depth,
							 ACC_AA_FOR_SPREAD, 0, 0, 4, 0, 1, &folded,
							 err, sizeof(err)), 0);
		assert_int_equal(folded, 5);
		for (int x = 0; x < 5; x++) {
			const float *o = accpx(&acc, (size_t)x), *p = accpx(&spr, (size_t)x);
			const double range = 3.0 * spread[x];
			for (int ch = 0; ch < ACC_NCH; ch++)
				if (ch != ACC_DIFF && ch != ACC_SCALES)
					assert_true(memcmp(&o[ch], &p[ch], sizeof(float)) == 0);
			assert_true(p[ACC_SCALES] == o[ACC_SCALES] + (float)(1u << ACC_AA_SPREAD_BIT));
			/* the same samples and means, so the same full difference
			 * and spread as the edge fold's */
			const double full = full_x[x];
			/* in proportion to the cells from ACC_AA_SPREAD_DEPTH's */
			const double kd = range / ACC_AA_SPREAD_RANGE * accum_edge_cells(depth) /
					  accum_edge_cells(ACC_AA_SPREAD_DEPTH);
			const double div = kd > 1.0 ? kd : 1.0;
			const double bound = v_x[x] / div;
			assert_close(p[ACC_DIFF], full < bound ? full : bound, 1e-4, 1e-12,
				     "the spread fold's error: the spread over range / 0.012 at depth 3");
			/* at its depth, charged more than for edges */
			if (depth == ACC_AA_SPREAD_DEPTH && x >= 1 && x <= 3)
				assert_true(p[ACC_DIFF] > o[ACC_DIFF]);
		}
		image_release(&spr);
		/* the lighter renders for spread error (+A0.1 +R3 and +A0.3
		 * +R2, whatever the depth): 36 and 16 cells a subdivided pixel;
		 * a pixel whose render pixels differ by less than the render's
		 * threshold was not subdivided, and its spread is its error's
		 * as it stands.  The deeper ones (+A0.03 +R5 and +R6, whatever
		 * the depth): 100 and 144 cells, divided as +R4's are */
		static const struct {
			int edges, cells;
			double t;
			int light;
		} lv[4] = {
			{ ACC_AA_FOR_SPREAD_R3, ACC_AA_SPREAD_R3_CELLS, ACC_AA_SPREAD_R3_THRESHOLD, 1 },
			{ ACC_AA_FOR_SPREAD_FLOOR, ACC_AA_SPREAD_FLOOR_CELLS,
			  ACC_AA_SPREAD_FLOOR_THRESHOLD, 1 },
			{ ACC_AA_FOR_SPREAD_R5, 100, ACC_AA_SPREAD_THRESHOLD, 0 },
			{ ACC_AA_FOR_SPREAD_R6, 144, ACC_AA_SPREAD_THRESHOLD, 0 },
		};
		for (int li = 0; li < 4; li++) {
			assert_true(accum_for_spread(lv[li].edges));
			const struct accum_spread sr = accum_spread_render(lv[li].edges, depth);
			assert_true(sr.light == lv[li].light && sr.threshold == lv[li].t);
			assert_int_equal(sr.cells, lv[li].cells);
			make_acc(&spr, 5, 1, flat_value);
			assert_int_equal(accum_merge_aa_region(&spr, &big, 0, ACC_AA, depth,
								 lv[li].edges, 0, 0, 4, 0, 1,
								 &folded, err, sizeof(err)), 0);
			assert_int_equal(folded, 5);
			for (int x = 0; x < 5; x++) {
				const float *p = accpx(&spr, (size_t)x);
				const double range = 3.0 * spread[x];
				const double ek = edge_cells_want(range, lv[li].cells);
				const int k = ek > ACC_AA_FIRST ? (int)lround(ek) : ACC_AA_FIRST;
				assert_true(p[ACC_SAMPLES] == (float)(1 + k));
				if (range >= ACC_AA_THRESHOLD)
					assert_int_equal(k, lv[li].cells);
				double d = 0.0, v = 0.0;
				for (int c = 0; c < 3; c++) {
					const double m = 0.4 + 0.1 * c;
					assert_close(p[c], (0.5 + k * m) / (1 + k), 1e-6, 0.0,
						     "the base sample and the mean, 1 to the cells");
					const double den = (double)p[c] * p[c] + METRICS_RELMSE_EPS;
					d += (m - 0.5) * (m - 0.5) / den / 3.0;
					v += spread[x] * spread[x] / 3.0 / 4.0 / den / 3.0;
				}
				const double full = ((double)k * k + 1.0) / ((1.0 + k) * (1.0 + k)) * d;
				const double kd = range / ACC_AA_SPREAD_RANGE * lv[li].cells /
						  accum_edge_cells(ACC_AA_SPREAD_DEPTH);
				const double div = lv[li].light && range < lv[li].t ? 1.0
						   : kd > 1.0 ? kd : 1.0;
				/* (pixel 3's range, 0.3, is +A0.3's threshold itself:
				 * which side the floats put it on is not the point) */
				if (!(li == 1 && x == 3))
					assert_close(p[ACC_DIFF], full < v / div ? full : v / div,
						     1e-4, 1e-12,
						     "a lighter render's error: the spread, over range "
						     "/ 0.012 in proportion to its cells where "
						     "subdivided");
				/* 0.06 below either threshold: not subdivided, the
				 * spread whole; 0.9 above both: divided */
				if (x == 2 && lv[li].light)
					assert_close(p[ACC_DIFF], full < v ? full : v, 1e-4, 1e-12,
						     "below the threshold the spread whole");
				if (x == 2 && !lv[li].light)	/* 0.06: above +A0.03 */
					assert_true(p[ACC_DIFF] < v);
				if (x == 4)
					assert_true(p[ACC_DIFF] < v);
				assert_true(accum_has_scale(&spr, (size_t)x, ACC_AA_SPREAD_BIT));
				assert_true(accum_has_scale(&spr, (size_t)x, ACC_AA_EDGE));
			}
			image_release(&spr);
		}
		if (depth < ACC_AA_DEPTH)
			image_release(&acc);	/* the deepest goes on below */
		image_release(&few);
	}
	for (int depth = 0; depth <= ACC_AA_DEPTH + 1; depth += ACC_AA_DEPTH + 1) {
		err[0] = '\0';
		assert_int_equal(accum_merge_aa_region(&acc, &big, 0, ACC_AA, depth, 1, 0, 0, 4, 0,
							 2, &folded, err, sizeof(err)), -1);
		assert_non_null(strstr(err, "depth"));
		err[0] = '\0';
		assert_int_equal(accum_merge_aa_region(&acc, &big, 0, ACC_AA, depth, 0, 0, 0, 4, 0,
							2, &folded, err, sizeof(err)), -1);
		assert_non_null(strstr(err, "depth"));
	}
	image_release(&plain);

	/* hidden edges: pixel 0 beside a pixel 0.6 brighter, with 8
	 * samples each, pixel 0's samples' standard deviation 0.02 (whose
	 * ACC_AA_STEP_SD reaches past the cap); as edge pixels the
	 * difference that counts is at most the threshold / 3; and where
	 * POV-Ray subdivided the neighbour (ACC_AA_DEEP) and not pixel 0, the
	 * edge is the neighbour's: none is charged to pixel 0 */
	struct image two;
	make_acc(&two, 2, 1, flat_value);
	double e[3];
	for (int k = 0; k < 3; k++) {
		for (int x = 0; x < 2; x++) {
			float *o = accpx(&two, (size_t)x);
			for (int c = 0; c < 3; c++) {
				o[c] = (float)(0.2 + 0.6 * x);
				o[ACC_VAR_R + c] = x ? 0.0f : 0.02f * 0.02f;
			}
			o[ACC_SAMPLES] = 8.0f;
			o[ACC_SCALES] = (float)(1u << 1 | 1u << 2 | 1u << ACC_AA | 1u << ACC_AA_HALF |
						(k ? 1u << ACC_AA_EDGE : 0u) |
						(k == 2 && x == 1 ? 1u << ACC_AA_DEEP : 0u));
		}
		e[k] = accum_pixel_error(&two, 0, NAN, NULL, 0.0);
	}
	assert_true(e[2] == 0.0);
	/* hidden_edge()'s term with |d| at the cap, scale 2, on this pixel's
	 * side: 2 / (2 + 2) */
	const double cap = 0.5 * edge_strip(0.2, ACC_AA_THRESHOLD / 3.0, 2);
	assert_true(e[0] > 10.0 * e[1]);
	assert_close(e[1], cap, 1e-6, 1e-15, "the hidden edge at most the threshold");
	/* pixel 0's samples' standard deviation 0.005: the step its own
	 * render pixels could hide, ACC_AA_STEP_SD of that, in place of the
	 * cap; alike to the last bit: none (the step is the neighbour's) */
	const double small = 0.5 * edge_strip(0.2, ACC_AA_STEP_SD * 0.005, 2);
	for (int c = 0; c < 3; c++)
		accpx(&two, 0)[ACC_VAR_R + c] = 0.005f * 0.005f;
	accpx(&two, 1)[ACC_SCALES] = accpx(&two, 0)[ACC_SCALES];
	assert_close(accum_pixel_error(&two, 0, NAN, NULL, 0.0), small, 1e-4, 1e-15,
		     "the hidden edge at most what the render pixels show");
	/* ... but of +AM1's render for spread error (ACC_AA_SPREAD_BIT), whose
	 * samples no neighbour shares, the threshold alone */
	accpx(&two, 0)[ACC_SCALES] += (float)(1u << ACC_AA_SPREAD_BIT);
	assert_close(accum_pixel_error(&two, 0, NAN, NULL, 0.0), cap, 1e-6, 1e-15,
		     "+AM1's hidden edge at most the threshold");
	accpx(&two, 0)[ACC_SCALES] -= (float)(1u << ACC_AA_SPREAD_BIT);
	for (int c = 0; c < 3; c++)
		accpx(&two, 0)[ACC_VAR_R + c] = 0.0f;
	assert_true(accum_pixel_error(&two, 0, NAN, NULL, 0.0) == 0.0);
	image_release(&two);

	/* a grid render of scale 4 over them: all 4 x 5 samples new (the
	 * render had none at the sub-pixel centres); over a pixel that has
	 * had scale 2 itself, 4 x 4 (each sub-pixel's centre sample is a
	 * repeat) */
	accpx(&acc, 4)[ACC_SCALES] = (float)(1u << 1 | 1u << 2);
	accpx(&acc, 4)[ACC_SAMPLES] = 5.0f;
	make_render(&plain, 10, 0, 2, 4);
	float before[5];
	for (int x = 0; x < 5; x++)
		before[x] = accpx(&acc, (size_t)x)[ACC_SAMPLES];
	assert_int_equal(accum_merge_region(&acc, &plain, 0, 4, 0, 0, 4, 0, 2, &folded, err,
					    sizeof(err)), 0);
	assert_int_equal(folded, 5);
	const int g = accum_grid_samples(4);
	for (int x = 0; x < 5; x++)
		assert_true(accpx(&acc, (size_t)x)[ACC_SAMPLES] ==
			    before[x] + (float)(x < 4 ? g : g - 4));
	image_release(&plain);
	image_release(&big);
	image_release(&acc);
}

/* 4. accum_read round-trips an accumulation; a missing channel is named. */
static void test_accum_read(void **state)
{
	struct image acc, got = {0}, partial;
	const char *names[ACC_NCH - 1];
	char path[256], err[512];
	double mean[3] = { 0.25, 0.5, 0.75 }, m2[3] = { 0.01, 0.02, 0.03 };

	(void)state;
	make_acc(&acc, 5, 4, base_value);
	assert_int_equal(accum_fold(&acc, 3, 2, 4, mean, m2, 1), 0);
	assert_int_equal(accum_fold(&acc, 3, 4, 16, mean, m2, 2), 0);
	assert_int_equal(accum_fold(&acc, 17, 2, 3, mean, m2, 1), 0);
	scratch(path, sizeof(path), "acc.exr");
	assert_int_equal(image_write_exr(path, &acc, err, sizeof(err)), 0);
	assert_int_equal(accum_read(path, &got, err, sizeof(err)), 0);
	assert_int_equal(got.w, 5);
	assert_int_equal(got.h, 4);
	assert_int_equal(got.nch, ACC_NCH);
	for (int c = 0; c < ACC_NCH; c++)
		assert_string_equal(got.names[c], accum_names[c]);
	assert_memory_equal(got.px, acc.px, (size_t)5 * 4 * ACC_NCH * sizeof(float));
	image_release(&got);

	/* every channel but 'samples' */
	for (int c = 0, k = 0; c < ACC_NCH; c++)
		if (c != ACC_SAMPLES)
			names[k++] = accum_names[c];
	assert_int_equal(image_init(&partial, 5, 4, ACC_NCH - 1, names, err, sizeof(err)), 0);
	scratch(path, sizeof(path), "partial.exr");
	assert_int_equal(image_write_exr(path, &partial, err, sizeof(err)), 0);
	err[0] = '\0';
	assert_int_equal(accum_read(path, &got, err, sizeof(err)), -1);
	if (!strstr(err, "'samples'") || !strstr(err, path))
		fail_msg("message \"%s\" does not name the channel and the file", err);
	image_release(&partial);
	image_release(&acc);
}

/* 5. image_read_exr_rows reads whole chunks around the rows (16 rows:
 * image_write_exr() writes a narrow image as ZIP). */
static void test_read_rows(void **state)
{
	const int w = 40, h = 100;
	struct image img, got;
	char path[256], err[512];
	int oy = -1;
	static const int ask[][2] = { { 37, 58 }, { 30, 70 }, { 90, 99 }, { 95, 150 } };

	(void)state;
	assert_int_equal(image_init(&img, w, h, 3, rgb_names, err, sizeof(err)), 0);
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++)
			for (int c = 0; c < 3; c++)
				img.px[((size_t)y * w + x) * 3 + c] = (float)(y * 1000 + x + 0.25 * c);
	scratch(path, sizeof(path), "rows.exr");
	assert_int_equal(image_write_exr(path, &img, err, sizeof(err)), 0);

	for (size_t t = 0; t < sizeof(ask) / sizeof(ask[0]); t++) {
		int y0 = ask[t][0], y1 = ask[t][1] < h ? ask[t][1] : h - 1;

		oy = -1;
		assert_int_equal(image_read_exr_rows(path, ask[t][0], ask[t][1], &got, &oy, err,
						     sizeof(err)), 0);
		assert_true(oy >= 0 && oy <= y0);
		/* from the start of the chunk holding y0, not a whole-file read */
		assert_int_equal(oy % 16, 0);
		assert_true(y0 - oy < 16);
		assert_true(oy + got.h - 1 >= y1);
		assert_true(oy + got.h <= h);
		assert_true(got.h < h || y0 < 16);	/* a band, not the file */
		assert_int_equal(got.w, w);
		for (int k = 0; k < got.h; k++)
			for (int x = 0; x < w; x++)
				for (int c = 0; c < 3; c++) {
					int gc = image_channel(&got, rgb_names[c]);
					float g = got.px[((size_t)k * w + x) * got.nch + gc];
					float e = img.px[((size_t)(oy + k) * w + x) * 3 + c];

					if (g != e)
						fail_msg("rows %d..%d: row %d x %d c %d: got %g, "
							 "want %g", y0, y1, oy + k, x, c, g, e);
				}
		image_release(&got);
	}

	/* past the last row */
	err[0] = '\0';
	assert_int_equal(image_read_exr_rows(path, 100, 120, &got, &oy, err, sizeof(err)), -1);
	assert_true(err[0] != '\0');
	assert_zeroed(&got);
	image_release(&img);
}

/* ------------------------------------------------------------------ */

#define PW 64
#define PH 48

struct plan_input {
	struct image acc;
	float press[PW * PH];
	float fit[PW * PH * 3];
};

/* A flat 0.5 image; press 0 except err on the listed blocks (x0 y0 x1 y1),
 * whose pixels are a checkerboard of 0 and 1 (a pixel's estimate from PRESS
 * is bounded by what its value could be off by within its neighbours'
 * range: about 0.99 there, 0 on the flat image).  The fit is 0.5 everywhere,
 * so a block pixel's estimate is err / (0.5^2 + 0.01) for err up to 0.25.
 * Every pixel has scale 8 in its mask besides the base pass's 1: no hidden-
 * edge part, and scale 2 next. */
static void plan_input(struct plan_input *in, const int (*blocks)[4], int nblocks, float err)
{
	make_acc(&in->acc, PW, PH, flat_value);
	for (int i = 0; i < PW * PH; i++) {
		in->press[i] = 0.0f;
		for (int c = 0; c < 3; c++)
			in->fit[3 * i + c] = accpx(&in->acc, (size_t)i)[c];
		accpx(&in->acc, (size_t)i)[ACC_SCALES] = 2 + 256;
	}
	for (int b = 0; b < nblocks; b++)
		for (int y = blocks[b][1]; y <= blocks[b][3]; y++)
			for (int x = blocks[b][0]; x <= blocks[b][2]; x++) {
				in->press[y * PW + x] = err;
				for (int c = 0; c < 3; c++)
					accpx(&in->acc, (size_t)y * PW + x)[c] = (float)((x + y) % 2);
			}
}

static int in_region(const struct plan_region *r, int x, int y)
{
	return x >= r->x0 && x <= r->x1 && y >= r->y0 && y <= r->y1;
}

/* Regions inside the image, at most max_regions, pixels counts their union. */
static void check_regions(const struct plan *pl, const struct plan_params *p)
{
	long inside = 0;

	assert_true(pl->nregions <= (size_t)p->max_regions);
	for (size_t k = 0; k < pl->nregions; k++) {
		const struct plan_region *r = &pl->regions[k];

		assert_true(r->x0 >= 0 && r->x0 <= r->x1 && r->x1 < PW);
		assert_true(r->y0 >= 0 && r->y0 <= r->y1 && r->y1 < PH);
		assert_int_equal(r->scale, 2);
	}
	for (int y = 0; y < PH; y++)
		for (int x = 0; x < PW; x++) {
			int any = 0;

			for (size_t k = 0; k < pl->nregions; k++)
				any |= in_region(&pl->regions[k], x, y);
			inside += any;
			assert_true(pl->scale[y * PW + x] == (any ? 2.0f : 0.0f));
		}
	assert_int_equal(pl->pixels, inside);
	assert_true(pl->samples == 4.0 * (double)inside);
}

/* plan_make() on the input, which must succeed: the plan's outcome. */
static enum plan_outcome plan_of(struct plan_input *in, const struct plan_params *p,
				 struct plan *pl)
{
	char err[256];

	assert_int_equal(plan_make(&in->acc, in->press, in->fit, p, pl, err, sizeof(err)), 0);
	return pl->outcome;
}

/* The plan of the whole frame with no budget and two cores, which must be
 * two regions covering it. */
static void plan_two_parts(struct plan_input *in, struct plan_params *p, struct plan *pl)
{
	p->budget = 0.0;
	p->min_split = 2;
	assert_int_equal(plan_of(in, p, pl), PLAN_REFINE);
	check_regions(pl, p);
	assert_int_equal(pl->nregions, 2);
	assert_int_equal(pl->pixels, PW * PH);
}

/* A block of 6 x 5 pixels with error, for the planner's tests. */
static const int block[1][4] = { { 20, 17, 25, 21 } };

/* A planner test's input (the listed blocks with error err, as
 * plan_input(); free() it) and default parameters. */
static struct plan_input *plan_setup_with(struct plan_params *p, const int (*blocks)[4],
					  int nblocks, float err)
{
	struct plan_input *in = malloc(sizeof(*in));

	assert_non_null(in);
	plan_params_init(p);
	plan_input(in, blocks, nblocks, err);
	return in;
}

/* The same with the block, error 0.25. */
static struct plan_input *plan_setup(struct plan_params *p)
{
	return plan_setup_with(p, block, 1, 0.25f);
}

/* plan_make_from()'s second fit: where splitting the regions for the cores
 * takes the plan past its budget by more than PLAN_SPLIT_OVER, the pass is
 * planned again for a budget less by half the excess. */
static void test_plan_split_budget(void **state)
{
	static const int whole[1][4] = { { 0, 0, PW - 1, PH - 1 } };
	struct plan_params p;
	struct plan_input *in = plan_setup_with(&p, whole, 1, 0.25f);
	struct plan pl;
	(void)state;

	p.cost_job = 1e-3;	/* a split costs 4% of the frame at scale 2 */
	p.min_split = 1;	/* one region: its cost */
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_int_equal(pl.nregions, 1);
	assert_true(pl.budget == 0.0);
	const double one = pl.cost;
	plan_release(&pl);
	p.min_split = 2;	/* split in two: a job more */
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_int_equal(pl.nregions, 2);
	const double two = pl.cost;
	plan_release(&pl);
	assert_true(two > PLAN_SPLIT_OVER * 1.005 * one);

	/* a budget the one region fits but its halves do not: planned again
	 * for less, until the plan is within PLAN_SPLIT_OVER of it */
	p.budget = 1.005 * one;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_true(pl.budget <= p.budget - 0.5 * (two - p.budget) + 1e-12);
	assert_true(pl.cost <= PLAN_SPLIT_OVER * p.budget);
	check_regions(&pl, &p);
	plan_release(&pl);

	/* a budget both fit: planned once, for it */
	p.budget = 2.0 * two;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_true(pl.budget == p.budget);
	assert_true(pl.cost <= p.budget);
	plan_release(&pl);
	image_release(&in->acc);
	free(in);
}

/* 6. plan_make: refine, target met, no budget, packing, too little gain,
 * no gain. */
static void test_plan_make(void **state)
{
	static const int two[2][4] = { { 2, 2, 4, 4 }, { 58, 40, 61, 43 } };
	struct plan_params p;
	struct plan_input *in = plan_setup(&p);
	struct plan pl;

	(void)state;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_int_equal(pl.chosen_pixels, 30);
	for (int y = 0; y < PH; y++)
		for (int x = 0; x < PW; x++) {
			int inb = x >= 20 && x <= 25 && y >= 17 && y <= 21, found = 0;

			assert_true(pl.chosen[y * PW + x] == (inb ? 1.0f : 0.0f));
			for (size_t k = 0; inb && k < pl.nregions; k++)
				found |= in_region(&pl.regions[k], x, y) && pl.regions[k].scale == 2;
			assert_true(!inb || (found && pl.scale[y * PW + x] == 2.0f));
		}
	check_regions(&pl, &p);
	/* e = press / (0.5^2 + 0.01) on the block; scale 2 divides it by 5 */
	double est = 30.0 * (0.25 / 0.26) / (PW * PH);
	assert_close(pl.est_relmse, est, 1e-6, 0.0, "est_relmse");
	assert_true(pl.est_after < pl.est_relmse);
	assert_close(pl.est_after, est / 5.0, 1e-6, 0.0, "est_after");
	plan_release(&pl);
	image_release(&in->acc);

	/* nothing to fix */
	plan_input(in, block, 0, 0.0f);
	assert_int_equal(plan_of(in, &p, &pl), PLAN_TARGET_MET);
	assert_int_equal(pl.nregions, 0);
	plan_release(&pl);
	image_release(&in->acc);

	/* a budget below one pixel's 4 samples */
	plan_input(in, block, 1, 0.25f);
	p.budget = 0.5 * 4 * p.cost_sample;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_NO_BUDGET);
	assert_int_equal(pl.nregions, 0);
	plan_release(&pl);
	p.budget = 0.0;
	image_release(&in->acc);

	/* two distant blocks: one render when a job is dear, two when free */
	plan_input(in, two, 2, 0.25f);
	p.cost_job = 1e3;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_int_equal(pl.nregions, 1);
	assert_true(pl.regions[0].x0 <= 2 && pl.regions[0].y0 <= 2 && pl.regions[0].x1 >= 61 &&
		    pl.regions[0].y1 >= 43);
	assert_int_equal(pl.chosen_pixels, 9 + 16);
	check_regions(&pl, &p);
	plan_release(&pl);

	p.cost_job = 0.0;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_int_equal(pl.nregions, 2);
	for (int b = 0; b < 2; b++) {
		int hits = 0;

		for (size_t k = 0; k < 2; k++)
			hits += in_region(&pl.regions[k], two[b][0], two[b][1]) &&
				in_region(&pl.regions[k], two[b][2], two[b][3]);
		assert_int_equal(hits, 1);
	}
	assert_false(in_region(&pl.regions[0], 30, 20) || in_region(&pl.regions[1], 30, 20));
	check_regions(&pl, &p);
	plan_release(&pl);

	/* ... and one again when the frame is dear: every render pays for its
	 * whole s W x s H frame (here scale 2's), whatever its region */
	p.cost_frame = 1e-3;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_int_equal(pl.nregions, 1);
	check_regions(&pl, &p);
	const struct plan_region *g = &pl.regions[0];
	assert_close(g->cost, p.cost_frame * PW * PH * 4.0 +
			      p.cost_sample * 4.0 * (double)plan_region_area(g), 1e-9, 0.0,
		     "a render's cost with its frame's");
	plan_release(&pl);
	p.cost_frame = 0.0;

	/* ... and a cap of one region forces the merge */
	p.max_regions = 1;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_int_equal(pl.nregions, 1);
	check_regions(&pl, &p);
	assert_int_equal(pl.chosen_pixels, 9 + 16);
	plan_release(&pl);
	plan_params_init(&p);
	image_release(&in->acc);

	/* under a budget, a pass taking less than min_pass_gain of the
	 * estimate off (the goal unmet) is not worth running; without a
	 * budget the share does not count */
	plan_input(in, block, 1, 0.25f);
	p.target = 1e-6;
	p.cost_job = 0.0;
	p.budget = 1.0;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	/* the block at scale 2: 4/5 of its error off */
	double share = (pl.est_relmse - pl.est_after) / pl.est_relmse;
	assert_close(share, 0.8, 1e-9, 0.0, "share");
	plan_release(&pl);
	p.min_pass_gain = share + 0.01;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_LITTLE_GAIN);
	assert_int_equal(pl.nregions, 0);
	assert_string_equal(plan_outcome_name(pl.outcome), "too little left to gain");
	plan_release(&pl);
	p.min_pass_gain = share - 0.01;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	plan_release(&pl);
	p.min_pass_gain = 1.0;
	p.budget = 0.0;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_true(pl.nregions > 0);
	plan_release(&pl);
	plan_params_init(&p);
	image_release(&in->acc);

	/* near the target a pass takes off what is missing over
	 * PLAN_REALIZED, not down to target * margin: the block's 30 pixels
	 * of equal error e, each gaining 4/5 of it at scale 2, the estimate
	 * 5% above the target: (1 - 1/1.05) 30 / 0.8 / 0.8 = 2.2, so 3
	 * pixels (with the margin alone 13) */
	plan_input(in, block, 1, 0.25f);
	const double e30 = 30.0 * (0.25 / 0.26) / (PW * PH);
	p.target = e30 / 1.05;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_int_equal(pl.chosen_pixels, 3);
	assert_true(pl.est_after <= p.target);
	plan_release(&pl);
	/* ... far above it, down to target * margin: the estimate 3 times
	 * the target, (1 - 0.7 / 3) 30 / 0.8 = 28.75, so 29 */
	p.target = e30 / 3.0;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_int_equal(pl.chosen_pixels, 29);
	plan_release(&pl);
	/* ... and under a budget a pass that meets the target by taking off
	 * less than min_pass_gain of the estimate (one pixel, 2.7%, where
	 * 0.5% is missing; 5% asked) still runs */
	p.target = e30 / 1.005;
	p.budget = 1.0;
	p.cost_job = 0.0;
	p.min_pass_gain = 0.05;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_true(pl.est_after <= p.target);
	assert_true(pl.est_relmse - pl.est_after < p.min_pass_gain * pl.est_relmse);
	plan_release(&pl);
	plan_params_init(&p);
	image_release(&in->acc);

	/* every scale already sampled everywhere, large error */
	static const int all[1][4] = { { 0, 0, PW - 1, PH - 1 } };
	plan_input(in, all, 1, 0.25f);
	for (int i = 0; i < PW * PH; i++)
		accpx(&in->acc, (size_t)i)[ACC_SCALES] = 2.0f + 4 + 16 + 256 + 65536;
	plan_of(in, &p, &pl);
	assert_true(pl.est_relmse > p.target);
	assert_int_equal(pl.outcome, PLAN_NO_GAIN);
	assert_int_equal(pl.nregions, 0);
	plan_release(&pl);
	image_release(&in->acc);
	free(in);
}

/* 6b. Packing looks past the last merge that saved: two renders' jobs
 * saved at once may pay where neither merge alone does; and pixels a
 * rectangle takes along count at the dearest gain the plan took. */
static void test_plan_pack_ahead(void **state)
{
	/* two tall blocks at the sides, a third between them, two tiles of
	 * the packing grid apart: any one merge adds more pixels than a job
	 * is worth, the frame's width less */
	static const int three[3][4] = { { 0, 0, 7, 39 }, { 56, 0, 63, 39 }, { 24, 16, 39, 25 } };
	static const int two[2][4] = { { 0, 0, 7, 7 }, { 24, 0, 31, 7 } };
	struct plan_params p;
	struct plan_input *in = plan_setup_with(&p, three, 3, 0.25f);
	struct plan pl;

	(void)state;
	p.target = 1e-6;
	/* a job worth 1000 pixels at scale 2: merging a side block and the
	 * middle one adds 1120 pixels, the two sides 1920; all three in one
	 * render cost 2560 and a job, against 800 and three jobs */
	p.cost_job = 1000.0 * 4.0 * p.cost_sample;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	check_regions(&pl, &p);
	assert_int_equal(pl.nregions, 1);
	assert_int_equal(pl.pixels, 64 * 40);
	assert_close(pl.cost, p.cost_job + 2560.0 * 4.0 * p.cost_sample, 1e-9, 0.0, "one render");
	plan_release(&pl);
	/* at 700 pixels a job the three alone are cheaper (2900 against 3260) */
	p.cost_job = 700.0 * 4.0 * p.cost_sample;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	check_regions(&pl, &p);
	assert_int_equal(pl.nregions, 3);
	assert_int_equal(pl.pixels, 800);
	plan_release(&pl);
	image_release(&in->acc);

	/* two 8 x 8 blocks 16 columns apart, the 128 pixels between them
	 * with a little error each (0.01 / 0.26), not chosen at this target:
	 * the merge adds 128 pixels at scale 2 for one job (the target too low
	 * to meet, but the strip's pixels gain too little to be taken) */
	plan_input(in, two, 2, 0.25f);
	for (int y = 0; y <= 7; y++)
		for (int x = 8; x <= 23; x++) {
			in->press[y * PW + x] = 0.01f;
			for (int c = 0; c < 3; c++)
				accpx(&in->acc, (size_t)y * PW + x)[c] = (float)((x + y) % 2);
		}
	p.target = 1e-6;
	p.min_gain = 0.05 / p.target;	/* a rider gains 0.031: not a candidate */
	/* the gap costs 512 sample costs: a job of 520 merges whatever the
	 * riders are worth, one of 500 only for them (each block pixel took
	 * its 0.77 of gain for 4 sample costs: a rider's 0.031 is worth 0.16
	 * of them, the strip's 20.5), and one of 480 not even so */
	const double job[3] = { 520.0, 500.0, 480.0 };
	const size_t regions[3] = { 1, 1, 2 };
	for (int k = 0; k < 3; k++) {
		p.cost_job = job[k] * p.cost_sample;
		assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
		check_regions(&pl, &p);
		assert_int_equal(pl.chosen_pixels, 128);
		assert_int_equal(pl.nregions, regions[k]);
		assert_int_equal(pl.pixels, regions[k] == 1 ? 256 : 128);
		plan_release(&pl);
	}
	image_release(&in->acc);
	free(in);
}

/* The factor value_bias() puts on a pixel's relative error (accum.c): mean
 * over R, G, B of m^2 + 0.01 over that of max(m^2 - var / n, m^2 / 4) + 0.01. */
/* The cost of a plan's regions as rect_cost() has it. */
static double plan_cost(const struct plan *pl, const struct plan_params *p)
{
	double c = 0.0;

	for (size_t k = 0; k < pl->nregions; k++) {
		const struct plan_region *r = &pl->regions[k];
		double area = (double)(r->x1 - r->x0 + 1) * (r->y1 - r->y0 + 1);

		c += p->cost_job + p->cost_sample * area * r->scale * r->scale;
	}
	return c;
}

/* 7. A pass that may be the last takes its pixels past their next scale;
 * a budget below the rectangles keeps their best bands; the dearest
 * region is split for the cores. */
static void test_plan_budget(void **state)
{
	static const int all[1][4] = { { 0, 0, PW - 1, PH - 1 } };
	struct plan_params p;
	struct plan_input *in = plan_setup(&p);
	struct plan pl;

	(void)state;
	p.target = 1e-6;
	p.budget = 0.2;
	/* without fill: scale 2, the next */
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	double est = pl.est_relmse, after2 = pl.est_after;
	check_regions(&pl, &p);
	plan_release(&pl);
	/* filling the budget: the block's pixels go to scale 16 (8 is done),
	 * 256 samples each, in one region within the budget */
	p.fill = p.budget;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_int_equal(pl.chosen_pixels, 30);
	for (size_t k = 0; k < pl.nregions; k++)
		assert_int_equal(pl.regions[k].scale, 16);
	for (int y = 17; y <= 21; y++)
		for (int x = 20; x <= 25; x++)
			assert_true(pl.scale[y * PW + x] == 16.0f);
	assert_true(plan_cost(&pl, &p) <= p.budget);
	assert_close(pl.est_after, est / 257.0, 1e-6, 0.0, "est_after at scale 16");
	assert_true(pl.est_after < after2);
	plan_release(&pl);
	/* a fill below scale 16's cost: scale 4 for some, within 1.25 fill */
	p.fill = 0.05 + 30 * 16 * p.cost_sample;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	int up = 0;
	for (size_t k = 0; k < pl.nregions; k++)
		up |= pl.regions[k].scale > 2;
	assert_true(up);
	assert_true(plan_cost(&pl, &p) <= 1.25 * p.fill);
	assert_true(pl.est_after < after2);
	plan_release(&pl);
	image_release(&in->acc);
	plan_params_init(&p);

	/* rows 0-15 with five times the error of the rest: at 0.001 + 8e-6 per
	 * pixel and a budget of 0.015 the pixels chosen (rows 0-15, then rows
	 * 16-29 by position) make one rectangle over the budget (0.0164); it
	 * keeps the bands of 8 rows worth most, rows 0-15, and what else fits */
	plan_input(in, all, 1, 0.05f);
	for (int y = 0; y < 16; y++)
		for (int x = 0; x < PW; x++)
			in->press[y * PW + x] = 0.25f;
	p.target = 1e-6;
	p.cost_job = 0.001;
	p.budget = 0.015;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	check_regions(&pl, &p);
	assert_true(plan_cost(&pl, &p) <= p.budget);
	for (int y = 0; y < 16; y++)
		for (int x = 0; x < PW; x++)
			assert_true(pl.scale[y * PW + x] == 2.0f);
	assert_true(pl.pixels < 30 * PW);
	plan_release(&pl);

	/* no budget, two cores: the frame in two halves of equal cost */
	plan_two_parts(in, &p, &pl);
	assert_int_equal(pl.chosen_pixels, PW * PH);
	assert_close(pl.regions[0].cost, pl.regions[1].cost, 1e-9, 0.0, "halves' costs");
	plan_release(&pl);
	/* ... and none when the cores are one */
	p.min_split = 1;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_int_equal(pl.nregions, 1);
	plan_release(&pl);
	image_release(&in->acc);
	free(in);
}

/* Region r's cost by a cost map, as plan.h models it. */
static double map_cost(const struct plan_region *r, const struct plan_params *p,
		       const float *map)
{
	double m = 0.0;

	for (int y = r->y0; y <= r->y1; y++)
		for (int x = r->x0; x <= r->x1; x++)
			m += map[y * PW + x];
	return p->cost_job + p->cost_sample * m * r->scale * r->scale;
}

/* 7b. A cost map: under a budget the cheap pixels go first at equal error,
 * regions cost their pixels' costs, and the frame is split for the cores
 * where its cost halves. */
static void test_plan_cost_map(void **state)
{
	static const int all[1][4] = { { 0, 0, PW - 1, PH - 1 } };
	static float map[PW * PH];
	struct plan_params p;
	struct plan_input *in = plan_setup_with(&p, all, 1, 0.05f);
	struct plan pl;

	(void)state;
	/* the right half nine times as dear a sample */
	for (int y = 0; y < PH; y++)
		for (int x = 0; x < PW; x++)
			map[y * PW + x] = x < PW / 2 ? 1.0f : 9.0f;
	p.target = 1e-6;
	p.cost_job = 0.001;
	p.budget = 0.015;	/* the left half at scale 2: 0.0123 s */
	/* without the map the budget's pixels come by position, from both
	 * halves */
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	long right = 0;
	for (int y = 0; y < PH; y++)
		for (int x = PW / 2; x < PW; x++)
			right += pl.chosen[y * PW + x] > 0.0f;
	assert_true(right > 0);
	plan_release(&pl);
	/* with it, the left half alone, costed by the map within the budget */
	p.cost_map = map;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	check_regions(&pl, &p);
	long left = 0;
	double c = 0.0;
	for (int y = 0; y < PH; y++)
		for (int x = 0; x < PW; x++) {
			if (x >= PW / 2)
				assert_true(pl.scale[y * PW + x] == 0.0f);
			else
				left += pl.chosen[y * PW + x] > 0.0f;
		}
	assert_true(left > PW / 2 * PH / 2);
	for (size_t k = 0; k < pl.nregions; k++) {
		assert_close(pl.regions[k].cost, map_cost(&pl.regions[k], &p, map), 1e-9, 0.0,
			     "a region's cost by the map");
		c += pl.regions[k].cost;
	}
	assert_close(pl.cost, c, 1e-9, 0.0, "the plan's cost");
	assert_true(pl.cost <= p.budget);
	plan_release(&pl);

	/* no budget, two cores: columns 0-15 three times as dear as the rest
	 * hold half the frame's cost, and the split falls after column 15 */
	for (int y = 0; y < PH; y++)
		for (int x = 0; x < PW; x++)
			map[y * PW + x] = x < 16 ? 3.0f : 1.0f;
	plan_two_parts(in, &p, &pl);
	assert_int_equal(pl.regions[0].x0, 0);
	assert_int_equal(pl.regions[0].x1, 15);
	assert_int_equal(pl.regions[1].x0, 16);
	assert_close(pl.regions[0].cost, pl.regions[1].cost, 1e-9, 0.0, "the parts' costs");
	assert_close(pl.regions[0].cost, map_cost(&pl.regions[0], &p, map), 1e-9, 0.0,
		     "the dear part's cost");
	plan_release(&pl);
	/* and at the middle without the map */
	p.cost_map = NULL;
	assert_int_equal(plan_of(in, &p, &pl), PLAN_REFINE);
	assert_int_equal(pl.nregions, 2);
	assert_int_equal(pl.regions[0].x1, PW / 2 - 1);
	plan_release(&pl);
	image_release(&in->acc);
	free(in);
}

static double want_bias(const float *o)
{
	double a = 0.0, b = 0.0;
	for (int c = 0; c < 3; c++) {
		double m2 = (double)o[c] * o[c], x2 = m2 - o[ACC_VAR_R + c] / o[ACC_SAMPLES];
		a += m2 + 0.01;
		b += (x2 > 0.25 * m2 ? x2 : 0.25 * m2) + 0.01;
	}
	return a / b;
}

/* Pixel (x, y) of a 7 x 7 accumulation given n samples of variance var
 * and the fold difference diff. */
static void set_px(struct image *acc, int x, int y, float n, float var, float diff)
{
	float *o = accpx(acc, (size_t)y * acc->w + x);
	o[ACC_SAMPLES] = n;
	for (int c = 0; c < 3; c++)
		o[ACC_VAR_R + c] = var;
	o[ACC_DIFF] = diff;
}

/* Pixel errors on threads: the same values and estimate as on one, on an
 * image of mixed pixels (1 to 20 samples, varied spread and differences,
 * a hole), tall enough for several bands. */
static double mixed_value(int x, int y, int c)
{
	return 0.1 + 0.6 * ((x / 5 + y / 7) % 2) + 0.05 * c + 0.002 * x;
}

/*
 * Edges a neighbour's samples already place.  A diagonal neighbour 0.6
 * brighter than the dark pixel 0 (3 x 3 pixels around, all 8 samples with
 * no spread): charged as a hidden edge while the two pixels beside both
 * are flat, not when either holds the step in its samples (a lamp's rim)
 * or was subdivided by POV-Ray (ACC_AA_DEEP).
 * A one-sample pixel beside a pixel POV-Ray subdivided for an edge (its
 * mean 0.035 below, its samples' standard deviation 0.05): its range bound
 * counts the neighbour at the nearest of its mean +- that, here the pixel's
 * own value; without the subdivision (or with scale 8's bit, which
 * ACC_AA_DEEP shares, but no edge render) the full 0.035.
 */
static void test_pixel_errors_edges(void **state)
{
	struct image acc;
	float fit[3] = { 0.2f, 0.2f, 0.2f };

	(void)state;
	make_acc(&acc, 3, 3, flat_value);
	for (int y = 0; y < 3; y++)
		for (int x = 0; x < 3; x++) {
			set_px(&acc, x, y, 8.0f, 0.0f, 0.0f);
			float *o = accpx(&acc, (size_t)y * 3 + x);
			o[ACC_SCALES] = 2 + 4 + 16;
			for (int c = 0; c < 3; c++)
				o[c] = 0.01f;
		}
	/* pixel (0, 0) dark, its diagonal (1, 1) bright; (2, *) and (*, 2)
	 * dark like it */
	for (int c = 0; c < 3; c++)
		accpx(&acc, 4)[c] = 0.61f;
	double flat = accum_pixel_error(&acc, 0, 1e-6, fit, accum_pixel_noise(&acc, 0, 0.0));
	assert_true(flat > 0.05);
	/* (1, 0) holds the rim: samples from dark to bright */
	for (int c = 0; c < 3; c++) {
		accpx(&acc, 1)[c] = 0.3f;
		accpx(&acc, 1)[ACC_VAR_R + c] = 0.6f * 0.6f / 4.0f;
	}
	double rim = accum_pixel_error(&acc, 0, 1e-6, fit, accum_pixel_noise(&acc, 0, 0.0));
	/* (1, 0) itself an edge-on neighbour with its spread: nothing left */
	assert_true(rim == 0.0);
	/* the rim's spread too small to hold the step: charged again */
	for (int c = 0; c < 3; c++)
		accpx(&acc, 1)[ACC_VAR_R + c] = 0.01f * 0.01f;
	const double small = accum_pixel_error(&acc, 0, 1e-6, fit, accum_pixel_noise(&acc, 0, 0.0));
	assert_true(small > 0.5 * flat);
	/* ... unless POV-Ray subdivided the rim (ACC_AA_DEEP): the diagonal
	 * step is in it, and only the smaller edge-on one is charged */
	accpx(&acc, 1)[ACC_SCALES] = (float)(2 + 4 + 16 + (1u << ACC_AA_DEEP));
	const double sub = accum_pixel_error(&acc, 0, 1e-6, fit, accum_pixel_noise(&acc, 0, 0.0));
	assert_true(sub > 0.0 && sub < 0.5 * small);
	accpx(&acc, 1)[ACC_SCALES] = 2 + 4 + 16;
	/* the rim in the other pixel beside both, (0, 1), the same */
	for (int c = 0; c < 3; c++) {
		accpx(&acc, 1)[c] = 0.01f;
		accpx(&acc, 1)[ACC_VAR_R + c] = 0.0f;
		accpx(&acc, 3)[c] = 0.3f;
		accpx(&acc, 3)[ACC_VAR_R + c] = 0.6f * 0.6f / 4.0f;
	}
	assert_true(accum_pixel_error(&acc, 0, 1e-6, fit, accum_pixel_noise(&acc, 0, 0.0)) == 0.0);
	image_release(&acc);

	/* one row: a one-sample pixel (0.41) beside a subdivided one (mean
	 * 0.375, spread 0.05) and beside its like (0.41) */
	make_acc(&acc, 3, 1, flat_value);
	const float val[3] = { 0.41f, 0.41f, 0.375f };
	for (int x = 0; x < 3; x++) {
		float *o = accpx(&acc, (size_t)x);
		for (int c = 0; c < 3; c++)
			o[c] = val[x];
	}
	set_px(&acc, 2, 0, 257.0f, 0.05f * 0.05f, 1e-6f);
	accpx(&acc, 2)[ACC_SCALES] = (float)(1u << 1 | 1u << 2 | 1u << ACC_AA | 1u << ACC_AA_HALF |
					     1u << ACC_AA_EDGE | 1u << ACC_AA_DEEP);
	const double range = 0.035 * 0.035 / (0.375 * 0.375 + METRICS_RELMSE_EPS);
	double deep = accum_pixel_error(&acc, 1, 1.0, val, NAN);
	assert_true(deep < 1e-4 * range);
	accpx(&acc, 2)[ACC_SCALES] = (float)(1u << 1 | 1u << 2 | 1u << ACC_AA | 1u << ACC_AA_HALF |
					     1u << ACC_AA_EDGE);
	assert_close(accum_pixel_error(&acc, 1, 1.0, val, NAN), range, 1e-3, 0.0,
		     "the range bound beside an edge pixel not subdivided");
	/* scale 8's bit alone (a grid render, no edge render): its spread is
	 * noise, and its mean counts as it is */
	accpx(&acc, 2)[ACC_SCALES] = (float)(1u << 1 | 1u << 2 | 1u << 4 | 1u << 8);
	assert_close(accum_pixel_error(&acc, 1, 1.0, val, NAN), range, 1e-3, 0.0,
		     "the range bound beside a pixel of scale 8");
	image_release(&acc);
}

static void test_pixel_errors_threads(void **state)
{
	enum { W = 37, H = 300, N = W * H };
	struct image acc;
	static float press[N], fit[3 * N];
	static double e1[N], e4[N], n1[N], n4[N];
	char err[256];

	(void)state;
	make_acc(&acc, W, H, mixed_value);
	for (int i = 0; i < N; i++) {
		int x = i % W, y = i / W;
		float n = (float)(1 + (x * 3 + y * 5) % 20);
		set_px(&acc, x, y, n, n > 1 ? 1e-4f * (float)(1 + (x * y) % 9) : 0.0f,
		       n >= 4 ? 2e-5f * (float)(1 + (x + 2 * y) % 5) : NAN);
		press[i] = 1e-4f * (float)(1 + (x + y) % 7);
		for (int c = 0; c < 3; c++)
			fit[3 * i + c] = (float)mixed_value(x, y, c) + 0.01f;
	}
	press[5 * W + 5] = NAN;
	double est1, est4;
	assert_int_equal(plan_pixel_errors(&acc, press, fit, e1, n1, &est1, err, sizeof err), 0);
	assert_int_equal(plan_pixel_errors_threads(&acc, press, fit, e4, n4, &est4, 4, err,
						   sizeof err), 0);
	assert_memory_equal(e1, e4, sizeof e1);
	assert_memory_equal(n1, n4, sizeof n1);
	assert_true(est1 == est4 && est1 > 0.0);
	image_release(&acc);
}

/* 6b. A pixel's error estimate: fold differences averaged over neighbours
 * of like sample variance, relative to an estimate of the true value. */
static void test_pixel_errors(void **state)
{
	enum { N = 7 };
	struct image acc;
	float press[N * N], fit[3 * N * N];
	double e[N * N];

	(void)state;
	make_acc(&acc, N, N, flat_value);
	for (int i = 0; i < N * N; i++) {
		press[i] = 1e-6f;
		fit[3 * i] = fit[3 * i + 1] = fit[3 * i + 2] = 0.5f;
	}
	/* flat rows of small variance and difference; row 3 an edge across
	 * the image: large variance, large difference */
	for (int y = 0; y < N; y++)
		for (int x = 0; x < N; x++)
			set_px(&acc, x, y, 5.0f, y == 3 ? 0.05f : 1e-6f, y == 3 ? 0.1f : 1e-6f);
	/* one flat pixel whose difference came out larger */
	set_px(&acc, 6, 6, 5.0f, 1e-6f, 2.5e-5f);
	double est;
	char err[256];
	assert_int_equal(plan_pixel_errors(&acc, press, fit, e, NULL, &est, err, sizeof(err)), 0);

	const double flat_bias = want_bias(accpx(&acc, 0)), edge_bias = want_bias(accpx(&acc, 21));
	double got;
	/* two rows from the edge: the edge's five differences (a plain mean
	 * would make 0.02 of them) are a variance ratio of 5e4 away */
	assert_close(e[1 * N + 3], 1e-6 * flat_bias, 1e-3, 0.0, "flat pixel beside the edge");
	/* the edge pixel keeps its own row's difference */
	assert_close(e[3 * N + 3], 0.1 * edge_bias, 1e-3, 0.0, "edge pixel");
	/* alike variances: the plain mean of the 3 x 3 window in the corner */
	assert_close(e[6 * N + 6], (8 * 1e-6 + 2.5e-5) / 9.0 * flat_bias, 1e-3, 0.0,
		     "corner pixel");
	/* (5, 5)'s window, rows 3 to 6 and columns 3 to 6: the 12 flat pixels
	 * count, the 4 of the edge row do not */
	assert_close(e[5 * N + 5], (11 * 1e-6 + 2.5e-5) / 12.0 * flat_bias, 1e-3, 0.0,
		     "window across the edge row");
	assert_true(flat_bias > 1.0 && flat_bias < 1.0001);
	image_release(&acc);

	/* one sample a pixel (PRESS): a dark pixel beside a lamp is charged at
	 * most what its value could be off by within its neighbours' range */
	make_acc(&acc, 3, 1, flat_value);
	for (int x = 0; x < 3; x++) {
		for (int c = 0; c < 3; c++)
			accpx(&acc, (size_t)x)[c] = x == 2 ? 26.0f : 0.01f;
		/* scale 8 in the mask: no hidden-edge part, PRESS alone */
		accpx(&acc, (size_t)x)[ACC_SCALES] = 2 + 256;
	}
	float dfit[3] = { 0.01f, 0.01f, 0.01f };
	/* the smoothed PRESS of the lamp's residual, relative to 0.01^2 + 0.01 */
	got = accum_pixel_error(&acc, 1, 3.3, dfit, accum_pixel_noise(&acc, 1, NAN));
	double dh = 26.0 - 0.01, bound = dh * dh / (26.0 * 26.0 + 0.01);
	assert_close(got, bound, 1e-5, 0.0, "dark pixel beside a lamp");
	assert_true(got < 1.0);
	/* the lamp itself: its range reaches down to 0.01, so PRESS stands */
	float lfit[3] = { 20.0f, 20.0f, 20.0f };
	got = accum_pixel_error(&acc, 2, 3.3, lfit, accum_pixel_noise(&acc, 2, NAN));
	assert_close(got, 3.3 / (20.0 * 20.0 + 0.01), 1e-5, 0.0, "the lamp");
	/* a flat neighbourhood: nothing to be off by */
	for (int x = 0; x < 3; x++)
		for (int c = 0; c < 3; c++)
			accpx(&acc, (size_t)x)[c] = 0.5f;
	assert_true(accum_pixel_error(&acc, 1, 0.01, fit, accum_pixel_noise(&acc, 1, NAN)) == 0.0);
	image_release(&acc);

	/* an edge between a dark pixel and a bright one, seen by neither's
	 * samples (no spread, no difference): the dark pixel's term is the
	 * mean over the edge's place in its strip 1/(2s) wide (s = 4 here),
	 * weighed by the odds that the edge lies on its side of the gap:
	 * s_j / (s + s_j), a half for a neighbour of the same scale, two
	 * thirds beside scale 8, a fifth beside the base pass alone */
	make_acc(&acc, 2, 1, flat_value);
	for (int x = 0; x < 2; x++) {
		set_px(&acc, x, 0, 5.0f, 0.0f, 0.0f);
		for (int c = 0; c < 3; c++)
			accpx(&acc, (size_t)x)[c] = x ? 1.0f : 0.01f;
	}
	const double strip = edge_strip(0.01, 0.99, 4);
	const float sj[3] = { 2 + 16, 2 + 256, 2 }, share[3] = { 0.5f, 2.0f / 3.0f, 0.2f };
	accpx(&acc, 0)[ACC_SCALES] = 2 + 16;
	for (int k = 0; k < 3; k++) {
		accpx(&acc, 1)[ACC_SCALES] = sj[k];
		got = accum_pixel_error(&acc, 0, 1e-6, fit, accum_pixel_noise(&acc, 0, 0.0));
		assert_close(got, share[k] * strip, 1e-5, 0.0, "hidden edge, its share");
	}
	/* the pair's shares make one edge, not two */
	accpx(&acc, 1)[ACC_SCALES] = 2 + 16;
	double bright = accum_pixel_error(&acc, 1, 1e-6, fit, accum_pixel_noise(&acc, 1, 0.0));
	assert_close(bright, 0.5 * edge_strip(1.0, -0.99, 4), 1e-5, 0.0,
		     "hidden edge, the bright side's half");
	image_release(&acc);

	/* a firefly: 5 samples of which one bright lifts the mean to 0.83;
	 * the error relative to it hid how far off the pixel is */
	make_acc(&acc, 1, 1, flat_value);
	float *o = accpx(&acc, 0);
	for (int c = 0; c < 3; c++)
		o[c] = 0.83f;
	set_px(&acc, 0, 0, 5.0f, 2.18f, 0.05f);
	got = accum_pixel_error(&acc, 0, 1e-6, fit, accum_pixel_noise(&acc, 0, 0.05));
	assert_close(got, 0.05 * want_bias(o), 1e-6, 0.0, "firefly");
	assert_true(got > 2.5 * 0.05 && got < 2.8 * 0.05);
	/* its true value estimated below a quarter of m^2: the floor */
	set_px(&acc, 0, 0, 5.0f, 5.0f, 0.05f);
	got = accum_pixel_error(&acc, 0, 1e-6, fit, accum_pixel_noise(&acc, 0, 0.05));
	assert_close(got, 0.05 * (3 * (0.83 * 0.83 + 0.01)) / (3 * (0.25 * 0.83 * 0.83 + 0.01)),
		     1e-5, 0.0, "firefly at the floor");
	/* the variance of the mean, where there is no fold difference */
	got = accum_pixel_error(&acc, 0, 1e-6, fit, accum_pixel_noise(&acc, 0, NAN));
	assert_close(got, 5.0 / 5.0 / (0.83 * 0.83 + 0.01) * want_bias(o), 1e-5, 0.0,
		     "variance of the mean");
	image_release(&acc);
}

/* 6c. The final image's blend of a pixel's samples and the fit: the share
 * of the fit the centre pixel takes. */
static double choose_centre(struct image *acc, const float *fit, float press, float lev,
			    double noise_abs, enum accum_final mode, double *e_centre)
{
	enum { N = 5, C = 12 };
	float pr[N * N], lv[N * N], take[N * N];
	double noise[N * N], e[N * N];
	const double sc = 0.5 * 0.5 + 0.01;

	for (int i = 0; i < N * N; i++) {
		pr[i] = press;
		lv[i] = lev;
		noise[i] = noise_abs / sc;
		e[i] = noise[i];
	}
	if (e_centre)
		e[C] = *e_centre;
	long took = accum_final_choose(acc, fit, pr, lv, noise, mode, take, e);
	long want = 0;
	for (int i = 0; i < N * N; i++) {
		assert_true(take[i] >= 0.0f && take[i] <= 1.0f);
		want += take[i] > 0.0f;
	}
	assert_int_equal(took, want);
	if (e_centre)
		*e_centre = e[C];
	return take[C];
}

static void set_fit(float *fit, int i, float v)
{
	for (int c = 0; c < 3; c++)
		fit[3 * i + c] = v;
}

static void test_final_choice(void **state)
{
	enum { N = 5, C = 12 };
	struct image acc;
	float fit[3 * N * N], rgb[3 * N * N];
	const double sc = 0.5 * 0.5 + 0.01;

	(void)state;
	make_acc(&acc, N, N, flat_value);
	/* 21 samples of variance 0.21: their mean's is u = 0.01; a fold
	 * difference each */
	for (int y = 0; y < N; y++)
		for (int x = 0; x < N; x++)
			set_px(&acc, x, y, 21.0f, 0.21f, 0.01f);
	for (int i = 0; i < 3 * N * N; i++)
		fit[i] = 0.6f;	/* one standard deviation off */

	/* noise: PRESS no more than the noise (the fit without the pixel is
	 * exact, b = 0): the whole fit, predicted to miss by 0.1^2 of the
	 * samples' 0.01, and charged the floor, a quarter of it */
	double e = 0.01 / sc;
	assert_true(choose_centre(&acc, fit, 0.01f, 0.1f, 0.01, ACC_FINAL_AUTO, &e) == 1.0);
	assert_close(e, ACC_FIT_FLOOR * 0.01 / sc, 1e-5, 0.0, "the fit's error, floored");
	/* b = 0.0037: Y + k (g - Y) with k = u / (u + b) is the fit's
	 * k / (1 - H), and errs by u b / (u + b), above the floor */
	e = 0.01 / sc;
	double k = 0.01 / 0.0137;
	assert_close(choose_centre(&acc, fit, 0.0137f, 0.1f, 0.01, ACC_FINAL_AUTO, &e),
		     k / 0.9, 1e-5, 0.0, "the fit's share");
	assert_close(e, 0.01 * 0.0037 / 0.0137 / sc, 1e-4, 0.0, "the blend's error");
	/* b = 0.04, four times the samples' error: a fifth of the way */
	e = 0.01 / sc;
	assert_close(choose_centre(&acc, fit, 0.05f, 0.1f, 0.01, ACC_FINAL_AUTO, &e),
		     0.2 / 0.9, 1e-5, 0.0, "the fit's share, its bias large");
	assert_close(e, 0.01 * 0.04 / 0.05 / sc, 1e-4, 0.0, "the blend's error, bias large");
	assert_true(choose_centre(&acc, fit, 0.01f, 0.1f, 0.01, ACC_FINAL_SAMPLES, NULL) == 0.0);
	assert_true(choose_centre(&acc, fit, 0.01f, 0.1f, 0.01, ACC_FINAL_RECONSTRUCTION, NULL) ==
		    1.0);
	/* an edge between the samples was the larger part of the estimate:
	 * the fit is taken, the estimate stays */
	e = 0.5;
	assert_true(choose_centre(&acc, fit, 0.01f, 0.1f, 0.01, ACC_FINAL_AUTO, &e) == 1.0);
	assert_true(e == 0.5);
	/* the fit 2.5 standard deviations off: (g - Y)^2 = 6.25 u / 0.81,
	 * within 9 (u + b); 3.5 off, 15.1 u, not */
	set_fit(fit, C, 0.75f);
	assert_true(choose_centre(&acc, fit, 0.01f, 0.1f, 0.01, ACC_FINAL_AUTO, NULL) == 1.0);
	set_fit(fit, C, 0.85f);
	assert_true(choose_centre(&acc, fit, 0.01f, 0.1f, 0.01, ACC_FINAL_AUTO, NULL) == 0.0);
	/* with b = 0.04 3.5 off agrees: (0.35^2 / 0.81) < 9 x 0.05 */
	assert_true(choose_centre(&acc, fit, 0.05f, 0.1f, 0.01, ACC_FINAL_AUTO, NULL) > 0.0);
	set_fit(fit, C, 0.6f);
	/* a leverage of 1: the fit would be the pixel's own value and g
	 * undefined; nothing is blended (the old rule took none here either,
	 * its prediction being u) */
	assert_true(choose_centre(&acc, fit, 0.01f, 1.0f, 0.01, ACC_FINAL_AUTO, NULL) == 0.0);
	/* stratified samples of a detail: the fold difference says the mean
	 * is off by 0.01, a tenth of what its sample variance says, so the fit
	 * is 10 of its errors away (the sample variance alone would have
	 * taken it) */
	assert_true(choose_centre(&acc, fit, 1e-4f, 0.1f, 1e-4, ACC_FINAL_AUTO, NULL) == 0.0);
	/* no fold difference: noise not measured */
	accpx(&acc, C)[ACC_DIFF] = NAN;
	assert_true(choose_centre(&acc, fit, 0.01f, 0.1f, 0.01, ACC_FINAL_AUTO, NULL) == 0.0);
	accpx(&acc, C)[ACC_DIFF] = 0.01f;
	/* noisier than its neighbours by 16 (a highlight among dark pixels):
	 * not theirs; by 2, alike */
	set_px(&acc, 2, 2, 21.0f, 16 * 0.21f, 0.01f);
	assert_true(choose_centre(&acc, fit, 0.16f, 0.1f, 0.16, ACC_FINAL_AUTO, NULL) == 0.0);
	set_px(&acc, 2, 2, 21.0f, 2 * 0.21f, 0.01f);
	assert_true(choose_centre(&acc, fit, 0.02f, 0.1f, 0.02, ACC_FINAL_AUTO, NULL) == 1.0);
	/* smoother than them by 16 (the fit 0.8 of its standard deviations
	 * off): the fit is theirs, not its; by 2, alike */
	set_fit(fit, C, 0.52f);
	set_px(&acc, 2, 2, 21.0f, 0.21f / 16, 0.01f);
	assert_true(choose_centre(&acc, fit, 0.01f / 16, 0.1f, 0.01 / 16, ACC_FINAL_AUTO, NULL) ==
		    0.0);
	set_px(&acc, 2, 2, 21.0f, 0.21f / 2, 0.01f);
	assert_true(choose_centre(&acc, fit, 0.01f / 2, 0.1f, 0.01 / 2, ACC_FINAL_AUTO, NULL) ==
		    1.0);
	/* fewer than 4 samples keep them; none take the fit */
	set_px(&acc, 2, 2, 2.0f, 0.21f, NAN);
	assert_true(choose_centre(&acc, fit, 0.01f, 0.1f, 0.01, ACC_FINAL_AUTO, NULL) == 0.0);
	set_px(&acc, 2, 2, 0.0f, 0.0f, NAN);
	assert_true(choose_centre(&acc, fit, 0.01f, 0.1f, 0.01, ACC_FINAL_AUTO, NULL) == 1.0);

	/* the image: the fit where taken, a quarter of it where a quarter is
	 * taken, else the samples' mean */
	float take[N * N] = {0};
	take[3] = 1.0f;
	take[4] = 0.25f;
	accum_final_image(&acc, fit, take, rgb);
	for (int i = 0; i < N * N; i++)
		for (int c = 0; c < 3; c++) {
			double m = accpx(&acc, (size_t)i)[c];
			double want = i == 3 ? 0.6 : i == 4 ? 0.25 * 0.6 + 0.75 * m : m;
			assert_close(rgb[3 * i + c], want, 1e-6, 0.0, "the final image");
		}
	image_release(&acc);
}

/* 6b. plan_sparse_error(): the largest 0.1% (at least one) of the pixels'
 * errors holding half of their sum. */
static void test_sparse_error(void **state)
{
	enum { N = 3000 };	/* 0.1% is 3 pixels */
	double e[N];

	(void)state;
	for (int i = 0; i < N; i++)
		e[i] = 1e-4;
	assert_false(plan_sparse_error(e, N));	/* spread */
	/* three pixels holding 0.3 / (0.3 + 0.2997): just over half */
	e[10] = e[500] = e[2999] = 0.1;
	assert_true(plan_sparse_error(e, N));
	/* four such pixels: the largest three hold 0.3 of 0.4 + 0.2996 */
	e[7] = 0.1;
	assert_false(plan_sparse_error(e, N));
	/* three, and the rest holding more than they: 0.3 of 0.3 + 0.5994 */
	e[7] = 1e-4;
	for (int i = 0; i < N; i++)
		if (e[i] < 0.05)
			e[i] = 2e-4;
	assert_false(plan_sparse_error(e, N));
	/* what is not finite or not positive is left out */
	for (int i = 0; i < N; i++)
		e[i] = i % 3 == 0 ? NAN : i % 3 == 1 ? -1.0 : 0.0;
	assert_false(plan_sparse_error(e, N));	/* nothing left */
	e[1] = INFINITY;
	e[2] = 1e-3;
	assert_true(plan_sparse_error(e, N));	/* one finite pixel holds it all */
	/* a small image: at least one pixel */
	double f[5] = { 1.0, 0.2, 0.2, 0.2, 0.2 };
	assert_true(plan_sparse_error(f, 5));
	f[0] = 0.7;
	assert_false(plan_sparse_error(f, 5));
}

/* 6c. plan_edge_error(): the largest 5% (at least one) of the pixels'
 * errors holding two thirds (PLAN_EDGE_FRAC) of their sum. */
static void test_edge_error(void **state)
{
	enum { N = 2000 };	/* 5% is 100 pixels */
	double e[N];

	(void)state;
	for (int i = 0; i < N; i++)
		e[i] = 1e-4;
	assert_false(plan_edge_error(e, N));	/* spread */
	/* 100 edge pixels at 4e-3: 0.4 of 0.4 + 0.19, 68% */
	for (int i = 0; i < 100; i++)
		e[i * 20] = 4e-3;
	assert_true(plan_edge_error(e, N));
	assert_false(plan_sparse_error(e, N));	/* not a few pixels: 2 of them hold 1.4% */
	/* the rest a little noisier: 0.4 of 0.4 + 0.2090, 66% */
	for (int i = 0; i < N; i++)
		if (e[i] < 1e-3)
			e[i] = 1.1e-4;
	assert_false(plan_edge_error(e, N));
	/* twice the edge pixels at half the error each: the largest 5% hold
	 * half of the edges' error, 0.2 of 0.4 + 0.18 */
	for (int i = 0; i < N; i++)
		e[i] = i % 10 == 0 ? 2e-3 : 1e-4;
	assert_false(plan_edge_error(e, N));
	/* what is not finite or not positive is left out; one pixel holds it all */
	for (int i = 0; i < N; i++)
		e[i] = i % 2 ? NAN : 0.0;
	assert_false(plan_edge_error(e, N));
	e[4] = 1e-3;
	assert_true(plan_edge_error(e, N));
	/* a small image: at least one pixel */
	double f[5] = { 1.0, 0.1, 0.1, 0.1, 0.1 };
	assert_true(plan_edge_error(f, 5));
	f[0] = 0.7;
	assert_false(plan_edge_error(f, 5));
}

/* 6d. plan_top_sum(): the sum of the largest share of the errors (at least
 * one), what is not finite or not positive left out. */
static void test_top_sum(void **state)
{
	enum { N = 200 };	/* 5% is 10 pixels */
	double e[N];

	(void)state;
	for (int i = 0; i < N; i++)
		e[i] = (double)(i + 1);	/* the largest ten: 191 to 200 */
	assert_close(plan_top_sum(e, N, 0.05, NULL), 1955.0, 1e-12, 0.0, "the top 5%");
	assert_close(plan_top_sum(e, N, 0.001, NULL), 200.0, 1e-12, 0.0, "at least one pixel");
	assert_close(plan_top_sum(e, N, 1.0, NULL), 20100.0, 1e-12, 0.0, "all of them");
	double all = 0.0;
	plan_top_sum(e, N, 0.05, &all);
	assert_close(all, 20100.0, 1e-12, 0.0, "the sum of all of them");
	for (int i = 0; i < N; i++)
		e[i] = i % 4 == 0 ? NAN : i % 4 == 1 ? -5.0 : i % 4 == 2 ? INFINITY : 0.0;
	assert_close(plan_top_sum(e, N, 0.05, NULL), 0.0, 0.0, 0.0, "nothing left");
	e[3] = 2.0;
	e[7] = 3.0;
	assert_close(plan_top_sum(e, N, 0.05, NULL), 5.0, 1e-12, 0.0, "the two that count");
}

/* The radiosity pass's trace model against measured traces: Debian's
 * radiosity/radiosity2.pov at 160x120 on two threads took 0.078 CPU s for
 * its trace and shot 109,130 radiosity rays after the pretrace; at 1280x960
 * on one thread 1.631 s.  scenes/radiosity_room.pov: 0.033 s and none;
 * 1.848 s. */
static void test_radiosity_trace(void **state)
{
	(void)state;
	const double px = 160.0 * 120.0;
	/* without radiosity rays: the cost a pixel times the frame's pixels */
	assert_float_equal(plan_radiosity_trace(2e-6, px, 0.0, 1), 2e-6 * px, 1e-15);
	assert_float_equal(plan_radiosity_trace(2e-6, px, 0.0, 8), 64 * 2e-6 * px, 1e-12);
	/* at the measured render's own size: its trace, whatever its rays */
	assert_float_equal(plan_radiosity_trace(0.078 / px, px, 109130 / px, 1), 0.078, 1e-12);
	/* the larger frame: within 10% of the measured trace, where the cost
	 * a pixel alone gave 3.1 times it; the rays' part grows, though */
	const double t8 = plan_radiosity_trace(0.078 / px, px, 109130 / px, 8);
	assert_true(t8 > 0.9 * 1.631 && t8 < 1.1 * 1.631);
	assert_true(64 * 0.078 > 3.0 * 1.631);
	assert_true(t8 > 0.078 * 64 / (1.0 + PLAN_RAD_RAY_COST * 109130 / px));
	const double r8 = plan_radiosity_trace(0.033 / px, px, 0.0, 8);
	assert_true(r8 > 1.848 && r8 < 1.2 * 1.848);
	/* more scale, more time */
	for (int k = 1; k < 8; k++)
		assert_true(plan_radiosity_trace(0.078 / px, px, 109130 / px, k + 1) >
			    plan_radiosity_trace(0.078 / px, px, 109130 / px, k));
}

/* 7. The regions file round-trips; a bad line is reported with its number. */
static void test_regions_file(void **state)
{
	struct plan_region rs[7] = {
		{ 0, 0, 7, 7, 2, 10, 1.0, 0.1, 0, 0, 0 },
		{ 12, 30, 40, 47, 4, 3, 0.5, 0.2, 0, 0, 0 },
		{ 63, 47, 63, 47, ACC_AA, 1, 0.1, 0.3, ACC_GRID_FRAME, 3, ACC_AA_FOR_EDGES },
		{ 8, 0, 15, 7, ACC_AA, 1, 0.1, 0.3, ACC_GRID_FRAME, 3, ACC_AA_FOR_SPREAD },
		{ 16, 0, 23, 7, ACC_AA, 1, 0.1, 0.3, ACC_GRID_FRAME, 3, ACC_AA_FOR_SPREAD_R3 },
		{ 24, 0, 31, 7, ACC_AA, 1, 0.1, 0.3, ACC_GRID_FRAME, 2, ACC_AA_FOR_SPREAD_FLOOR },
		{ 32, 0, 39, 7, ACC_AA, 1, 0.1, 0.3, ACC_GRID_FRAME, 3, ACC_AA_FOR_SPREAD_R6 },
	};
	static char o0[] = "r0.exr", o1[] = "a dir/with spaces/region 1.exr",
		o2[] = "/tmp/x y\tz 4\t1.exr", o3[] = "p1-r3-aa.exr", o4[] = "p1-r4-aa.exr",
		o5[] = "p1-r5-aa.exr", o6[] = "p1-r6-aa.exr";
	char *outs[7] = { o0, o1, o2, o3, o4, o5, o6 };
	struct plan pl;
	struct plan_region *got;
	char **gout, path[256], err[512];
	int *passes;
	size_t n = 99;
	FILE *f;

	(void)state;
	memset(&pl, 0, sizeof(pl));
	pl.regions = rs;
	pl.nregions = 7;
	scratch(path, sizeof(path), "regions file.txt");
	f = fopen(path, "w");
	assert_non_null(f);
	assert_int_equal(plan_regions_write(f, &pl, 7, outs), 0);
	assert_int_equal(fclose(f), 0);
	assert_int_equal(plan_regions_read(path, &got, &gout, &passes, &n, err, sizeof(err)), 0);
	assert_int_equal(n, 7);
	for (size_t k = 0; k < 7; k++) {
		assert_int_equal(passes[k], 7);
		assert_int_equal(got[k].x0, rs[k].x0);
		assert_int_equal(got[k].y0, rs[k].y0);
		assert_int_equal(got[k].x1, rs[k].x1);
		assert_int_equal(got[k].y1, rs[k].y1);
		assert_int_equal(got[k].scale, rs[k].scale);
		assert_int_equal(got[k].depth, rs[k].depth);
		assert_int_equal(got[k].edges, rs[k].edges);
		assert_string_equal(gout[k], outs[k]);
		free(gout[k]);
	}
	free(got);
	free(gout);
	free(passes);

	/* a file from before depth and edges: its lines end at the output,
	 * tabs and digits and all, and its regions have depth 0, edges 0 */
	f = fopen(path, "w");
	assert_non_null(f);
	fputs("# povpress regions: pass x0 y0 x1 y1 scale output (pixels 0-based, inclusive)\r\n"
	      "2\t1\t2\t3\t4\t0\tr 1\t4\t1\r\n", f);
	assert_int_equal(fclose(f), 0);
	assert_int_equal(plan_regions_read(path, &got, &gout, &passes, &n, err, sizeof(err)), 0);
	assert_int_equal(n, 1);
	assert_int_equal(got[0].scale, ACC_AA);
	assert_int_equal(got[0].depth, 0);
	assert_int_equal(got[0].edges, 0);
	assert_string_equal(gout[0], "r 1\t4\t1");
	free(gout[0]);
	free(got);
	free(gout);
	free(passes);

	/* line 3 has a letter for y0; then a line without an output; then,
	 * under the header naming depth and edges, lines without them, with
	 * a depth out of range, with edges on a scaled region, with edges 7 */
#define HDR "# povpress regions: pass x0 y0 x1 y1 scale output depth edges\n"
	static const char *const bad[] = {
		"# header\n1\t0\t0\t3\t3\t2\ta.exr\t0\t0\n1\t0\tx\t3\t3\t2\tb.exr\t0\t0\n",
		"# header\n\n1\t0\t0\t3\t3\t2\t\t0\t0\n",
		HDR "1\t0\t0\t3\t3\t0\ta.exr\t4\t1\n1\t0\t0\t3\t3\t2\tb.exr\n",
		HDR "1\t0\t0\t3\t3\t2\ta.exr\t0\t0\n1\t0\t0\t3\t3\t0\tb.exr\t6\t0\n",
		HDR "\n1\t0\t0\t3\t3\t2\ta.exr\t3\t1\n",
		HDR "1\t0\t0\t3\t3\t0\ta.exr\t4\t0\n1\t0\t0\t3\t3\t0\tb.exr\t4\t7\n",
		/* a sign; no header at all, old-format lines */
		HDR "1\t0\t0\t3\t3\t0\ta.exr\t4\t0\n1\t0\t0\t3\t3\t0\tb.exr\t+4\t0\n",
		"# x\n1\t0\t0\t3\t3\t2\ta.exr\t0\t0\n1\t0\t0\t3\t3\t2\tb.exr\n",
	};
#undef HDR
	for (int b = 0; b < 8; b++) {
		f = fopen(path, "w");
		assert_non_null(f);
		fputs(bad[b], f);
		assert_int_equal(fclose(f), 0);
		err[0] = '\0';
		assert_int_equal(plan_regions_read(path, &got, &gout, &passes, &n, err,
						   sizeof(err)), -1);
		if (!strstr(err, path) || !strstr(err, "line 3"))
			fail_msg("message \"%s\" does not name '%s' line 3", err, path);
		assert_null(got);
		assert_null(gout);
		assert_null(passes);
	}
}

/* 8. The POV-Ray job for a region. */
/* A region job's frame (w x h) and the rectangle in it it renders. */
static void assert_job_frame(const struct pov_job *job, const struct pov_region *region, int w,
			     int h, int x0, int y0, int x1, int y1)
{
	assert_int_equal(job->width, w);
	assert_int_equal(job->height, h);
	assert_ptr_equal(job->region, region);
	assert_int_equal(region->x0, x0);
	assert_int_equal(region->y0, y0);
	assert_int_equal(region->x1, x1);
	assert_int_equal(region->y1, y1);
}

/* The antialiasing options a region job appends after the user's two:
 * method, threshold, depth, jitter. */
static void assert_aa_options(const struct pov_job *job, const char *method,
			      const char *threshold, const char *depth, const char *jitter)
{
	assert_int_equal(job->nextra, 6);
	assert_string_equal(job->extra[2], method);
	assert_string_equal(job->extra[3], threshold);
	assert_string_equal(job->extra[4], depth);
	assert_string_equal(job->extra[5], jitter);
}

static void test_plan_job(void **state)
{
	static const char *const base_extra[] = { "+Q9", "Antialias_Threshold=0.1" };
	struct pov_job base, job;
	struct plan_region r = { 3, 2, 10, 7, 4, 0, 0.0, 0.0, 0, 0, 0 };
	struct pov_region region;
	const char *extra[3];

	(void)state;
	memset(&base, 0, sizeof(base));
	base.scene = "scenes/x.pov";
	base.output = "base.exr";
	base.width = 64;
	base.height = 48;
	base.threads = 3;
	base.extra = base_extra;
	base.nextra = 2;
	plan_job(&base, &r, "out/r.exr", &region, extra, &job);
	assert_job_frame(&job, &region, 256, 192, 12, 8, 43, 31);
	assert_string_equal(job.output, "out/r.exr");
	assert_string_equal(job.scene, "scenes/x.pov");
	assert_int_equal(job.threads, 3);
	assert_int_equal(job.nextra, 3);
	assert_string_equal(job.extra[0], "+Q9");
	assert_string_equal(job.extra[1], "Antialias_Threshold=0.1");
	assert_string_equal(job.extra[2], "-A");
	assert_string_equal(base.output, "base.exr");
	assert_int_equal(base.nextra, 2);

	/* an antialiased region: scale 1, POV-Ray's antialiasing, jittered */
	const char *aextra[6];
	r.scale = ACC_AA;
	plan_job(&base, &r, "out/a.exr", &region, aextra, &job);
	assert_int_equal(job.width, 64);
	assert_int_equal(job.height, 48);
	assert_int_equal(region.x0, 3);
	assert_int_equal(region.y1, 7);
	assert_string_equal(job.extra[1], "Antialias_Threshold=0.1");
	assert_aa_options(&job, "+AM2", "+A0.0", "+R4", "+J");
	/* in scale 2's place: twice the size, threshold 0.1; depth 0 (a
	 * regions file without the column) at +R4, as merge folds it */
	r.frame = ACC_GRID_FRAME;
	plan_job(&base, &r, "out/a1.exr", &region, aextra, &job);
	assert_job_frame(&job, &region, 128, 96, 6, 4, 21, 15);
	assert_aa_options(&job, "+AM2", "+A0.1", "+R4", "+J");
	assert_int_equal(ACC_AA_DEPTH_V1, 4);
	/* at the depth it was given (render.c, aa_depth()) */
	for (int d = 1; d <= ACC_AA_DEPTH; d++) {
		char want[16];
		snprintf(want, sizeof(want), "+R%d", d);
		r.depth = d;
		plan_job(&base, &r, "out/a2.exr", &region, aextra, &job);
		assert_job_frame(&job, &region, 128, 96, 6, 4, 21, 15);
		assert_aa_options(&job, "+AM2", "+A0.1", want, "+J");
		/* taken for spread error: +AM1 at the threshold, its grid's
		 * side giving a pixel as many samples as +AM2's cells */
		r.edges = ACC_AA_FOR_SPREAD;
		snprintf(want, sizeof(want), "+R%d", 1 << (d - 1));
		plan_job(&base, &r, "out/a3.exr", &region, aextra, &job);
		assert_job_frame(&job, &region, 128, 96, 6, 4, 21, 15);
		assert_aa_options(&job, "+AM1", "+A0.03", want, "+J");
		assert_int_equal(4 * (1 << (d - 1)) * (1 << (d - 1)), accum_edge_cells(d));
		assert_true(fabs(strtod("0.03", NULL) - ACC_AA_SPREAD_THRESHOLD) < 1e-12);
		/* the lighter renders for spread error at any depth: +A0.1
		 * +R3, 2 x 2 render pixels of 3 x 3 samples, and +A0.3 +R2,
		 * of 2 x 2 */
		static const struct {
			int edges, cells, want_cells;
			const char *a, *rr;
			double t;
		} lv[4] = {
			{ ACC_AA_FOR_SPREAD_R3, ACC_AA_SPREAD_R3_CELLS, 4 * 3 * 3, "+A0.1", "+R3",
			  ACC_AA_SPREAD_R3_THRESHOLD },
			{ ACC_AA_FOR_SPREAD_FLOOR, ACC_AA_SPREAD_FLOOR_CELLS, 4 * 2 * 2, "+A0.3", "+R2",
			  ACC_AA_SPREAD_FLOOR_THRESHOLD },
			{ ACC_AA_FOR_SPREAD_R5, 4 * ACC_AA_SPREAD_R5_SIDE * ACC_AA_SPREAD_R5_SIDE,
			  4 * 5 * 5, "+A0.03", "+R5", ACC_AA_SPREAD_THRESHOLD },
			{ ACC_AA_FOR_SPREAD_R6, 4 * ACC_AA_SPREAD_R6_SIDE * ACC_AA_SPREAD_R6_SIDE,
			  4 * 6 * 6, "+A0.03", "+R6", ACC_AA_SPREAD_THRESHOLD },
		};
		for (int li = 0; li < 4; li++) {
			r.edges = lv[li].edges;
			plan_job(&base, &r, "out/a4.exr", &region, aextra, &job);
			assert_job_frame(&job, &region, 128, 96, 6, 4, 21, 15);
			assert_aa_options(&job, "+AM1", lv[li].a, lv[li].rr, "+J");
			assert_true(fabs(strtod(lv[li].a + 2, NULL) - lv[li].t) < 1e-12);
			assert_int_equal(lv[li].cells, lv[li].want_cells);
		}
		r.edges = ACC_AA_FOR_FEW;
	}
	r.depth = 0;
	r.frame = 0;
	char name[64];
	plan_output_name(name, sizeof(name), "w", 3, 7, ACC_AA);
	assert_string_equal(name, "w/p03-r007-aa.exr");
	plan_output_name(name, sizeof(name), "w", 3, 7, 8);
	assert_string_equal(name, "w/p03-r007-s8.exr");

	/* a grid region: twice the size whatever the scale, every pixel
	 * supersampled on a (scale/2)^2 grid jittered inside its cells */
	for (int s = 4; s <= 16; s *= 2) {
		r.scale = s;
		r.frame = ACC_GRID_FRAME;
		plan_job(&base, &r, "out/g.exr", &region, aextra, &job);
		assert_job_frame(&job, &region, 128, 96, 6, 4, 21, 15);
		assert_aa_options(&job, "+AM1", "+A0.0", s == 4 ? "+R2" : s == 8 ? "+R4" : "+R8", "+J0.75");
		assert_int_equal(accum_grid_samples(s), s * s + 4);
	}
	/* which scales are grid renders */
	struct plan_params pp;
	plan_params_init(&pp);
	assert_int_equal(pp.grid, PLAN_GRID_NEVER);
	assert_false(plan_grid_scale(&pp, 640, 480, 16));
	pp.grid = PLAN_GRID_ALWAYS;
	assert_true(plan_grid_scale(&pp, 8, 6, 4));
	assert_false(plan_grid_scale(&pp, 640, 480, 2));
	pp.grid = PLAN_GRID_LARGE;	/* the scaled frame above 1 Mpixel */
	assert_false(plan_grid_scale(&pp, 80, 60, 8));	/* 640x480 */
	assert_true(plan_grid_scale(&pp, 80, 60, 16));	/* 1280x960 */
	assert_false(plan_grid_scale(&pp, 160, 120, 4));
	assert_true(plan_grid_scale(&pp, 160, 120, 8));
	assert_false(plan_grid_scale(&pp, 512, 512, 2));
	assert_false(plan_grid_scale(&pp, 256, 256, 4));	/* exactly 1 Mpixel */
	assert_true(plan_grid_scale(&pp, 640, 480, 4));
	/* focal blur: scaling up to 8 Mpixel frames */
	pp.grid_frame = PLAN_FOCAL_FRAME;
	assert_false(plan_grid_scale(&pp, 160, 120, 8));	/* 1280x960 */
	assert_false(plan_grid_scale(&pp, 160, 120, 16));	/* 2560x1920 */
	assert_false(plan_grid_scale(&pp, 640, 480, 4));	/* 2560x1920 */
	assert_true(plan_grid_scale(&pp, 320, 240, 16));	/* 5120x3840 */
	assert_true(plan_grid_scale(&pp, 1280, 720, 4));	/* 5120x2880 */
	pp.grid = PLAN_GRID_ALWAYS;	/* the frame matters to auto alone */
	assert_true(plan_grid_scale(&pp, 160, 120, 8));
	pp.grid_frame = PLAN_GRID_FRAME;
	/* --sampler jitter: grid renders from scale 4, and no scale 2 */
	pp.grid = PLAN_GRID_ONLY;
	assert_true(plan_grid_scale(&pp, 8, 6, 4));
	assert_false(plan_grid_scale(&pp, 8, 6, 2));
	struct image acc;
	make_acc(&acc, 4, 1, flat_value);	/* scale 1 (the base) everywhere */
	accpx(&acc, 1)[ACC_SCALES] = 2 + 4;	/* 1 and 2 */
	accpx(&acc, 2)[ACC_SCALES] = 2 + 4 + 16;	/* 1, 2 and 4 */
	accpx(&acc, 3)[ACC_SCALES] = 2 + 16 + 256 + 65536;	/* all but 2 */
	static const int only[4] = { 4, 4, 8, 0 }, always[4] = { 2, 4, 8, 2 };
	for (int i = 0; i < 4; i++) {
		assert_int_equal(plan_next_scale(&pp, &acc, (size_t)i), only[i]);
		pp.grid = PLAN_GRID_ALWAYS;
		assert_int_equal(plan_next_scale(&pp, &acc, (size_t)i), always[i]);
		pp.grid = PLAN_GRID_ONLY;
	}
	image_release(&acc);
	/* a whole plan of base-pass pixels: grid renders of scale 4 only */
	make_acc(&acc, 32, 16, base_value);
	double e[32 * 16];
	for (int i = 0; i < 32 * 16; i++)
		e[i] = 0.05;
	pp.target = 1e-3;
	struct plan pl;
	char err[256];
	assert_int_equal(plan_make_from(&acc, e, &pp, &pl, err, sizeof(err)), 0);
	assert_int_equal(pl.outcome, PLAN_REFINE);
	assert_true(pl.nregions >= 1);
	for (size_t k = 0; k < pl.nregions; k++) {
		assert_int_equal(pl.regions[k].scale, 4);
		assert_int_equal(pl.regions[k].frame, ACC_GRID_FRAME);
	}
	plan_release(&pl);
	image_release(&acc);
	/* scale 2 stays a plain render at twice the size */
	r.scale = 2;
	plan_job(&base, &r, "out/t.exr", &region, aextra, &job);
	assert_int_equal(job.width, 128);
	assert_int_equal(job.nextra, 3);
	assert_string_equal(job.extra[2], "-A");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_fold),
		cmocka_unit_test(test_merge_region),
		cmocka_unit_test(test_merge_nonfinite),
		cmocka_unit_test(test_split_diff),
		cmocka_unit_test(test_merge_aa),
		cmocka_unit_test(test_merge_aa_edges),
		cmocka_unit_test(test_merge_grid),
		cmocka_unit_test(test_merge_partial),
		cmocka_unit_test(test_merge_stratified),
		cmocka_unit_test(test_accum_read),
		cmocka_unit_test(test_read_rows),
		cmocka_unit_test(test_plan_make),
		cmocka_unit_test(test_plan_split_budget),
		cmocka_unit_test(test_plan_budget),
		cmocka_unit_test(test_plan_pack_ahead),
		cmocka_unit_test(test_plan_cost_map),
		cmocka_unit_test(test_pixel_errors),
		cmocka_unit_test(test_pixel_errors_edges),
		cmocka_unit_test(test_pixel_errors_threads),
		cmocka_unit_test(test_final_choice),
		cmocka_unit_test(test_sparse_error),
		cmocka_unit_test(test_edge_error),
		cmocka_unit_test(test_top_sum),
		cmocka_unit_test(test_radiosity_trace),
		cmocka_unit_test(test_regions_file),
		cmocka_unit_test(test_plan_job),
	};

	return cmocka_run_group_tests(tests, setup_dir, teardown_dir);
}
