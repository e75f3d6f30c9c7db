#include "regression/wls.h"

#include <math.h>
#include <string.h>

int wls_factor(const double *a, int p, const int *act, int nact, struct wls_factor *f)
{
	f->p = p;
	f->nact = nact;
	f->rank = 0;
	memcpy(f->act, act, (size_t)nact * sizeof(int));
	for (int i = 0; i < nact; i++) {
		double d = a[act[i] * p + act[i]];
		f->scale[i] = d > 0.0 ? 1.0 / sqrt(d) : 0.0;
	}
	double *l = f->l;
	for (int k = 0; k < nact; k++) {
		int ck = act[k];
		f->kept[k] = 0;
		f->inv[k] = 0.0;
		for (int i = 0; i < nact; i++)
			l[i * nact + k] = 0.0;
		if (f->scale[k] == 0.0)
			continue;
		/* Equilibrated diagonal is 1: the pivot is what column k adds
		 * beyond the kept columns before it, as a fraction of itself. */
		double d = 1.0;
		for (int m = 0; m < k; m++)
			d -= l[k * nact + m] * l[k * nact + m];
		if (!(d > WLS_PIVOT_TOL))
			continue;
		double lkk = sqrt(d);
		l[k * nact + k] = lkk;
		f->inv[k] = 1.0 / lkk;
		f->kept[k] = 1;
		f->rank++;
		for (int i = k + 1; i < nact; i++) {
			int ci = act[i];
			if (f->scale[i] == 0.0)
				continue;
			double s = a[ci * p + ck] * f->scale[i] * f->scale[k];
			for (int m = 0; m < k; m++)
				s -= l[i * nact + m] * l[k * nact + m];
			l[i * nact + k] = s / lkk;
		}
	}
	return f->rank;
}

void wls_solve_n(const struct wls_factor *f, int nrhs, const double *b, double *x, int ld)
{
	const int n = f->nact, p = f->p;
	const double *l = f->l;
	double y[WLS_MAXP][WLS_NRHS];

	/* Dropped columns have a zero column in l and inv = 0, so they come
	 * out as 0 without a test.  The right-hand sides run in the inner
	 * loops: independent sums that the processor overlaps. */
	for (int k = 0; k < n; k++) {
		const int ck = f->act[k];
		for (int j = 0; j < nrhs; j++)
			y[k][j] = b[j * ld + ck] * f->scale[k];
		for (int m = 0; m < k; m++) {
			const double lkm = l[k * n + m];
			for (int j = 0; j < nrhs; j++)
				y[k][j] -= lkm * y[m][j];
		}
		for (int j = 0; j < nrhs; j++)
			y[k][j] *= f->inv[k];
	}
	for (int k = n - 1; k >= 0; k--) {
		for (int m = k + 1; m < n; m++) {
			const double lmk = l[m * n + k];
			for (int j = 0; j < nrhs; j++)
				y[k][j] -= lmk * y[m][j];
		}
		for (int j = 0; j < nrhs; j++)
			y[k][j] *= f->inv[k];
	}
	for (int j = 0; j < nrhs; j++) {
		double *xj = x + j * ld;
		for (int i = 0; i < p; i++)
			xj[i] = 0.0;
		for (int k = 0; k < n; k++)
			xj[f->act[k]] = y[k][j] * f->scale[k];
	}
}

void wls_solve(const struct wls_factor *f, const double *b, double *x)
{
	wls_solve_n(f, 1, b, x, f->p);
}

int wls_kept(const struct wls_factor *f, int col)
{
	for (int k = 0; k < f->nact; k++)
		if (f->act[k] == col)
			return f->kept[k];
	return 0;
}
