/*
 * gen_image - write synthetic EXR test images with known content.
 *
 *   gen_image PATTERN W H OUT.exr [SEED]
 *
 * x and y are pixel coordinates (y downward); X = (x - W/2) / W and
 * Y = (y - H/2) / H, computed in double, so X and Y run over about
 * [-0.5, 0.5).  c is the channel index (R = 0, G = 1, B = 2).  Images are
 * float RGB unless the pattern says otherwise.  Noise comes from a
 * splitmix64 generator seeded by SEED (default 1) through Box-Muller, so
 * the same arguments always give the same file.
 */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "driver/image.h"

#define PI 3.14159265358979323846

struct rng {
	uint64_t state;
	int have_spare;
	double spare;
};

static uint64_t rng_next(struct rng *r)
{
	uint64_t z = (r->state += 0x9e3779b97f4a7c15ULL);

	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
	return z ^ (z >> 31);
}

/* Uniform in (0, 1]: never 0, so log() below is finite. */
static double rng_uniform(struct rng *r)
{
	return ((double)(rng_next(r) >> 11) + 1.0) * 0x1.0p-53;
}

/* Standard normal deviate (Box-Muller, both values of each pair used). */
static double rng_gauss(struct rng *r)
{
	double u1, u2, rad;

	if (r->have_spare) {
		r->have_spare = 0;
		return r->spare;
	}
	u1 = rng_uniform(r);
	u2 = rng_uniform(r);
	rad = sqrt(-2.0 * log(u1));
	r->spare = rad * sin(2.0 * PI * u2);
	r->have_spare = 1;
	return rad * cos(2.0 * PI * u2);
}

struct gen {
	int w, h;
	struct rng rng;
};

static double coord_x(const struct gen *g, int x)
{
	return ((double)x - 0.5 * g->w) / g->w;
}

static double coord_y(const struct gen *g, int y)
{
	return ((double)y - 0.5 * g->h) / g->h;
}

static double quadratic(const struct gen *g, int x, int y, int c)
{
	double X = coord_x(g, x), Y = coord_y(g, y);

	return 0.4 + 0.1 * c + 0.3 * X + 0.2 * Y + 0.5 * X * X - 0.3 * X * Y + 0.4 * Y * Y;
}

/* High-frequency texture shared by all channels. */
static double texture_t(int x, int y)
{
	return 0.5 + 0.4 * sin(2.1 * x) * sin(1.7 * y);
}

/* Smooth shading, brighter in later channels. */
static double texture_s(const struct gen *g, int x, int y, int c)
{
	double X = coord_x(g, x), Y = coord_y(g, y);

	return (0.6 + 0.3 * X + 0.2 * Y * Y) * (1.0 + 0.1 * c);
}

enum pattern {
	P_QUADRATIC, P_RAMP, P_NOISE, P_STEP, P_HOLES, P_TEXTURE, P_TEXTURE_FEATURE,
	P_TEXTURE_CLEAN, P_QUADRATIC_HALF, P_RGBA, P_NOCOLOUR
};

static const struct {
	const char *name;
	enum pattern p;
	const char *help;
} patterns[] = {
	{ "quadratic", P_QUADRATIC, "smooth quadratic surface in X, Y" },
	{ "ramp", P_RAMP, "0.2 + 0.001*(c+1)*x + 0.002*y" },
	{ "noise", P_NOISE, "0.5 + gaussian noise, sigma 0.05" },
	{ "step", P_STEP, "0.2 left of W/2, 0.8 from there on" },
	{ "holes", P_HOLES, "quadratic with 5% NaN pixels and a 6x6 NaN block" },
	{ "texture", P_TEXTURE, "texture * shading + gaussian noise, sigma 0.02" },
	{ "texture-feature", P_TEXTURE_FEATURE, "the texture alone, noise-free" },
	{ "texture-clean", P_TEXTURE_CLEAN, "texture * shading, noise-free" },
	{ "quadratic-half", P_QUADRATIC_HALF, "quadratic stored as half" },
	{ "rgba", P_RGBA, "quadratic plus A = 1" },
	{ "nocolour", P_NOCOLOUR, "one channel Z (quadratic, channel 0)" },
};

static void usage(FILE *f)
{
	fprintf(f, "usage: gen_image PATTERN W H OUT.exr [SEED]\n\npatterns:\n");
	for (size_t i = 0; i < sizeof(patterns) / sizeof(patterns[0]); i++)
		fprintf(f, "  %-16s %s\n", patterns[i].name, patterns[i].help);
}

static int parse_int(const char *s, long lo, long hi, long *out)
{
	char *end;
	long v;

	errno = 0;
	v = strtol(s, &end, 10);
	if (errno || end == s || *end || v < lo || v > hi)
		return -1;
	*out = v;
	return 0;
}

static void fill(struct image *img, enum pattern p, struct gen *g)
{
	for (int y = 0; y < img->h; y++) {
		for (int x = 0; x < img->w; x++) {
			float *px = img->px + ((size_t)y * img->w + x) * img->nch;
			/* one draw per pixel, whether or not it becomes a hole */
			int hole = p == P_HOLES && rng_uniform(&g->rng) <= 0.05;

			for (int c = 0; c < img->nch; c++) {
				double v;

				switch (p) {
				case P_RAMP:
					v = 0.2 + 0.001 * (c + 1) * x + 0.002 * y;
					break;
				case P_NOISE:
					v = 0.5 + 0.05 * rng_gauss(&g->rng);
					break;
				case P_STEP:
					v = x < 0.5 * g->w ? 0.2 : 0.8;
					break;
				case P_TEXTURE:
					v = texture_t(x, y) * texture_s(g, x, y, c) +
						0.02 * rng_gauss(&g->rng);
					break;
				case P_TEXTURE_FEATURE:
					v = texture_t(x, y);
					break;
				case P_TEXTURE_CLEAN:
					v = texture_t(x, y) * texture_s(g, x, y, c);
					break;
				case P_RGBA:
					v = c == 3 ? 1.0 : quadratic(g, x, y, c);
					break;
				case P_HOLES:
					v = hole ? NAN : quadratic(g, x, y, c);
					break;
				case P_QUADRATIC:
				case P_QUADRATIC_HALF:
				case P_NOCOLOUR:
				default:
					v = quadratic(g, x, y, c);
					break;
				}
				px[c] = (float)v;
			}
		}
	}
	if (p == P_HOLES) {
		int x0 = g->w / 3, y0 = g->h / 3;

		for (int y = y0; y < y0 + 6 && y < img->h; y++)
			for (int x = x0; x < x0 + 6 && x < img->w; x++)
				for (int c = 0; c < img->nch; c++)
					img->px[((size_t)y * img->w + x) * img->nch + c] = NAN;
	}
}

int main(int argc, char **argv)
{
	static const char *const rgba[] = { "R", "G", "B", "A" };
	static const char *const z[] = { "Z" };
	struct image img = { 0 };
	struct gen g;
	char err[512];
	long w, h, seed = 1;
	enum pattern p = P_QUADRATIC;
	size_t i, np = sizeof(patterns) / sizeof(patterns[0]);
	int nch, rc;

	if (argc == 2 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) {
		usage(stdout);
		return 0;
	}
	if (argc < 5 || argc > 6) {
		usage(stderr);
		return 2;
	}
	for (i = 0; i < np; i++)
		if (!strcmp(argv[1], patterns[i].name))
			break;
	if (i == np) {
		fprintf(stderr, "gen_image: unknown pattern '%s'\n", argv[1]);
		usage(stderr);
		return 2;
	}
	p = patterns[i].p;
	if (parse_int(argv[2], 1, 1 << 16, &w) || parse_int(argv[3], 1, 1 << 16, &h)) {
		fprintf(stderr, "gen_image: bad size '%s' x '%s' (1 to 65536)\n",
			argv[2], argv[3]);
		return 2;
	}
	if (argc == 6 && parse_int(argv[5], 0, LONG_MAX, &seed)) {
		fprintf(stderr, "gen_image: bad seed '%s'\n", argv[5]);
		return 2;
	}

	nch = p == P_RGBA ? 4 : p == P_NOCOLOUR ? 1 : 3;
	if (image_init(&img, (int)w, (int)h, nch, p == P_NOCOLOUR ? z : rgba,
		       err, sizeof(err))) {
		fprintf(stderr, "gen_image: %s\n", err);
		return 1;
	}
	memset(&g, 0, sizeof(g));
	g.w = (int)w;
	g.h = (int)h;
	g.rng.state = (uint64_t)seed;
	fill(&img, p, &g);

	if (p == P_QUADRATIC_HALF)
		rc = image_write_exr_half(argv[4], &img, err, sizeof(err));
	else
		rc = image_write_exr(argv[4], &img, err, sizeof(err));
	image_release(&img);
	if (rc) {
		fprintf(stderr, "gen_image: %s\n", err);
		return 1;
	}
	return 0;
}
