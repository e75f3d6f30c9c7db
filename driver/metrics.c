/*
 * metrics.c - relMSE, MSE and PSNR of an image against a reference.
 */
#include "driver/metrics.h"

#include <math.h>
#include <stdio.h>
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
