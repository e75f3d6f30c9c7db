/*
 * bench_denoise.c - speed of the final image's filter (driver/denoise.c).
 *
 * Filters a W x H RGB test image (default 1920x1080: smooth shading, a
 * checker texture and noise whose variance is known, so that the weights
 * take every value from 1 to none) with the default parameters, on one
 * thread and on every core, and prints the best of several runs' wall time
 * and CPU time and the throughput in megapixels per CPU second.
 *
 * usage: bench_denoise [W H [REPS]]
 */
#include "driver/denoise.h"
#include "scripts/bench.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static unsigned long long rng = 0x9e3779b97f4a7c15ull;


int main(int argc, char **argv)
{
	int w = argc > 2 ? atoi(argv[1]) : 1920, h = argc > 2 ? atoi(argv[2]) : 1080;
	int reps = argc > 3 ? atoi(argv[3]) : 3;
	if (w <= 0 || h <= 0 || reps <= 0 || argc == 2 || argc > 4) {
		fprintf(stderr, "usage: bench_denoise [W H [REPS]]\n");
		return 2;
	}
	size_t n = (size_t)w * h * 3;
	float *px = malloc(n * sizeof *px), *var = malloc(n * sizeof *var);
	float *out = malloc(n * sizeof *out), *vout = malloc(n * sizeof *vout);
	float *self = malloc(n / 3 * sizeof *self);
	if (!px || !var || !out || !vout || !self) {
		fprintf(stderr, "bench_denoise: out of memory for a %dx%d image\n", w, h);
		return 1;
	}
	bench_image(px, var, w, h, &rng);
	printf("filter (non-local means) of a %dx%d RGB image, best of %d\n", w, h, reps);
	printf("%-12s %9s %9s %12s\n", "threads", "wall s", "CPU s", "MP/CPU s");
	const int threads[2] = { 1, 0 };
	for (int t = 0; t < 2; t++) {
		double bw = 1e30, bc = 1e30;
		for (int r = 0; r < reps; r++) {
			struct denoise_params p;
			char err[256];
			denoise_params_init(&p);
			p.nthreads = threads[t];
			double w0 = bench_clock(CLOCK_MONOTONIC), c0 = bench_clock(CLOCK_PROCESS_CPUTIME_ID);
			if (denoise_nlm(w, h, px, var, &p, out, vout, self, err, sizeof err)) {
				fprintf(stderr, "bench_denoise: %s\n", err);
				return 1;
			}
			double dw = bench_clock(CLOCK_MONOTONIC) - w0, dc = bench_clock(CLOCK_PROCESS_CPUTIME_ID) - c0;
			bw = dw < bw ? dw : bw;
			bc = dc < bc ? dc : bc;
		}
		printf("%-12s %9.3f %9.3f %12.2f\n", threads[t] ? "1" : "all cores", bw, bc,
		       (double)w * h / 1e6 / bc);
	}
	free(px);
	free(var);
	free(out);
	free(vout);
	free(self);
	return 0;
}
