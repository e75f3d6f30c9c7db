/*
 * metrics.h - error of an image against a reference.
 *
 * Both metrics average over every pixel and every channel of two images of
 * the same size and channel count (normally the R, G, B views made by
 * image_rgb()).  A pixel where any channel of either image is NaN or
 * infinite is left out of both averages and counted instead.
 */
#ifndef POVPRESS_METRICS_H
#define POVPRESS_METRICS_H

#include <stddef.h>

#include "driver/image.h"

/* The regulariser in relMSE's denominator, as in the denoising literature. */
#define METRICS_RELMSE_EPS 0.01

struct metrics {
	double relmse;		/* mean of (x - ref)^2 / (ref^2 + METRICS_RELMSE_EPS) */
	double mse;		/* mean of (x - ref)^2 */
	double psnr;		/* 10 log10(1 / mse), peak 1; +infinity when mse is 0 */
	size_t compared;	/* pixels that went into the means */
	size_t skipped;		/* pixels left out for NaN or infinity */
};

/*
 * Compare img with ref.  Returns 0 and fills *out, or -1 with a message
 * when the sizes or channel counts differ or no pixel is finite in both.
 */
int metrics_compute(const struct image *img, const struct image *ref, struct metrics *out,
		    char *err, size_t errlen);

#endif
