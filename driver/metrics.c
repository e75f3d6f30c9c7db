/*
 * metrics.c - relMSE, MSE and PSNR of an image against a reference.
 */
#include "driver/metrics.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int metrics_compute(const struct image *img, const struct image *ref, struct metrics *out,
		    char *err, size_t errlen)
{
	double sum_rel = 0.0, sum_sq = 0.0;
	size_t npix, nch;

	memset(out, 0, sizeof(*out));
	if (img->w != ref->w || img->h != ref->h || img->nch != ref->nch) {
		if (err && errlen)
			snprintf(err, errlen, "image is %dx%d with %d channels, reference "
				 "is %dx%d with %d channels", img->w, img->h, img->nch,
				 ref->w, ref->h, ref->nch);
		return -1;
	}
	npix = (size_t)img->w * (size_t)img->h;
	nch = (size_t)img->nch;
	for (size_t i = 0; i < npix; i++) {
		const float *a = img->px + i * nch, *b = ref->px + i * nch;
		double rel = 0.0, sq = 0.0;
		size_t c;

		for (c = 0; c < nch; c++)
			if (!isfinite(a[c]) || !isfinite(b[c]))
				break;
		if (c < nch) {
			out->skipped++;
			continue;
		}
		for (c = 0; c < nch; c++) {
			double d = (double)a[c] - (double)b[c];
			double r = b[c];

			sq += d * d;
			rel += d * d / (r * r + METRICS_RELMSE_EPS);
		}
		sum_sq += sq;
		sum_rel += rel;
		out->compared++;
	}
	if (!out->compared) {
		if (err && errlen)
			snprintf(err, errlen, "no pixel is finite in both images");
		return -1;
	}
	out->mse = sum_sq / ((double)out->compared * (double)nch);
	out->relmse = sum_rel / ((double)out->compared * (double)nch);
	out->psnr = out->mse > 0.0 ? 10.0 * log10(1.0 / out->mse) : INFINITY;
	return 0;
}

struct ranked {
	double key, truth;
};

static int by_key_desc(const void *a, const void *b)
{
	double x = ((const struct ranked *)a)->key, y = ((const struct ranked *)b)->key;
	return x < y ? 1 : x > y ? -1 : 0;
}

/* Share of the truth in the first 20% of v after sorting by key. */
static double top_share(struct ranked *v, size_t n, double total)
{
	qsort(v, n, sizeof *v, by_key_desc);
	size_t top = (n + 4) / 5;
	double s = 0.0;
	for (size_t i = 0; i < top; i++)
		s += v[i].truth;
	return total > 0.0 ? s / total : 1.0;
}

/* The mean of the finite values of t (w x h) in the 3 x 3 neighbourhood
 * of (x, y), itself included (finite). */
static double local_mean(const double *t, int w, int h, int x, int y)
{
	double s = 0.0;
	int m = 0;
	for (int j = y > 0 ? y - 1 : 0; j <= y + 1 && j < h; j++)
		for (int l = x > 0 ? x - 1 : 0; l <= x + 1 && l < w; l++)
			if (isfinite(t[(size_t)j * w + l])) {
				s += t[(size_t)j * w + l];
				m++;
			}
	return s / m;
}

int metrics_fidelity(const struct image *img, const struct image *ref, const float *err_map,
		     const struct image *fit, struct fidelity *out, char *err, size_t errlen)
{
	memset(out, 0, sizeof(*out));
	if (img->w != ref->w || img->h != ref->h || img->nch != 3 || ref->nch != 3 ||
	    (fit && (fit->w != img->w || fit->h != img->h || fit->nch != 3))) {
		if (err && errlen)
			snprintf(err, errlen, "the image, reference and analysis differ in size");
		return -1;
	}
	size_t npix = (size_t)img->w * (size_t)img->h, n = 0;
	struct ranked *v = malloc(npix * sizeof *v);
	double *tv = malloc(npix * sizeof *tv);	/* each pixel's truth, NaN if left out */
	if (!v || !tv) {
		free(v);
		free(tv);
		if (err && errlen)
			snprintf(err, errlen, "out of memory");
		return -1;
	}
	double total = 0.0, est = 0.0;
	for (size_t i = 0; i < npix; i++) {
		tv[i] = NAN;
		const float *a = img->px + 3 * i, *b = ref->px + 3 * i;
		const float *f = fit ? fit->px + 3 * i : a;
		double t = 0.0, m2 = 0.0;
		int ok = isfinite(err_map[i]);
		for (int c = 0; c < 3; c++) {
			ok = ok && isfinite(a[c]) && isfinite(b[c]) && isfinite(f[c]);
			double d = (double)a[c] - b[c];
			t += d * d / ((double)b[c] * b[c] + METRICS_RELMSE_EPS);
			m2 += (double)f[c] * f[c];
		}
		if (!ok)
			continue;
		v[n].truth = tv[i] = t / 3.0;
		v[n].key = fit ? err_map[i] / (m2 / 3.0 + METRICS_RELMSE_EPS) : err_map[i];
		total += v[n].truth;
		est += v[n].key;
		n++;
	}
	if (!n) {
		free(v);
		free(tv);
		if (err && errlen)
			snprintf(err, errlen, "no pixel is finite in all images");
		return -1;
	}
	out->true_relmse = total / n;
	out->est_relmse = est / n;
	out->capture = top_share(v, n, total);
	for (size_t i = 0; i < n; i++)
		v[i].key = v[i].truth;
	out->oracle = top_share(v, n, total);
	/* the local ranking: by the mean truth of each pixel's neighbourhood */
	size_t k = 0;
	for (int y = 0; y < img->h; y++)
		for (int x = 0; x < img->w; x++) {
			double t = tv[(size_t)y * img->w + x];
			if (!isfinite(t))
				continue;
			v[k].truth = t;
			v[k].key = local_mean(tv, img->w, img->h, x, y);
			k++;
		}
	out->local = top_share(v, k, total);
	free(v);
	free(tv);
	return 0;
}
