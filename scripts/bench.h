/*
 * bench.h - what the benchmarks share (scripts/bench_analyze.c,
 * scripts/bench_denoise.c): a clock and a fixed-seed normal deviate, so
 * that each run times the same image.
 */
#ifndef POVPRESS_BENCH_H
#define POVPRESS_BENCH_H

#include <math.h>
#include <stddef.h>
#include <time.h>

/* Seconds on clock id (CLOCK_MONOTONIC for wall time,
 * CLOCK_PROCESS_CPUTIME_ID for the process's CPU). */
static inline double bench_clock(clockid_t id)
{
	struct timespec ts;
	clock_gettime(id, &ts);
	return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* A standard normal deviate from the xorshift state *rng (Box-Muller). */
static inline double bench_gauss(unsigned long long *rng)
{
	double u[2];
	for (int i = 0; i < 2; i++) {
		*rng ^= *rng << 13;
		*rng ^= *rng >> 7;
		*rng ^= *rng << 17;
		u[i] = ((*rng >> 11) + 0.5) * (1.0 / 9007199254740992.0);
	}
	return sqrt(-2.0 * log(u[0])) * cos(6.283185307179586 * u[1]);
}

/* The benchmarks' W x H RGB test image into px (3 floats a pixel): smooth
 * shading, a checker of 40-pixel squares and noise of standard deviation
 * 0.01 on the left half, 0.05 on the right; with var, each value's noise
 * variance.  Every path and candidate of the analysis, and every weight of
 * the filter, is exercised. */
static inline void bench_image(float *px, float *var, int w, int h, unsigned long long *rng)
{
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++) {
			double X = (double)x / w, Y = (double)y / h;
			double shade = 0.3 + 0.5 * X * X + 0.2 * Y;
			double tex = (x / 40 + y / 40) % 2 ? 1.0 : 0.6;
			double sd = X > 0.5 ? 0.05 : 0.01;
			for (int c = 0; c < 3; c++) {
				size_t i = ((size_t)y * w + x) * 3 + c;
				px[i] = (float)(shade * tex * (1.0 + 0.1 * c) + sd * bench_gauss(rng));
				if (var)
					var[i] = (float)(sd * sd);
			}
		}
}

#endif
