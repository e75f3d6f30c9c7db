/*
 * window.c - the general path: one local fit at one pixel, solved directly.
 *
 * Used for windows clipped by the image border, windows with missing
 * samples, and fits with feature predictors.  The centre sample is left out
 * of the normal equations: solving A' beta' = b' gives the leave-one-out
 * prediction beta'_0 directly (the predictors are centred at the pixel, so
 * the prediction at the centre is the intercept), and with g = (A'^-1)_00
 * and centre weight w0 the full fit follows by Sherman-Morrison:
 *   H_cc = w0 g / (1 + w0 g),   1 - H_cc = 1 / (1 + w0 g),
 *   fit = Y_c - e / (1 + w0 g),  beta = beta' + (w0 e / (1 + w0 g)) A'^-1 e_0,
 * where e = Y_c - beta'_0.  No difference of nearly equal numbers is formed,
 * even when H_cc is close to 1.
 */
#include "regression/lpr_internal.h"
#include "regression/kernel.h"
#include "regression/wls.h"

#include <math.h>
#include <string.h>

#define NSP 6

int lpr_sample_valid(const struct lpr_image *img, const struct lpr_image *feat, size_t i)
{
	const float *p = img->px + i * (size_t)img->nch;
	for (int c = 0; c < img->nch; c++)
		if (!isfinite(p[c]))
			return 0;
	if (feat) {
		const float *f = feat->px + i * (size_t)feat->nch;
		for (int c = 0; c < feat->nch; c++)
			if (!isfinite(f[c]))
				return 0;
	}
	return 1;
}

struct design {
	int r, nf;                  /* radius, features kept */
	int fidx[LPR_MAXFEAT];      /* feature channel of each kept feature */
	double fc[LPR_MAXFEAT];     /* feature value at the centre */
	double fs[LPR_MAXFEAT];     /* 1 / feature scale in the window */
};

static int design_row(const struct design *d, const struct lpr_image *feat,
		      size_t idx, int i, int j, double *xr)
{
	double u = (double)i / d->r, v = (double)j / d->r;
	xr[0] = 1.0;
	xr[1] = u;
	xr[2] = v;
	xr[3] = u * u;
	xr[4] = u * v;
	xr[5] = v * v;
	if (d->nf) {
		const float *f = feat->px + idx * (size_t)feat->nch;
		for (int k = 0; k < d->nf; k++)
			xr[NSP + k] = ((double)f[d->fidx[k]] - d->fc[k]) * d->fs[k];
	}
	return NSP + d->nf;
}

/* Choose and standardise the features of the window around (x, y). */
static void design_features(struct design *d, const struct lpr_image *img,
			    const struct lpr_image *feat, int x, int y,
			    int x0, int x1, int y0, int y1, const double *t)
{
	d->nf = 0;
	if (!feat)
		return;
	const float *fcen = feat->px + ((size_t)y * img->w + x) * (size_t)feat->nch;
	for (int k = 0; k < feat->nch; k++)
		if (!isfinite(fcen[k]))
			return;
	double sw = 0.0, m1[LPR_MAXFEAT] = {0}, m2[LPR_MAXFEAT] = {0};
	for (int yy = y0; yy <= y1; yy++)
		for (int xx = x0; xx <= x1; xx++) {
			size_t idx = (size_t)yy * img->w + xx;
			if ((xx == x && yy == y) || !lpr_sample_valid(img, feat, idx))
				continue;
			double w = t[xx - x + d->r] * t[yy - y + d->r];
			const float *f = feat->px + idx * (size_t)feat->nch;
			sw += w;
			for (int k = 0; k < feat->nch; k++) {
				double df = (double)f[k] - fcen[k];
				m1[k] += w * df;
				m2[k] += w * df * df;
			}
		}
	if (sw <= 0.0)
		return;
	for (int k = 0; k < feat->nch; k++) {
		double mean = m1[k] / sw;
		double var = m2[k] / sw - mean * mean;
		double sd = var > 0.0 ? sqrt(var) : 0.0;
		/* Relative variation below float resolution is no feature. */
		if (!(sd > 1e-6 * (fabs(fcen[k]) + fabs(mean))) || sd == 0.0)
			continue;
		d->fidx[d->nf] = k;
		d->fc[d->nf] = fcen[k];
		d->fs[d->nf] = 1.0 / sd;
		d->nf++;
	}
}

/*
 * Normal equations of a clipped window with no missing sample and no
 * features.  The product kernel makes every moment separable:
 * sum W u^a v^b = (sum_i t_i u_i^a) (sum_j t_j v_j^b), so A' and
 * B' = sum W^2 x x^T come from 1-D sums, and X'^T W Y from row sums.
 */
static void unmasked_system(const struct lpr_image *img, int x, int y, int r,
			    const double *t, int x0, int x1, int y0, int y1,
			    double *a, double (*b)[WLS_MAXP], double *bq)
{
	static const int ea[NSP] = { 0, 1, 0, 2, 1, 0 }, eb[NSP] = { 0, 0, 1, 0, 1, 2 };
	double mu[5] = {0}, mv[5] = {0}, qu[5] = {0}, qv[5] = {0};
	for (int i = x0 - x; i <= x1 - x; i++) {
		double u = (double)i / r, w = t[i + r], pw = 1.0;
		for (int k = 0; k < 5; k++, pw *= u) {
			mu[k] += w * pw;
			qu[k] += w * w * pw;
		}
	}
	for (int j = y0 - y; j <= y1 - y; j++) {
		double v = (double)j / r, w = t[j + r], pw = 1.0;
		for (int k = 0; k < 5; k++, pw *= v) {
			mv[k] += w * pw;
			qv[k] += w * w * pw;
		}
	}
	for (int k = 0; k < NSP; k++)
		for (int m = 0; m < NSP; m++) {
			a[k * NSP + m] = mu[ea[k] + ea[m]] * mv[eb[k] + eb[m]];
			bq[k * NSP + m] = qu[ea[k] + ea[m]] * qv[eb[k] + eb[m]];
		}
	/* Leave the centre out: its row of X is e_0 and its weight 1. */
	a[0] -= 1.0;
	bq[0] -= 1.0;

	const int nch = img->nch;
	for (int c = 0; c < nch; c++)
		for (int k = 0; k < NSP; k++)
			b[c][k] = 0.0;
	for (int yy = y0; yy <= y1; yy++) {
		double v = (double)(yy - y) / r, tj = t[yy - y + r];
		const float *row = img->px + (size_t)yy * img->w * nch;
		for (int c = 0; c < nch; c++) {
			double r0 = 0.0, r1 = 0.0, r2 = 0.0;
			for (int xx = x0; xx <= x1; xx++) {
				double u = (double)(xx - x) / r, ty = t[xx - x + r] * row[(size_t)xx * nch + c];
				r0 += ty;
				r1 += ty * u;
				r2 += ty * u * u;
			}
			b[c][0] += tj * r0;
			b[c][1] += tj * r1;
			b[c][2] += tj * v * r0;
			b[c][3] += tj * r2;
			b[c][4] += tj * v * r1;
			b[c][5] += tj * v * v * r0;
		}
	}
	const float *yc = img->px + ((size_t)y * img->w + x) * nch;
	for (int c = 0; c < nch; c++)
		b[c][0] -= yc[c];
}

void lpr_system_solve(const struct lpr_system *sys, int maxorder, int hole,
		      struct lpr_fit *out, struct lpr_solution *sol)
{
	const int p = NSP + sys->nf;
	for (int o = 0; o <= maxorder; o++) {
		struct lpr_fit *f = &out[o];
		memset(f, 0, sizeof *f);
		f->hole = hole;
		int act[WLS_MAXP], nact = 0, nsp = lpr_nspatial(o);
		for (int k = 0; k < nsp; k++)
			act[nact++] = k;
		for (int k = 0; k < sys->nf; k++)
			act[nact++] = NSP + k;
		struct wls_factor fac;
		f->rank = wls_factor(sys->a, p, act, nact, &fac);
		int ok = sys->n > 0;
		for (int k = 0; k < nsp; k++)
			ok = ok && wls_kept(&fac, k);
		f->valid = ok;
		if (!ok)
			continue;
		/* One solve for e_0 and every channel's b'. */
		double rhs[1 + LPR_MAXCH][WLS_MAXP], x[1 + LPR_MAXCH][WLS_MAXP];
		memset(rhs[0], 0, sizeof rhs[0]);
		rhs[0][0] = 1.0;
		for (int c = 0; c < sys->nch; c++)
			memcpy(rhs[1 + c], sys->b[c], sizeof rhs[0]);
		wls_solve_n(&fac, 1 + sys->nch, rhs[0], x[0], WLS_MAXP);
		memcpy(sol->z[o], x[0], sizeof x[0]);
		for (int c = 0; c < sys->nch; c++)
			memcpy(sol->beta[o][c], x[1 + c], sizeof x[0]);
		/* The variance of the leave-one-out prediction is z^T B' z. */
		sol->vsum[o] = 0.0;
		if (sys->have_bq)
			for (int k = 0; k < p; k++)
				for (int m = 0; m < p; m++)
					sol->vsum[o] += sol->z[o][k] * sys->bq[k * p + m] * sol->z[o][m];
		for (int c = 0; c < sys->nch; c++)
			sol->rss[o][c] = 0.0;
	}
}

void lpr_system_finish(const struct lpr_system *sys, const float *yc, int hole, int r,
		       int maxorder, const struct lpr_solution *sol, struct lpr_fit *out)
{
	const int nch = sys->nch;
	for (int o = 0; o <= maxorder; o++) {
		struct lpr_fit *f = &out[o];
		if (!f->valid)
			continue;
		const double *z = sol->z[o];
		double g = z[0];
		f->vloo = sol->vsum[o];
		double press = 0.0, noise = 0.0;
		if (!hole) {
			double den = 1.0 + g;   /* centre weight w0 = 1 */
			f->leverage = g / den;
			for (int c = 0; c < nch; c++) {
				const double *beta = sol->beta[o][c];
				double e = yc[c] - beta[0];
				f->loo[c] = beta[0];
				f->fit[c] = yc[c] - e / den;
				double s = e / den;
				f->dx[c] = (beta[1] + s * z[1]) / r;
				f->dy[c] = (beta[2] + s * z[2]) / r;
				press += e * e;
			}
			press /= nch;
			noise = press / (1.0 + f->vloo);
		} else {
			for (int c = 0; c < nch; c++) {
				const double *beta = sol->beta[o][c];
				f->loo[c] = f->fit[c] = beta[0];
				f->dx[c] = beta[1] / r;
				f->dy[c] = beta[2] / r;
				noise += sol->rss[o][c];
			}
			if (sys->n > f->rank) {
				noise = noise / nch / sys->sw * sys->n / (sys->n - f->rank);
				press = noise * (1.0 + f->vloo);
			} else {
				noise = press = NAN;
			}
		}
		f->press = press;
		f->noise = noise;
	}
	/* Order 0 has no slope of its own: report the local linear one. */
	if (maxorder >= 1 && out[0].valid && out[1].valid)
		for (int c = 0; c < nch; c++) {
			out[0].dx[c] = out[1].dx[c];
			out[0].dy[c] = out[1].dy[c];
		}
	else if (out[0].valid)
		for (int c = 0; c < nch; c++)
			out[0].dx[c] = out[0].dy[c] = 0.0;
}

void lpr_general_fits(const struct lpr_image *img, const struct lpr_image *feat,
		      int x, int y, int r, int maxorder, int unmasked, struct lpr_fit *out)
{
	const int nch = img->nch;
	double t[2 * LPR_MAXRADIUS + 1];
	kernel_weights(r, t);
	int x0 = x - r < 0 ? 0 : x - r, x1 = x + r >= img->w ? img->w - 1 : x + r;
	int y0 = y - r < 0 ? 0 : y - r, y1 = y + r >= img->h ? img->h - 1 : y + r;

	struct design d = { .r = r };
	design_features(&d, img, feat, x, y, x0, x1, y0, y1, t);
	const int p = NSP + d.nf;

	/* Normal equations without the centre sample. */
	struct lpr_system sys;
	memset(&sys, 0, sizeof sys);
	sys.nf = d.nf;
	sys.nch = nch;
	double xr[WLS_MAXP];
	unmasked = unmasked && !feat;
	if (unmasked) {
		unmasked_system(img, x, y, r, t, x0, x1, y0, y1, sys.a, sys.b, sys.bq);
		sys.have_bq = 1;
		sys.n = (x1 - x0 + 1) * (y1 - y0 + 1) - 1;
		sys.sw = sys.a[0];
	} else {
		for (int yy = y0; yy <= y1; yy++)
			for (int xx = x0; xx <= x1; xx++) {
				size_t idx = (size_t)yy * img->w + xx;
				if ((xx == x && yy == y) || !lpr_sample_valid(img, feat, idx))
					continue;
				double w = t[xx - x + r] * t[yy - y + r];
				design_row(&d, feat, idx, xx - x, yy - y, xr);
				for (int k = 0; k < p; k++) {
					double wx = w * xr[k];
					for (int m = k; m < p; m++)
						sys.a[k * p + m] += wx * xr[m];
				}
				const float *yv = img->px + idx * (size_t)nch;
				for (int c = 0; c < nch; c++)
					for (int k = 0; k < p; k++)
						sys.b[c][k] += w * xr[k] * yv[c];
				sys.sw += w;
				sys.n++;
			}
		for (int k = 0; k < p; k++)
			for (int m = 0; m < k; m++)
				sys.a[k * p + m] = sys.a[m * p + k];
	}

	size_t cidx = (size_t)y * img->w + x;
	int hole = !lpr_sample_valid(img, NULL, cidx);
	const float *yc = img->px + cidx * (size_t)nch;
	struct lpr_solution sol;
	lpr_system_solve(&sys, maxorder, hole, out, &sol);

	/* Without B', a second pass over the window gives the variance of the
	 * leave-one-out prediction and, for a hole, the residuals of the fit. */
	if (!sys.have_bq)
		for (int yy = y0; yy <= y1; yy++)
			for (int xx = x0; xx <= x1; xx++) {
				size_t idx = (size_t)yy * img->w + xx;
				if ((xx == x && yy == y) || !lpr_sample_valid(img, feat, idx))
					continue;
				double w = t[xx - x + r] * t[yy - y + r];
				design_row(&d, feat, idx, xx - x, yy - y, xr);
				const float *yv = img->px + idx * (size_t)nch;
				for (int o = 0; o <= maxorder; o++) {
					if (!out[o].valid)
						continue;
					double sz = 0.0;
					for (int k = 0; k < p; k++)
						sz += xr[k] * sol.z[o][k];
					sol.vsum[o] += (w * sz) * (w * sz);
					if (!hole)
						continue;
					for (int c = 0; c < nch; c++) {
						double fv = 0.0;
						for (int k = 0; k < p; k++)
							fv += xr[k] * sol.beta[o][c][k];
						double res = yv[c] - fv;
						sol.rss[o][c] += w * res * res;
					}
				}
			}
	lpr_system_finish(&sys, yc, hole, r, maxorder, &sol, out);
}

int lpr_fit_pixel(const struct lpr_image *img, const struct lpr_image *features,
		  int x, int y, int order, int radius, struct lpr_fit *out)
{
	if (!img || !out || order < 0 || order > 2 || radius < 1 || radius > LPR_MAXRADIUS ||
	    x < 0 || y < 0 || x >= img->w || y >= img->h || img->nch < 1 ||
	    img->nch > LPR_MAXCH)
		return -1;
	if (features && (features->w != img->w || features->h != img->h ||
			 features->nch < 1 || features->nch > LPR_MAXFEAT))
		return -1;
	struct lpr_fit f[LPR_NORDERS];
	int maxo = order < 1 ? 1 : order;
	lpr_general_fits(img, features, x, y, radius, maxo, 0, f);
	*out = f[order];
	return 0;
}
