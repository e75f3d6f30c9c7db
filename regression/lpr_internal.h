/* lpr_internal.h - what the modules of regression/ share with each other. */
#ifndef LPR_INTERNAL_H
#define LPR_INTERNAL_H

#include "regression/lpr.h"
#include "regression/wls.h"

#define LPR_NORDERS 3

/* A pixel's window of some radius, as the strip code classifies it. */
enum {
	LPR_WIN_MASKED,    /* holds a missing sample (or a missing feature) */
	LPR_WIN_INTERIOR,  /* inside the image, complete */
	LPR_WIN_CLIPPED,   /* clipped by the border, otherwise complete */
};

/* Number of spatial columns of a polynomial of the given order. */
static inline int lpr_nspatial(int order)
{
	return order == 0 ? 1 : order == 1 ? 3 : 6;
}

/* 1 when every channel of pixel i of img (and of feat, if any) is finite. */
int lpr_sample_valid(const struct lpr_image *img, const struct lpr_image *feat, size_t i);

/*
 * General-path fits at pixel (x, y) with radius r for orders 0 .. maxorder,
 * sharing one pass over the window; out[o] receives order o.  unmasked says
 * the clipped window holds no missing sample, which allows the moments to
 * be computed from separable sums (it is ignored when feat is set).
 */
void lpr_general_fits(const struct lpr_image *img, const struct lpr_image *feat,
		      int x, int y, int r, int maxorder, int unmasked, struct lpr_fit *out);



/*
 * The normal equations of one window without its centre sample, in the
 * columns 1, u, v, u^2, uv, v^2, then nf standardised features (p = 6 + nf,
 * row-major p x p), however they were accumulated.
 */
struct lpr_system {
	int nf, nch;
	int n;                               /* samples, centre excluded */
	double sw;                           /* their total weight */
	double a[WLS_MAXP * WLS_MAXP];       /* A' = sum W x x^T */
	double b[LPR_MAXCH][WLS_MAXP];       /* b' = sum W x Y, per channel */
	double bq[WLS_MAXP * WLS_MAXP];      /* B' = sum W^2 x x^T, if have_bq */
	int have_bq;
};

struct lpr_solution {
	double z[LPR_NORDERS][WLS_MAXP];               /* A'^-1 e_0 */
	double beta[LPR_NORDERS][LPR_MAXCH][WLS_MAXP]; /* A'^-1 b' */
	double vsum[LPR_NORDERS];                      /* z^T B' z */
	double rss[LPR_NORDERS][LPR_MAXCH];            /* weighted residuals (holes) */
};

/*
 * Factor and solve sys for orders 0 .. maxorder, setting out[o].valid,
 * .rank and .hole; vsum is filled when sys has B', else left 0 (as is rss)
 * for the caller to accumulate.
 */
void lpr_system_solve(const struct lpr_system *sys, int maxorder, int hole,
		      struct lpr_fit *out, struct lpr_solution *sol);

/*
 * Turn a solution into fits: leave-one-out prediction, fit, leverage,
 * slopes, PRESS and noise terms (see window.c).  yc is the centre sample
 * (ignored for a hole), r the radius.
 */
void lpr_system_finish(const struct lpr_system *sys, const float *yc, int hole, int r,
		       int maxorder, const struct lpr_solution *sol, struct lpr_fit *out);

/* Per-candidate results for the rows of one strip; NaN marks "no fit". */
struct lpr_cand_buf {
	float *fit, *dx, *dy;   /* npx * nch */
	float *lev, *e2, *q;    /* npx: H_cc, PRESS term e^2, noise term */
};

/*
 * The fixed filters of an unmasked interior window of radius r, without
 * features (see fastpath.c).
 */
struct lpr_filters {
	int r;
	double t[2 * LPR_MAXRADIUS + 1];   /* 1-D tricube weights */
	double tu[2 * LPR_MAXRADIUS + 1];  /* t * u */
	double tu2[2 * LPR_MAXRADIUS + 1]; /* t * u^2 */
	double s;          /* sum of t */
	double c0, c3, c5; /* centre row of the order-2 inverse moment matrix */
	double h0, h2;     /* centre leverages of orders 0 and 2 */
	double v0, v2;     /* leave-one-out prediction variance factors */
	double gscale;     /* slope = gscale * sum W u Y */
};

void lpr_filters_init(struct lpr_filters *f, int r);

/* Store a general-path fit (NaN everywhere when it is not valid). */
void lpr_cand_write(struct lpr_cand_buf *b, size_t i, int nch, const struct lpr_fit *f);

/* Scratch the fast path needs for a strip of nrows rows, in doubles. */
size_t lpr_fast_scratch(int w, int nch, int nrows, int r);

/*
 * Fit every pixel of rows [ya, yb) whose elig flag is LPR_WIN_INTERIOR (elig
 * is indexed from row ya), from clean (the image with holes replaced by 0), writing
 * the order-0, -1 and -2 candidates into c[0..2] (an entry may be NULL).
 * The order-1 fit equals the order-0 fit on these pixels: only its e2, q
 * and lev are written, and its first fit value is set to NaN to say so.
 * Buffers are indexed from row ya.  Returns the number of pixels fitted.
 */
long lpr_fast_strip(const struct lpr_filters *f, const float *clean, int w, int h,
		    int nch, int ya, int yb, const unsigned char *elig,
		    double *scratch, struct lpr_cand_buf *const c[LPR_NORDERS]);

/* Scratch lpr_feat_strip needs, in doubles. */
size_t lpr_feat_scratch(int w, int nch, int nf, int nrows, int r);

/*
 * Fit, with the features of feat, every pixel of rows [ya, yb) whose elig
 * flag is not LPR_WIN_MASKED (its window holds no missing sample), for orders
 * 0 .. maxorder, writing c[0..2] (an entry may be NULL).  Returns the
 * number of pixels fitted.
 */
long lpr_feat_strip(const struct lpr_filters *f, const struct lpr_image *img,
		    const float *clean, const struct lpr_image *feat, int ya, int yb,
		    const unsigned char *elig, double *scratch,
		    struct lpr_cand_buf *const c[LPR_NORDERS], int maxorder);

#endif
