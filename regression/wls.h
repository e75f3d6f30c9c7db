/*
 * wls.h - small dense weighted least squares through the normal equations.
 *
 * The caller accumulates A = X^T W X (p x p, row-major, both triangles) and
 * solves A beta = b for a chosen subset of the columns.  The factorisation
 * is stabilised as locfit and loess do: the active sub-matrix is Jacobi
 * equilibrated (unit diagonal), then Cholesky-factored with a relative pivot
 * test; a column whose pivot falls below WLS_PIVOT_TOL (it is, to that
 * precision, a combination of the columns before it) is dropped and its
 * coefficient set to 0 instead of being divided by ~0.  Everything is double.
 */
#ifndef LPR_WLS_H
#define LPR_WLS_H

#define WLS_MAXP 16
#define WLS_PIVOT_TOL 1e-9
#define WLS_NRHS 17

struct wls_factor {
	int p;                          /* size of the full system */
	int nact;                       /* number of active columns */
	int act[WLS_MAXP];              /* active column indices, in order */
	int kept[WLS_MAXP];             /* per active column: 1 kept, 0 dropped */
	int rank;                       /* number of kept columns */
	double scale[WLS_MAXP];         /* equilibration, per active column */
	double l[WLS_MAXP * WLS_MAXP];  /* Cholesky factor, nact x nact */
	double inv[WLS_MAXP];           /* 1 / diagonal of l; 0 for dropped columns */
};

/*
 * Factor the sub-matrix of the p x p matrix a on columns act[0 .. nact-1].
 * A column with a non-positive diagonal is dropped.  Returns the rank.
 */
int wls_factor(const double *a, int p, const int *act, int nact, struct wls_factor *f);

/*
 * Solve with a factor: x (length p) receives the solution on the active
 * columns and 0 elsewhere, including on dropped columns; b has length p and
 * only its active entries are read.
 */
void wls_solve(const struct wls_factor *f, const double *b, double *x);

/*
 * Solve for nrhs <= WLS_NRHS right-hand sides at once: right-hand side j
 * is b[j * ld .. j * ld + p - 1], and its solution goes to x[j * ld ..]
 * (ld >= p).
 */
void wls_solve_n(const struct wls_factor *f, int nrhs, const double *b, double *x, int ld);

/* 1 when column col is active and kept, else 0. */
int wls_kept(const struct wls_factor *f, int col);

#endif
