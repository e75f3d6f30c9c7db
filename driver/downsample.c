/*
 * downsample.c - box-average an image by an integer factor.
 *
 * The image is walked one band of s input rows at a time, row by row, so
 * memory is read in order: a first pass sums every block of the band into
 * one row of double accumulators, and, when a variance is wanted, a second
 * pass over the same rows sums the squared deviations from those means
 * (two passes rather than sum of squares minus square of sum, which loses
 * every digit on a bright, nearly constant block).
 */
#include "driver/downsample.h"
#include "driver/errbuf.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int image_box_down(const struct image *in, int s, struct image *mean, struct image *var,
		   char *err, size_t errlen)
{
	double *sum = NULL, *dev = NULL;
	size_t nch, orow;
	double n;
	int ow, oh;

	memset(mean, 0, sizeof(*mean));
	if (var)
		memset(var, 0, sizeof(*var));
	if (s < 1) {
		errbuf_printf(err, errlen, "invalid downsampling factor %d", s);
		return -1;
	}
	if (in->w <= 0 || in->h <= 0 || in->nch <= 0 || !in->px) {
		errbuf_printf(err, errlen, "cannot downsample an empty image");
		return -1;
	}
	if (in->w % s || in->h % s) {
		errbuf_printf(err, errlen, "image size %dx%d is not a multiple of %d",
			      in->w, in->h, s);
		return -1;
	}
	ow = in->w / s;
	oh = in->h / s;
	nch = (size_t)in->nch;
	orow = (size_t)ow * nch;
	n = (double)s * (double)s;

	if (image_init(mean, ow, oh, in->nch, (const char *const *)in->names, err, errlen))
		return -1;
	if (var && image_init(var, ow, oh, in->nch, (const char *const *)in->names,
			      err, errlen))
		goto fail;
	sum = malloc(orow * sizeof(double));
	if (var)
		dev = malloc(orow * sizeof(double));
	if (!sum || (var && !dev)) {
		errbuf_printf(err, errlen, "out of memory for a %dx%d image with %d channels",
			      ow, oh, in->nch);
		goto fail;
	}

	for (int by = 0; by < oh; by++) {
		float *mrow = mean->px + (size_t)by * orow;

		for (size_t i = 0; i < orow; i++)
			sum[i] = 0.0;
		for (int y = by * s; y < (by + 1) * s; y++) {
			const float *row = in->px + (size_t)y * (size_t)in->w * nch;

			for (int x = 0; x < in->w; x++) {
				double *acc = sum + (size_t)(x / s) * nch;

				for (size_t c = 0; c < nch; c++)
					acc[c] += (double)row[(size_t)x * nch + c];
			}
		}
		for (size_t i = 0; i < orow; i++) {
			sum[i] /= n;
			mrow[i] = (float)sum[i];
		}
		if (!var)
			continue;

		float *vrow = var->px + (size_t)by * orow;

		if (s == 1) {
			for (size_t i = 0; i < orow; i++)
				vrow[i] = isfinite(sum[i]) ? 0.0f : NAN;
			continue;
		}
		for (size_t i = 0; i < orow; i++)
			dev[i] = 0.0;
		for (int y = by * s; y < (by + 1) * s; y++) {
			const float *row = in->px + (size_t)y * (size_t)in->w * nch;

			for (int x = 0; x < in->w; x++) {
				size_t o = (size_t)(x / s) * nch;

				for (size_t c = 0; c < nch; c++) {
					double d = (double)row[(size_t)x * nch + c] - sum[o + c];

					dev[o + c] += d * d;
				}
			}
		}
		for (size_t i = 0; i < orow; i++)
			vrow[i] = (float)(dev[i] / (n - 1.0));
	}
	free(sum);
	free(dev);
	return 0;

fail:
	free(sum);
	free(dev);
	image_release(mean);
	if (var)
		image_release(var);
	return -1;
}
