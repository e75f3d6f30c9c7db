/*
 * test_downsample.c - unit tests for driver/downsample.c (box averaging).
 *
 * Known answers: constant blocks, a linear ramp (whose block mean is its
 * value at the block centre and whose block variance is s^2 (a^2 + b^2) / 12
 * for slopes a and b), hand-computed blocks, a bright block with a small
 * spread, and the sizes that must be refused.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "driver/downsample.h"
#include "driver/image.h"
#include "tests/testutil.h"

static const char *const rgb_names[] = { "R", "G", "B" };

static float *at(struct image *img, int x, int y, int c)
{
	return img->px + ((size_t)y * (size_t)img->w + (size_t)x) * (size_t)img->nch +
		(size_t)c;
}

static void make_rgb(struct image *img, int w, int h)
{
	char err[256];

	assert_int_equal(image_init(img, w, h, 3, rgb_names, err, sizeof(err)), 0);
}

/* Blocks of different constant colours: means are the constants, variances 0. */
static void test_constant_blocks(void **state)
{
	struct image in, mean, var;
	char err[256];

	(void)state;
	make_rgb(&in, 8, 6);	/* 4 x 3 blocks of 2 x 2 */
	for (int y = 0; y < 6; y++)
		for (int x = 0; x < 8; x++)
			for (int c = 0; c < 3; c++)
				*at(&in, x, y, c) = (float)(0.1 * (x / 2) + 0.7 * (y / 2) +
							    10.0 * c);
	assert_int_equal(image_box_down(&in, 2, &mean, &var, err, sizeof(err)), 0);
	assert_int_equal(mean.w, 4);
	assert_int_equal(mean.h, 3);
	assert_int_equal(mean.nch, 3);
	assert_int_equal(var.w, 4);
	assert_int_equal(var.h, 3);
	assert_int_equal(var.nch, 3);
	for (int c = 0; c < 3; c++) {
		assert_string_equal(mean.names[c], rgb_names[c]);
		assert_string_equal(var.names[c], rgb_names[c]);
	}
	for (int y = 0; y < 3; y++)
		for (int x = 0; x < 4; x++)
			for (int c = 0; c < 3; c++) {
				/* the block's samples are one float: the mean is it exactly */
				assert_true(*at(&mean, x, y, c) == *at(&in, 2 * x, 2 * y, c));
				assert_true(*at(&var, x, y, c) == 0.0f);
			}
	image_release(&in);
	image_release(&mean);
	image_release(&var);
}

/*
 * A ramp v = r0 + a x + b y (x, y pixel indices) in each channel: the mean
 * of a block is the ramp at the block's centre, x = s bx + (s - 1) / 2, and
 * its sample variance is s^2 (a^2 + b^2) / 12.  Non-square image, several
 * factors.
 */
static void test_ramp(void **state)
{
	static const double r0[3] = { 0.25, 1.5, -2.0 };
	static const double a[3] = { 0.01, -0.03, 0.5 };
	static const double b[3] = { 0.02, 0.004, -0.25 };
	static const int factors[] = { 1, 2, 3, 4, 6, 12 };
	struct image in, mean, var;
	char err[256];

	(void)state;
	make_rgb(&in, 36, 24);
	for (int y = 0; y < in.h; y++)
		for (int x = 0; x < in.w; x++)
			for (int c = 0; c < 3; c++)
				*at(&in, x, y, c) = (float)(r0[c] + a[c] * x + b[c] * y);
	for (size_t k = 0; k < sizeof(factors) / sizeof(factors[0]); k++) {
		int s = factors[k];

		assert_int_equal(image_box_down(&in, s, &mean, &var, err, sizeof(err)), 0);
		assert_int_equal(mean.w, 36 / s);
		assert_int_equal(mean.h, 24 / s);
		for (int y = 0; y < mean.h; y++)
			for (int x = 0; x < mean.w; x++)
				for (int c = 0; c < 3; c++) {
					double cx = s * x + (s - 1) / 2.0, cy = s * y + (s - 1) / 2.0;
					double m = r0[c] + a[c] * cx + b[c] * cy;
					double v = s * s * (a[c] * a[c] + b[c] * b[c]) / 12.0;

					/* the inputs are floats, so within their rounding */
					assert_float_equal(*at(&mean, x, y, c), m, 2e-6);
					if (s == 1)
						assert_true(*at(&var, x, y, c) == 0.0f);
					else
						assert_float_equal(*at(&var, x, y, c), v,
								   1e-6 + 1e-5 * v);
				}
		image_release(&mean);
		image_release(&var);
	}
	image_release(&in);
}

/* Hand-computed blocks, and no loss of precision on a bright block. */
static void test_known_variance(void **state)
{
	struct image in, mean, var;
	char err[256];

	(void)state;
	make_rgb(&in, 4, 2);
	/* block 0: R = 1 2 / 3 4, G = 0 0 / 0 8, B = 1e4 + (0 1 / 1 0) */
	static const float r[2][2] = { { 1, 2 }, { 3, 4 } };
	static const float g[2][2] = { { 0, 0 }, { 0, 8 } };
	static const float bl[2][2] = { { 10000, 10001 }, { 10001, 10000 } };
	for (int y = 0; y < 2; y++)
		for (int x = 0; x < 2; x++) {
			*at(&in, x, y, 0) = r[y][x];
			*at(&in, x, y, 1) = g[y][x];
			*at(&in, x, y, 2) = bl[y][x];
			/* block 1: every channel the same float, 0.1f */
			for (int c = 0; c < 3; c++)
				*at(&in, 2 + x, y, c) = 0.1f;
		}
	assert_int_equal(image_box_down(&in, 2, &mean, &var, err, sizeof(err)), 0);
	assert_int_equal(mean.w, 2);
	assert_int_equal(mean.h, 1);
	/* mean 2.5, deviations^2 2.25 + 0.25 + 0.25 + 2.25 = 5, over n - 1 = 3 */
	assert_float_equal(*at(&mean, 0, 0, 0), 2.5, 0.0);
	assert_float_equal(*at(&var, 0, 0, 0), 5.0 / 3.0, 1e-6);
	/* mean 2, deviations^2 4 + 4 + 4 + 36 = 48, over 3 */
	assert_float_equal(*at(&mean, 0, 0, 1), 2.0, 0.0);
	assert_float_equal(*at(&var, 0, 0, 1), 16.0, 1e-5);
	/* mean 10000.5, deviations^2 4 x 0.25 = 1, over 3: exact despite the offset */
	assert_float_equal(*at(&mean, 0, 0, 2), 10000.5, 0.0);
	assert_float_equal(*at(&var, 0, 0, 2), 1.0 / 3.0, 1e-7);
	for (int c = 0; c < 3; c++) {
		assert_true(*at(&mean, 1, 0, c) == 0.1f);
		assert_true(*at(&var, 1, 0, c) == 0.0f);
	}
	image_release(&mean);
	image_release(&var);

	/* the whole image as one block (s = h), and the variance is optional */
	struct image sq;
	make_rgb(&sq, 3, 3);
	for (int i = 0; i < 9; i++)
		*at(&sq, i % 3, i / 3, 0) = (float)i;	/* 0..8: mean 4, variance 60 / 8 */
	assert_int_equal(image_box_down(&sq, 3, &mean, NULL, err, sizeof(err)), 0);
	assert_int_equal(mean.w, 1);
	assert_int_equal(mean.h, 1);
	assert_float_equal(*at(&mean, 0, 0, 0), 4.0, 0.0);
	image_release(&mean);
	assert_int_equal(image_box_down(&sq, 3, &mean, &var, err, sizeof(err)), 0);
	assert_float_equal(*at(&var, 0, 0, 0), 7.5, 1e-6);
	assert_true(*at(&var, 0, 0, 1) == 0.0f);
	image_release(&mean);
	image_release(&var);
	image_release(&sq);
	image_release(&in);
}

/* A NaN spoils its own block only; s = 1 copies the image with variance 0. */
static void test_nonfinite_and_identity(void **state)
{
	struct image in, mean, var;
	char err[256];

	(void)state;
	make_rgb(&in, 4, 2);
	for (int i = 0; i < 4 * 2 * 3; i++)
		in.px[i] = 0.5f + 0.01f * (float)i;
	*at(&in, 1, 1, 2) = NAN;
	assert_int_equal(image_box_down(&in, 2, &mean, &var, err, sizeof(err)), 0);
	assert_true(isnan(*at(&mean, 0, 0, 2)));
	assert_true(isnan(*at(&var, 0, 0, 2)));
	assert_true(isfinite(*at(&mean, 0, 0, 1)));
	assert_true(isfinite(*at(&var, 0, 0, 1)));
	for (int c = 0; c < 3; c++) {
		assert_true(isfinite(*at(&mean, 1, 0, c)));
		assert_true(isfinite(*at(&var, 1, 0, c)));
	}
	image_release(&mean);
	image_release(&var);

	assert_int_equal(image_box_down(&in, 1, &mean, &var, err, sizeof(err)), 0);
	assert_int_equal(mean.w, 4);
	assert_int_equal(mean.h, 2);
	for (int i = 0; i < 4 * 2 * 3; i++) {
		if (isnan(in.px[i])) {
			assert_true(isnan(mean.px[i]));
			assert_true(isnan(var.px[i]));
			continue;
		}
		assert_true(mean.px[i] == in.px[i]);
		assert_true(var.px[i] == 0.0f);
	}
	image_release(&mean);
	image_release(&var);
	image_release(&in);
}

/* A factor that does not divide the size, or is not positive, is refused. */
static void test_bad_sizes(void **state)
{
	static const struct { int w, h, s; const char *msg; } cases[] = {
		{ 6, 4, 4, "not a multiple of 4" },	/* width */
		{ 4, 6, 4, "not a multiple of 4" },	/* height */
		{ 5, 5, 2, "not a multiple of 2" },	/* both */
		{ 4, 4, 8, "not a multiple of 8" },	/* larger than the image */
		{ 4, 4, 0, "invalid downsampling factor 0" },
		{ 4, 4, -2, "invalid downsampling factor -2" },
	};
	struct image in, mean, var;
	char err[256];

	(void)state;
	for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
		make_rgb(&in, cases[k].w, cases[k].h);
		memset(&mean, 0xff, sizeof(mean));	/* must come back zeroed */
		memset(&var, 0xff, sizeof(var));
		err[0] = '\0';
		assert_int_equal(image_box_down(&in, cases[k].s, &mean, &var, err,
						sizeof(err)), -1);
		assert_non_null(strstr(err, cases[k].msg));
		assert_zeroed(&mean);
		assert_zeroed(&var);
		image_release(&in);
	}

	/* an empty image */
	struct image empty = { 0 };
	assert_int_equal(image_box_down(&empty, 1, &mean, NULL, err, sizeof(err)), -1);
	assert_non_null(strstr(err, "empty"));
	assert_zeroed(&mean);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_constant_blocks),
		cmocka_unit_test(test_ramp),
		cmocka_unit_test(test_known_variance),
		cmocka_unit_test(test_nonfinite_and_identity),
		cmocka_unit_test(test_bad_sizes),
	};
	return cmocka_run_group_tests_name("downsample", tests, NULL, NULL);
}
