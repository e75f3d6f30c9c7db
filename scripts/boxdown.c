/*
 * boxdown.c - box-average an EXR by an integer factor (a helper of
 * scripts/sweep.sh, built by the Makefile as build/tools/boxdown).
 *
 *     boxdown IN.exr S OUT.exr [VAR.exr]
 *
 * Reads the R, G, B channels of IN.exr (a lone Y channel stands for all
 * three), averages each S x S block into one pixel and writes the means to
 * OUT.exr and, if given, the per-pixel unbiased sample variances of the
 * blocks to VAR.exr (the variance of one sample; divide by S^2 for that of
 * the mean), both as R, G, B float EXR.  This is how a render at S*W x S*H
 * with antialiasing off becomes a W x H image of S^2 samples per pixel.
 * IN's width and height must be multiples of S.
 *
 * Exit status: 0 on success, 1 on a runtime error (unreadable input, sizes
 * that are not multiples of S, an unwritable output), 2 on a usage error.
 */
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "driver/downsample.h"
#include "driver/image.h"

static const char usage[] =
	"usage: boxdown IN.exr S OUT.exr [VAR.exr]\n"
	"\n"
	"Average each S x S block of IN's R, G, B channels into one pixel of\n"
	"OUT.exr, and write the blocks' sample variances to VAR.exr if given.\n";

int main(int argc, char **argv)
{
	struct image in = { 0 }, rgb = { 0 }, mean = { 0 }, var = { 0 };
	char err[1024], *end;
	const char *var_path;
	long s;
	int ret = 1;

	if (argc == 2 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) {
		fputs(usage, stdout);
		return 0;
	}
	if (argc != 4 && argc != 5) {
		fputs(usage, stderr);
		return 2;
	}
	errno = 0;
	s = strtol(argv[2], &end, 10);
	if (errno || end == argv[2] || *end || s < 1 || s > INT_MAX) {
		fprintf(stderr, "boxdown: invalid factor '%s': expected a positive integer\n",
			argv[2]);
		return 2;
	}
	var_path = argc == 5 ? argv[4] : NULL;

	if (image_read_exr(argv[1], &in, err, sizeof(err)) ||
	    image_rgb(&in, argv[1], &rgb, err, sizeof(err))) {
		fprintf(stderr, "boxdown: %s\n", err);
		goto out;
	}
	if (image_box_down(&rgb, (int)s, &mean, var_path ? &var : NULL, err, sizeof(err))) {
		fprintf(stderr, "boxdown: cannot downsample '%s': %s\n", argv[1], err);
		goto out;
	}
	if (image_write_exr(argv[3], &mean, err, sizeof(err)) ||
	    (var_path && image_write_exr(var_path, &var, err, sizeof(err)))) {
		fprintf(stderr, "boxdown: %s\n", err);
		goto out;
	}
	ret = 0;
out:
	image_release(&in);
	image_release(&rgb);
	image_release(&mean);
	image_release(&var);
	return ret;
}
