/*
 * featpath.c - fits with feature predictors from separable moments.
 *
 * For a window without missing samples, every entry of the normal
 * equations is a kernel-weighted sum over the window of a product image:
 *   sum W u^i v^j Y_c,  sum W u^i v^j f_a,  sum W f_a f_b,  sum W f_a Y_c
 * (and the same with W^2 for the variance of the leave-one-out
 * prediction).  The product kernel makes each a separable convolution of
 * the zero-padded image, so a window clipped by the border needs nothing
 * special, and the polynomial-only entries come from 1-D sums of the
 * kernel.  Centring the features at the pixel is done afterwards:
 *   sum W (f_a - f_ac) g = sum W f_a g - f_ac sum W g,
 * in double, and the centre sample drops out of every feature column by
 * itself because its centred feature is 0; only the polynomial entries
 * need the centre removed.  The rest of the fit is the general path's
 * (lpr_system_solve and lpr_system_finish).
 *
 * Per pixel and radius this costs O(r (6 + F)^2) instead of the general
 * path's O(r^2 (6 + F)^2).
 */
#include "regression/lpr_internal.h"
#include "regression/kernel.h"

#include <math.h>
#include <string.h>

#define NSP 6

/* Horizontal kernels: t u^i (i = 0..2) and q u^i with q = t^2. */
enum { HT, HTU, HTU2, HQ, HQU, HQU2, NHK };

/* The spatial columns as exponents (i, j) of u^i v^j. */
static const int ex[NSP] = { 0, 1, 0, 2, 1, 0 }, ey[NSP] = { 0, 0, 1, 0, 1, 2 };

#define MAXPLANES (LPR_MAXCH + LPR_MAXFEAT + LPR_MAXFEAT * (LPR_MAXFEAT + 1) / 2 + \
		   LPR_MAXFEAT * LPR_MAXCH)

struct layout {
	int nch, nf, nff;
	/* planes: nch colours, nf features, nff feature products, nf*nch
	 * feature-colour products */
	int np;
	int nh;                /* horizontal rows per image row */
	int nv;                /* vertical moments per pixel */
	int hbase[MAXPLANES];  /* first horizontal row of each plane */
	int hcount[MAXPLANES]; /* horizontal kernels of each plane: 1, 2, 3 or 6 */
	/* A plane's value at a pixel is v[fa] * v[fb] (or v[fa] when fb < 0),
	 * where v is the pixel's colours followed by its features. */
	int fa[MAXPLANES], fb[MAXPLANES];
};

static void layout_init(struct layout *l, int nch, int nf)
{
	l->nch = nch;
	l->nf = nf;
	l->nff = nf * (nf + 1) / 2;
	l->np = nch + nf + l->nff + nf * nch;
	int h = 0, v = 0, p = 0;
	for (int c = 0; c < nch; c++, p++) {          /* colours: W moments */
		l->fa[p] = c, l->fb[p] = -1;
		l->hcount[p] = 3, v += 6;
	}
	for (int a = 0; a < nf; a++, p++) {           /* features: W and W^2 moments */
		l->fa[p] = nch + a, l->fb[p] = -1;
		l->hcount[p] = 6, v += 12;
	}
	for (int a = 0; a < nf; a++)                  /* feature products: W and W^2 */
		for (int b = a; b < nf; b++, p++) {
			l->fa[p] = nch + a, l->fb[p] = nch + b;
			l->hcount[p] = 2, v += 2;
		}
	for (int a = 0; a < nf; a++)                  /* feature-colour products: W */
		for (int c = 0; c < nch; c++, p++) {
			l->fa[p] = nch + a, l->fb[p] = c;
			l->hcount[p] = 1, v += 1;
		}
	for (p = 0; p < l->np; p++) {
		l->hbase[p] = h;
		h += l->hcount[p];
	}
	l->nh = h;
	l->nv = v;
}

size_t lpr_feat_scratch(int w, int nch, int nf, int nrows, int r)
{
	struct layout l;
	layout_init(&l, nch, nf);
	size_t wp = (size_t)w + 2 * (size_t)r;
	return (size_t)l.nh * (size_t)(nrows + 2 * r) * w   /* horizontal sums */
	       + (size_t)l.nv * w                          /* vertical moments of a row */
	       + wp                                        /* one padded plane row */
	       + 10 * (size_t)w;                           /* 1-D kernel sums per x */
}

/* Index of the product f_a f_b (a <= b) among the feature products. */
static inline int ff_index(int nf, int a, int b)
{
	return a * nf - a * (a - 1) / 2 + (b - a);
}

#define BLK 8

/* o[x] = sum_i k[i] src[x + i * stride] for i in [0, n), x in [0, w): BLK
 * outputs at a time so that the sums stay in registers. */
static void conv_1d(double *restrict o, const double *restrict src, size_t stride,
		    const double *restrict k, int n, int w)
{
	int x = 0;
	for (; x + BLK <= w; x += BLK) {
		double acc[BLK] = {0};
		for (int i = 0; i < n; i++) {
			const double *s = src + (size_t)i * stride + x;
			for (int m = 0; m < BLK; m++)
				acc[m] += k[i] * s[m];
		}
		memcpy(o + x, acc, sizeof acc);
	}
	for (; x < w; x++) {
		double acc = 0.0;
		for (int i = 0; i < n; i++)
			acc += k[i] * src[(size_t)i * stride + x];
		o[x] = acc;
	}
}

/* 1-D sums over the clipped window of offsets lo..hi: t u^k and t^2 u^k. */
static void sums_1d(const double *t, int r, int lo, int hi, double *m, double *q)
{
	for (int k = 0; k < 5; k++)
		m[k] = q[k] = 0.0;
	for (int i = lo; i <= hi; i++) {
		double u = (double)i / r, w = t[i + r], pw = 1.0;
		for (int k = 0; k < 5; k++, pw *= u) {
			m[k] += w * pw;
			q[k] += w * w * pw;
		}
	}
}

long lpr_feat_strip(const struct lpr_filters *f, const struct lpr_image *img,
		    const float *clean, const struct lpr_image *feat, int ya, int yb,
		    const unsigned char *elig, double *scratch,
		    struct lpr_cand_buf *const c[LPR_NORDERS], int maxorder)
{
	const int w = img->w, h = img->h, nch = img->nch, nf = feat->nch, r = f->r;
	struct layout l;
	layout_init(&l, nch, nf);
	const int ha = ya - r < 0 ? 0 : ya - r, hb = yb + r > h ? h : yb + r;
	const size_t nrow = (size_t)(hb - ha);
	double *hs = scratch;                               /* [nh][nrow][w] */
	double *vm = hs + (size_t)l.nh * nrow * w;          /* [nv][w] */
	double *prow = vm + (size_t)l.nv * w;               /* [w + 2r] */
	double *mx = prow + w + 2 * r;                      /* [w][10] */

	double hk[NHK][2 * LPR_MAXRADIUS + 1];
	for (int i = -r; i <= r; i++) {
		double t = f->t[i + r], u = (double)i / r, q = t * t;
		hk[HT][i + r] = t;
		hk[HTU][i + r] = t * u;
		hk[HTU2][i + r] = t * u * u;
		hk[HQ][i + r] = q;
		hk[HQU][i + r] = q * u;
		hk[HQU2][i + r] = q * u * u;
	}
	for (int x = 0; x < w; x++) {
		int lo = x - r < 0 ? -x : -r, hi = x + r >= w ? w - 1 - x : r;
		sums_1d(f->t, r, lo, hi, mx + 10 * (size_t)x, mx + 10 * (size_t)x + 5);
	}

	/* Horizontal passes of every plane over the zero-padded rows. */
	for (int y = ha; y < hb; y++) {
		const float *yrow = clean + (size_t)y * w * nch;
		const float *frow = feat->px + (size_t)y * w * nf;
		for (int p = 0; p < l.np; p++) {
			for (int i = 0; i < r; i++)
				prow[i] = prow[w + r + i] = 0.0;
			/* the one or two channels the plane is made of */
			const int fa = l.fa[p], fb = l.fb[p];
			const float *pa = fa < nch ? yrow + fa : frow + (fa - nch);
			const size_t sa = fa < nch ? (size_t)nch : (size_t)nf;
			if (fb < 0) {
				for (int x = 0; x < w; x++)
					prow[x + r] = pa[x * sa];
			} else {
				const float *pb = fb < nch ? yrow + fb : frow + (fb - nch);
				const size_t sb = fb < nch ? (size_t)nch : (size_t)nf;
				for (int x = 0; x < w; x++)
					prow[x + r] = (double)pa[x * sa] * pb[x * sb];
			}
			for (int k = 0; k < l.hcount[p]; k++) {
				/* planes with 2 rows use (t, q); otherwise t.. in order */
				int kern = l.hcount[p] == 2 ? (k ? HQ : HT) : k;
				double *o = hs + ((size_t)(l.hbase[p] + k) * nrow + (y - ha)) * w;
				conv_1d(o, prow, 1, hk[kern], 2 * r + 1, w);
			}
		}
	}

	long n = 0;
	for (int y = ya; y < yb; y++) {
		const unsigned char *el = elig + (size_t)(y - ya) * w;
		int any = 0;
		for (int x = 0; x < w && !any; x++)
			any = el[x] != LPR_WIN_MASKED;
		if (!any)
			continue;
		int jlo = y - r < 0 ? -y : -r, jhi = y + r >= h ? h - 1 - y : r;
		double my[5], qy[5];
		sums_1d(f->t, r, jlo, jhi, my, qy);

		/* Vertical passes: the moments of every plane for this row. */
		int v = 0;
		for (int p = 0; p < l.np; p++) {
			/* (horizontal kernel row, vertical kernel) pairs */
			int pairs[12][2], np = 0;
			if (l.hcount[p] >= 3)
				for (int s = 0; s < NSP; s++) {
					pairs[np][0] = ex[s];          /* HT, HTU, HTU2 */
					pairs[np++][1] = ey[s];        /* t v^j */
				}
			if (l.hcount[p] == 6)
				for (int s = 0; s < NSP; s++) {
					pairs[np][0] = 3 + ex[s];      /* HQ, HQU, HQU2 */
					pairs[np++][1] = 3 + ey[s];    /* q v^j */
				}
			if (l.hcount[p] == 2) {
				pairs[np][0] = 0, pairs[np++][1] = 0;
				pairs[np][0] = 1, pairs[np++][1] = 3;
			}
			if (l.hcount[p] == 1)
				pairs[np][0] = 0, pairs[np++][1] = 0;
			for (int k = 0; k < np; k++, v++) {
				const double *base = hs + (size_t)(l.hbase[p] + pairs[k][0]) * nrow * w;
				conv_1d(vm + (size_t)v * w, base + (size_t)(y + jlo - ha) * w, (size_t)w,
					hk[pairs[k][1]] + jlo + r, jhi - jlo + 1, w);
			}
		}

		/* Per pixel: assemble the normal equations and solve. */
		for (int x = 0; x < w; x++) {
			size_t li = (size_t)(y - ya) * w + x;
			if (el[x] == LPR_WIN_MASKED)
				continue;
			size_t gi = (size_t)y * w + x;
			const float *yc = img->px + gi * nch;
			const float *fc = feat->px + gi * nf;
			const double *mu = mx + 10 * (size_t)x, *qu = mu + 5;
			/* moments of this pixel: vm[k * w + x] */
#define VM(k) vm[(size_t)(k) * w + x]
			const int vf = nch * 6, vff = vf + nf * 12, vfy = vff + l.nff * 2;
			/* Every entry of the p x p system is set below. */
			struct lpr_system sys;
			sys.nch = nch;
			sys.have_bq = 1;

			/* Which features vary in this window, and their scales. */
			double msp[NSP], qsp[NSP];
			for (int s = 0; s < NSP; s++) {
				msp[s] = mu[ex[s]] * my[ey[s]];
				qsp[s] = qu[ex[s]] * qy[ey[s]];
			}
			double sw = msp[0] - 1.0;
			int kf[LPR_MAXFEAT], nk = 0;
			double sc[LPR_MAXFEAT];
			for (int a = 0; a < nf; a++) {
				double m1 = VM(vf + a * 12) - fc[a] * msp[0];
				double m2 = VM(vff + 2 * ff_index(nf, a, a)) -
					    2.0 * fc[a] * VM(vf + a * 12) + (double)fc[a] * fc[a] * msp[0];
				double mean = m1 / sw, var = m2 / sw - mean * mean;
				double sd = var > 0.0 ? sqrt(var) : 0.0;
				/* the general path's rule (window.c) */
				if (!(sd > 1e-6 * (fabs(fc[a]) + fabs(mean))) || sd == 0.0)
					continue;
				kf[nk] = a;
				sc[nk++] = 1.0 / sd;
			}
			sys.nf = nk;
			const int p = NSP + nk;
			sys.n = ((x + r >= w ? w - 1 : x + r) - (x - r < 0 ? 0 : x - r) + 1) *
					(jhi - jlo + 1) - 1;
			sys.sw = sw;
			for (int s = 0; s < NSP; s++)
				for (int t2 = 0; t2 < NSP; t2++) {
					sys.a[s * p + t2] = mu[ex[s] + ex[t2]] * my[ey[s] + ey[t2]];
					sys.bq[s * p + t2] = qu[ex[s] + ex[t2]] * qy[ey[s] + ey[t2]];
				}
			sys.a[0] -= 1.0;
			sys.bq[0] -= 1.0;
			for (int ka = 0; ka < nk; ka++) {
				int a = kf[ka];
				double fa = fc[a], sa = sc[ka];
				for (int s = 0; s < NSP; s++) {
					double va = (VM(vf + a * 12 + s) - fa * msp[s]) * sa;
					double qa = (VM(vf + a * 12 + 6 + s) - fa * qsp[s]) * sa;
					sys.a[s * p + NSP + ka] = sys.a[(NSP + ka) * p + s] = va;
					sys.bq[s * p + NSP + ka] = sys.bq[(NSP + ka) * p + s] = qa;
				}
				for (int kb = ka; kb < nk; kb++) {
					int b = kf[kb];
					double fb = fc[b], sb = sc[kb];
					int fi = vff + 2 * ff_index(nf, a, b);
					double va = VM(fi) - fa * VM(vf + b * 12) - fb * VM(vf + a * 12) +
						    fa * fb * msp[0];
					double qa = VM(fi + 1) - fa * VM(vf + b * 12 + 6) -
						    fb * VM(vf + a * 12 + 6) + fa * fb * qsp[0];
					sys.a[(NSP + ka) * p + NSP + kb] = sys.a[(NSP + kb) * p + NSP + ka] =
						va * sa * sb;
					sys.bq[(NSP + ka) * p + NSP + kb] = sys.bq[(NSP + kb) * p + NSP + ka] =
						qa * sa * sb;
				}
			}
			for (int ch = 0; ch < nch; ch++) {
				for (int s = 0; s < NSP; s++)
					sys.b[ch][s] = VM(ch * 6 + s);
				sys.b[ch][0] -= yc[ch];
				for (int ka = 0; ka < nk; ka++) {
					int a = kf[ka];
					sys.b[ch][NSP + ka] =
						(VM(vfy + a * nch + ch) - fc[a] * VM(ch * 6)) * sc[ka];
				}
			}
#undef VM
			struct lpr_fit fits[LPR_NORDERS];
			struct lpr_solution sol;
			lpr_system_solve(&sys, maxorder, 0, fits, &sol);
			lpr_system_finish(&sys, yc, 0, r, maxorder, &sol, fits);
			for (int o = 0; o < LPR_NORDERS; o++)
				if (c[o])
					lpr_cand_write(c[o], li, nch, &fits[o]);
			n++;
		}
	}
	return n;
}
