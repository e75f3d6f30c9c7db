/*
 * fastpath.c - unmasked interior windows as separable convolutions.
 *
 * With the product tricube kernel, offsets scaled by 1/r and a full window,
 * the moment matrix is the same at every interior pixel and symmetric in u
 * and v, so the centre fits are fixed filters:
 *   order 0 and 1:  fit = sum W Y / S^2              (W = t(i) t(j), S = sum t)
 *   order 2:        fit = sum W (c0 + c3 u^2 + c5 v^2) Y
 *   slope (1, 2):   df/dx = sum W u Y / (r sum W u^2), likewise y
 * where (c0 .. c5) is the first row of the inverse moment matrix (c1, c2
 * and c4 vanish by symmetry).  Each is a sum of separable filters: three
 * horizontal passes (t, t u, t u^2) feed five vertical ones.  The leverage
 * H_cc is the filter's centre tap, so the leave-one-out residual is
 * (Y - fit) / (1 - H_cc); all sums are accumulated in double.
 */
#include "regression/lpr_internal.h"
#include "regression/kernel.h"
#include "regression/wls.h"

#include <math.h>
#include <string.h>

#define BLK 8   /* horizontal pass: outputs summed in registers */
#define VBLK 4  /* vertical pass: five sums each */
#define TILE 64 /* vertical pass: pixels per column tile */

/* The convolutions are most of the analysis time: on x86-64 build them
 * also for AVX2 with FMA and let the loader pick what the CPU runs. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define FAST_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define FAST_CLONES
#endif

void lpr_filters_init(struct lpr_filters *f, int r)
{
	memset(f, 0, sizeof *f);
	f->r = r;
	kernel_weights(r, f->t);
	double s = 0.0, s2 = 0.0, su2 = 0.0;
	for (int i = -r; i <= r; i++) {
		double u = (double)i / r, t = f->t[i + r];
		f->tu[i + r] = t * u;
		f->tu2[i + r] = t * u * u;
		s += t;
		s2 += t * t;
		su2 += t * u * u;
	}
	f->s = s;
	f->h0 = 1.0 / (s * s);
	f->v0 = (s2 * s2 - 1.0) / ((s * s - 1.0) * (s * s - 1.0));
	f->gscale = 1.0 / (r * su2 * s);

	/* Order 2: invert the moment matrix of the full window. */
	double a[36] = {0};
	for (int j = -r; j <= r; j++)
		for (int i = -r; i <= r; i++) {
			double u = (double)i / r, v = (double)j / r;
			double w = f->t[i + r] * f->t[j + r];
			double x[6] = { 1.0, u, v, u * u, u * v, v * v };
			for (int k = 0; k < 6; k++)
				for (int m = 0; m < 6; m++)
					a[k * 6 + m] += w * x[k] * x[m];
		}
	int act[6] = { 0, 1, 2, 3, 4, 5 };
	struct wls_factor fac;
	wls_factor(a, 6, act, 6, &fac);
	double e0[6] = { 1, 0, 0, 0, 0, 0 }, c[6];
	wls_solve(&fac, e0, c);
	f->c0 = c[0];
	f->c3 = c[3];
	f->c5 = c[5];
	f->h2 = c[0];
	double v = 0.0;
	for (int j = -r; j <= r; j++)
		for (int i = -r; i <= r; i++) {
			if (!i && !j)
				continue;
			double u = (double)i / r, vv = (double)j / r;
			double l = f->t[i + r] * f->t[j + r] * (c[0] + c[3] * u * u + c[5] * vv * vv);
			v += l * l;
		}
	f->v2 = v / ((1.0 - f->h2) * (1.0 - f->h2));
}

size_t lpr_fast_scratch(int w, int nch, int nrows, int r)
{
	size_t rowlen = (size_t)w * nch;
	return rowlen * 3 * (size_t)(nrows + 2 * r) + rowlen * 5;
}

static void put(struct lpr_cand_buf *b, size_t i, int nch, const double *fit,
		const double *dx, const double *dy, double lev, double e2, double q)
{
	if (!b)
		return;
	for (int c = 0; c < nch; c++) {
		b->fit[i * nch + c] = (float)fit[c];
		b->dx[i * nch + c] = (float)dx[c];
		b->dy[i * nch + c] = (float)dy[c];
	}
	b->lev[i] = (float)lev;
	b->e2[i] = (float)e2;
	b->q[i] = (float)q;
}

FAST_CLONES
long lpr_fast_strip(const struct lpr_filters *f, const float *clean, int w, int h,
		    int nch, int ya, int yb, const unsigned char *elig,
		    double *scratch, struct lpr_cand_buf *const c[LPR_NORDERS])
{
	const int r = f->r;
	if (w < 2 * r + 1 || h < 2 * r + 1)
		return 0;
	int ha = ya - r < 0 ? 0 : ya - r, hb = yb + r > h ? h : yb + r;
	int va = ya < r ? r : ya, vb = yb > h - r ? h - r : yb;
	if (va >= vb)
		return 0;
	const size_t rowlen = (size_t)w * nch;
	const size_t nrow = (size_t)(hb - ha);
	double *hw = scratch, *hu = hw + rowlen * nrow, *hu2 = hu + rowlen * nrow;
	double *acc = hu2 + rowlen * nrow;
	/* Valid x range in interleaved units. */
	const size_t xa = (size_t)r * nch, xb = (size_t)(w - r) * nch;

	/* Horizontal passes, BLK outputs at a time so that the sums stay in
	 * registers; the tail of a row is done one element at a time.  The
	 * taps are symmetric (t, t u^2) or antisymmetric (t u) about the
	 * centre, whose t u and t u^2 are 0: each pair of values at +-i is
	 * summed or differenced once, then weighted (in the vertical passes
	 * too). */
	const double tc = f->t[r];
	for (int y = ha; y < hb; y++) {
		const float *in = clean + (size_t)y * rowlen;
		double *o0 = hw + (size_t)(y - ha) * rowlen;
		double *o1 = hu + (size_t)(y - ha) * rowlen;
		double *o2 = hu2 + (size_t)(y - ha) * rowlen;
		size_t k = xa;
		for (; k + BLK <= xb; k += BLK) {
			double s0[BLK], s1[BLK] = {0}, s2[BLK] = {0};
			for (int m = 0; m < BLK; m++)
				s0[m] = tc * in[k + m];
			for (int i = 1; i <= r; i++) {
				const float *p = in + k + (ptrdiff_t)i * nch, *q = in + k - (ptrdiff_t)i * nch;
				const double t = f->t[i + r], tu = f->tu[i + r], tu2 = f->tu2[i + r];
				for (int m = 0; m < BLK; m++) {
					const double a = (double)p[m] + q[m], d = (double)p[m] - q[m];
					s0[m] += t * a;
					s1[m] += tu * d;
					s2[m] += tu2 * a;
				}
			}
			memcpy(o0 + k, s0, sizeof s0);
			memcpy(o1 + k, s1, sizeof s1);
			memcpy(o2 + k, s2, sizeof s2);
		}
		for (; k < xb; k++) {
			double s0 = tc * in[k], s1 = 0.0, s2 = 0.0;
			for (int i = 1; i <= r; i++) {
				const double p = in[k + (size_t)i * nch], q = in[k - (size_t)i * nch];
				s0 += f->t[i + r] * (p + q);
				s1 += f->tu[i + r] * (p - q);
				s2 += f->tu2[i + r] * (p + q);
			}
			o0[k] = s0;
			o1[k] = s1;
			o2[k] = s2;
		}
	}

	/* Vertical passes, a tile of TILE pixels at a time for every row, so
	 * that the 2r + 1 rows a tile reads stay in cache from row to row. */
	const double s2 = f->s * f->s;
	const double d0 = 1.0 - f->h0, d2 = 1.0 - f->h2;
	long n = 0;
	for (int tx = r; tx < w - r; tx += TILE) {
		const int tx1 = tx + TILE < w - r ? tx + TILE : w - r;
		const size_t ka = (size_t)tx * nch, kb = (size_t)tx1 * nch;
		for (int y = va; y < vb; y++) {
			const unsigned char *el = elig + (size_t)(y - ya) * w;
			int any = 0;
			for (int x = tx; x < tx1 && !any; x++)
				any = el[x] == LPR_WIN_INTERIOR;
			if (!any)
				continue;
			double *a00 = acc, *a20 = acc + rowlen, *a02 = acc + 2 * rowlen;
			double *ax = acc + 3 * rowlen, *ay = acc + 4 * rowlen;
			for (size_t k0 = ka; k0 < kb; k0 += VBLK) {
				int nb = kb - k0 < VBLK ? (int)(kb - k0) : VBLK;
				double s00[VBLK] = {0}, s20[VBLK] = {0}, s02[VBLK] = {0};
				double sx[VBLK] = {0}, sy[VBLK] = {0};
				const int nm = nb == VBLK ? VBLK : nb;
				/* the centre row, then the rows at +-j in pairs (as the
				 * horizontal pass) */
				const size_t oc = (size_t)(y - ha) * rowlen + k0;
				for (int m = 0; m < nm; m++) {
					s00[m] = tc * hw[oc + m];
					s20[m] = tc * hu2[oc + m];
					sx[m] = tc * hu[oc + m];
				}
				for (int j = 1; j <= r; j++) {
					const size_t op = oc + (size_t)j * rowlen, on = oc - (size_t)j * rowlen;
					const double t = f->t[j + r], tv = f->tu[j + r], tv2 = f->tu2[j + r];
					for (int m = 0; m < nm; m++) {
						const double aw = hw[op + m] + hw[on + m];
						const double dw = hw[op + m] - hw[on + m];
						s00[m] += t * aw;
						s20[m] += t * (hu2[op + m] + hu2[on + m]);
						s02[m] += tv2 * aw;
						sx[m] += t * (hu[op + m] + hu[on + m]);
						sy[m] += tv * dw;
					}
				}
				size_t nbytes = (size_t)nb * sizeof(double);
				memcpy(a00 + k0, s00, nbytes);
				memcpy(a20 + k0, s20, nbytes);
				memcpy(a02 + k0, s02, nbytes);
				memcpy(ax + k0, sx, nbytes);
				memcpy(ay + k0, sy, nbytes);
			}
			size_t base = (size_t)(y - ya) * w;
			const float *in = clean + (size_t)y * rowlen;
			for (int x = tx; x < tx1; x++) {
				if (el[x] != LPR_WIN_INTERIOR)
					continue;
				double fit0[LPR_MAXCH], fit2[LPR_MAXCH], dx[LPR_MAXCH], dy[LPR_MAXCH];
				double p0 = 0.0, p2 = 0.0;
				for (int ch = 0; ch < nch; ch++) {
					size_t k = (size_t)x * nch + ch;
					double yv = in[k];
					fit0[ch] = a00[k] / s2;
					fit2[ch] = f->c0 * a00[k] + f->c3 * a20[k] + f->c5 * a02[k];
					dx[ch] = f->gscale * ax[k];
					dy[ch] = f->gscale * ay[k];
					double e0 = (yv - fit0[ch]) / d0, e2 = (yv - fit2[ch]) / d2;
					p0 += e0 * e0;
					p2 += e2 * e2;
				}
				p0 /= nch;
				p2 /= nch;
				put(c[0], base + x, nch, fit0, dx, dy, f->h0, p0, p0 / (1.0 + f->v0));
				if (c[1]) {
					/* Order 1 is order 0 here (u, v are orthogonal to 1
					 * in a full symmetric window): store its criterion and
					 * mark the fit NaN to say "same as order 0". */
					c[1]->fit[(base + x) * nch] = NAN;
					c[1]->lev[base + x] = (float)f->h0;
					c[1]->e2[base + x] = (float)p0;
					c[1]->q[base + x] = (float)(p0 / (1.0 + f->v0));
				}
				put(c[2], base + x, nch, fit2, dx, dy, f->h2, p2, p2 / (1.0 + f->v2));
				n++;
			}
		}
	}
	return n;
}
