/*
 * analyze.c - `povpress analyze`: the regression's view of one image.
 */
#include "driver/args.h"
#include "driver/commands.h"
#include "driver/image.h"
#include "regression/lpr.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static const char usage[] =
	"usage: povpress analyze IN.exr -o OUT.exr [--features F.exr] [--order auto|0|1|2]\n"
	"                        [--radius auto|R] [--radii R1,R2,...] [--threads N] [-v]\n"
	"\n"
	"Fit a local polynomial regression at every pixel of IN.exr (RGB or RGBA,\n"
	"half or float, scanline or tiled; NaN/Inf pixels are holes), choose the\n"
	"order and radius per pixel by PRESS, and write OUT.exr (float) with:\n"
	"  R, G, B          the reconstruction (fitted value; holes filled)\n"
	"  error            estimated squared error of the input pixel, mean over R, G, B\n"
	"  order            selected polynomial order (0, 1 or 2)\n"
	"  bandwidth        selected kernel radius in pixels (0: no estimate)\n"
	"  dx.R dx.G dx.B   derivative along x (to the right), per pixel\n"
	"  dy.R dy.G dy.B   derivative along y (downward), per pixel\n"
	"  leverage         H_cc, the weight of the pixel in its own fit\n"
	"\n"
	"options:\n"
	"  -o, --output FILE   output EXR (required)\n"
	"  --features FILE     noise-free feature image of the same size (e.g. a POV-Ray\n"
	"                      +Q1 render); its R, G, B (or all channels) become predictors\n"
	"  --order auto|N      fix the polynomial order (default auto)\n"
	"  --radius auto|R     fix the kernel radius, 1..32 (default auto)\n"
	"  --radii LIST        the radii auto chooses among, comma-separated, at most 8\n"
	"                      (default 2,3,5,8; fewer and smaller radii are faster)\n"
	"  --threads N         worker threads (default: one per core)\n"
	"  -v, --verbose       print timing and summary figures to stderr\n"
	"  -h, --help          this text\n";

/* "2,5,8" -> p->radii; -1 on anything else. */
static int parse_radii(const char *s, struct lpr_params *p)
{
	char buf[128];
	if (strlen(s) >= sizeof buf)
		return -1;
	strcpy(buf, s);
	int n = 0;
	for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok;
	     tok = strtok_r(NULL, ",", &save)) {
		if (n == 8 || args_int(tok, 1, LPR_MAXRADIUS, &p->radii[n]))
			return -1;
		n++;
	}
	if (!n)
		return -1;
	p->nradii = n;
	return 0;
}

static double now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Feature predictors: the colour channels if there are any, else all. */
static int load_features(const char *path, const struct image *img, struct image *out,
			 char *err, size_t errlen)
{
	struct image raw = {0};
	if (image_read_exr(path, &raw, err, errlen))
		return -1;
	if (raw.w != img->w || raw.h != img->h) {
		snprintf(err, errlen, "features '%s' are %dx%d but the image is %dx%d", path,
			 raw.w, raw.h, img->w, img->h);
		image_release(&raw);
		return -1;
	}
	if (image_channel(&raw, "R") >= 0 || image_channel(&raw, "Y") >= 0) {
		int rc = image_rgb(&raw, path, out, err, errlen);
		image_release(&raw);
		return rc;
	}
	if (raw.nch > LPR_MAXFEAT) {
		snprintf(err, errlen, "features '%s' have %d channels (at most %d)", path, raw.nch,
			 LPR_MAXFEAT);
		image_release(&raw);
		return -1;
	}
	*out = raw;
	return 0;
}

static const char *const out_names[] = {
	"R", "G", "B", "error", "order", "bandwidth", "leverage",
	"dx.R", "dx.G", "dx.B", "dy.R", "dy.G", "dy.B",
};
#define NOUT (int)(sizeof out_names / sizeof out_names[0])

static int build_output(const struct lpr_result *r, struct image *out, char *err, size_t errlen)
{
	if (image_init(out, r->w, r->h, NOUT, out_names, err, errlen))
		return -1;
	size_t n = (size_t)r->w * r->h;
	for (size_t i = 0; i < n; i++) {
		float *o = out->px + i * NOUT;
		for (int c = 0; c < 3; c++) {
			o[c] = r->fit[i * 3 + c];
			o[7 + c] = r->dx[i * 3 + c];
			o[10 + c] = r->dy[i * 3 + c];
		}
		o[3] = r->error[i];
		o[4] = r->order[i];
		o[5] = r->bandwidth[i];
		o[6] = r->leverage[i];
	}
	return 0;
}

int cmd_analyze(int argc, char **argv)
{
	const char *in = NULL, *outpath = NULL, *feat = NULL;
	int verbose = 0;
	struct lpr_params p;
	lpr_params_init(&p);

	for (int i = 1; i < argc; i++) {
		const char *a = argv[i];
		int more = i + 1 < argc;
		if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
			fputs(usage, stdout);
			return 0;
		} else if (!strcmp(a, "-v") || !strcmp(a, "--verbose")) {
			verbose = 1;
		} else if ((!strcmp(a, "-o") || !strcmp(a, "--output")) && more) {
			outpath = argv[++i];
		} else if (!strcmp(a, "--features") && more) {
			feat = argv[++i];
		} else if (!strcmp(a, "--order") && more) {
			const char *v = argv[++i];
			if (!strcmp(v, "auto"))
				p.order = -1;
			else if (args_int(v, 0, 2, &p.order)) {
				fprintf(stderr, "povpress analyze: bad --order '%s' (auto, 0, 1 or 2)\n", v);
				return 2;
			}
		} else if (!strcmp(a, "--radius") && more) {
			const char *v = argv[++i];
			if (!strcmp(v, "auto"))
				p.radius = 0;
			else if (args_int(v, 1, LPR_MAXRADIUS, &p.radius)) {
				fprintf(stderr, "povpress analyze: bad --radius '%s' (auto or 1..%d)\n", v,
					LPR_MAXRADIUS);
				return 2;
			}
		} else if (!strcmp(a, "--radii") && more) {
			const char *v = argv[++i];
			if (parse_radii(v, &p)) {
				fprintf(stderr, "povpress analyze: bad --radii '%s' (1 to 8 radii in 1..%d, "
					"comma-separated)\n", v, LPR_MAXRADIUS);
				return 2;
			}
		} else if (!strcmp(a, "--threads") && more) {
			const char *v = argv[++i];
			if (args_int(v, 1, 1024, &p.nthreads)) {
				fprintf(stderr, "povpress analyze: bad --threads '%s'\n", v);
				return 2;
			}
		} else if (a[0] == '-' && a[1]) {
			fprintf(stderr, "povpress analyze: unknown option or missing value '%s'\n%s", a,
				usage);
			return 2;
		} else if (!in) {
			in = a;
		} else {
			fprintf(stderr, "povpress analyze: unexpected argument '%s'\n%s", a, usage);
			return 2;
		}
	}
	if (!in || !outpath) {
		fprintf(stderr, "povpress analyze: %s\n%s",
			!in ? "no input image given" : "no output given (-o OUT.exr)", usage);
		return 2;
	}

	char err[512];
	int rc = 1;
	struct image raw = {0}, rgb = {0}, fimg = {0}, out = {0};
	struct lpr_result res = {0};
	double t0 = now();
	if (image_read_exr(in, &raw, err, sizeof err) ||
	    image_rgb(&raw, in, &rgb, err, sizeof err))
		goto fail;
	image_release(&raw);
	if (feat && load_features(feat, &rgb, &fimg, err, sizeof err))
		goto fail;
	double t1 = now();
	struct lpr_image li = { rgb.w, rgb.h, 3, rgb.px };
	struct lpr_image lf = { fimg.w, fimg.h, fimg.nch, fimg.px };
	char lerr[256];
	if (lpr_analyze(&li, feat ? &lf : NULL, &p, &res, lerr, sizeof lerr)) {
		snprintf(err, sizeof err, "cannot analyse '%s': %s", in, lerr);
		goto fail;
	}
	double t2 = now();
	if (build_output(&res, &out, err, sizeof err) ||
	    image_write_exr(outpath, &out, err, sizeof err))
		goto fail;
	if (verbose) {
		size_t n = (size_t)res.w * res.h;
		double me = 0.0;
		size_t cnt[3] = {0}, fin = 0;
		for (size_t i = 0; i < n; i++) {
			if (isfinite(res.error[i])) {
				me += res.error[i];
				fin++;
			}
			int o = (int)res.order[i];
			if (o >= 0 && o <= 2)
				cnt[o]++;
		}
		fprintf(stderr,
			"povpress analyze: %dx%d, read %.3f s, analysis %.3f s, write %.3f s\n"
			"  mean error %.6g; order 0/1/2 on %.1f%%/%.1f%%/%.1f%% of pixels; "
			"%ld fast and %ld general fits\n",
			res.w, res.h, t1 - t0, t2 - t1, now() - t2, fin ? me / fin : 0.0,
			100.0 * cnt[0] / n, 100.0 * cnt[1] / n, 100.0 * cnt[2] / n, res.fast_pixels,
			res.general_pixels);
	}
	rc = 0;
	goto done;
fail:
	fprintf(stderr, "povpress analyze: %s\n", err);
done:
	image_release(&raw);
	image_release(&rgb);
	image_release(&fimg);
	image_release(&out);
	lpr_result_release(&res);
	return rc;
}
