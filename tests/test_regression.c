/*
 * test_regression.c - unit tests of the regression core (regression/).
 *
 * One test per hard case of the design notes, plus the properties the
 * analysis promises on synthetic images with known answers.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "regression/kernel.h"
#include "regression/lpr.h"
#include "regression/wls.h"

/* ---- helpers ------------------------------------------------------ */

static uint64_t rng_state;

static void rng_seed(uint64_t s)
{
	rng_state = s * 0x9e3779b97f4a7c15ull + 1;
}

static double urand(void)
{
	/* splitmix64 */
	uint64_t z = (rng_state += 0x9e3779b97f4a7c15ull);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
	z ^= z >> 31;
	return ((z >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

static double gauss(void)
{
	double u = urand(), v = urand();
	return sqrt(-2.0 * log(u)) * cos(6.283185307179586 * v);
}

struct img {
	int w, h, nch;
	float *px;
};

static struct img img_new(int w, int h, int nch)
{
	struct img m = { w, h, nch, calloc((size_t)w * h * nch, sizeof(float)) };
	assert_non_null(m.px);
	return m;
}

static struct lpr_image view(const struct img *m)
{
	return (struct lpr_image){ m->w, m->h, m->nch, m->px };
}

static float *at(struct img *m, int x, int y)
{
	return m->px + ((size_t)y * m->w + x) * m->nch;
}

/* A polynomial of the given degree in pixel coordinates, per channel. */
static double poly(int deg, int c, double x, double y)
{
	double X = x / 64.0, Y = y / 64.0;
	double v = 0.4 + 0.1 * c;
	if (deg >= 1)
		v += 0.3 * X - 0.2 * Y;
	if (deg >= 2)
		v += 0.5 * X * X - 0.3 * X * Y + 0.4 * Y * Y;
	return v;
}

static void fill_poly(struct img *m, int deg)
{
	for (int y = 0; y < m->h; y++)
		for (int x = 0; x < m->w; x++)
			for (int c = 0; c < m->nch; c++)
				at(m, x, y)[c] = (float)poly(deg, c, x, y);
}

static struct lpr_result analyze(const struct img *m, const struct img *feat,
				 const struct lpr_params *p)
{
	struct lpr_result r;
	char err[256];
	struct lpr_image v = view(m), f = feat ? view(feat) : (struct lpr_image){0};
	int rc = lpr_analyze(&v, feat ? &f : NULL, p, &r, err, sizeof err);
	if (rc)
		fail_msg("lpr_analyze: %s", err);
	return r;
}

static double mean(const float *v, size_t n)
{
	double s = 0.0;
	for (size_t i = 0; i < n; i++)
		s += v[i];
	return s / n;
}

/* ---- the solver ----------------------------------------------------- */

/* H = X (X^T W X)^-1 X^T W is idempotent (not symmetric) with trace = rank. */
static void test_hat_idempotent(void **state)
{
	(void)state;
	enum { N = 25, P = 6 };
	double x[N][P], w[N], a[P * P] = {0};
	int k = 0;
	for (int j = -2; j <= 2; j++)
		for (int i = -2; i <= 2; i++, k++) {
			double u = i / 2.0, v = j / 2.0;
			double row[P] = { 1, u, v, u * u, u * v, v * v };
			memcpy(x[k], row, sizeof row);
			w[k] = kernel_tricube(i / 3.0) * kernel_tricube(j / 3.0);
		}
	for (k = 0; k < N; k++)
		for (int r = 0; r < P; r++)
			for (int c = 0; c < P; c++)
				a[r * P + c] += w[k] * x[k][r] * x[k][c];
	int act[P] = { 0, 1, 2, 3, 4, 5 };
	struct wls_factor f;
	assert_int_equal(wls_factor(a, P, act, P, &f), P);
	static double h[N][N], h2[N][N];
	for (int col = 0; col < N; col++) {
		double b[P], beta[P];
		for (int r = 0; r < P; r++)
			b[r] = w[col] * x[col][r];
		wls_solve(&f, b, beta);
		for (int row = 0; row < N; row++) {
			double s = 0.0;
			for (int r = 0; r < P; r++)
				s += x[row][r] * beta[r];
			h[row][col] = s;
		}
	}
	double tr = 0.0, asym = 0.0;
	for (int i = 0; i < N; i++) {
		tr += h[i][i];
		for (int j = 0; j < N; j++) {
			double s = 0.0;
			for (int m = 0; m < N; m++)
				s += h[i][m] * h[m][j];
			h2[i][j] = s;
			assert_true(fabs(h2[i][j] - h[i][j]) < 1e-12);
			asym = fmax(asym, fabs(h[i][j] - h[j][i]));
		}
	}
	assert_true(fabs(tr - P) < 1e-12);
	/* The weighted hat matrix is not symmetric: the slide's claim is wrong. */
	assert_true(asym > 1e-3);
}

/* A column that is a combination of others is dropped, not divided by ~0. */
static void test_solver_drops_collinear(void **state)
{
	(void)state;
	enum { N = 10, P = 3 };
	double a[P * P] = {0}, b[P] = {0};
	for (int i = 0; i < N; i++) {
		double t = i;
		double row[P] = { 1.0, t, 2.0 * t + 1.0 };  /* third = 2 t + 1 */
		double y = 3.0 + 0.5 * t;
		for (int r = 0; r < P; r++) {
			b[r] += row[r] * y;
			for (int c = 0; c < P; c++)
				a[r * P + c] += row[r] * row[c];
		}
	}
	int act[P] = { 0, 1, 2 };
	struct wls_factor f;
	assert_int_equal(wls_factor(a, P, act, P, &f), 2);
	assert_int_equal(wls_kept(&f, 2), 0);
	double beta[P];
	wls_solve(&f, b, beta);
	assert_true(fabs(beta[0] - 3.0) < 1e-12);
	assert_true(fabs(beta[1] - 0.5) < 1e-12);
	assert_true(beta[2] == 0.0);
}

/* ---- single-pixel fits ------------------------------------------------ */

/* Polynomials up to the fitted order are reproduced exactly, in full,
 * clipped and masked windows, with their slopes. */
static void test_polynomial_reproduction(void **state)
{
	(void)state;
	struct img m = img_new(40, 30, 3);
	const int pos[][2] = { { 20, 15 }, { 0, 0 }, { 39, 29 }, { 1, 28 }, { 20, 15 } };
	for (int order = 0; order <= 2; order++)
		for (int deg = 0; deg <= order; deg++) {
			fill_poly(&m, deg);
			for (int k = 0; k < 5; k++) {
				int x = pos[k][0], y = pos[k][1];
				if (k == 4)  /* masked: holes around the centre */
					for (int j = -2; j <= 2; j += 2)
						at(&m, x + 1, y + j)[0] = NAN;
				struct lpr_image v = view(&m);
				struct lpr_fit f;
				assert_int_equal(lpr_fit_pixel(&v, NULL, x, y, order, 4, &f), 0);
				assert_true(f.valid);
				for (int c = 0; c < 3; c++) {
					double ex = poly(deg, c, x, y);
					assert_true(fabs(f.fit[c] - ex) < 1e-6);
					assert_true(fabs(f.loo[c] - ex) < 1e-6);
					if (order >= 1) {
						double h = 1e-3;
						double gx = (poly(deg, c, x + h, y) - poly(deg, c, x - h, y)) / (2 * h);
						double gy = (poly(deg, c, x, y + h) - poly(deg, c, x, y - h)) / (2 * h);
						assert_true(fabs(f.dx[c] - gx) < 1e-6);
						assert_true(fabs(f.dy[c] - gy) < 1e-6);
					}
				}
				assert_true(f.press < 1e-12);
			}
		}
	free(m.px);
}

/* Leave-one-out without refitting equals the refit without the sample. */
static void test_loo_identity(void **state)
{
	(void)state;
	rng_seed(7);
	struct img m = img_new(20, 20, 3);
	for (size_t i = 0; i < 20 * 20 * 3; i++)
		m.px[i] = (float)(0.5 + 0.2 * gauss());
	struct img hole = img_new(20, 20, 3);
	const int pos[][2] = { { 10, 10 }, { 0, 5 }, { 19, 19 } };
	for (int k = 0; k < 3; k++)
		for (int order = 0; order <= 2; order++) {
			int x = pos[k][0], y = pos[k][1];
			memcpy(hole.px, m.px, sizeof(float) * 20 * 20 * 3);
			for (int c = 0; c < 3; c++)
				at(&hole, x, y)[c] = NAN;
			struct lpr_image v = view(&m), vh = view(&hole);
			struct lpr_fit f, g;
			assert_int_equal(lpr_fit_pixel(&v, NULL, x, y, order, 3, &f), 0);
			assert_int_equal(lpr_fit_pixel(&vh, NULL, x, y, order, 3, &g), 0);
			assert_true(f.valid && g.valid && g.hole && !f.hole);
			double press = 0.0;
			for (int c = 0; c < 3; c++) {
				double yc = at(&m, x, y)[c];
				assert_true(fabs(f.loo[c] - g.fit[c]) < 1e-9);
				/* (Y - fit) / (1 - H) is the leave-one-out residual. */
				double e = (yc - f.fit[c]) / (1.0 - f.leverage);
				assert_true(fabs(e - (yc - g.fit[c])) < 1e-7);
				press += e * e;
			}
			assert_true(fabs(press / 3 - f.press) < 1e-9 * (1 + f.press));
			assert_true(f.leverage > 0.0 && f.leverage < 1.0);
		}
	free(m.px);
	free(hole.px);
}

/* With p samples the fit interpolates (H = 1): such a model is never
 * valid, and a window with one valid sample only supports order 0. */
static void test_interpolation_and_single_sample(void **state)
{
	(void)state;
	struct img m = img_new(9, 9, 1);
	for (size_t i = 0; i < 81; i++)
		m.px[i] = NAN;
	/* Exactly 3 samples for order 1 (3 parameters), centre included. */
	*at(&m, 4, 4) = 1.0f;
	*at(&m, 5, 4) = 2.0f;
	*at(&m, 4, 5) = 3.0f;
	struct lpr_image v = view(&m);
	struct lpr_fit f;
	assert_int_equal(lpr_fit_pixel(&v, NULL, 4, 4, 1, 2, &f), 0);
	assert_false(f.valid);
	assert_int_equal(lpr_fit_pixel(&v, NULL, 4, 4, 0, 2, &f), 0);
	assert_true(f.valid);
	/* A hole with a single valid neighbour takes its value. */
	for (size_t i = 0; i < 81; i++)
		m.px[i] = NAN;
	*at(&m, 3, 3) = 0.25f;
	assert_int_equal(lpr_fit_pixel(&v, NULL, 4, 4, 0, 2, &f), 0);
	assert_true(f.valid && f.hole);
	assert_true(fabs(f.fit[0] - 0.25) < 1e-12);
	assert_int_equal(lpr_fit_pixel(&v, NULL, 4, 4, 2, 2, &f), 0);
	assert_false(f.valid);

	/* The whole analysis: finite wherever a valid pixel is within reach. */
	struct lpr_params p;
	lpr_params_init(&p);
	struct lpr_result r = analyze(&m, NULL, &p);
	for (int y = 0; y < 9; y++)
		for (int x = 0; x < 9; x++) {
			size_t i = (size_t)y * 9 + x;
			if (abs(x - 3) <= 8 && abs(y - 3) <= 8) {
				assert_true(isfinite(r.fit[i]));
				assert_true(isfinite(r.error[i]));
				assert_true(fabs(r.fit[i] - 0.25) < 1e-6);
			}
		}
	lpr_result_release(&r);
	free(m.px);
}

/* A single valid row supports order 0 and 1 in x but not a full order 2. */
static void test_single_row(void **state)
{
	(void)state;
	struct img m = img_new(15, 9, 1);
	for (size_t i = 0; i < 15 * 9; i++)
		m.px[i] = NAN;
	for (int x = 0; x < 15; x++)
		*at(&m, x, 4) = (float)(0.1 * x);
	struct lpr_image v = view(&m);
	struct lpr_fit f;
	assert_int_equal(lpr_fit_pixel(&v, NULL, 7, 4, 0, 3, &f), 0);
	assert_true(f.valid);
	assert_true(fabs(f.fit[0] - 0.7) < 1e-6);
	assert_int_equal(lpr_fit_pixel(&v, NULL, 7, 4, 2, 3, &f), 0);
	assert_false(f.valid);
	struct lpr_params p;
	lpr_params_init(&p);
	struct lpr_result r = analyze(&m, NULL, &p);
	/* Order 0 is unbiased on a ramp only where its window is symmetric. */
	for (int x = 0; x < 15; x++) {
		if (x >= 5 && x <= 9)
			assert_true(fabs(r.fit[4 * 15 + x] - 0.1 * x) < 1e-5);
		for (int y = 0; y < 9; y++)
			assert_true(isfinite(r.fit[y * 15 + x]) && isfinite(r.error[y * 15 + x]));
	}
	lpr_result_release(&r);
	free(m.px);
}

/* ---- whole-image properties -------------------------------------------- */

/* Constant image: zero PRESS; a large offset plus small noise: no
 * cancellation in the error estimate. */
static void test_constant_and_cancellation(void **state)
{
	(void)state;
	struct img m = img_new(64, 64, 3);
	for (size_t i = 0; i < 64 * 64 * 3; i++)
		m.px[i] = 0.3f;
	struct lpr_params p;
	lpr_params_init(&p);
	struct lpr_result r = analyze(&m, NULL, &p);
	for (size_t i = 0; i < 64 * 64; i++) {
		assert_true(r.error[i] < 1e-20);
		assert_int_equal((int)r.order[i], 0);
		assert_true(fabs(r.fit[3 * i] - 0.3) < 1e-7);
	}
	lpr_result_release(&r);

	rng_seed(3);
	const double sigma = 0.01;
	for (size_t i = 0; i < 64 * 64 * 3; i++)
		m.px[i] = (float)(1e4 + sigma * gauss());
	r = analyze(&m, NULL, &p);
	double me = mean(r.error, 64 * 64) / (sigma * sigma);
	assert_true(me > 0.75 && me < 1.25);
	lpr_result_release(&r);
	free(m.px);
}

/* An exact quadratic is reproduced, its error is ~0, order 2 is chosen. */
static void test_quadratic(void **state)
{
	(void)state;
	struct img m = img_new(96, 80, 3);
	fill_poly(&m, 2);
	struct lpr_params p;
	lpr_params_init(&p);
	struct lpr_result r = analyze(&m, NULL, &p);
	int n = 0, o2 = 0;
	for (int y = 0; y < m.h; y++)
		for (int x = 0; x < m.w; x++) {
			size_t i = (size_t)y * m.w + x;
			for (int c = 0; c < 3; c++)
				assert_true(fabs(r.fit[3 * i + c] - m.px[3 * i + c]) <= 1e-5 * fabs(m.px[3 * i + c]));
			assert_true(r.error[i] < 1e-12);
			if (x >= 8 && y >= 8 && x < m.w - 8 && y < m.h - 8) {
				n++;
				o2 += r.order[i] == 2.0f;
			}
		}
	assert_true(o2 >= 0.9 * n);
	lpr_result_release(&r);
	free(m.px);
}

/* Independent noise: error ~ sigma^2, order 0 mostly, MSE well below. */
static void test_noise(void **state)
{
	(void)state;
	rng_seed(11);
	const double sigma = 0.05;
	struct img m = img_new(128, 128, 3);
	for (size_t i = 0; i < 128 * 128 * 3; i++)
		m.px[i] = (float)(0.5 + sigma * gauss());
	struct lpr_params p;
	lpr_params_init(&p);
	struct lpr_result r = analyze(&m, NULL, &p);
	size_t n = 128 * 128;
	double me = mean(r.error, n) / (sigma * sigma);
	int o0 = 0;
	double mse = 0.0;
	for (size_t i = 0; i < n; i++) {
		o0 += r.order[i] == 0.0f;
		for (int c = 0; c < 3; c++)
			mse += (r.fit[3 * i + c] - 0.5) * (r.fit[3 * i + c] - 0.5);
	}
	mse /= 3.0 * n;
	assert_true(me > 0.75 && me < 1.25);
	assert_true(o0 >= 0.7 * n);
	assert_true(mse <= sigma * sigma / 4);
	lpr_result_release(&r);
	free(m.px);
}

/* Scaling the image by s scales error by s^2 and changes no choice;
 * translating the values leaves the choices alone too. */
static void test_scale_and_translation(void **state)
{
	(void)state;
	rng_seed(5);
	struct img m = img_new(80, 64, 3), s = img_new(80, 64, 3);
	for (int y = 0; y < m.h; y++)
		for (int x = 0; x < m.w; x++)
			for (int c = 0; c < 3; c++)
				at(&m, x, y)[c] = (float)(poly(2, c, x, y) + (x > 40 ? 0.3 : 0.0) +
							  0.02 * gauss());
	struct lpr_params p;
	lpr_params_init(&p);
	struct lpr_result r0 = analyze(&m, NULL, &p);
	const double scales[] = { 1e4, 1e-6 };
	for (int k = 0; k < 2; k++) {
		double sc = scales[k];
		for (size_t i = 0; i < 80 * 64 * 3; i++)
			s.px[i] = (float)(m.px[i] * sc);
		struct lpr_result r1 = analyze(&s, NULL, &p);
		for (size_t i = 0; i < 80 * 64; i++) {
			assert_true(r0.order[i] == r1.order[i]);
			assert_true(r0.bandwidth[i] == r1.bandwidth[i]);
			double want = r0.error[i] * sc * sc;
			assert_true(fabs(r1.error[i] - want) <= 1e-3 * want + 1e-30);
		}
		lpr_result_release(&r1);
	}
	lpr_result_release(&r0);

	/* Offsets near 1e6 in the features: the fit does not change (the
	 * feature's variation, 16, is exact in float at that offset). */
	struct img fe = img_new(80, 64, 1), fe2 = img_new(80, 64, 1);
	for (int y = 0; y < 64; y++)
		for (int x = 0; x < 80; x++) {
			at(&fe, x, y)[0] = (float)((x % 3) * 16);
			at(&fe2, x, y)[0] = (float)(1e6 + (x % 3) * 16);
		}
	r0 = analyze(&m, &fe, &p);
	struct lpr_result r1 = analyze(&m, &fe2, &p);
	for (size_t i = 0; i < 80 * 64 * 3; i++)
		assert_true(fabs(r0.fit[i] - r1.fit[i]) < 1e-5);
	lpr_result_release(&r0);
	lpr_result_release(&r1);
	free(m.px);
	free(s.px);
	free(fe.px);
	free(fe2.px);
}

/* A linear ramp: dx = a and dy = b in the interior. */
static void test_ramp_gradient(void **state)
{
	(void)state;
	struct img m = img_new(64, 48, 3);
	const double a[3] = { 0.001, 0.002, 0.003 }, b = 0.002;
	for (int y = 0; y < 48; y++)
		for (int x = 0; x < 64; x++)
			for (int c = 0; c < 3; c++)
				at(&m, x, y)[c] = (float)(0.2 + a[c] * x + b * y);
	struct lpr_params p;
	lpr_params_init(&p);
	struct lpr_result r = analyze(&m, NULL, &p);
	int o0 = 0;
	for (int y = 8; y < 40; y++)
		for (int x = 8; x < 56; x++) {
			for (int c = 0; c < 3; c++) {
				size_t i = ((size_t)y * 64 + x) * 3 + c;
				assert_true(fabs(r.dx[i] - a[c]) < 1e-5);
				assert_true(fabs(r.dy[i] - b) < 1e-5);
			}
			o0 += r.order[(size_t)y * 64 + x] == 0.0f;
		}
	/* Every order reproduces a ramp at an interior pixel: their PRESS
	 * differ only by rounding, which counts as a tie, and ties go to the
	 * lower order. */
	assert_true(o0 >= 0.99 * 32 * 48);
	lpr_result_release(&r);
	free(m.px);
}

/* NaN and Inf anywhere: holes are filled, nothing non-finite comes out. */
static void test_holes(void **state)
{
	(void)state;
	rng_seed(9);
	struct img m = img_new(96, 96, 3), ref = img_new(96, 96, 3);
	fill_poly(&ref, 2);
	memcpy(m.px, ref.px, sizeof(float) * 96 * 96 * 3);
	for (int y = 0; y < 96; y++)
		for (int x = 0; x < 96; x++)
			if (urand() < 0.05)
				at(&m, x, y)[(x + y) % 3] = (x % 2) ? NAN : INFINITY;
	for (int y = 32; y < 38; y++)
		for (int x = 32; x < 38; x++)
			for (int c = 0; c < 3; c++)
				at(&m, x, y)[c] = NAN;
	/* Holes in the corners and along the border too. */
	at(&m, 0, 0)[0] = NAN;
	at(&m, 95, 95)[1] = -INFINITY;
	struct lpr_params p;
	lpr_params_init(&p);
	struct lpr_result r = analyze(&m, NULL, &p);
	for (size_t i = 0; i < 96 * 96; i++) {
		assert_true(isfinite(r.error[i]));
		for (int c = 0; c < 3; c++) {
			assert_true(isfinite(r.fit[3 * i + c]));
			assert_true(isfinite(r.dx[3 * i + c]) && isfinite(r.dy[3 * i + c]));
			assert_true(fabs(r.fit[3 * i + c] - ref.px[3 * i + c]) <= 1e-3 * fabs(ref.px[3 * i + c]));
		}
	}
	lpr_result_release(&r);
	free(m.px);
	free(ref.px);
}

/* A noiseless step: the error is concentrated at the edge. */
static void test_step_edge(void **state)
{
	(void)state;
	struct img m = img_new(64, 48, 3);
	for (int y = 0; y < 48; y++)
		for (int x = 0; x < 64; x++)
			for (int c = 0; c < 3; c++)
				at(&m, x, y)[c] = x < 32 ? 0.2f : 0.8f;
	struct lpr_params p;
	lpr_params_init(&p);
	struct lpr_result r = analyze(&m, NULL, &p);
	double near = 0.0, far = 0.0;
	int nn = 0, nf = 0;
	for (int y = 0; y < 48; y++)
		for (int x = 0; x < 64; x++) {
			double d = fabs(x - 31.5);
			double e = r.error[(size_t)y * 64 + x];
			if (d <= 2.0) {
				near += e;
				nn++;
			} else if (d >= 10.0) {
				far += e;
				nf++;
			}
		}
	near /= nn;
	far /= nf;
	assert_true(near > 0.0);
	assert_true(near >= 10.0 * far);
	lpr_result_release(&r);
	free(m.px);
}

/* Texture explained by a feature: PRESS measures noise, not detail. */
static void test_texture_features(void **state)
{
	(void)state;
	rng_seed(13);
	const int w = 96, h = 96;
	const double sigma = 0.02;
	struct img m = img_new(w, h, 3), t = img_new(w, h, 3), clean = img_new(w, h, 3);
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++) {
			double X = (x - w / 2.0) / w, Y = (y - h / 2.0) / h;
			double T = 0.5 + 0.4 * sin(2.1 * x) * sin(1.7 * y);
			double S = 0.6 + 0.3 * X + 0.2 * Y * Y;
			for (int c = 0; c < 3; c++) {
				double v = T * S * (1 + 0.1 * c);
				at(&clean, x, y)[c] = (float)v;
				at(&m, x, y)[c] = (float)(v + sigma * gauss());
				at(&t, x, y)[c] = (float)T;  /* collinear channels */
			}
		}
	struct lpr_params p;
	lpr_params_init(&p);
	struct lpr_result rf = analyze(&m, &t, &p), rn = analyze(&m, NULL, &p);
	size_t n = (size_t)w * h;
	double ef = mean(rf.error, n), en = mean(rn.error, n), mse = 0.0;
	for (size_t i = 0; i < 3 * n; i++)
		mse += (rf.fit[i] - clean.px[i]) * (rf.fit[i] - clean.px[i]);
	mse /= 3.0 * n;
	double s2 = sigma * sigma;
	assert_true(ef > 0.5 * s2 && ef < 1.5 * s2);
	assert_true(mse <= s2 / 2);
	assert_true(en >= 5.0 * ef);
	lpr_result_release(&rf);
	lpr_result_release(&rn);
	free(m.px);
	free(t.px);
	free(clean.px);
}

/* Constant, collinear and nearly collinear features are guarded: they
 * give the same analysis as the one informative feature alone. */
static void test_degenerate_features(void **state)
{
	(void)state;
	rng_seed(17);
	const int w = 48, h = 40;
	struct img m = img_new(w, h, 3), f = img_new(w, h, 3), g = img_new(w, h, 1);
	for (size_t i = 0; i < (size_t)w * h * 3; i++)
		m.px[i] = (float)(0.5 + 0.05 * gauss());
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++) {
			double v = 0.3 + 0.2 * ((x * 7 + y * 3) % 5);
			at(&f, x, y)[0] = 0.5f;                          /* constant */
			at(&f, x, y)[1] = (float)v;
			at(&f, x, y)[2] = (float)(v * (1.0 + 1e-7 * x)); /* nearly collinear */
			at(&g, x, y)[0] = (float)v;
		}
	struct lpr_params p;
	lpr_params_init(&p);
	struct lpr_result r = analyze(&m, &f, &p), r1 = analyze(&m, &g, &p);
	for (size_t i = 0; i < (size_t)w * h; i++) {
		assert_true(isfinite(r.error[i]));
		assert_true(fabs(r.error[i] - r1.error[i]) <= 1e-4 * r1.error[i]);
		for (int c = 0; c < 3; c++) {
			assert_true(isfinite(r.fit[3 * i + c]));
			assert_true(fabs(r.fit[3 * i + c] - r1.fit[3 * i + c]) < 1e-5);
		}
	}
	lpr_result_release(&r);
	lpr_result_release(&r1);
	free(m.px);
	free(f.px);
	free(g.px);
}

/* The fast paths agree with the general path. */
static void test_fast_vs_general(void **state)
{
	(void)state;
	rng_seed(19);
	struct img m = img_new(70, 50, 3);
	for (int y = 0; y < 50; y++)
		for (int x = 0; x < 70; x++)
			for (int c = 0; c < 3; c++)
				at(&m, x, y)[c] = (float)(poly(2, c, x, y) + (x > 35) * 0.2 + 0.03 * gauss());
	struct lpr_params p;
	lpr_params_init(&p);
	struct lpr_result a = analyze(&m, NULL, &p);
	p.force_general = 1;
	struct lpr_result b = analyze(&m, NULL, &p);
	assert_true(a.fast_pixels > 0);
	assert_int_equal(b.fast_pixels, 0);
	int diff = 0;
	for (size_t i = 0; i < 70 * 50; i++) {
		diff += a.order[i] != b.order[i] || a.bandwidth[i] != b.bandwidth[i];
		assert_true(fabs(a.error[i] - b.error[i]) <= 1e-4 * b.error[i] + 1e-12);
		for (int c = 0; c < 3; c++) {
			assert_true(fabs(a.fit[3 * i + c] - b.fit[3 * i + c]) < 1e-5);
			assert_true(fabs(a.dx[3 * i + c] - b.dx[3 * i + c]) < 1e-5);
		}
	}
	assert_true(diff <= 3);
	lpr_result_release(&a);
	lpr_result_release(&b);

	/* With features: the separable moments against the direct sums, on
	 * interior, clipped and (next to a hole) masked windows. */
	struct img fe = img_new(70, 50, 2);
	for (int y = 0; y < 50; y++)
		for (int x = 0; x < 70; x++) {
			at(&fe, x, y)[0] = (float)(0.5 + 0.4 * sin(1.3 * x) * sin(0.9 * y));
			at(&fe, x, y)[1] = (float)((x * 3 + y) % 4 * 0.25);
		}
	at(&m, 20, 20)[1] = NAN;
	p.force_general = 0;
	a = analyze(&m, &fe, &p);
	p.force_general = 1;
	b = analyze(&m, &fe, &p);
	assert_true(a.fast_pixels > 0);
	assert_int_equal(b.fast_pixels, 0);
	diff = 0;
	for (size_t i = 0; i < 70 * 50; i++) {
		diff += a.order[i] != b.order[i] || a.bandwidth[i] != b.bandwidth[i];
		assert_true(fabs(a.error[i] - b.error[i]) <= 1e-4 * b.error[i] + 1e-12);
		for (int c = 0; c < 3; c++) {
			assert_true(fabs(a.fit[3 * i + c] - b.fit[3 * i + c]) < 1e-5);
			assert_true(fabs(a.dy[3 * i + c] - b.dy[3 * i + c]) < 1e-5);
		}
	}
	assert_true(diff <= 3);
	lpr_result_release(&a);
	lpr_result_release(&b);
	free(fe.px);
	free(m.px);
}

/* The most channels and features the library takes: the moment path has a
 * plane per channel, feature and product of them (188 here). */
static void test_max_channels_and_features(void **state)
{
	(void)state;
	rng_seed(31);
	struct img m = img_new(24, 20, LPR_MAXCH), f = img_new(24, 20, LPR_MAXFEAT);
	for (size_t i = 0; i < (size_t)24 * 20 * LPR_MAXCH; i++)
		m.px[i] = (float)(0.5 + 0.05 * gauss());
	for (size_t i = 0; i < (size_t)24 * 20 * LPR_MAXFEAT; i++)
		f.px[i] = (float)urand();
	struct lpr_params p;
	lpr_params_init(&p);
	p.radii[0] = 2;
	p.radii[1] = 3;
	p.nradii = 2;
	struct lpr_result a = analyze(&m, &f, &p);
	p.force_general = 1;
	struct lpr_result b = analyze(&m, &f, &p);
	assert_true(a.fast_pixels > 0);
	for (size_t i = 0; i < (size_t)24 * 20; i++) {
		assert_true(isfinite(a.error[i]));
		assert_true(fabs(a.error[i] - b.error[i]) <= 1e-4 * b.error[i] + 1e-12);
		for (int c = 0; c < LPR_MAXCH; c++)
			assert_true(fabs(a.fit[i * LPR_MAXCH + c] - b.fit[i * LPR_MAXCH + c]) < 1e-5);
	}
	lpr_result_release(&a);
	lpr_result_release(&b);
	free(m.px);
	free(f.px);
}

/* Mirroring the image mirrors the analysis (and negates the slope). */
static void test_mirror_symmetry(void **state)
{
	(void)state;
	rng_seed(23);
	const int w = 41, h = 33;
	struct img m = img_new(w, h, 3), mm = img_new(w, h, 3);
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++)
			for (int c = 0; c < 3; c++) {
				float v = (float)(poly(2, c, x, y) + 0.05 * gauss());
				at(&m, x, y)[c] = v;
				at(&mm, w - 1 - x, y)[c] = v;
			}
	struct lpr_params p;
	lpr_params_init(&p);
	struct lpr_result a = analyze(&m, NULL, &p), b = analyze(&mm, NULL, &p);
	int diff = 0;
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++) {
			size_t i = (size_t)y * w + x, j = (size_t)y * w + (w - 1 - x);
			diff += a.order[i] != b.order[j] || a.bandwidth[i] != b.bandwidth[j];
			if (a.order[i] != b.order[j] || a.bandwidth[i] != b.bandwidth[j])
				continue;
			for (int c = 0; c < 3; c++) {
				assert_true(fabs(a.fit[3 * i + c] - b.fit[3 * j + c]) < 1e-5);
				assert_true(fabs(a.dx[3 * i + c] + b.dx[3 * j + c]) < 1e-5);
			}
		}
	assert_true(diff <= 2);
	lpr_result_release(&a);
	lpr_result_release(&b);
	free(m.px);
	free(mm.px);
}

/* The thread count does not change a single bit of the output. */
static void test_threads_identical(void **state)
{
	(void)state;
	rng_seed(29);
	struct img m = img_new(100, 150, 3);
	for (size_t i = 0; i < 100 * 150 * 3; i++)
		m.px[i] = (float)(0.5 + 0.1 * gauss());
	m.px[3 * 777] = NAN;
	struct lpr_params p;
	lpr_params_init(&p);
	p.nthreads = 1;
	struct lpr_result a = analyze(&m, NULL, &p);
	p.nthreads = 3;
	struct lpr_result b = analyze(&m, NULL, &p);
	size_t n = 100 * 150;
	assert_memory_equal(a.fit, b.fit, n * 3 * sizeof(float));
	assert_memory_equal(a.error, b.error, n * sizeof(float));
	assert_memory_equal(a.dx, b.dx, n * 3 * sizeof(float));
	assert_memory_equal(a.order, b.order, n * sizeof(float));
	lpr_result_release(&a);
	lpr_result_release(&b);
	free(m.px);
}

/* Bad parameters are refused with a message. */
static void test_bad_arguments(void **state)
{
	(void)state;
	struct img m = img_new(8, 8, 3);
	struct lpr_image v = view(&m);
	struct lpr_params p;
	struct lpr_result r;
	char err[256] = "";
	lpr_params_init(&p);
	p.order = 3;
	assert_int_equal(lpr_analyze(&v, NULL, &p, &r, err, sizeof err), -1);
	assert_non_null(strstr(err, "order"));
	lpr_params_init(&p);
	p.radius = 99;
	assert_int_equal(lpr_analyze(&v, NULL, &p, &r, err, sizeof err), -1);
	assert_non_null(strstr(err, "radius"));
	struct img f = img_new(4, 8, 1);
	struct lpr_image fv = view(&f);
	lpr_params_init(&p);
	assert_int_equal(lpr_analyze(&v, &fv, &p, &r, err, sizeof err), -1);
	assert_non_null(strstr(err, "features"));
	lpr_result_release(&r);
	free(m.px);
	free(f.px);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_hat_idempotent),
		cmocka_unit_test(test_solver_drops_collinear),
		cmocka_unit_test(test_polynomial_reproduction),
		cmocka_unit_test(test_loo_identity),
		cmocka_unit_test(test_interpolation_and_single_sample),
		cmocka_unit_test(test_single_row),
		cmocka_unit_test(test_constant_and_cancellation),
		cmocka_unit_test(test_quadratic),
		cmocka_unit_test(test_noise),
		cmocka_unit_test(test_scale_and_translation),
		cmocka_unit_test(test_ramp_gradient),
		cmocka_unit_test(test_holes),
		cmocka_unit_test(test_step_edge),
		cmocka_unit_test(test_texture_features),
		cmocka_unit_test(test_degenerate_features),
		cmocka_unit_test(test_fast_vs_general),
		cmocka_unit_test(test_max_channels_and_features),
		cmocka_unit_test(test_mirror_symmetry),
		cmocka_unit_test(test_threads_identical),
		cmocka_unit_test(test_bad_arguments),
	};
	return cmocka_run_group_tests_name("regression", tests, NULL, NULL);
}
