/*
 * bench_analyze.c - analysis throughput of the regression core.
 *
 * Builds a 1920x1080 RGB test image (smooth shading, a texture, edges and
 * noise, so every path and candidate is exercised) and times lpr_analyze
 * with the default settings and with each fixed order, as wall-clock
 * megapixels per second (best of several runs), and once with a 3-channel
 * feature image.  Then, in the same run, it
 * times the fast interior path against the general path on the same pixels
 * (a 480x270 crop, every pixel forced through the general path).
 */
#include "regression/lpr.h"
#include "scripts/bench.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static unsigned long long rng = 0x9e3779b97f4a7c15ull;

static double now(void)
{
	return bench_clock(CLOCK_MONOTONIC);
}


static double best_time_f(const struct lpr_image *img, const struct lpr_image *feat,
			  const struct lpr_params *p, int reps)
{
	double best = 1e30;
	char err[256];
	for (int i = 0; i < reps; i++) {
		struct lpr_result r;
		double t0 = now();
		if (lpr_analyze(img, feat, p, &r, err, sizeof err)) {
			fprintf(stderr, "bench: %s\n", err);
			exit(1);
		}
		double t = now() - t0;
		lpr_result_release(&r);
		best = t < best ? t : best;
	}
	return best;
}

static double best_time(const struct lpr_image *img, const struct lpr_params *p, int reps)
{
	return best_time_f(img, NULL, p, reps);
}

int main(int argc, char **argv)
{
	int reps = argc > 1 ? atoi(argv[1]) : 3;
	const int w = 1920, h = 1080;
	float *px = malloc(sizeof(float) * w * h * 3);
	if (!px)
		return 1;
	bench_image(px, NULL, w, h, &rng);
	struct lpr_image img = { w, h, 3, px };
	struct lpr_params p;
	double mp = w * (double)h / 1e6;

	printf("analysis of a %dx%d RGB image, wall time, best of %d\n", w, h, reps);
	printf("%-22s %9s %9s\n", "setting", "seconds", "MP/s");
	const char *names[] = { "default (auto)", "--order 0", "--order 1", "--order 2" };
	for (int o = -1; o <= 2; o++) {
		lpr_params_init(&p);
		p.order = o;
		double t = best_time(&img, &p, reps);
		printf("%-22s %9.3f %9.2f\n", names[o + 1], t, mp / t);
	}
	lpr_params_init(&p);
	p.nradii = 2;
	p.radii[0] = 2;
	p.radii[1] = 5;
	double t25 = best_time(&img, &p, reps);
	printf("%-22s %9.3f %9.2f\n", "--radii 2,5", t25, mp / t25);
	lpr_params_init(&p);
	p.nthreads = 1;
	double t1 = best_time(&img, &p, reps);
	printf("%-22s %9.3f %9.2f\n", "default, 1 thread", t1, mp / t1);

	/* With a noise-free 3-channel feature image (the texture). */
	float *fpx = malloc(sizeof(float) * w * h * 3);
	if (!fpx)
		return 1;
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++)
			for (int c = 0; c < 3; c++)
				fpx[((size_t)y * w + x) * 3 + c] =
					(float)(((x / 40 + y / 40) % 2 ? 1.0 : 0.6) * (1.0 + 0.2 * c));
	struct lpr_image fimg = { w, h, 3, fpx };
	lpr_params_init(&p);
	double tfe = best_time_f(&img, &fimg, &p, 1);
	printf("%-22s %9.3f %9.2f\n", "--features (3 ch)", tfe, mp / tfe);

	/* Fast against general path, same pixels, same run. */
	const int cw = 480, ch = 270;
	float *crop = malloc(sizeof(float) * cw * ch * 3);
	for (int y = 0; y < ch; y++)
		memcpy(crop + (size_t)y * cw * 3, px + ((size_t)(y + 400) * w + 700) * 3,
		       sizeof(float) * cw * 3);
	struct lpr_image cimg = { cw, ch, 3, crop };
	lpr_params_init(&p);
	double tf = best_time(&cimg, &p, reps);
	p.force_general = 1;
	double tg = best_time(&cimg, &p, reps);
	printf("fast path vs general path on a %dx%d crop: %.3f s vs %.3f s, "
	       "fast is %.1fx faster\n", cw, ch, tf, tg, tg / tf);
	free(crop);
	free(fpx);
	free(px);
	return 0;
}
