/*
 * denoise.c - non-local means weighted by each pixel's noise (denoise.h).
 *
 * For each offset (dx, dy) of the search window, every pixel's term (the
 * distance between it and the pixel at the offset, denoise.h) is computed
 * once, box-summed over the patch (a horizontal then a vertical pass), and
 * the weights it gives are added to the pixels' sums: O(w h (2 radius +
 * 1)^2) with no per-patch loop.  Rows are split into bands, one thread
 * each; a band computes its terms for `patch` rows beyond it on both sides.
 * Terms of pixels beyond the border are those of the nearest pixel inside
 * (the image extended by its edge); a neighbour beyond it is no neighbour.
 */
#include "driver/denoise.h"
#include "driver/errbuf.h"
#include "driver/metrics.h"
#include "driver/parallel.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define TERM_FLOOR (-1.0)
#define TERM_EPS 1e-6
#define MAX_RADIUS 16

/*
 * The row loops in an AVX2 build too, chosen at load time, as the
 * regression's fast path does (regression/fastpath.c); ISO C contracts no
 * multiply-add, so both builds give the same values.  Without trapping math
 * the compiler may evaluate both sides of a term's selects (a comparison
 * with a NaN would raise an exception no one tests), which is what lets it
 * vectorise them; no value changes.
 */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define DENOISE_CLONES \
	__attribute__((target_clones("arch=x86-64-v3", "default"), optimize("no-trapping-math")))
#else
#define DENOISE_CLONES
#endif

void denoise_params_init(struct denoise_params *p)
{
	p->radius = 3;
	p->patch = 2;
	p->k = 0.75;
	p->nthreads = 0;
}

/*
 * The image in planes, shared by every band: each channel's values and
 * variances, and which pixels have a value that is not finite (a hole no
 * fit reached: no one's neighbour).  In planes the terms of a row are a
 * loop the compiler vectorises.
 */
struct planes {
	const float *y[3], *v[3];
	const unsigned char *bad;
};

struct band {
	int w, h, y0, y1;
	const float *rgb, *var;
	const struct planes *pl;
	const struct denoise_params *p;
	float *out, *vout, *self;
	int failed;
};

static int clampi(int v, int lo, int hi)
{
	return v < lo ? lo : v > hi ? hi : v;
}

/* One channel's part of a term, added to t: a of pixel p, q of its
 * neighbour, va and vq their variances (double).  A macro, so that the
 * vectorised row (term_row()) and the clamped pixels (term_at()) compute
 * it alike with each one's own compiler options. */
#define TERM_CH(t, a, q, va, vq, k2)                                                         \
	do {                                                                                 \
		const double d_ = (a) - (q), vm_ = (va) < (vq) ? (va) : (vq);                  \
		const double s_ = (d_ * d_ - ((va) + vm_)) /                                 \
				  (2.0 * (k2) * vm_ + TERM_EPS * ((a) * (a) + METRICS_RELMSE_EPS)); \
		(t) += s_ > TERM_FLOOR ? s_ : TERM_FLOOR;                                    \
	} while (0)

/* The term of pixel i against pixel q (indices into the planes). */
static inline double term_at(const struct planes *pl, size_t i, size_t q, double k2)
{
	if (pl->bad[i] | pl->bad[q])
		return HUGE_VAL;
	double t = 0.0;
	for (int c = 0; c < 3; c++) {
		const double a = pl->y[c][i], b = pl->y[c][q], va = pl->v[c][i], vq = pl->v[c][q];
		TERM_CH(t, a, b, va, vq, k2);
	}
	return t / 3.0;
}

/* The terms tr[x], x in [0, n), of the n pixels from index i against the n
 * from index q (their neighbours, none clamped).  The callers pass the
 * first pixel whose neighbour is inside, so that every pointer lies in its
 * array. */
DENOISE_CLONES
static void term_row(double *restrict tr, const struct planes *pl, size_t i, size_t q, int n,
		     double k2)
{
	if (n <= 0)
		return;
	const float *restrict a0 = pl->y[0] + i, *restrict a1 = pl->y[1] + i, *restrict a2 = pl->y[2] + i;
	const float *restrict q0 = pl->y[0] + q, *restrict q1 = pl->y[1] + q, *restrict q2 = pl->y[2] + q;
	const float *restrict u0 = pl->v[0] + i, *restrict u1 = pl->v[1] + i, *restrict u2 = pl->v[2] + i;
	const float *restrict r0 = pl->v[0] + q, *restrict r1 = pl->v[1] + q, *restrict r2 = pl->v[2] + q;
	const unsigned char *restrict ba = pl->bad + i, *restrict bq = pl->bad + q;
	for (int x = 0; x < n; x++) {
		double t = 0.0;
		const double x0 = a0[x], y0 = q0[x], v0 = u0[x], w0 = r0[x];
		const double x1 = a1[x], y1 = q1[x], v1 = u1[x], w1 = r1[x];
		const double x2 = a2[x], y2 = q2[x], v2 = u2[x], w2 = r2[x];
		TERM_CH(t, x0, y0, v0, w0, k2);
		TERM_CH(t, x1, y1, v1, w1, k2);
		TERM_CH(t, x2, y2, v2, w2, k2);
		const double m = t / 3.0;	/* unconditional: a select vectorises */
		tr[x] = (ba[x] | bq[x]) ? HUGE_VAL : m;
	}
}

/* The sum of tr[x - f .. x + f] in that order, each index clamped inside
 * the row of w. */
static inline double box_at(const double *tr, int w, int f, int x)
{
	double s = 0.0;
	for (int o = -f; o <= f; o++)
		s += tr[clampi(x + o, 0, w - 1)];
	return s;
}

/* hs[x] = box_at(tr, w, f, x) for x in [xa, xb), where no index is
 * clamped: the same sums, in the same order. */
DENOISE_CLONES
static void box_row(double *restrict hs, const double *restrict tr, int f, int xa, int xb)
{
	for (int x = xa; x < xb; x++)
		hs[x] = tr[x - f];
	for (int o = -f + 1; o <= f; o++)
		for (int x = xa; x < xb; x++)
			hs[x] += tr[x + o];
}

/* dst[x] += src[x] for x in [xa, xb). */
DENOISE_CLONES
static void add_row(double *restrict dst, const double *restrict src, int xa, int xb)
{
	for (int x = xa; x < xb; x++)
		dst[x] += src[x];
}

/*
 * The neighbours' weights wt[x], x in [0, n), of the n pixels from index i
 * (in the band's sums, planes np apart) on the n from index q (in the
 * image's planes) into the sums: num += wt Y, v2 += wt^2 V, den += wt.  A
 * weight of 0 is no neighbour: its value, perhaps not finite, is not read
 * into the sums.  As for term_row(), the first pixel is one whose
 * neighbour is inside.
 */
DENOISE_CLONES
static void add_weighted(double *restrict num, double *restrict v2, double *restrict den,
			 const struct planes *pl, const double *restrict wt, size_t i, size_t q,
			 size_t np, int n)
{
	if (n <= 0)
		return;
	for (int c = 0; c < 3; c++) {
		double *restrict nc = num + np * c + i, *restrict vc = v2 + np * c + i;
		const float *restrict yc = pl->y[c] + q, *restrict uc = pl->v[c] + q;
		for (int x = 0; x < n; x++) {
			const double k = wt[x], yv = yc[x], vv = uc[x];
			nc[x] += k > 0.0 ? k * yv : 0.0;
			vc[x] += k > 0.0 ? k * k * vv : 0.0;
		}
	}
	for (int x = 0; x < n; x++)
		den[i + x] += wt[x];
}

/* A band's buffers for a chunk of rows (filter_rows()). */
struct scratch {
	double *t, *hs, *ds, *num, *v2, *den, *own;
};

/*
 * Rows [y0, y1) of the band's image, as many as sc has room for: for each
 * offset of the search window, the terms of the rows and `patch` rows
 * beyond on both sides, their patch sums, and the weights they give added
 * to the rows' sums; then the rows' means.  A chunk of rows keeps its sums
 * in the core's cache across the offsets (a band's whole sums, 56 bytes a
 * pixel, did not fit: the sums' memory traffic was a third of the filter's
 * time at 640x480).
 */
static void filter_rows(const struct band *b, int y0, int y1, const struct scratch *sc)
{
	const struct planes *pl = b->pl;
	const int w = b->w, f = b->p->patch, R = b->p->radius;
	const int nb = y1 - y0, nr = nb + 2 * f;
	const double k2 = b->p->k * b->p->k, area = (double)(2 * f + 1) * (2 * f + 1);
	double *t = sc->t, *hs = sc->hs, *ds = sc->ds;
	double *num = sc->num, *v2 = sc->v2, *den = sc->den, *own = sc->own;
	const size_t np = (size_t)nb * w;
	memset(num, 0, sizeof(double) * np * 3);
	memset(v2, 0, sizeof(double) * np * 3);
	memset(den, 0, sizeof(double) * np);
	memset(own, 0, sizeof(double) * np);
	for (int dy = -R; dy <= R; dy++)
		for (int dx = -R; dx <= R; dx++) {
			/* x in [xa, xb): the neighbour x + dx inside the row
			 * (none when |dx| >= w: xa = xb = w) */
			int xa = dx < 0 ? -dx : 0, xb = dx > 0 ? w - dx : w;
			if (xa >= xb)
				xa = xb = w;
			for (int r = 0; r < nr; r++) {
				const int y = clampi(y0 - f + r, 0, b->h - 1);
				const int qy = clampi(y + dy, 0, b->h - 1);
				const size_t row = (size_t)y * w, qrow = (size_t)qy * w;
				double *tr = t + (size_t)r * w;
				for (int x = 0; x < xa; x++)
					tr[x] = term_at(pl, row + x, qrow + clampi(x + dx, 0, w - 1), k2);
				term_row(tr + xa, pl, row + xa, qrow + xa + dx, xb - xa, k2);
				for (int x = xb; x < w; x++)
					tr[x] = term_at(pl, row + x, qrow + clampi(x + dx, 0, w - 1), k2);
			}
			/* the patch's horizontal sums: its columns beyond the
			 * border are the border's (clamped within f of it) */
			const int ha = f < w ? f : w, hb = w - f > ha ? w - f : ha;
			for (int r = 0; r < nr; r++) {
				const double *tr = t + (size_t)r * w;
				double *hr = hs + (size_t)r * w;
				for (int x = 0; x < ha; x++)
					hr[x] = box_at(tr, w, f, x);
				box_row(hr, tr, f, ha, hb);
				for (int x = hb; x < w; x++)
					hr[x] = box_at(tr, w, f, x);
			}
			for (int j = 0; j < nb; j++) {
				const int y = y0 + j, qy = y + dy;
				if (qy < 0 || qy >= b->h || xa >= xb)
					continue;
				memcpy(ds + xa, hs + (size_t)j * w + xa, sizeof(double) * (size_t)(xb - xa));
				for (int o = 1; o <= 2 * f; o++)
					add_row(ds, hs + (size_t)(j + o) * w, xa, xb);
				for (int x = xa; x < xb; x++) {
					const double d = ds[x] / area;
					/* 0: no neighbour, also one that is not finite
					 * (its term at the patch's centre is infinite,
					 * term_at()) */
					ds[x] = d >= 40.0 ? 0.0 : d > 0.0 ? exp(-d) : 1.0;
				}
				const size_t i = (size_t)j * w + xa, q = (size_t)qy * w + xa + dx;
				add_weighted(num, v2, den, pl, ds + xa, i, q, np, xb - xa);
				if (!dx && !dy)
					memcpy(own + i, ds + xa, sizeof(double) * (size_t)(xb - xa));
			}
		}
	for (int j = 0; j < nb; j++)
		for (int x = 0; x < w; x++) {
			const size_t i = (size_t)j * w + x, g = (size_t)(y0 + j) * w + x;
			/* the pixel's own weight is 1 (its distance to itself is
			 * at most 0), so den >= 1, unless its value is not
			 * finite: then it stays as it is */
			if (!(den[i] > 0.0)) {
				for (int c = 0; c < 3; c++) {
					b->out[3 * g + c] = b->rgb[3 * g + c];
					if (b->vout)
						b->vout[3 * g + c] = b->var[3 * g + c];
				}
				if (b->self)
					b->self[g] = 1.0f;
				continue;
			}
			for (int c = 0; c < 3; c++) {
				b->out[3 * g + c] = (float)(num[np * c + i] / den[i]);
				if (b->vout)
					b->vout[3 * g + c] = (float)(v2[np * c + i] / (den[i] * den[i]));
			}
			if (b->self)
				b->self[g] = (float)(own[i] / den[i]);
		}
}

/* Sums of about this many bytes fit a core's cache (56 bytes a pixel). */
#define CHUNK_BYTES (512 * 1024)

static void *run_band(void *arg)
{
	struct band *b = arg;
	const int w = b->w, f = b->p->patch, nb = b->y1 - b->y0;
	int rows = (int)(CHUNK_BYTES / (56 * (size_t)w));
	rows = rows < 8 ? 8 : rows;
	rows = rows > nb ? nb : rows;
	const size_t nr = (size_t)rows + 2 * f, np = (size_t)rows * w;
	struct scratch sc = { malloc(sizeof(double) * nr * w), malloc(sizeof(double) * nr * w),
			      malloc(sizeof(double) * (size_t)w), malloc(sizeof(double) * np * 3),
			      malloc(sizeof(double) * np * 3), malloc(sizeof(double) * np),
			      malloc(sizeof(double) * np) };
	if (!sc.t || !sc.hs || !sc.ds || !sc.num || !sc.v2 || !sc.den || !sc.own)
		b->failed = 1;
	else
		for (int y = b->y0; y < b->y1; y += rows)
			filter_rows(b, y, y + rows < b->y1 ? y + rows : b->y1, &sc);
	free(sc.t);
	free(sc.hs);
	free(sc.ds);
	free(sc.num);
	free(sc.v2);
	free(sc.den);
	free(sc.own);
	return NULL;
}

int denoise_nlm(int w, int h, const float *rgb, const float *var,
		const struct denoise_params *p, float *out, float *vout, float *self,
		char *err, size_t errlen)
{
	if (w <= 0 || h <= 0 || !rgb || !var || !out) {
		errbuf_printf(err, errlen, "cannot filter an empty %dx%d image", w, h);
		return -1;
	}
	if (p->radius < 0 || p->radius > MAX_RADIUS || p->patch < 0 || p->patch > MAX_RADIUS ||
	    !(p->k > 0.0) || !isfinite(p->k)) {
		errbuf_printf(err, errlen, "bad filter parameters: radius %d, patch %d, k %g",
			      p->radius, p->patch, p->k);
		return -1;
	}
	int nth = p->nthreads;
	if (nth <= 0) {
		long n = sysconf(_SC_NPROCESSORS_ONLN);
		nth = n > 0 ? (int)n : 1;
	}
	/* bands of at least 16 rows: each computes 2 patch rows of terms twice */
	if (nth > h / 16)
		nth = h / 16 > 0 ? h / 16 : 1;
	const size_t npx = (size_t)w * h;
	struct band *bs = calloc((size_t)nth, sizeof *bs);
	float *pv = malloc(sizeof(float) * npx * 6);
	unsigned char *bad = malloc(npx);
	int failed = !bs || !pv || !bad;
	if (failed)
		goto out;
	struct planes pl;
	for (int c = 0; c < 3; c++) {
		float *yc = pv + npx * c, *vc = pv + npx * (3 + c);
		for (size_t i = 0; i < npx; i++) {
			yc[i] = rgb[3 * i + c];
			vc[i] = var[3 * i + c];
		}
		pl.y[c] = yc;
		pl.v[c] = vc;
	}
	for (size_t i = 0; i < npx; i++)
		bad[i] = !(isfinite(rgb[3 * i]) && isfinite(rgb[3 * i + 1]) && isfinite(rgb[3 * i + 2]));
	pl.bad = bad;
	for (int k = 0; k < nth; k++) {
		bs[k] = (struct band){ w, h, (int)((long)h * k / nth), (int)((long)h * (k + 1) / nth),
				       rgb, var, &pl, p, out, vout, self, 0 };
	}
	parallel_run(run_band, bs, sizeof *bs, nth);
	for (int k = 0; k < nth; k++)
		failed |= bs[k].failed;
out:
	free(pv);
	free(bad);
	free(bs);
	if (failed) {
		errbuf_printf(err, errlen, "out of memory filtering a %dx%d image", w, h);
		return -1;
	}
	return 0;
}
