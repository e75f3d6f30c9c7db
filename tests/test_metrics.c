/*
 * test_metrics.c - unit tests for driver/metrics.c: relMSE, MSE and PSNR on
 * hand-computed images, and the fidelity of an error map (its estimate,
 * its capture of the true error, the oracle's and the local ranking's).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "driver/image.h"
#include "driver/metrics.h"
#include "tests/testutil.h"

static const char *const rgb_names[] = { "R", "G", "B" };

static void make_rgb(struct image *img, int w, int h, float v)
{
	char err[256];

	assert_int_equal(image_init(img, w, h, 3, rgb_names, err, sizeof(err)), 0);
	for (size_t i = 0; i < (size_t)w * h * 3; i++)
		img->px[i] = v;
}

/* Pixel (x, y) of img set to v in all three channels. */
static void set(struct image *img, int x, int y, float v)
{
	for (int c = 0; c < 3; c++)
		img->px[((size_t)y * img->w + x) * 3 + c] = v;
}

/* metrics_fidelity() of img against ref with the relative map, which must
 * succeed. */
static struct fidelity judge(const struct image *img, const struct image *ref, const float *map)
{
	struct fidelity f;
	char err[256];

	assert_int_equal(metrics_fidelity(img, ref, map, NULL, &f, err, sizeof(err)), 0);
	return f;
}

/* One pixel off by 0.3 on a grey 0.5 frame of 4 x 4: relMSE and MSE by hand. */
static void test_relmse_by_hand(void **state)
{
	(void)state;
	struct image a, r;
	struct metrics m;
	char err[256];

	make_rgb(&a, 4, 4, 0.5f);
	make_rgb(&r, 4, 4, 0.5f);
	set(&a, 2, 1, 0.8f);
	assert_int_equal(metrics_compute(&a, &r, &m, err, sizeof(err)), 0);
	double d = 0.8f - 0.5f;
	assert_true(fabs(m.relmse - d * d / (0.25 + METRICS_RELMSE_EPS) / 16.0) < 1e-9);
	assert_true(fabs(m.mse - d * d / 16.0) < 1e-9);
	image_release(&a);
	image_release(&r);
}

/*
 * The true error a ramp in x (pixel x off by 0.01 (x + 1)), a map that
 * ranks it exactly: capture, oracle and local rankings all hold the top
 * fifth's share; a map that ranks it backwards captures the bottom fifth's.
 */
static void test_ramp_rankings(void **state)
{
	(void)state;
	const int w = 10, h = 6;
	struct image a, r;
	struct fidelity f;
	float map[60], back[60];

	make_rgb(&a, w, h, 0.5f);
	make_rgb(&r, w, h, 0.5f);
	double top = 0.0, bottom = 0.0, total = 0.0;
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++) {
			float v = 0.5f + 0.01f * (x + 1);
			set(&a, x, y, v);
			double t = ((double)v - 0.5) * ((double)v - 0.5) / (0.25 + METRICS_RELMSE_EPS);
			map[y * w + x] = (float)t;
			back[y * w + x] = (float)(1.0 - t);
			total += t;
			top += x >= 8 ? t : 0.0;
			bottom += x <= 1 ? t : 0.0;
		}
	f = judge(&a, &r, map);
	assert_true(fabs(f.oracle - top / total) < 1e-6);
	assert_true(fabs(f.capture - top / total) < 1e-6);
	assert_true(fabs(f.local - top / total) < 1e-6);
	assert_true(fabs(f.est_relmse - total / (w * h)) < 1e-9);
	assert_true(fabs(f.true_relmse - total / (w * h)) < 1e-9);
	f = judge(&a, &r, back);
	assert_true(fabs(f.capture - bottom / total) < 1e-6);
	assert_true(fabs(f.local - top / total) < 1e-6);	/* the map plays no part */
	image_release(&a);
	image_release(&r);
}

/*
 * Error as noise of the same spread everywhere: scattered pixels (about 3
 * in 10, by a hash of the position) off by 0.01, the rest exact.  The
 * oracle takes the off pixels alone; the local ranking, which sees 3 x 3
 * means, can hardly tell a pixel from its neighbours and takes exact pixels
 * too, so it holds far less.  And a single hot pixel in
 * a quiet frame: its neighbourhood ranks high, so the local ranking holds
 * it as the oracle does.
 */
static void test_local_below_oracle_on_noise(void **state)
{
	(void)state;
	const int w = 20, h = 20;
	struct image a, r;
	struct fidelity f;
	float map[400];

	make_rgb(&a, w, h, 0.5f);
	make_rgb(&r, w, h, 0.5f);
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++) {
			map[y * w + x] = 1.0f;
			unsigned hsh = ((unsigned)x * 73856093u) ^ ((unsigned)y * 19349663u);
			if ((hsh >> 4) % 10 < 3)
				set(&a, x, y, 0.51f);
		}
	f = judge(&a, &r, map);
	assert_true(f.oracle > 0.6);
	assert_true(f.local < 0.75 * f.oracle);
	assert_true(f.local > 0.0);

	image_release(&a);
	make_rgb(&a, w, h, 0.5f);
	set(&a, 7, 11, 0.9f);
	f = judge(&a, &r, map);
	assert_true(fabs(f.oracle - 1.0) < 1e-9);
	assert_true(fabs(f.local - 1.0) < 1e-9);
	image_release(&a);
	image_release(&r);
}

/* A pixel that is not finite in the map is left out of every ranking. */
static void test_nonfinite_left_out(void **state)
{
	(void)state;
	const int w = 5, h = 5;
	struct image a, r;
	struct fidelity f;
	float map[25];

	make_rgb(&a, w, h, 0.5f);
	make_rgb(&r, w, h, 0.5f);
	for (int i = 0; i < 25; i++)
		map[i] = 0.0f;
	set(&a, 2, 2, 0.9f);
	map[2 * w + 2] = NAN;
	set(&a, 0, 4, 0.6f);
	f = judge(&a, &r, map);
	assert_true(fabs(f.oracle - 1.0) < 1e-9);
	assert_true(fabs(f.local - 1.0) < 1e-9);
	double t = 0.1 * 0.1 / (0.25 + METRICS_RELMSE_EPS);
	assert_true(fabs(f.true_relmse - t / 24.0) < 1e-9);
	image_release(&a);
	image_release(&r);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_relmse_by_hand),
		cmocka_unit_test(test_ramp_rankings),
		cmocka_unit_test(test_local_below_oracle_on_noise),
		cmocka_unit_test(test_nonfinite_left_out),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
