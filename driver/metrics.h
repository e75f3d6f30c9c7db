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

/*
 * How well an error map predicts the true error of img against ref.
 * Per pixel, the true error is mean_c (x - ref)^2 / (ref^2 + eps) (its
 * relMSE term) and the estimate is est / (mean_c fit^2 + eps), with est the
 * estimated squared error and fit the reconstruction standing in for the
 * unknown reference.
 */
struct fidelity {
	double capture;      /* share of the true error in the top 20% by estimate */
	double oracle;       /* the same share, ranking by the true error itself */
	double local;        /* the same share, ranking by the mean true error of
			      * the pixel's 3 x 3 neighbourhood: a map that knows
			      * the error where it lies but not how each pixel's
			      * noise fell, which the oracle also ranks by */
	double est_relmse;   /* mean estimated relMSE term */
	double true_relmse;  /* mean true relMSE term */
};

/*
 * Compute the fidelity of the estimate err_map (w * h values) with
 * reconstruction fit (RGB, same size) for img against ref (both RGB): the
 * map is of squared errors, made relative with fit's values.  With fit
 * NULL the map is already relative (terms of relMSE).
 * Pixels with a non-finite value anywhere are left out.  Returns 0, or -1
 * with a message on a size mismatch, no usable pixel or no memory.
 */
int metrics_fidelity(const struct image *img, const struct image *ref, const float *err_map,
		     const struct image *fit, struct fidelity *out, char *err, size_t errlen);

#endif
