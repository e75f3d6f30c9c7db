/*
 * test_denoise.c - unit tests for driver/denoise.c: the noise-weighted
 * non-local means of the final image.  Noise is drawn from a fixed-seed
 * generator, so every figure is the same every run.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "driver/denoise.h"

enum { W = 48, H = 40, NPX = W * H };

/* A fixed-seed generator: xorshift64*, and a normal deviate from it. */
static uint64_t rng = 88172645463325252ull;

static double uniform(void)
{
	rng ^= rng >> 12;
	rng ^= rng << 25;
	rng ^= rng >> 27;
	return (double)((rng * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}

static double normal(void)
{
	double u = uniform(), v = uniform();
	return sqrt(-2.0 * log(u > 1e-300 ? u : 1e-300)) * cos(6.283185307179586 * v);
}

struct scene {
	float truth[NPX * 3], noisy[NPX * 3], var[NPX * 3];
	float out[NPX * 3], vout[NPX * 3], self[NPX];
};

/* truth(x, y) + noise of standard deviation sigma(x, y), var = sigma^2 */
static void make(struct scene *s, double (*truth)(int, int), double (*sigma)(int, int))
{
	rng = 88172645463325252ull;
	for (int y = 0; y < H; y++)
		for (int x = 0; x < W; x++)
			for (int c = 0; c < 3; c++) {
				size_t i = 3 * ((size_t)y * W + x) + c;
				double t = truth(x, y), sd = sigma(x, y);
				s->truth[i] = (float)t;
				s->noisy[i] = (float)(t + sd * normal());
				s->var[i] = (float)(sd * sd);
			}
}

static void filter(struct scene *s, int nthreads)
{
	struct denoise_params p;
	char err[256];
	denoise_params_init(&p);
	p.nthreads = nthreads;
	assert_int_equal(denoise_nlm(W, H, s->noisy, s->var, &p, s->out, s->vout, s->self, err,
				     sizeof err), 0);
}

/* Mean squared error of img against the truth over pixels with x in
 * [x0, x1). */
static double mse(const struct scene *s, const float *img, int x0, int x1)
{
	double sum = 0.0;
	long n = 0;
	for (int y = 0; y < H; y++)
		for (int x = x0; x < x1; x++)
			for (int c = 0; c < 3; c++) {
				size_t i = 3 * ((size_t)y * W + x) + c;
				double d = (double)img[i] - s->truth[i];
				sum += d * d;
				n++;
			}
	return sum / (double)n;
}

static double flat(int x, int y)
{
	(void)x, (void)y;
	return 0.5;
}

static double step(int x, int y)
{
	(void)y;
	return x < W / 2 ? 0.2 : 0.8;
}

static double sigma05(int x, int y)
{
	(void)x, (void)y;
	return 0.05;
}

static double sigma0(int x, int y)
{
	(void)x, (void)y;
	return 0.0;
}

/* Noise on a flat image: the filter averages it down, and its variance
 * output says by how much. */
static void test_flat_noise_reduced(void **state)
{
	(void)state;
	static struct scene s;
	make(&s, flat, sigma05);
	filter(&s, 1);
	double before = mse(&s, s.noisy, 0, W), after = mse(&s, s.out, 0, W);
	assert_true(before > 0.002 && before < 0.003);	/* sigma^2 = 0.0025 */
	assert_true(after < 0.25 * before);
	double vmean = 0.0;
	for (size_t i = 0; i < NPX * 3; i++)
		vmean += s.vout[i] / (NPX * 3.0);
	assert_true(vmean < 0.25 * 0.0025);
	assert_true(vmean > 0.0025 / 49.0 * 0.99);	/* at most the whole window */
	for (size_t i = 0; i < NPX; i++)
		assert_true(s.self[i] > 0.0f && s.self[i] <= 1.0f);
}

/* A step between two noisy levels 12 standard deviations apart: the filter
 * does not average across it.  The columns next to the edge keep their own
 * level, and both halves' errors fall. */
static void test_step_edge_kept(void **state)
{
	(void)state;
	static struct scene s;
	make(&s, step, sigma05);
	filter(&s, 2);
	for (int y = 0; y < H; y++) {
		for (int c = 0; c < 3; c++) {
			size_t l = 3 * ((size_t)y * W + W / 2 - 1) + c, r = l + 3;
			assert_true(fabs(s.out[l] - 0.2) < 0.1);
			assert_true(fabs(s.out[r] - 0.8) < 0.1);
		}
	}
	assert_true(mse(&s, s.out, 0, W / 2) < 0.5 * mse(&s, s.noisy, 0, W / 2));
	assert_true(mse(&s, s.out, W / 2, W) < 0.5 * mse(&s, s.noisy, W / 2, W));
	/* the edge's own columns do not pay for it */
	assert_true(mse(&s, s.out, W / 2 - 1, W / 2 + 1) < mse(&s, s.noisy, W / 2 - 1, W / 2 + 1));
}

/* A star: one pixel far brighter and far noisier than the quiet sky around
 * it keeps its value, and the sky around it takes none of it. */
static void test_star_kept(void **state)
{
	(void)state;
	static struct scene s;
	make(&s, flat, sigma05);
	const int sx = 20, sy = 17;
	for (int c = 0; c < 3; c++) {
		size_t i = 3 * ((size_t)sy * W + sx) + c;
		s.noisy[i] = 6.0f;
		s.var[i] = 4.0f;	/* as noisy as its value's square: the star's own */
	}
	filter(&s, 1);
	for (int c = 0; c < 3; c++) {
		size_t i = 3 * ((size_t)sy * W + sx) + c;
		assert_true(s.out[i] > 5.4f);
		size_t n = 3 * ((size_t)sy * W + sx + 1) + c;
		assert_true(s.out[n] < 0.7f);
	}
}

/* Without noise nothing moves: a textured image with variance 0 comes out
 * as it went in, each pixel its own mean. */
static void test_noise_free_unchanged(void **state)
{
	(void)state;
	static struct scene s;
	make(&s, step, sigma0);
	for (size_t i = 0; i < NPX * 3; i++)
		s.noisy[i] = s.truth[i] = (float)(0.3 + 0.2 * sin(0.7 * (double)(i / 3)));
	filter(&s, 1);
	for (size_t i = 0; i < NPX * 3; i++)
		assert_true(fabs(s.out[i] - s.noisy[i]) <= 1e-3 * fabs(s.noisy[i]));
}

/* A hole (a value that is not finite) stays a hole and spreads to no
 * neighbour. */
static void test_hole_not_spread(void **state)
{
	(void)state;
	static struct scene s;
	make(&s, flat, sigma05);
	const size_t h = (size_t)10 * W + 10;
	for (int c = 0; c < 3; c++)
		s.noisy[3 * h + c] = NAN;
	filter(&s, 1);
	assert_true(isnan(s.out[3 * h]));
	for (size_t i = 0; i < NPX * 3; i++)
		if (i / 3 != h)
			assert_true(isfinite(s.out[i]) && isfinite(s.vout[i]));
	assert_true(mse(&s, s.out, 12, W) < 0.25 * mse(&s, s.noisy, 12, W));
}

/* Bands on threads give the same image as one band. */
static void test_threads_same(void **state)
{
	(void)state;
	static struct scene a, b;
	make(&a, step, sigma05);
	make(&b, step, sigma05);
	filter(&a, 1);
	filter(&b, 2);
	assert_memory_equal(a.out, b.out, sizeof a.out);
	assert_memory_equal(a.vout, b.vout, sizeof a.vout);
	assert_memory_equal(a.self, b.self, sizeof a.self);
}

/*
 * The filter's definition, pixel by pixel (denoise.h): for each pixel and
 * each neighbour inside the image within the radius, the mean over the
 * patch's offsets (each pixel clamped inside) of the term, the weight, and
 * the weighted means.  Slow and plain, to check the row-wise, vectorised
 * and chunked filter against.
 */
static double ref_term(int w, int h, const float *y, const float *v, int px, int py, int qx,
		       int qy, double k)
{
	px = px < 0 ? 0 : px >= w ? w - 1 : px;
	py = py < 0 ? 0 : py >= h ? h - 1 : py;
	qx = qx < 0 ? 0 : qx >= w ? w - 1 : qx;
	qy = qy < 0 ? 0 : qy >= h ? h - 1 : qy;
	size_t a = 3 * ((size_t)py * w + px), b = 3 * ((size_t)qy * w + qx);
	double t = 0.0;
	for (int c = 0; c < 3; c++) {
		double d = (double)y[a + c] - y[b + c];
		if (!isfinite(d))
			return HUGE_VAL;
		double vm = v[a + c] < v[b + c] ? v[a + c] : v[b + c];
		double e = (d * d - (v[a + c] + vm)) /
			   (2.0 * k * k * vm + 1e-6 * ((double)y[a + c] * y[a + c] + 0.01));
		t += e > -1.0 ? e : -1.0;
	}
	return t / 3.0;
}

static void ref_filter(int w, int h, const float *y, const float *v, int radius, int patch,
		       double k, float *out, float *vout)
{
	for (int py = 0; py < h; py++)
		for (int px = 0; px < w; px++) {
			double num[3] = { 0 }, v2[3] = { 0 }, den = 0.0;
			for (int dy = -radius; dy <= radius; dy++)
				for (int dx = -radius; dx <= radius; dx++) {
					int qx = px + dx, qy = py + dy;
					if (qx < 0 || qx >= w || qy < 0 || qy >= h)
						continue;
					double d = 0.0;
					for (int oy = -patch; oy <= patch; oy++)
						for (int ox = -patch; ox <= patch; ox++) {
							int ax = px + ox, ay = py + oy;
							ax = ax < 0 ? 0 : ax >= w ? w - 1 : ax;
							ay = ay < 0 ? 0 : ay >= h ? h - 1 : ay;
							d += ref_term(w, h, y, v, ax, ay, ax + dx, ay + dy, k);
						}
					d /= (2.0 * patch + 1) * (2.0 * patch + 1);
					if (d >= 40.0)
						continue;
					double wt = d > 0.0 ? exp(-d) : 1.0;
					size_t q = 3 * ((size_t)qy * w + qx);
					for (int c = 0; c < 3; c++) {
						num[c] += wt * y[q + c];
						v2[c] += wt * wt * v[q + c];
					}
					den += wt;
				}
			size_t i = 3 * ((size_t)py * w + px);
			for (int c = 0; c < 3; c++) {
				out[i + c] = den > 0.0 ? (float)(num[c] / den) : y[i + c];
				vout[i + c] = den > 0.0 ? (float)(v2[c] / (den * den)) : v[i + c];
			}
		}
}

/* The filter against its definition on noisy texture with holes, noise
 * that varies from pixel to pixel and noise-free pixels, at sizes where the
 * window and the patch reach past both borders, and on images narrower
 * than the patch or the window. */
static void test_matches_definition(void **state)
{
	(void)state;
	static const int sizes[][2] = { { 48, 40 }, { 37, 19 }, { 5, 33 }, { 3, 3 }, { 1, 7 } };
	static const int params[][2] = { { 3, 2 }, { 1, 0 }, { 5, 3 } };
	static float y[NPX * 3], v[NPX * 3], out[NPX * 3], vout[NPX * 3], ro[NPX * 3],
		rv[NPX * 3], self[NPX];
	for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; si++)
		for (size_t pi = 0; pi < sizeof params / sizeof params[0]; pi++) {
			const int w = sizes[si][0], h = sizes[si][1];
			rng = 88172645463325252ull + si;
			for (int i = 0; i < w * h * 3; i++) {
				int x = (i / 3) % w, yy = (i / 3) / w;
				double sd = uniform() < 0.1 ? 0.0 : 0.02 + 0.1 * uniform();
				y[i] = (float)(0.3 + 0.4 * ((x / 4 + yy / 3) % 2) + sd * normal());
				v[i] = (float)(sd * sd);
			}
			if (w * h > 20)
				for (int c = 0; c < 3; c++)
					y[3 * (w * h / 2) + c] = NAN;
			struct denoise_params p;
			char err[256];
			denoise_params_init(&p);
			p.radius = params[pi][0];
			p.patch = params[pi][1];
			p.nthreads = 2;
			assert_int_equal(denoise_nlm(w, h, y, v, &p, out, vout, self, err, sizeof err), 0);
			ref_filter(w, h, y, v, p.radius, p.patch, p.k, ro, rv);
			for (int i = 0; i < w * h * 3; i++) {
				if (isnan(ro[i])) {
					assert_true(isnan(out[i]));
					continue;
				}
				assert_true(fabs(out[i] - ro[i]) <= 1e-5 * (fabs(ro[i]) + 1e-3));
				assert_true(fabs(vout[i] - rv[i]) <= 1e-5 * (fabs(rv[i]) + 1e-9));
			}
		}
}

static void test_bad_input(void **state)
{
	(void)state;
	static struct scene s;
	struct denoise_params p;
	char err[256] = "";
	make(&s, flat, sigma05);
	denoise_params_init(&p);
	p.k = 0.0;
	assert_int_equal(denoise_nlm(W, H, s.noisy, s.var, &p, s.out, NULL, NULL, err, sizeof err),
			 -1);
	assert_non_null(strstr(err, "bad filter parameters"));
	denoise_params_init(&p);
	assert_int_equal(denoise_nlm(0, H, s.noisy, s.var, &p, s.out, NULL, NULL, err, sizeof err),
			 -1);
	assert_non_null(strstr(err, "empty"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_flat_noise_reduced),
		cmocka_unit_test(test_step_edge_kept),
		cmocka_unit_test(test_star_kept),
		cmocka_unit_test(test_noise_free_unchanged),
		cmocka_unit_test(test_hole_not_spread),
		cmocka_unit_test(test_threads_same),
		cmocka_unit_test(test_matches_definition),
		cmocka_unit_test(test_bad_input),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
