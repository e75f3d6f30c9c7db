/*
 * denoise.c - non-local means weighted by each pixel's noise (denoise.h).
 *
 * For each offset (dx, dy) of the search window, every pixel's term (the
 * distance between it and the pixel at the offset, denoise.h) is computed
 * once, box-summed over the patch (a horizontal then a vertical pass), and
 * the weights it gives are added to the pixels' sums: O(w h (2 radius +
 * 1)^2) with no per-patch loop.  Rows are split into bands, one thread
 * each; a band computes its terms for `patch` rows beyond it on both sides.
 * Terms of pixels beyond the border are those of the nearest pixel inside
 * (the image extended by its edge); a neighbour beyond it is no neighbour.
 */
#include "driver/denoise.h"
#include "driver/errbuf.h"
#include "driver/metrics.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define TERM_FLOOR (-1.0)
#define TERM_EPS 1e-6
#define MAX_RADIUS 16

void denoise_params_init(struct denoise_params *p)
{
	p->radius = 3;
	p->patch = 2;
	p->k = 0.75;
	p->nthreads = 0;
}

struct band {
	int w, h, y0, y1;
	const float *rgb, *var;
	const struct denoise_params *p;
	float *out, *vout, *self;
	int failed;
};

static int clampi(int v, int lo, int hi)
{
	return v < lo ? lo : v > hi ? hi : v;
}

/* The term of pixel (x, y) against (x + dx, y + dy), both clamped inside. */
static double term(const struct band *b, int x, int y, int dx, int dy, double k2)
{
	const int qx = clampi(x + dx, 0, b->w - 1), qy = clampi(y + dy, 0, b->h - 1);
	const float *a = b->rgb + 3 * ((size_t)y * b->w + x), *q = b->rgb + 3 * ((size_t)qy * b->w + qx);
	const float *va = b->var + 3 * ((size_t)y * b->w + x), *vq = b->var + 3 * ((size_t)qy * b->w + qx);
	double t = 0.0;
	/* a value that is not finite (a hole no fit reached) is no one's
	 * neighbour */
	for (int c = 0; c < 3; c++) {
		double d = (double)a[c] - q[c], vm = va[c] < vq[c] ? va[c] : vq[c];
		if (!isfinite(d))
			return HUGE_VAL;
		double s = (d * d - (va[c] + vm)) /
			   (2.0 * k2 * vm + TERM_EPS * ((double)a[c] * a[c] + METRICS_RELMSE_EPS));
		t += s > TERM_FLOOR ? s : TERM_FLOOR;
	}
	return t / 3.0;
}

static void *run_band(void *arg)
{
	struct band *b = arg;
	const int w = b->w, f = b->p->patch, R = b->p->radius;
	const int nb = b->y1 - b->y0, nr = nb + 2 * f;
	const double k2 = b->p->k * b->p->k, area = (double)(2 * f + 1) * (2 * f + 1);
	double *t = malloc(sizeof(double) * (size_t)nr * w);
	double *hs = malloc(sizeof(double) * (size_t)nr * w);
	double *num = calloc((size_t)nb * w * 3, sizeof(double));
	double *v2 = calloc((size_t)nb * w * 3, sizeof(double));
	double *den = calloc((size_t)nb * w, sizeof(double));
	double *own = calloc((size_t)nb * w, sizeof(double));
	if (!t || !hs || !num || !v2 || !den || !own) {
		b->failed = 1;
		goto out;
	}
	for (int dy = -R; dy <= R; dy++)
		for (int dx = -R; dx <= R; dx++) {
			for (int r = 0; r < nr; r++) {
				const int y = clampi(b->y0 - f + r, 0, b->h - 1);
				for (int x = 0; x < w; x++)
					t[(size_t)r * w + x] = term(b, x, y, dx, dy, k2);
			}
			for (int r = 0; r < nr; r++) {
				const double *tr = t + (size_t)r * w;
				for (int x = 0; x < w; x++) {
					double s = 0.0;
					for (int o = -f; o <= f; o++)
						s += tr[clampi(x + o, 0, w - 1)];
					hs[(size_t)r * w + x] = s;
				}
			}
			for (int j = 0; j < nb; j++) {
				const int y = b->y0 + j, qy = y + dy;
				if (qy < 0 || qy >= b->h)
					continue;
				for (int x = 0; x < w; x++) {
					const int qx = x + dx;
					if (qx < 0 || qx >= w)
						continue;
					double d = 0.0;
					for (int o = 0; o <= 2 * f; o++)
						d += hs[(size_t)(j + o) * w + x];
					d /= area;
					/* also a neighbour that is not finite: its term
					 * at the patch's centre is infinite (term()) */
					if (d >= 40.0)
						continue;
					const double wt = d > 0.0 ? exp(-d) : 1.0;
					const size_t i = (size_t)j * w + x, q = (size_t)qy * w + qx;
					for (int c = 0; c < 3; c++) {
						num[3 * i + c] += wt * b->rgb[3 * q + c];
						v2[3 * i + c] += wt * wt * b->var[3 * q + c];
					}
					den[i] += wt;
					if (!dx && !dy)
						own[i] = wt;
				}
			}
		}
	for (int j = 0; j < nb; j++)
		for (int x = 0; x < w; x++) {
			const size_t i = (size_t)j * w + x, g = (size_t)(b->y0 + j) * w + x;
			/* the pixel's own weight is 1 (its distance to itself is
			 * at most 0), so den >= 1, unless its value is not
			 * finite: then it stays as it is */
			if (!(den[i] > 0.0)) {
				for (int c = 0; c < 3; c++) {
					b->out[3 * g + c] = b->rgb[3 * g + c];
					if (b->vout)
						b->vout[3 * g + c] = b->var[3 * g + c];
				}
				if (b->self)
					b->self[g] = 1.0f;
				continue;
			}
			for (int c = 0; c < 3; c++) {
				b->out[3 * g + c] = (float)(num[3 * i + c] / den[i]);
				if (b->vout)
					b->vout[3 * g + c] = (float)(v2[3 * i + c] / (den[i] * den[i]));
			}
			if (b->self)
				b->self[g] = (float)(own[i] / den[i]);
		}
out:
	free(t);
	free(hs);
	free(num);
	free(v2);
	free(den);
	free(own);
	return NULL;
}

int denoise_nlm(int w, int h, const float *rgb, const float *var,
		const struct denoise_params *p, float *out, float *vout, float *self,
		char *err, size_t errlen)
{
	if (w <= 0 || h <= 0 || !rgb || !var || !out) {
		errbuf_printf(err, errlen, "cannot filter an empty %dx%d image", w, h);
		return -1;
	}
	if (p->radius < 0 || p->radius > MAX_RADIUS || p->patch < 0 || p->patch > MAX_RADIUS ||
	    !(p->k > 0.0) || !isfinite(p->k)) {
		errbuf_printf(err, errlen, "bad filter parameters: radius %d, patch %d, k %g",
			      p->radius, p->patch, p->k);
		return -1;
	}
	int nth = p->nthreads;
	if (nth <= 0) {
		long n = sysconf(_SC_NPROCESSORS_ONLN);
		nth = n > 0 ? (int)n : 1;
	}
	/* bands of at least 16 rows: each computes 2 patch rows of terms twice */
	if (nth > h / 16)
		nth = h / 16 > 0 ? h / 16 : 1;
	struct band *bs = calloc((size_t)nth, sizeof *bs);
	pthread_t *tid = calloc((size_t)nth, sizeof *tid);
	int started = 0, failed = 0;
	if (!bs || !tid) {
		free(bs);
		free(tid);
		errbuf_printf(err, errlen, "out of memory filtering a %dx%d image", w, h);
		return -1;
	}
	for (int k = 0; k < nth; k++) {
		bs[k] = (struct band){ w, h, (int)((long)h * k / nth), (int)((long)h * (k + 1) / nth),
				       rgb, var, p, out, vout, self, 0 };
	}
	for (int k = 1; k < nth; k++) {
		if (pthread_create(&tid[k], NULL, run_band, &bs[k]))
			break;
		started = k;
	}
	/* bands whose thread did not start run here */
	run_band(&bs[0]);
	for (int k = started + 1; k < nth; k++)
		run_band(&bs[k]);
	for (int k = 1; k <= started; k++)
		pthread_join(tid[k], NULL);
	for (int k = 0; k < nth; k++)
		failed |= bs[k].failed;
	free(bs);
	free(tid);
	if (failed) {
		errbuf_printf(err, errlen, "out of memory filtering a %dx%d image", w, h);
		return -1;
	}
	return 0;
}
