/*
 * denoise.h - the final image's filter: non-local means weighted by each
 * pixel's noise.
 *
 * Every pixel p becomes a weighted mean of the pixels q within `radius` of
 * it (a locally constant regression whose kernel is the similarity of the
 * two pixels' neighbourhoods rather than their distance).  The weight of q
 * is exp(-max(d, 0)), d the mean over the (2 patch + 1)^2 offsets o around
 * the two pixels and over R, G, B of
 *
 *   ((Y(p+o) - Y(q+o))^2 - (V(p+o) + min(V(p+o), V(q+o))))
 *     / (2 k^2 min(V(p+o), V(q+o)) + 1e-6 (Y(p+o)^2 + 0.01)),
 *
 * each term at least -1.  V is the variance of each value's error, so the
 * numerator is the squared difference beyond what noise alone would give
 * (Rousselle, Knaus and Zwicker's variance-cancelled distance), and the
 * denominator scales it by the quieter pixel's noise: a star among dark
 * sky, far noisier than its neighbours, is not of their kind and keeps its
 * value (the sum of the two variances averaged the starfield's stars into
 * the sky: relMSE up to 1.75 times higher, at k = 1.5).  The floor of -1
 * keeps one noise-free pair (V = 0) from cancelling the whole patch.
 * Pixels with V = 0 all round take only neighbours equal to them within
 * about 0.1%.  k = 0.75 rather than 1.5: the larger took 2% more error off
 * the bundled scenes but blurred texture as faint as the noise (Debian's
 * woodbox: 1.24 times the unfiltered error; see the README).
 */
#ifndef POVPRESS_DENOISE_H
#define POVPRESS_DENOISE_H

#include <stddef.h>

struct denoise_params {
	int radius;	/* search window: (2 radius + 1)^2 pixels, default 3 */
	int patch;	/* neighbourhood compared: (2 patch + 1)^2, default 2 */
	double k;	/* how far beyond the noise two pixels may differ, 0.75 */
	int nthreads;	/* 0: one per online core */
};

void denoise_params_init(struct denoise_params *p);

/*
 * Filter the w x h RGB image rgb (row-major, 3 floats a pixel) whose values
 * have error variances var (the same layout; 0 where none is known) into
 * out (w x h x 3).  When not NULL, vout receives each output value's
 * variance from the inputs' noise, sum_q w_q^2 V_q / (sum_q w_q)^2, and
 * self each pixel's own weight in its mean, w_p / sum_q w_q (the output's
 * derivative with respect to the pixel's value, for a SURE estimate of the
 * filter's error).  Returns 0, or -1 with a message in err (bad sizes or
 * parameters, out of memory).
 */
int denoise_nlm(int w, int h, const float *rgb, const float *var,
		const struct denoise_params *p, float *out, float *vout, float *self,
		char *err, size_t errlen);

#endif
