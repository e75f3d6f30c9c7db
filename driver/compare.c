/*
 * compare.c - "povpress compare": error of an image against a reference.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "driver/commands.h"
#include "driver/image.h"
#include "driver/metrics.h"

static const char compare_usage[] =
	"usage: povpress compare IMAGE.exr REF.exr [--analysis ANALYSIS.exr]\n"
	"\n"
	"Print the error of IMAGE against the reference REF over the R, G, B\n"
	"channels (a lone Y channel stands for all three):\n"
	"\n"
	"  relmse: V   mean of (x - ref)^2 / (ref^2 + 0.01)\n"
	"  mse: V      mean of (x - ref)^2\n"
	"  psnr: V     10 log10(1 / mse), peak 1; inf when mse is 0\n"
	"\n"
	"Pixels that are NaN or infinite in either image are left out, and a\n"
	"fourth line \"skipped: N\" counts them.\n"
	"\n"
	"With --analysis, the output of 'povpress analyze IMAGE.exr' (its error and\n"
	"R, G, B channels) or the error map of 'povpress render' (its relerror\n"
	"channel) is judged as a prediction of IMAGE's true error:\n"
	"\n"
	"  est_relmse: V  the relMSE the error map predicts for IMAGE\n"
	"  capture20: V   share of the true error in the 20% of pixels the map\n"
	"                 ranks highest\n"
	"  oracle20: V    the same share for a perfect ranking\n"
	"  local20: V     the same share for a ranking by each pixel's 3x3\n"
	"                 neighbourhood's mean true error (which knows where the\n"
	"                 error lies but not how each pixel's noise fell, as the\n"
	"                 oracle does)\n";

/* Read path and reduce it to R, G, B; prints the error itself. */
static int load_rgb(const char *path, struct image *rgb)
{
	struct image img;
	char err[1024];
	int rc;

	if (image_read_exr(path, &img, err, sizeof(err))) {
		fprintf(stderr, "povpress compare: %s\n", err);
		return -1;
	}
	rc = image_rgb(&img, path, rgb, err, sizeof(err));
	image_release(&img);
	if (rc)
		fprintf(stderr, "povpress compare: %s\n", err);
	return rc;
}

int cmd_compare(int argc, char **argv)
{
	struct image img = { 0 }, ref = { 0 }, ana = { 0 }, fit = { 0 };
	const char *paths[2], *analysis = NULL;
	struct metrics m;
	char err[1024];
	int npaths = 0, options_done = 0, ret = 1;

	for (int i = 1; i < argc; i++) {
		const char *arg = argv[i];

		if (!options_done && arg[0] == '-' && arg[1]) {
			if (!strcmp(arg, "--")) {
				options_done = 1;
				continue;
			}
			if (!strcmp(arg, "--help") || !strcmp(arg, "-h")) {
				fputs(compare_usage, stdout);
				return 0;
			}
			if (!strcmp(arg, "--analysis") && i + 1 < argc) {
				analysis = argv[++i];
				continue;
			}
			fprintf(stderr, "povpress compare: unknown option '%s'\n\n", arg);
			fputs(compare_usage, stderr);
			return 2;
		}
		if (npaths == 2) {
			fprintf(stderr, "povpress compare: too many arguments\n\n");
			fputs(compare_usage, stderr);
			return 2;
		}
		paths[npaths++] = arg;
	}
	if (npaths != 2) {
		fputs(compare_usage, stderr);
		return 2;
	}

	if (load_rgb(paths[0], &img) || load_rgb(paths[1], &ref))
		goto out;
	if (img.w != ref.w || img.h != ref.h) {
		fprintf(stderr, "povpress compare: '%s' is %dx%d but '%s' is %dx%d\n",
			paths[0], img.w, img.h, paths[1], ref.w, ref.h);
		goto out;
	}
	if (metrics_compute(&img, &ref, &m, err, sizeof(err))) {
		fprintf(stderr, "povpress compare: cannot compare '%s' with '%s': %s\n",
			paths[0], paths[1], err);
		goto out;
	}

	printf("relmse: %.6g\n", m.relmse);
	printf("mse: %.6g\n", m.mse);
	if (isinf(m.psnr))
		printf("psnr: inf\n");
	else
		printf("psnr: %.6g\n", m.psnr);
	if (m.skipped)
		printf("skipped: %zu\n", m.skipped);
	if (analysis) {
		struct fidelity fd;
		int ech;
		if (image_read_exr(analysis, &ana, err, sizeof(err))) {
			fprintf(stderr, "povpress compare: %s\n", err);
			goto out;
		}
		/* a render's error map has its relative error; an analysis has
		 * the absolute one and the fit to make it relative with */
		int rel = image_channel(&ana, "relerror") >= 0;
		if (!rel && image_rgb(&ana, analysis, &fit, err, sizeof(err))) {
			fprintf(stderr, "povpress compare: %s\n", err);
			goto out;
		}
		ech = image_channel(&ana, rel ? "relerror" : "error");
		if (ech < 0) {
			fprintf(stderr, "povpress compare: '%s' has no error channel\n", analysis);
			goto out;
		}
		if (ana.w != img.w || ana.h != img.h) {
			fprintf(stderr, "povpress compare: '%s' is %dx%d, not %dx%d\n", analysis,
				ana.w, ana.h, img.w, img.h);
			goto out;
		}
		size_t n = (size_t)ana.w * ana.h;
		float *emap = malloc(n * sizeof(float));
		if (!emap) {
			fprintf(stderr, "povpress compare: out of memory\n");
			goto out;
		}
		for (size_t i = 0; i < n; i++)
			emap[i] = ana.px[i * ana.nch + ech];
		int rc = metrics_fidelity(&img, &ref, emap, rel ? NULL : &fit, &fd, err,
					  sizeof(err));
		free(emap);
		if (rc) {
			fprintf(stderr, "povpress compare: cannot judge '%s': %s\n", analysis, err);
			goto out;
		}
		printf("est_relmse: %.6g\n", fd.est_relmse);
		printf("capture20: %.4f\n", fd.capture);
		printf("oracle20: %.4f\n", fd.oracle);
		printf("local20: %.4f\n", fd.local);
	}
	if (fflush(stdout) || ferror(stdout)) {
		fprintf(stderr, "povpress compare: cannot write output: %s\n", strerror(errno));
		goto out;
	}
	ret = 0;
out:
	image_release(&img);
	image_release(&ref);
	image_release(&ana);
	image_release(&fit);
	return ret;
}
