/*
 * lpr.h - local polynomial regression of images with PRESS error estimates.
 *
 * At every pixel a kernel-weighted polynomial in the pixel offsets (tricube
 * product kernel, offsets scaled to [-1, 1], orders 0, 1 and 2), optionally
 * plus a linear term in each of F feature channels, is fitted to the pixels
 * of a square window.  Each candidate model (order, radius) gets, per pixel,
 * its leave-one-out residual e = Y - f_(-c)(x_c); the PRESS criterion of a
 * candidate at a pixel is the kernel-weighted mean of e^2 (averaged over the
 * channels) in a small neighbourhood, and the candidate with the smallest
 * criterion is selected, ties going to the lower order and then the larger
 * radius.  NaN and Inf mark missing samples ("holes"): they are left out of
 * every fit and predicted from their neighbours.
 *
 * Unmasked interior windows without features are fixed linear filters and
 * are computed as separable convolutions (the fast path); borders, windows
 * with holes and feature fits are solved per pixel (the general path).  Work
 * is split into fixed strips of rows, so the result does not depend on the
 * number of threads.
 *
 * The library knows nothing of files or of POV-Ray.
 */
#ifndef LPR_H
#define LPR_H

#include <stddef.h>

#define LPR_MAXCH 16       /* colour channels per image */
#define LPR_MAXFEAT 8      /* feature channels */
#define LPR_MAXRADIUS 32

/* An input image: w x h pixels of nch interleaved floats. */
struct lpr_image {
	int w, h, nch;
	const float *px;   /* px[((size_t)y * w + x) * nch + c]; not owned */
};

struct lpr_params {
	int order;          /* -1 (default): select among 0, 1, 2; else fixed */
	int radius;         /* 0 (default): select among radii[]; else fixed */
	int nradii;
	int radii[8];       /* candidate radii, default 2, 3, 5, 8 */
	int smooth_radius;  /* radius of the PRESS neighbourhood, default 2 */
	double tie_tol;     /* relative margin a higher order must win by */
	int nthreads;       /* 0 (default): one per online core */
	int force_general;  /* testing: solve every pixel on the general path */
};

/* Set p to the defaults described above. */
void lpr_params_init(struct lpr_params *p);

/*
 * The analysis of an image.  All arrays are w * h (times nch where said),
 * row-major, and owned by the result; free them with lpr_result_release().
 */
struct lpr_result {
	int w, h, nch;
	float *fit;        /* w*h*nch: the reconstruction */
	float *dx, *dy;    /* w*h*nch: derivatives per pixel, x right, y down */
	float *leverage;   /* H_cc of the selected fit (0 at holes) */
	float *error;      /* estimated squared error of the input value */
	float *order;      /* selected order (whole number) */
	float *bandwidth;  /* selected radius in pixels; 0 = no estimate */
	long fast_pixels;  /* candidate fits done on the fast path */
	long general_pixels; /* candidate fits done on the general path */
};

/*
 * Analyse img.  features, when not NULL, has the same w and h and 1 to
 * LPR_MAXFEAT channels; each becomes a local linear predictor, centred at
 * the pixel and standardised per window; a feature that is constant or
 * collinear with the others in a window is dropped there.  Returns 0, or -1
 * with a message in err (bad sizes, out of memory, bad parameters).
 */
int lpr_analyze(const struct lpr_image *img, const struct lpr_image *features,
		const struct lpr_params *p, struct lpr_result *out,
		char *err, size_t errlen);

/* Free what r owns and zero it; a zeroed result is a no-op. */
void lpr_result_release(struct lpr_result *r);

/* One candidate fit at one pixel, as the general path computes it. */
struct lpr_fit {
	int valid;                   /* 0: the model cannot be fitted here */
	int hole;                    /* the centre pixel is missing */
	int rank;                    /* kept columns of the leave-one-out fit */
	double fit[LPR_MAXCH];       /* fitted value at the centre */
	double loo[LPR_MAXCH];       /* leave-one-out prediction at the centre */
	double dx[LPR_MAXCH], dy[LPR_MAXCH];
	double leverage;             /* H_cc (0 for a hole) */
	double vloo;                 /* var(loo prediction) / sigma^2 */
	double noise;                /* per-channel mean of e^2 / (1 + vloo) */
	double press;                /* per-channel mean of e^2 */
};

/*
 * Fit the model (order 0..2, radius 1..LPR_MAXRADIUS) at pixel (x, y) on the
 * general path.  For a hole, noise and press come from the residuals of the
 * fit.  Returns 0, or -1 on bad arguments.
 */
int lpr_fit_pixel(const struct lpr_image *img, const struct lpr_image *features,
		  int x, int y, int order, int radius, struct lpr_fit *out);

#endif
