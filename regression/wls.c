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

void wls_solve(const struct wls_factor *f, const double *b, double *x)
{
	int n = f->nact;
	const double *l = f->l;
	double y[WLS_MAXP];

	for (int k = 0; k < n; k++) {
		if (!f->kept[k]) {
			y[k] = 0.0;
			continue;
		}
		double s = b[f->act[k]] * f->scale[k];
		for (int m = 0; m < k; m++)
			s -= l[k * n + m] * y[m];
		y[k] = s / l[k * n + k];
	}
	for (int k = n - 1; k >= 0; k--) {
		if (!f->kept[k]) {
			y[k] = 0.0;
			continue;
		}
		double s = y[k];
		for (int m = k + 1; m < n; m++)
			s -= l[m * n + k] * y[m];
		y[k] = s / l[k * n + k];
	}
	for (int i = 0; i < f->p; i++)
		x[i] = 0.0;
	for (int k = 0; k < n; k++)
		x[f->act[k]] = y[k] * f->scale[k];
}

int wls_kept(const struct wls_factor *f, int col)
{
	for (int k = 0; k < f->nact; k++)
		if (f->act[k] == col)
			return f->kept[k];
	return 0;
}
