/*
 * press.c - per-pixel model selection by PRESS over whole images.
 *
 * The image is cut into strips of STRIP_ROWS rows; threads take strips in
 * turn, each with its own scratch, and every strip is computed the same way
 * whichever thread takes it, so the output does not depend on the number of
 * threads.  For a strip, one radius at a time, the candidates of every
 * order are fitted on the strip's rows plus a margin of smooth_radius rows,
 * on the fast path where the window is interior and unmasked and on the
 * general path elsewhere.  The PRESS terms e^2 of each candidate are then
 * averaged over a tricube neighbourhood (holes and unfittable pixels left
 * out): that average is the candidate's criterion CV.  Each pixel keeps the
 * candidate with the smallest score
 *     CV * (1 + tie_tol * order) + 1e-12 * mean(Y^2) * order,
 * ties going to the lower order and then to the larger radius: a higher
 * order has to win by a margin, and differences below float resolution of
 * the pixel's own values count as ties.  The score does not depend on the
 * order in which candidates are visited, so they are visited radius by
 * radius and only the best so far is kept.
 */
#include "regression/lpr_internal.h"
#include "regression/kernel.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define STRIP_ROWS 64

struct shared {
	const struct lpr_image *img, *feat;
	const struct lpr_params *p;
	struct lpr_result *out;
	int nr, omin, omax, s;
	struct lpr_filters filt[8];
	float *clean;                     /* holes replaced by 0 */
	int *sat;                         /* summed-area table of invalid pixels */
	unsigned char *valid;
	int nstrips, next;
	pthread_mutex_t lock;
};

struct worker {
	struct shared *sh;
	size_t npx;                       /* pixels of the fitted rows */
	float *store;
	struct lpr_cand_buf buf[LPR_NORDERS]; /* the current radius, per order */
	unsigned char *elig;
	double *fscratch;
	float *hn;          /* smoothing: 3 horizontal sums per pixel */
	float *pad;         /* smoothing: 3 padded rows */
	float *cv, *qs;     /* smoothed PRESS and noise, STRIP_ROWS * w per order */
	double *score;      /* best score so far, STRIP_ROWS * w */
	int *key;           /* its tie-break key; KEY_NONE, or fallback keys */
	float *mag2;        /* mean square of the pixel's values */
	long fast, general;
};

#define KEY_NONE 0x7fffffff
#define KEY_FALLBACK (1 << 20)

static void seterr(char *err, size_t len, const char *fmt, ...)
{
	if (!err || !len)
		return;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(err, len, fmt, ap);
	va_end(ap);
}

void lpr_params_init(struct lpr_params *p)
{
	memset(p, 0, sizeof *p);
	p->order = -1;
	p->radius = 0;
	p->nradii = 4;
	p->radii[0] = 2;
	p->radii[1] = 3;
	p->radii[2] = 5;
	p->radii[3] = 8;
	p->smooth_radius = 2;
	p->tie_tol = 0.02;
	p->nthreads = 0;
}

void lpr_result_release(struct lpr_result *r)
{
	if (!r)
		return;
	free(r->fit);
	free(r->dx);
	free(r->dy);
	free(r->leverage);
	free(r->error);
	free(r->order);
	free(r->bandwidth);
	memset(r, 0, sizeof *r);
}

static int invalid_in(const struct shared *sh, int x0, int y0, int x1, int y1)
{
	/* Count of invalid pixels in [x0, x1] x [y0, y1]. */
	const int *s = sh->sat;
	size_t W = (size_t)sh->img->w + 1;
	return s[(size_t)(y1 + 1) * W + x1 + 1] - s[(size_t)y0 * W + x1 + 1] -
	       s[(size_t)(y1 + 1) * W + x0] + s[(size_t)y0 * W + x0];
}

void lpr_cand_write(struct lpr_cand_buf *b, size_t i, int nch, const struct lpr_fit *f)
{
	for (int c = 0; c < nch; c++) {
		b->fit[i * nch + c] = f->valid ? (float)f->fit[c] : NAN;
		b->dx[i * nch + c] = f->valid ? (float)f->dx[c] : NAN;
		b->dy[i * nch + c] = f->valid ? (float)f->dy[c] : NAN;
	}
	b->lev[i] = f->valid ? (float)f->leverage : NAN;
	b->e2[i] = f->valid ? (float)f->press : NAN;
	b->q[i] = f->valid ? (float)f->noise : NAN;
}

/* Fit the candidates of radius index ri, every order, on rows [ya, yb). */
static void fit_radius(struct worker *wk, int ri, int ya, int yb)
{
	struct shared *sh = wk->sh;
	const struct lpr_image *img = sh->img;
	const int w = img->w, h = img->h, nch = img->nch;
	const struct lpr_filters *f = &sh->filt[ri];
	const int r = f->r;
	struct lpr_cand_buf *cb[LPR_NORDERS];
	for (int o = 0; o < LPR_NORDERS; o++)
		cb[o] = o >= sh->omin && o <= sh->omax ? &wk->buf[o] : NULL;

	for (int y = ya; y < yb; y++)
		for (int x = 0; x < w; x++) {
			int x0 = x - r < 0 ? 0 : x - r, x1 = x + r >= w ? w - 1 : x + r;
			int y0 = y - r < 0 ? 0 : y - r, y1 = y + r >= h ? h - 1 : y + r;
			int inside = x0 == x - r && x1 == x + r && y0 == y - r && y1 == y + r;
			wk->elig[(size_t)(y - ya) * w + x] =
				invalid_in(sh, x0, y0, x1, y1) ? LPR_WIN_MASKED :
				inside ? LPR_WIN_INTERIOR : LPR_WIN_CLIPPED;
		}

	/* Who fits what: without features the fast path takes the interior
	 * windows; with features the moment path takes every unmasked one;
	 * the general path takes the rest (all, when forced). */
	const int maxo = sh->omax < 1 ? 1 : sh->omax;
	const int force = sh->p->force_general;
	if (!force && !sh->feat)
		wk->fast += lpr_fast_strip(f, sh->clean, w, h, nch, ya, yb, wk->elig,
					   wk->fscratch, cb);
	if (!force && sh->feat)
		wk->fast += lpr_feat_strip(f, img, sh->clean, sh->feat, ya, yb, wk->elig,
					   wk->fscratch, cb, maxo);
	for (int y = ya; y < yb; y++)
		for (int x = 0; x < w; x++) {
			size_t i = (size_t)(y - ya) * w + x;
			int e = wk->elig[i];
			if (!force && (sh->feat ? e != LPR_WIN_MASKED : e == LPR_WIN_INTERIOR))
				continue;
			struct lpr_fit fits[LPR_NORDERS];
			lpr_general_fits(img, sh->feat, x, y, r, maxo,
					 !force && e == LPR_WIN_CLIPPED, fits);
			for (int o = 0; o < LPR_NORDERS; o++)
				if (cb[o])
					lpr_cand_write(cb[o], i, nch, &fits[o]);
			wk->general++;
		}
}

/* o[x] = sum_i t[i] in[x + i] for i in [0, n): in is padded. */
static void conv_row(float *restrict o, const float *restrict in, int w,
		     const float *restrict t, int n)
{
	for (int x = 0; x < w; x++)
		o[x] = 0.0f;
	for (int i = 0; i < n; i++) {
		const float ti = t[i];
		const float *restrict src = in + i;
		for (int x = 0; x < w; x++)
			o[x] += ti * src[x];
	}
}

/* acc[x] += t in[x] */
static void axpy_row(float *restrict acc, const float *restrict in, float t, int w)
{
	for (int x = 0; x < w; x++)
		acc[x] += t * in[x];
}

static void smooth(struct worker *wk, const struct lpr_cand_buf *b, int ya, int yb,
		   int y0, int y1, float *cv, float *qs)
{
	const int w = wk->sh->img->w, s = wk->sh->s;
	double td[2 * LPR_MAXRADIUS + 1];
	float t[2 * LPR_MAXRADIUS + 1];
	kernel_weights(s, td);
	for (int i = 0; i <= 2 * s; i++)
		t[i] = (float)td[i];
	float *hn = wk->hn;
	const size_t plane = (size_t)(yb - ya) * w;
	/* Padded copies of one row: values where finite, else 0, and the
	 * 0/1 mask, so that the horizontal sums need no tests. */
	float *pe = wk->pad, *pq = pe + w + 2 * s, *pm = pq + w + 2 * s;
	for (int i = 0; i < s; i++)
		pe[i] = pq[i] = pm[i] = pe[w + s + i] = pq[w + s + i] = pm[w + s + i] = 0.0f;
	for (int y = ya; y < yb; y++) {
		size_t row = (size_t)(y - ya) * w;
		for (int x = 0; x < w; x++) {
			float e = b->e2[row + x];
			int ok = isfinite(e);
			pe[x + s] = ok ? e : 0.0f;
			pq[x + s] = ok ? b->q[row + x] : 0.0f;
			pm[x + s] = ok ? 1.0f : 0.0f;
		}
		conv_row(hn + row, pe, w, t, 2 * s + 1);
		conv_row(hn + plane + row, pq, w, t, 2 * s + 1);
		conv_row(hn + 2 * plane + row, pm, w, t, 2 * s + 1);
	}
	float *ae = wk->pad, *aq = ae + w, *am = aq + w;
	for (int y = y0; y < y1; y++) {
		int j0 = y - s < ya ? ya - y : -s, j1 = y + s >= yb ? yb - 1 - y : s;
		for (int x = 0; x < w; x++)
			ae[x] = aq[x] = am[x] = 0.0f;
		for (int j = j0; j <= j1; j++) {
			size_t k = (size_t)(y + j - ya) * w;
			float tj = t[j + s];
			axpy_row(ae, hn + k, tj, w);
			axpy_row(aq, hn + plane + k, tj, w);
			axpy_row(am, hn + 2 * plane + k, tj, w);
		}
		size_t o = (size_t)(y - y0) * w;
		for (int x = 0; x < w; x++) {
			cv[o + x] = am[x] > 0.0f ? ae[x] / am[x] : NAN;
			qs[o + x] = am[x] > 0.0f ? aq[x] / am[x] : NAN;
		}
	}
}

static void put_choice(struct worker *wk, const struct lpr_cand_buf *b, size_t li,
		       size_t gi, int order, int r, float error)
{
	struct lpr_result *out = wk->sh->out;
	const int nch = wk->sh->img->nch;
	for (int c = 0; c < nch; c++) {
		out->fit[gi * nch + c] = b->fit[li * nch + c];
		out->dx[gi * nch + c] = b->dx[li * nch + c];
		out->dy[gi * nch + c] = b->dy[li * nch + c];
	}
	out->leverage[gi] = b->lev[li];
	out->error[gi] = error;
	out->order[gi] = (float)order;
	out->bandwidth[gi] = (float)r;
}

/* Fold the candidates of radius index ri into the best choice so far. */
static void update_best(struct worker *wk, int ri, int ya, int y0, int y1)
{
	struct shared *sh = wk->sh;
	const int w = sh->img->w, nch = sh->img->nch, r = sh->filt[ri].r;
	const size_t sp = (size_t)STRIP_ROWS * w;
	const double tol = sh->p->tie_tol;

	for (int o = sh->omin; o <= sh->omax; o++) {
		const int key = o * 64 + (LPR_MAXRADIUS - r);
		const float *cv = wk->cv + o * sp, *qs = wk->qs + o * sp;
		for (int y = y0; y < y1; y++)
			for (int x = 0; x < w; x++) {
				size_t li = (size_t)(y - ya) * w + x;  /* fitted-rows index */
				size_t si = (size_t)(y - y0) * w + x;  /* strip index */
				size_t gi = (size_t)y * w + x;         /* image index */
				const struct lpr_cand_buf *b = &wk->buf[o];
				/* Order 1 on the fast path is order 0 (see fastpath.c). */
				if (isnan(b->fit[li * nch]) && o == 1 && isfinite(b->e2[li]))
					b = &wk->buf[0];
				if (isnan(b->fit[li * nch]))
					continue;
				if (isnan(wk->mag2[si])) {
					double m2 = 0.0;
					for (int c = 0; c < nch; c++)
						m2 += (double)b->fit[li * nch + c] * b->fit[li * nch + c];
					wk->mag2[si] = (float)(m2 / nch);
				}
				if (!isfinite(cv[si])) {
					/* Fitted but without a criterion: a fallback. */
					int fk = KEY_FALLBACK + key;
					if (wk->key[si] >= KEY_FALLBACK && fk < wk->key[si]) {
						wk->key[si] = fk;
						put_choice(wk, b, li, gi, o, 0, 0.0f);
					}
					continue;
				}
				double score = cv[si] * (1.0 + tol * o) + 1e-12 * wk->mag2[si] * o;
				if (score < wk->score[si] || (score == wk->score[si] && key < wk->key[si])) {
					wk->score[si] = score;
					wk->key[si] = key;
					put_choice(wk, b, li, gi, o, r, qs[si]);
				}
			}
	}
}

/* Pixels no candidate could fit: keep the sample, or NaN for a hole. */
static void finish_rows(struct worker *wk, int y0, int y1)
{
	struct shared *sh = wk->sh;
	const struct lpr_image *img = sh->img;
	const int w = img->w, nch = img->nch;
	struct lpr_result *out = sh->out;
	for (int y = y0; y < y1; y++)
		for (int x = 0; x < w; x++) {
			size_t si = (size_t)(y - y0) * w + x, gi = (size_t)y * w + x;
			if (wk->key[si] != KEY_NONE)
				continue;
			int ok = sh->valid[gi];
			for (int c = 0; c < nch; c++) {
				out->fit[gi * nch + c] = ok ? img->px[gi * nch + c] : NAN;
				out->dx[gi * nch + c] = ok ? 0.0f : NAN;
				out->dy[gi * nch + c] = ok ? 0.0f : NAN;
			}
			out->leverage[gi] = ok ? 1.0f : NAN;
			out->error[gi] = ok ? 0.0f : NAN;
			out->order[gi] = 0.0f;
			out->bandwidth[gi] = 0.0f;
		}
}

static void do_strip(struct worker *wk, int st)
{
	struct shared *sh = wk->sh;
	const struct lpr_image *img = sh->img;
	const int h = img->h, w = img->w, nch = img->nch;
	const int y0 = st * STRIP_ROWS, y1 = y0 + STRIP_ROWS > h ? h : y0 + STRIP_ROWS;
	const int ya = y0 - sh->s < 0 ? 0 : y0 - sh->s, yb = y1 + sh->s > h ? h : y1 + sh->s;
	const size_t sp = (size_t)STRIP_ROWS * w;

	for (int y = y0; y < y1; y++)
		for (int x = 0; x < w; x++) {
			size_t si = (size_t)(y - y0) * w + x, gi = (size_t)y * w + x;
			wk->score[si] = INFINITY;
			wk->key[si] = KEY_NONE;
			double m2 = 0.0;
			for (int c = 0; c < nch; c++)
				m2 += (double)img->px[gi * nch + c] * img->px[gi * nch + c];
			wk->mag2[si] = sh->valid[gi] ? (float)(m2 / nch) : NAN;
		}
	for (int ri = 0; ri < sh->nr; ri++) {
		fit_radius(wk, ri, ya, yb);
		for (int o = sh->omin; o <= sh->omax; o++)
			smooth(wk, &wk->buf[o], ya, yb, y0, y1, wk->cv + o * sp, wk->qs + o * sp);
		update_best(wk, ri, ya, y0, y1);
	}
	finish_rows(wk, y0, y1);
}

static void *work(void *arg)
{
	struct worker *wk = arg;
	struct shared *sh = wk->sh;
	for (;;) {
		pthread_mutex_lock(&sh->lock);
		int st = sh->next++;
		pthread_mutex_unlock(&sh->lock);
		if (st >= sh->nstrips)
			break;
		do_strip(wk, st);
	}
	return NULL;
}

static int worker_init(struct worker *wk, struct shared *sh)
{
	memset(wk, 0, sizeof *wk);
	wk->sh = sh;
	const int w = sh->img->w, nch = sh->img->nch;
	const int rows = STRIP_ROWS + 2 * sh->s;
	wk->npx = (size_t)rows * w;
	const size_t sp = (size_t)STRIP_ROWS * w;
	size_t per = wk->npx * (3 * (size_t)nch + 3);
	wk->store = malloc(per * LPR_NORDERS * sizeof(float));
	wk->elig = malloc(wk->npx);
	int rmax = 0;
	for (int i = 0; i < sh->nr; i++)
		rmax = sh->filt[i].r > rmax ? sh->filt[i].r : rmax;
	size_t fs = sh->feat ? lpr_feat_scratch(w, nch, sh->feat->nch, rows, rmax)
			     : lpr_fast_scratch(w, nch, rows, rmax);
	wk->fscratch = malloc(fs * sizeof(double));
	wk->hn = malloc(3 * wk->npx * sizeof(float));
	wk->pad = malloc(3 * ((size_t)w + 2 * LPR_MAXRADIUS) * sizeof(float));
	wk->cv = malloc(LPR_NORDERS * sp * sizeof(float));
	wk->qs = malloc(LPR_NORDERS * sp * sizeof(float));
	wk->score = malloc(sp * sizeof(double));
	wk->key = malloc(sp * sizeof(int));
	wk->mag2 = malloc(sp * sizeof(float));
	if (!wk->store || !wk->elig || !wk->fscratch || !wk->hn || !wk->pad || !wk->cv ||
	    !wk->qs || !wk->score || !wk->key || !wk->mag2)
		return -1;
	for (int k = 0; k < LPR_NORDERS; k++) {
		float *b = wk->store + per * k;
		wk->buf[k].fit = b;
		wk->buf[k].dx = b + wk->npx * nch;
		wk->buf[k].dy = b + 2 * wk->npx * nch;
		wk->buf[k].lev = b + 3 * wk->npx * nch;
		wk->buf[k].e2 = wk->buf[k].lev + wk->npx;
		wk->buf[k].q = wk->buf[k].e2 + wk->npx;
	}
	return 0;
}

static void worker_release(struct worker *wk)
{
	free(wk->store);
	free(wk->elig);
	free(wk->fscratch);
	free(wk->hn);
	free(wk->pad);
	free(wk->cv);
	free(wk->qs);
	free(wk->score);
	free(wk->key);
	free(wk->mag2);
}

static int check_args(const struct lpr_image *img, const struct lpr_image *feat,
		      const struct lpr_params *p, char *err, size_t errlen)
{
	if (!img || !img->px || img->w < 1 || img->h < 1) {
		seterr(err, errlen, "empty image");
		return -1;
	}
	if (img->nch < 1 || img->nch > LPR_MAXCH) {
		seterr(err, errlen, "image has %d channels (1 to %d supported)", img->nch, LPR_MAXCH);
		return -1;
	}
	if (feat && (feat->w != img->w || feat->h != img->h)) {
		seterr(err, errlen, "features are %dx%d but the image is %dx%d",
		       feat->w, feat->h, img->w, img->h);
		return -1;
	}
	if (feat && (feat->nch < 1 || feat->nch > LPR_MAXFEAT || !feat->px)) {
		seterr(err, errlen, "features have %d channels (1 to %d supported)",
		       feat->nch, LPR_MAXFEAT);
		return -1;
	}
	if (p->order < -1 || p->order > 2) {
		seterr(err, errlen, "order %d is not one of auto, 0, 1, 2", p->order);
		return -1;
	}
	if (p->radius < 0 || p->radius > LPR_MAXRADIUS) {
		seterr(err, errlen, "radius %d is not in 1..%d", p->radius, LPR_MAXRADIUS);
		return -1;
	}
	if (!p->radius && (p->nradii < 1 || p->nradii > 8)) {
		seterr(err, errlen, "bad number of candidate radii %d", p->nradii);
		return -1;
	}
	for (int i = 0; !p->radius && i < p->nradii; i++)
		if (p->radii[i] < 1 || p->radii[i] > LPR_MAXRADIUS) {
			seterr(err, errlen, "radius %d is not in 1..%d", p->radii[i], LPR_MAXRADIUS);
			return -1;
		}
	if (p->smooth_radius < 1 || p->smooth_radius > LPR_MAXRADIUS) {
		seterr(err, errlen, "smoothing radius %d is not in 1..%d", p->smooth_radius,
		       LPR_MAXRADIUS);
		return -1;
	}
	return 0;
}

static int result_alloc(struct lpr_result *out, int w, int h, int nch)
{
	memset(out, 0, sizeof *out);
	out->w = w;
	out->h = h;
	out->nch = nch;
	size_t n = (size_t)w * h;
	out->fit = malloc(n * nch * sizeof(float));
	out->dx = malloc(n * nch * sizeof(float));
	out->dy = malloc(n * nch * sizeof(float));
	out->leverage = malloc(n * sizeof(float));
	out->error = malloc(n * sizeof(float));
	out->order = malloc(n * sizeof(float));
	out->bandwidth = malloc(n * sizeof(float));
	if (!out->fit || !out->dx || !out->dy || !out->leverage || !out->error ||
	    !out->order || !out->bandwidth) {
		lpr_result_release(out);
		return -1;
	}
	return 0;
}

/* The fixed per-image inputs: clean copy, validity, summed-area table. */
static int prepare(struct shared *sh)
{
	const struct lpr_image *img = sh->img;
	const int w = img->w, h = img->h, nch = img->nch;
	size_t n = (size_t)w * h;
	sh->clean = malloc(n * nch * sizeof(float));
	sh->valid = malloc(n);
	sh->sat = calloc((size_t)(w + 1) * (h + 1), sizeof(int));
	if (!sh->clean || !sh->valid || !sh->sat)
		return -1;
	for (size_t i = 0; i < n; i++) {
		int ok = lpr_sample_valid(img, sh->feat, i);
		sh->valid[i] = (unsigned char)ok;
		for (int c = 0; c < nch; c++)
			sh->clean[i * nch + c] = ok ? img->px[i * nch + c] : 0.0f;
	}
	size_t W = (size_t)w + 1;
	for (int y = 0; y < h; y++) {
		int rowsum = 0;
		for (int x = 0; x < w; x++) {
			rowsum += !sh->valid[(size_t)y * w + x];
			sh->sat[(size_t)(y + 1) * W + x + 1] = sh->sat[(size_t)y * W + x + 1] + rowsum;
		}
	}
	return 0;
}

int lpr_analyze(const struct lpr_image *img, const struct lpr_image *features,
		const struct lpr_params *p, struct lpr_result *out,
		char *err, size_t errlen)
{
	struct lpr_params defaults;
	if (!p) {
		lpr_params_init(&defaults);
		p = &defaults;
	}
	memset(out, 0, sizeof *out);
	if (check_args(img, features, p, err, errlen))
		return -1;

	struct shared *sh = calloc(1, sizeof *sh);
	if (!sh) {
		seterr(err, errlen, "out of memory");
		return -1;
	}
	sh->img = img;
	sh->feat = features;
	sh->p = p;
	sh->out = out;
	sh->s = p->smooth_radius;
	sh->nr = p->radius ? 1 : p->nradii;
	for (int i = 0; i < sh->nr; i++)
		lpr_filters_init(&sh->filt[i], p->radius ? p->radius : p->radii[i]);
	sh->omin = p->order < 0 ? 0 : p->order;
	sh->omax = p->order < 0 ? 2 : p->order;

	int nth = p->nthreads;
	if (nth <= 0) {
		long n = sysconf(_SC_NPROCESSORS_ONLN);
		nth = n > 0 ? (int)n : 1;
	}
	sh->nstrips = (img->h + STRIP_ROWS - 1) / STRIP_ROWS;
	if (nth > sh->nstrips)
		nth = sh->nstrips;
	pthread_mutex_init(&sh->lock, NULL);

	int rc = -1;
	struct worker *wk = calloc((size_t)nth, sizeof *wk);
	pthread_t *tid = calloc((size_t)nth, sizeof *tid);
	if (!wk || !tid || prepare(sh) || result_alloc(out, img->w, img->h, img->nch)) {
		seterr(err, errlen, "out of memory");
		goto done;
	}
	int started = 0;
	for (int i = 0; i < nth; i++)
		if (worker_init(&wk[i], sh)) {
			seterr(err, errlen, "out of memory");
			goto join;
		}
	for (; started < nth; started++) {
		int e = pthread_create(&tid[started], NULL, work, &wk[started]);
		if (e) {
			seterr(err, errlen, "cannot start a thread: %s", strerror(e));
			/* Let the threads already started finish the work. */
			break;
		}
	}
	if (started == 0)
		work(&wk[0]);
	rc = 0;
join:
	for (int i = 0; i < started; i++)
		pthread_join(tid[i], NULL);
	for (int i = 0; i < nth; i++) {
		out->fast_pixels += wk[i].fast;
		out->general_pixels += wk[i].general;
		worker_release(&wk[i]);
	}
done:
	if (rc)
		lpr_result_release(out);
	pthread_mutex_destroy(&sh->lock);
	free(sh->clean);
	free(sh->valid);
	free(sh->sat);
	free(sh);
	free(wk);
	free(tid);
	return rc;
}
