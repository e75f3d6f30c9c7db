/*
 * downsample.h - box-average an image by an integer factor.
 *
 * Resolution scaling is POV-Ray's second way of adding samples: render at
 * s*W x s*H with antialiasing off, then average each s x s block into one
 * pixel.  Each output pixel is then the mean of exactly s^2 stratified
 * samples, and the spread of those samples gives a per-pixel variance that
 * POV-Ray's own antialiasing never reports.
 */
#ifndef POVPRESS_DOWNSAMPLE_H
#define POVPRESS_DOWNSAMPLE_H

#include <stddef.h>

#include "driver/image.h"

/*
 * Average each s x s block of in into one pixel of *mean, an
 * in->w / s x in->h / s image with in's channels and channel names (for
 * POV-Ray's output, R, G, B).  When var is not NULL, *var receives the
 * same-sized image of the blocks' unbiased sample variances, per channel:
 * sum (x - mean)^2 / (s^2 - 1) over the block's s^2 samples, which is the
 * variance of one sample, not of their mean (divide by s^2 for that); it is
 * 0 for s = 1.  Sums are accumulated in double and the mean is subtracted
 * before squaring, so a large constant offset costs no precision.  A NaN or
 * infinity in a block makes that block's mean and variance non-finite.
 *
 * s must be at least 1 and divide in->w and in->h.  Returns 0, or -1 with a
 * message in err (bad factor, sizes that are not multiples of s, no
 * memory), leaving *mean and *var zeroed.  mean and var must be distinct
 * from in.  You own *mean and *var; free them with image_release().
 */
int image_box_down(const struct image *in, int s, struct image *mean, struct image *var,
		   char *err, size_t errlen);

#endif
