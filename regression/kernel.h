/*
 * kernel.h - the tricube kernel used by every local fit.
 *
 * w(u) = (1 - |u|^3)^3 for |u| < 1, else 0: the kernel loess and locfit call
 * tricube.  Windows are square, radius r pixels, and the 2-D weight of an
 * offset (i, j) is the product w(i / (r + 1)) * w(j / (r + 1)), so that every
 * sample of the window has a positive weight and the kernel is separable.
 */
#ifndef LPR_KERNEL_H
#define LPR_KERNEL_H

/* The tricube weight of a scaled distance u. */
double kernel_tricube(double u);

/* Fill t[0 .. 2r] with the 1-D weights of offsets -r .. r for radius r >= 1. */
void kernel_weights(int r, double *t);

#endif
