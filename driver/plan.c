/*
 * plan.c - choose pixels, pack rectangles, write regions (see plan.h).
 */
#include "driver/plan.h"
#include "driver/accum.h"
#include "driver/errbuf.h"
#include "driver/files.h"
#include "driver/metrics.h"
#include "driver/parallel.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

void plan_params_init(struct plan_params *p)
{
	memset(p, 0, sizeof(*p));
	p->target = 1e-3;
	p->margin = 0.7;
	p->cost_job = 0.05;
	p->cost_sample = 2e-6;
	p->max_regions = 64;
	p->tile = 8;
	p->min_gain = 0.05;
	p->grid_frame = PLAN_GRID_FRAME;
}

const char *plan_outcome_name(enum plan_outcome o)
{
	switch (o) {
	case PLAN_REFINE: return "refine";
	case PLAN_TARGET_MET: return "target met";
	case PLAN_NO_GAIN: return "no pixel would gain";
	case PLAN_NO_BUDGET: return "budget spent";
	case PLAN_LITTLE_GAIN: return "too little left to gain";
	}
	return "?";
}

/* The neighbourhood the fold differences are averaged over. */
#define DIFF_RADIUS 2

/* The relative variance of pixel o's mean: its sample variance over n,
 * relative to value^2 + 0.01, mean over R, G, B (0 with fewer than 2
 * samples); a tiny floor keeps its logarithm finite. */
static double mean_var(const float *o)
{
	double n = o[ACC_SAMPLES], r = 0.0;
	if (n >= 2.0)
		for (int c = 0; c < 3; c++)
			r += o[ACC_VAR_R + c] / n / ((double)o[c] * o[c] + METRICS_RELMSE_EPS) / 3.0;
	return (isfinite(r) ? r : 0.0) + 1e-12;
}

/*
 * The 'diff' estimate of pixel (x, y) averaged over the 5x5 pixels around
 * it that have one (a single pixel's is a difference of two noisy means:
 * about three degrees of freedom); NaN when none has.  A neighbour counts
 * by how alike the two pixels' sample variances are (of their means,
 * relative; lmv holds the logarithm of every pixel's mean_var()): with weight
 * exp(-ln^2(v_j / v_i) / 2), so a factor e apart 0.61, ten apart 0.07.  A
 * plain mean spread one pixel's difference over all 25: the horizon's (a
 * sky/floor edge whose coarse samples all fell on the floor) put 0.035 on
 * the flat sky rows beside it, a quarter of soft_shadows' whole estimate at
 * --target 3e-3, and the thin rods' onto the background around them.
 */
static double diff_around(const struct image *acc, const double *lmv, int x, int y)
{
	const double li = lmv[(size_t)y * acc->w + x];
	double sum = 0.0, wsum = 0.0;
	for (int j = y - DIFF_RADIUS; j <= y + DIFF_RADIUS; j++) {
		if (j < 0 || j >= acc->h)
			continue;
		for (int k = x - DIFF_RADIUS; k <= x + DIFF_RADIUS; k++) {
			if (k < 0 || k >= acc->w)
				continue;
			const size_t q = (size_t)j * acc->w + k;
			const float d = acc->px[q * ACC_NCH + ACC_DIFF];
			if (!isfinite(d))
				continue;
			double l = lmv[q] - li, wt = exp(-0.5 * l * l);
			sum += wt * d;
			wsum += wt;
		}
	}
	return wsum > 0.0 ? sum / wsum : NAN;
}

/* Rows [y0, y1) of plan_pixel_errors(), on a thread of their own: in
 * stage 0 the logarithms of their pixels' mean variances (lmv), in stage 1
 * (once every band's are there) their errors. */
struct err_band {
	const struct image *acc;
	const float *press, *fit;
	double *e, *noise, *lmv;
	int y0, y1;
	int stage;
};

static void *err_band_run(void *arg)
{
	const struct err_band *b = arg;
	const struct image *acc = b->acc;
	const size_t i0 = (size_t)b->y0 * acc->w, i1 = (size_t)b->y1 * acc->w;
	if (b->stage == 0) {
		for (size_t i = i0; i < i1; i++)	/* ln of each, once: 25 neighbours use it */
			b->lmv[i] = log(mean_var(acc->px + i * ACC_NCH));
		return NULL;
	}
	for (size_t i = i0; i < i1; i++) {
		const float *o = acc->px + i * ACC_NCH;
		double diff = isfinite(o[ACC_DIFF]) ?
			diff_around(acc, b->lmv, (int)(i % (size_t)acc->w), (int)(i / (size_t)acc->w)) : NAN;
		double ns = accum_pixel_noise(acc, i, diff);
		b->e[i] = accum_pixel_error(acc, i, b->press[i], b->fit + 3 * i, ns);
		if (b->noise)
			b->noise[i] = ns;
	}
	return NULL;
}

int plan_pixel_errors_threads(const struct image *acc, const float *press, const float *fit,
			      double *e, double *noise, double *est, int nthreads, char *err,
			      size_t errlen)
{
	size_t n = (size_t)acc->w * acc->h;
	double *lmv = malloc((n ? n : 1) * sizeof(*lmv));
	if (!lmv) {
		errbuf_printf(err, errlen, "out of memory estimating a %dx%d image's errors",
			      acc->w, acc->h);
		return -1;
	}
	/* bands of 64 rows or more: a thread's start costs more than a few
	 * rows' errors */
	int nb = nthreads < 1 ? 1 : nthreads > PLAN_MAX_THREADS ? PLAN_MAX_THREADS : nthreads;
	if (nb > acc->h / 64)
		nb = acc->h / 64 > 1 ? acc->h / 64 : 1;
	struct err_band bs[PLAN_MAX_THREADS];
	for (int stage = 0; stage < 2; stage++) {
		for (int k = 0; k < nb; k++)
			bs[k] = (struct err_band){ acc, press, fit, e, noise, lmv,
						   (int)((long)acc->h * k / nb),
						   (int)((long)acc->h * (k + 1) / nb), stage };
		parallel_run(err_band_run, bs, sizeof *bs, nb);
	}
	free(lmv);
	/* summed in pixel order, whatever the threads: the same estimate */
	double sum = 0.0;
	for (size_t i = 0; i < n; i++)
		sum += e[i];
	*est = n ? sum / n : 0.0;
	return 0;
}

int plan_pixel_errors(const struct image *acc, const float *press, const float *fit,
		      double *e, double *noise, double *est, char *err, size_t errlen)
{
	return plan_pixel_errors_threads(acc, press, fit, e, noise, est, 1, err, errlen);
}

struct cand {
	size_t i;
	int s;			/* the scale it is refined at next */
	double gain, score;
};

static int by_score(const void *a, const void *b)
{
	const struct cand *x = a, *y = b;
	if (x->score != y->score)
		return x->score < y->score ? 1 : -1;
	return x->i < y->i ? -1 : x->i > y->i;	/* stable: the same plan every run */
}

/* plan_grid_scale() for an image of px pixels. */
static int grid_at(const struct plan_params *p, int s, double px)
{
	return s >= 4 && (p->grid == PLAN_GRID_ALWAYS || p->grid == PLAN_GRID_ONLY ||
			  (p->grid == PLAN_GRID_LARGE && (double)s * s * px > p->grid_frame));
}

static double job_cost(const struct plan_params *p, int s, double px)
{
	if (!(p->cost_frame > 0.0))
		return p->cost_job;
	return p->cost_job + p->cost_frame * px * (grid_at(p, s, px) ? 4.0 : (double)s * s);
}

double plan_job_cost(const struct plan_params *p, int s, double px)
{
	return job_cost(p, s, px);
}

double plan_radiosity_trace(double cost_pixel, double px, double rays, int k)
{
	const double r = rays > 0.0 ? PLAN_RAD_RAY_COST * rays : 0.0;
	const double a = cost_pixel / (1.0 + r);	/* a pixel's ray */
	return a * px * ((double)k * k + r * pow(k, PLAN_RAD_RAY_GROWTH));
}

double plan_region_map(const struct plan_params *p, const struct plan_region *r, int w)
{
	if (!p->cost_map)
		return (double)plan_region_area(r);
	double m = 0.0;
	for (int y = r->y0; y <= r->y1; y++)
		for (int x = r->x0; x <= r->x1; x++)
			m += p->cost_map[(size_t)y * w + x];
	return m;
}

/* The sum over pixels x0..x1 x y0..y1 (inclusive) of an image w pixels
 * wide from its summed-area table t, (w + 1) x (h + 1) (sat_fill()). */
static double sat_sum(const double *t, int w, int x0, int y0, int x1, int y1)
{
	const size_t sw = (size_t)w + 1;
	return t[(size_t)(y1 + 1) * sw + x1 + 1] - t[(size_t)y0 * sw + x1 + 1] -
	       t[(size_t)(y1 + 1) * sw + x0] + t[(size_t)y0 * sw + x0];
}

/* Make t, (w + 1) x (h + 1), a summed-area table in place: it holds pixel
 * (x, y)'s value at t[(y + 1) (w + 1) + x + 1]; its first row and column are
 * set to 0. */
static void sat_fill(double *t, int w, int h)
{
	const size_t sw = (size_t)w + 1;
	for (int x = 0; x <= w; x++)
		t[x] = 0.0;
	for (int y = 0; y < h; y++) {
		double row = 0.0;
		t[(size_t)(y + 1) * sw] = 0.0;
		for (int x = 0; x < w; x++) {
			double *c = &t[(size_t)(y + 1) * sw + x + 1];
			row += *c;
			*c = t[(size_t)y * sw + x + 1] + row;
		}
	}
}

/* The cost map's sum over pixels x0..x1 x y0..y1 (inclusive) from its
 * summed-area table: their area without a map. */
static double map_sum(const struct plan_params *p, int x0, int y0, int x1, int y1)
{
	if (!p->cost_sat)
		return (double)(x1 - x0 + 1) * (y1 - y0 + 1);
	return sat_sum(p->cost_sat, p->cost_sat_w, x0, y0, x1, y1);
}

/* Pixel i's cost a sample over cost_sample. */
static double map_at(const struct plan_params *p, size_t i)
{
	return p->cost_map ? p->cost_map[i] : 1.0;
}

static double rect_cost(const struct plan_params *p, const struct plan_region *r, double px)
{
	return job_cost(p, r->scale, px) +
	       p->cost_sample * map_sum(p, r->x0, r->y0, r->x1, r->y1) * r->scale * r->scale;
}

static void bbox(const struct plan_region *a, const struct plan_region *b,
		 struct plan_region *o)
{
	*o = *a;
	o->x0 = a->x0 < b->x0 ? a->x0 : b->x0;
	o->y0 = a->y0 < b->y0 ? a->y0 : b->y0;
	o->x1 = a->x1 > b->x1 ? a->x1 : b->x1;
	o->y1 = a->y1 > b->y1 ? a->y1 : b->y1;
	o->chosen = a->chosen + b->chosen;
	o->gain = a->gain + b->gain;
}

static int inside(const struct plan_region *in, const struct plan_region *out)
{
	return in->x0 >= out->x0 && in->x1 <= out->x1 && in->y0 >= out->y0 && in->y1 <= out->y1;
}

/* The greedy merge is quadratic per step: more runs than this and the
 * grid is made coarser. */
#define PACK_MAX_RUNS 400
/* At most this many rectangles are merged on past the last merge that
 * saved, to find a set cheaper still (pack()). */
#define PACK_AHEAD 32

/* Whether tile (tx, ty) of the grid holds a marked pixel. */
static int tile_occupied(const unsigned char *mark, int w, int h, int tile, int tx, int ty)
{
	for (int y = ty * tile; y < (ty + 1) * tile && y < h; y++)
		for (int x = tx * tile; x < (tx + 1) * tile && x < w; x++)
			if (mark[(size_t)y * w + x])
				return 1;
	return 0;
}

/*
 * What a rectangle's pixels that were not chosen gain from it (riders):
 * sat the summed-area table of each such pixel's gain at the scale packed,
 * worth lambda seconds a unit of gain (the dearest gain the plan took).
 * No riders (NULL): they are worth nothing.
 */
struct riders {
	const double *sat;
	int w;
	double lambda;
};

/* A rectangle's cost less what its riders are worth. */
static double rect_net(const struct plan_params *p, const struct riders *rd,
		       const struct plan_region *r, double px)
{
	double c = rect_cost(p, r, px);
	return rd ? c - rd->lambda * sat_sum(rd->sat, rd->w, r->x0, r->y0, r->x1, r->y1) : c;
}

/* The net cost of the n rectangles r (rect_net()) together. */
static double set_net(const struct plan_params *p, const struct riders *rd,
		      const struct plan_region *r, size_t n, double px)
{
	double net = 0.0;
	for (size_t k = 0; k < n; k++)
		net += rect_net(p, rd, &r[k], px);
	return net;
}

/*
 * Pack the chosen pixels of one scale (mark[i] set, gain[i] their gains)
 * into rectangles appended to *rs.  tile is the grid; rd values the pixels
 * a rectangle covers but were not chosen (NULL: nothing).  Returns 0, -1
 * when out of memory, 1 when the grid leaves more than PACK_MAX_RUNS runs.
 */
static int pack(const struct plan_params *p, int w, int h, int s, const unsigned char *mark,
		const double *gain, const struct riders *rd, int tile, int cap,
		struct plan_region **rs, size_t *nrs)
{
	int tw = (w + tile - 1) / tile, th = (h + tile - 1) / tile;
	const double px = (double)w * h;
	struct plan_region *r = NULL;
	size_t n = 0, alloc = 0;
	int ret = -1;
	/* runs of occupied tiles per tile row, extended downward when the row
	 * below has a run with the same span */
	int *open_of = malloc(sizeof(int) * (size_t)tw);	/* region index by run start */
	if (!open_of)
		return -1;
	for (int tx = 0; tx < tw; tx++)
		open_of[tx] = -1;
	for (int ty = 0; ty < th; ty++) {
		int tx = 0;
		while (tx < tw) {
			if (!tile_occupied(mark, w, h, tile, tx, ty)) {
				open_of[tx] = -1;
				tx++;
				continue;
			}
			int t0 = tx;
			for (tx++; tx < tw; tx++)
				if (!tile_occupied(mark, w, h, tile, tx, ty))
					break;
			int x0 = t0 * tile, x1 = tx * tile - 1;
			if (x1 >= w)
				x1 = w - 1;
			int k = open_of[t0];
			if (k >= 0 && r[k].x0 == x0 && r[k].x1 == x1 && r[k].y1 == ty * tile - 1) {
				r[k].y1 = (ty + 1) * tile - 1 < h ? (ty + 1) * tile - 1 : h - 1;
			} else {
				if (n == alloc) {
					alloc = alloc ? 2 * alloc : 64;
					void *q = realloc(r, alloc * sizeof(*r));
					if (!q)
						goto out;
					r = q;
				}
				memset(&r[n], 0, sizeof(r[n]));
				r[n].x0 = x0;
				r[n].x1 = x1;
				r[n].y0 = ty * tile;
				r[n].y1 = (ty + 1) * tile - 1 < h ? (ty + 1) * tile - 1 : h - 1;
				r[n].scale = s;
				k = (int)n++;
			}
			for (int t = t0; t < tx; t++)
				open_of[t] = -1;
			open_of[t0] = k;
			/* tiles t0+1.. of the run are closed for the next row: a run
			 * continues only with the same span */
		}
	}
	if (n > PACK_MAX_RUNS) {	/* too many to merge pairwise: a coarser grid */
		ret = 1;
		goto out;
	}
	/* shrink each rectangle to its chosen pixels; count them */
	for (size_t k = 0; k < n; k++) {
		int bx0 = r[k].x1, by0 = r[k].y1, bx1 = r[k].x0, by1 = r[k].y0;
		for (int y = r[k].y0; y <= r[k].y1; y++)
			for (int x = r[k].x0; x <= r[k].x1; x++) {
				size_t i = (size_t)y * w + x;
				if (!mark[i])
					continue;
				bx0 = x < bx0 ? x : bx0;
				bx1 = x > bx1 ? x : bx1;
				by0 = y < by0 ? y : by0;
				by1 = y > by1 ? y : by1;
				r[k].chosen++;
				r[k].gain += gain[i];
			}
		r[k].x0 = bx0;
		r[k].x1 = bx1;
		r[k].y0 = by0;
		r[k].y1 = by1;
	}
	/* greedy merging: the pair whose bounding box saves the most (or, over
	 * the cap, costs the least extra), its riders' worth taken off its
	 * cost.  Where no merge saves any more and PACK_AHEAD rectangles or
	 * fewer (and no more than the cap) are left, merging goes on down to
	 * one, and the cheapest of the sets it passes is kept: two merges may
	 * save what neither does alone
	 * (soft_shadows at --target 3e-3: five rectangles, or two covering 3,149
	 * pixels more for the same CPU and a quarter less error, as the cost
	 * of a POV-Ray run was measured 2^-6 or 2^-5 s) */
	struct plan_region keep[PACK_AHEAD];
	size_t nkeep = 0;
	double keep_net = INFINITY;
	int ahead = 0;
	for (;;) {
		double best = INFINITY;
		size_t ba = 0, bb = 0;
		for (size_t a = 0; a < n; a++)
			for (size_t b = a + 1; b < n; b++) {
				struct plan_region m;
				bbox(&r[a], &r[b], &m);
				double d = rect_net(p, rd, &m, px) - rect_net(p, rd, &r[a], px) -
					   rect_net(p, rd, &r[b], px);
				if (d < best) {
					best = d;
					ba = a;
					bb = b;
				}
			}
		if (!ahead && n >= 2 && n <= PACK_AHEAD && best > 0.0 && n <= (size_t)cap) {
			ahead = 1;
			nkeep = n;
			memcpy(keep, r, n * sizeof(*r));
			keep_net = set_net(p, rd, r, n, px);
		}
		/* (no finite cost: nothing to merge by) */
		if (n < 2 || !(best < INFINITY) || (!ahead && best > 0.0 && n <= (size_t)cap))
			break;
		struct plan_region m;
		bbox(&r[ba], &r[bb], &m);
		r[ba] = m;
		r[bb] = r[--n];
		/* absorb whatever now lies inside the merged box */
		for (size_t k = 0; k < n; k++) {
			if (k == ba || !inside(&r[k], &r[ba]))
				continue;
			r[ba].chosen += r[k].chosen;
			r[ba].gain += r[k].gain;
			r[k] = r[--n];
			if (ba == n)
				ba = k;
			k--;
		}
		if (ahead) {
			const double net = set_net(p, rd, r, n, px);
			/* cheaper by more than rounding */
			if (net < keep_net - 1e-9 * fabs(keep_net)) {
				keep_net = net;
				nkeep = n;
				memcpy(keep, r, n * sizeof(*r));
			}
		}
	}
	if (ahead) {
		n = nkeep;
		memcpy(r, keep, n * sizeof(*r));
	}
	for (size_t k = 0; k < n; k++)
		r[k].cost = rect_cost(p, &r[k], px);
	if (n) {
		void *q = realloc(*rs, (*nrs + n) * sizeof(**rs));
		if (!q)
			goto out;
		*rs = q;
		memcpy(*rs + *nrs, r, n * sizeof(*r));
		*nrs += n;
	}
	ret = 0;
out:
	free(open_of);
	free(r);
	return ret;
}

static const char *const grid_names[] = { "scale", "grid", "auto", "jitter" };
#define NGRID (int)(sizeof(grid_names) / sizeof(grid_names[0]))

const char *plan_grid_name(int grid)
{
	return grid >= 0 && grid < NGRID ? grid_names[grid] : "?";
}

int plan_grid_parse(const char *name)
{
	for (int k = 0; k < NGRID; k++)
		if (!strcmp(name, grid_names[k]))
			return k;
	return -1;
}

int plan_grid_scale(const struct plan_params *p, int w, int h, int s)
{
	return grid_at(p, s, (double)w * h);
}

/* The first scale past cur that pixel i may be refined at: unused, and
 * not 2 under PLAN_GRID_ONLY; 0 if none. */
static int scale_after(const struct plan_params *p, const struct image *acc, size_t i, int cur)
{
	for (int k = 0; k < ACC_NSCALES; k++) {
		int s = accum_scales[k];
		if (s > cur && !(s == 2 && p->grid == PLAN_GRID_ONLY) && !accum_has_scale(acc, i, s))
			return s;
	}
	return 0;
}

int plan_next_scale(const struct plan_params *p, const struct image *acc, size_t i)
{
	return scale_after(p, acc, i, 0);
}

/* Taking a pixel from scale `from` on to `to` in this pass: what it gains
 * and costs more, and the gain per cost, in a max-heap of upgrades. */
struct upgrade {
	size_t i;
	int to;
	double gain, cost, score;
};

static int upgrade_before(const struct upgrade *a, const struct upgrade *b)
{
	if (a->score != b->score)
		return a->score > b->score;
	return a->i < b->i;	/* the same plan every run */
}

static void heap_push(struct upgrade *h, size_t *n, struct upgrade u)
{
	size_t k = (*n)++;
	while (k > 0 && upgrade_before(&u, &h[(k - 1) / 2])) {
		h[k] = h[(k - 1) / 2];
		k = (k - 1) / 2;
	}
	h[k] = u;
}

static struct upgrade heap_pop(struct upgrade *h, size_t *n)
{
	struct upgrade top = h[0], last = h[--*n];
	size_t k = 0;
	for (;;) {
		size_t c = 2 * k + 1;
		if (c >= *n)
			break;
		if (c + 1 < *n && upgrade_before(&h[c + 1], &h[c]))
			c++;
		if (!upgrade_before(&h[c], &last))
			break;
		h[k] = h[c];
		k = c;
	}
	if (*n)
		h[k] = last;
	return top;
}

/* The upgrade of pixel i (error e, n samples) from scale cur to the next
 * it may take; 0 when there is none. */
static int next_upgrade(const struct plan_params *p, const struct image *acc, size_t i, double e,
			int cur, int smax, struct upgrade *u)
{
	int to = scale_after(p, acc, i, cur);
	if (!to || to > smax)
		return 0;
	double n = acc->px[i * ACC_NCH + ACC_SAMPLES];
	double m1 = (double)cur * cur, m2 = (double)to * to;
	u->i = i;
	u->to = to;
	u->gain = e * (m2 / (n + m2) - m1 / (n + m1));
	u->cost = p->cost_sample * (m2 - m1) * map_at(p, i);
	u->score = u->gain / u->cost;
	return 1;
}

/* The upgrades in the order a heap of each chosen pixel's next one gives
 * them (see plan_make_from()): the heap, and the n taken from it so far. */
struct upgrades {
	struct upgrade *heap, *order;
	size_t nh, n, cap;
};

/* Take the heap's next upgrade onto up->order, the pixel's one after it into
 * the heap: 1, 0 when the heap is empty, -1 when out of memory. */
static int order_next(const struct plan_params *p, const struct image *acc, const double *e,
		      int smax, struct upgrades *up)
{
	if (!up->nh)
		return 0;
	if (up->n == up->cap) {
		size_t cap = up->cap ? 2 * up->cap : up->nh;
		struct upgrade *o = realloc(up->order, cap * sizeof(*o));
		if (!o)
			return -1;
		up->order = o;
		up->cap = cap;
	}
	struct upgrade u = heap_pop(up->heap, &up->nh), v;
	up->order[up->n++] = u;
	if (next_upgrade(p, acc, u.i, e[u.i], u.to, smax, &v))
		heap_push(up->heap, &up->nh, v);
	return 1;
}

/* The pixels of the plan's image (a render's frame grows with them). */
static double plan_px(const struct plan *out)
{
	return (double)out->w * out->h;
}

/* Count region r's pixels that its scale was planned for (ps) into its
 * chosen and gain, and set its cost. */
static void region_count(const struct plan_params *p, struct plan_region *r,
			 const struct plan *out, const unsigned char *ps, const double *gain)
{
	const int w = out->w;
	r->chosen = 0;
	r->gain = 0.0;
	for (int y = r->y0; y <= r->y1; y++)
		for (int x = r->x0; x <= r->x1; x++) {
			size_t i = (size_t)y * w + x;
			if (ps[i] == r->scale) {
				r->chosen++;
				r->gain += gain[i];
			}
		}
	r->cost = rect_cost(p, r, plan_px(out));
}

/* The cost map's sum over region r's first rows (rows) or columns, up to
 * and including m. */
static double head_sum(const struct plan_params *p, const struct plan_region *r, int rows, int m)
{
	return rows ? map_sum(p, r->x0, r->y0, r->x1, m) : map_sum(p, r->x0, r->y0, m, r->y1);
}

/* The last row (rows) or column of region r's first part when it is cut
 * where the cost map's sum over it comes nearest to halving, both parts one
 * or more wide. */
static int cost_half(const struct plan_params *p, const struct plan_region *r, int rows)
{
	const int lo = rows ? r->y0 : r->x0, hi = rows ? r->y1 : r->x1;
	const double half = 0.5 * map_sum(p, r->x0, r->y0, r->x1, r->y1);
	int a = lo, b = hi - 1;	/* the first cut reaching half lies in a..b */
	while (a < b) {
		int m = a + (b - a) / 2;
		if (head_sum(p, r, rows, m) < half)
			a = m + 1;
		else
			b = m;
	}
	/* or the one before it, if nearer (a dear row straddling the half) */
	if (a > lo && half - head_sum(p, r, rows, a - 1) < head_sum(p, r, rows, a) - half)
		a--;
	return a;
}

/*
 * Split the dearest region in two across its longer side (at its middle,
 * or with a cost map where its cost halves) while it costs
 * more than the pass over p->min_split, renders more than four
 * invocations' worth of samples, and the plan has fewer than twice
 * p->max_regions: so that the cores finish together.  (With the cap at
 * p->max_regions, glossy_reflection's pass 3 at --budget 8 kept one region
 * of 55% of its samples, and the pass took 7.9 s for 8.2 CPU s on two
 * cores.)  Returns 0, -1 when out of memory.
 */
static int split_regions(const struct plan_params *p, struct plan *out, const unsigned char *ps,
			 const double *gain)
{
	if (p->min_split < 2)
		return 0;
	double total = 0.0;
	for (size_t k = 0; k < out->nregions; k++)
		total += out->regions[k].cost;
	while (out->nregions < 2 * (size_t)p->max_regions) {
		size_t d = 0;
		for (size_t k = 1; k < out->nregions; k++)
			if (out->regions[k].cost > out->regions[d].cost)
				d = k;
		struct plan_region a = out->regions[d], b = a;
		int rw = a.x1 - a.x0 + 1, rh = a.y1 - a.y0 + 1;
		const double jc = job_cost(p, a.scale, plan_px(out));
		/* (a tolerance: costs are sums, not exact, and parts of equal
		 * cost must not split again) */
		if (a.cost <= total / p->min_split * (1.0 + 1e-9) || a.cost - jc < 4.0 * jc ||
		    (rw < 2 && rh < 2))
			break;
		/* b is still the whole region here: the cut halves its cost */
		if (rh >= rw) {
			a.y1 = p->cost_map ? cost_half(p, &b, 1) : a.y0 + rh / 2 - 1;
			b.y0 = a.y1 + 1;
		} else {
			a.x1 = p->cost_map ? cost_half(p, &b, 0) : a.x0 + rw / 2 - 1;
			b.x0 = a.x1 + 1;
		}
		region_count(p, &a, out, ps, gain);
		region_count(p, &b, out, ps, gain);
		void *q = realloc(out->regions, (out->nregions + 1) * sizeof(*out->regions));
		if (!q)
			return -1;
		out->regions = q;
		out->regions[d] = a;
		out->regions[out->nregions++] = b;
		total += jc;
	}
	return 0;
}

/* A band of a rectangle, for fit_budget(). */
struct band {
	struct plan_region r;
	size_t parent, seq;
	int keep;
};

static int band_by_value(const void *a, const void *b)
{
	const struct band *x = a, *y = b;
	double vx = x->r.gain / x->r.cost, vy = y->r.gain / y->r.cost;
	if (vx != vy)
		return vx < vy ? 1 : -1;
	if (x->parent != y->parent)
		return x->parent < y->parent ? -1 : 1;
	return x->seq < y->seq ? -1 : x->seq > y->seq;
}

static int band_by_place(const void *a, const void *b)
{
	const struct band *x = a, *y = b;
	if (x->parent != y->parent)
		return x->parent < y->parent ? -1 : 1;
	return x->seq < y->seq ? -1 : x->seq > y->seq;
}

/*
 * Rectangles costing more than the budget together: cut them into bands of
 * p->tile rows, keep the bands worth most per cost that fit, and join again
 * the kept bands of a rectangle that touch, so that what goes is the least
 * worth, not whole rectangles.  Returns 0, -1 when out of memory.
 */
static int fit_budget(const struct plan_params *p, struct plan *out, const unsigned char *ps,
		      const double *gain)
{
	double c = 0.0;
	size_t nb = 0;
	for (size_t k = 0; k < out->nregions; k++) {
		c += out->regions[k].cost;
		nb += (size_t)((out->regions[k].y1 - out->regions[k].y0) / p->tile + 1);
	}
	if (!(p->budget > 0.0) || c <= p->budget)
		return 0;
	struct band *b = malloc(nb * sizeof(*b));
	if (!b)
		return -1;
	nb = 0;
	for (size_t k = 0; k < out->nregions; k++) {
		const struct plan_region *r = &out->regions[k];
		for (int y = r->y0, q = 0; y <= r->y1; y += p->tile, q++) {
			struct band *d = &b[nb++];
			d->r = *r;
			d->r.y0 = y;
			d->r.y1 = y + p->tile - 1 < r->y1 ? y + p->tile - 1 : r->y1;
			region_count(p, &d->r, out, ps, gain);
			d->parent = k;
			d->seq = (size_t)q;
			d->keep = 0;
		}
	}
	qsort(b, nb, sizeof(*b), band_by_value);
	c = 0.0;
	for (size_t k = 0; k < nb; k++)
		if (b[k].r.gain > 0.0 && c + b[k].r.cost <= p->budget) {
			b[k].keep = 1;
			c += b[k].r.cost;
		}
	qsort(b, nb, sizeof(*b), band_by_place);
	void *q = realloc(out->regions, nb * sizeof(*out->regions));
	if (!q) {
		free(b);
		return -1;
	}
	out->regions = q;
	size_t n = 0;
	for (size_t k = 0; k < nb; k++) {
		if (!b[k].keep)
			continue;
		if (n && b[k - 1].keep && b[k - 1].parent == b[k].parent) {
			struct plan_region *m = &out->regions[n - 1];
			m->y1 = b[k].r.y1;
			m->chosen += b[k].r.chosen;
			m->gain += b[k].r.gain;
			m->cost = rect_cost(p, m, plan_px(out));
		} else {
			out->regions[n++] = b[k].r;
		}
	}
	out->nregions = n;
	free(b);
	return 0;
}

/* Into sat, (w + 1) x (h + 1), the summed-area table of what each pixel
 * of acc that the plan did not choose (ps 0) would gain at scale s (e its
 * error; 0 where it has had s). */
static void riders_table(const struct image *acc, const double *e, const unsigned char *ps, int s,
			 double *sat)
{
	const int w = acc->w, h = acc->h;
	const size_t sw = (size_t)w + 1;
	const double m = (double)s * s;
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++) {
			const size_t i = (size_t)y * w + x;
			double g = 0.0;
			if (!ps[i] && !accum_has_scale(acc, i, s))
				g = e[i] * m / (acc->px[i * ACC_NCH + ACC_SAMPLES] + m);
			sat[(size_t)(y + 1) * sw + x + 1] = isfinite(g) && g > 0.0 ? g : 0.0;
		}
	sat_fill(sat, w, h);
}

/* Pack the chosen pixels (the first taken of cand) per scale, ps their
 * planned scales, into out's regions; with sat (scratch, (w + 1) x (h + 1))
 * and lambda > 0 the pixels a rectangle takes along are worth lambda
 * seconds a unit of their gain (e their errors).  Returns 0, -1 when out of
 * memory. */
static int pack_all(const struct plan_params *p, const struct image *acc, const double *e,
		    const struct cand *cand, size_t taken, const unsigned char *ps,
		    const double *gain, double lambda, double *sat, unsigned char *mark,
		    struct plan *out)
{
	const int w = acc->w, h = acc->h;
	for (int k = 0; k < ACC_NSCALES; k++) {
		int s = accum_scales[k], any = 0;
		memset(mark, 0, (size_t)w * h);
		for (size_t t = 0; t < taken; t++)
			if (ps[cand[t].i] == s)
				any = mark[cand[t].i] = 1;
		if (!any)
			continue;
		const struct riders rd = { sat, w, lambda };
		const struct riders *rdp = sat && lambda > 0.0 ? &rd : NULL;
		if (rdp)
			riders_table(acc, e, ps, s, sat);
		int rc, tile = p->tile;
		while ((rc = pack(p, w, h, s, mark, gain, rdp, tile, p->max_regions, &out->regions,
				  &out->nregions)) == 1)
			tile *= 2;
		if (rc)
			return -1;
	}
	return 0;
}

static int by_value(const void *a, const void *b)
{
	const struct plan_region *x = a, *y = b;
	double vx = x->gain / x->cost, vy = y->gain / y->cost;
	if (vx != vy)
		return vx < vy ? 1 : -1;
	if (x->y0 != y->y0)
		return x->y0 - y->y0;
	return x->x0 - y->x0;
}

static int by_position(const void *a, const void *b)
{
	const struct plan_region *x = a, *y = b;
	if (x->scale != y->scale)
		return x->scale - y->scale;
	if (x->y0 != y->y0)
		return x->y0 - y->y0;
	return x->x0 - y->x0;
}

int plan_make(const struct image *acc, const float *press, const float *fit,
	      const struct plan_params *p, struct plan *out, char *err, size_t errlen)
{
	size_t npx = (size_t)acc->w * acc->h;
	double *e = malloc(npx * sizeof(*e));
	if (!e) {
		memset(out, 0, sizeof(*out));
		errbuf_printf(err, errlen, "out of memory planning a %dx%d image", acc->w, acc->h);
		return -1;
	}
	double est;
	int rc = plan_pixel_errors(acc, press, fit, e, NULL, &est, err, errlen);
	if (rc)
		memset(out, 0, sizeof(*out));
	else
		rc = plan_make_from(acc, e, p, out, err, errlen);
	free(e);
	return rc;
}

/* The summed-area table of a w x h cost map, (w + 1) x (h + 1); NULL when
 * out of memory. */
static double *map_table(const float *map, int w, int h)
{
	const size_t sw = (size_t)w + 1;
	double *t = malloc(sw * ((size_t)h + 1) * sizeof(*t));
	if (!t)
		return NULL;
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++)
			t[(size_t)(y + 1) * sw + x + 1] = map[(size_t)y * w + x];
	sat_fill(t, w, h);
	return t;
}

static int make_once(const struct image *acc, const double *e, const struct plan_params *pin,
		     struct plan *out, char *err, size_t errlen)
{
	const int w = acc->w, h = acc->h;
	const size_t npx = (size_t)w * h;
	double *gain = NULL;
	struct cand *cand = NULL;
	unsigned char *mark = NULL, *ps = NULL;
	struct upgrades up = { 0 };
	unsigned char *dead = NULL;
	struct plan_params pm = *pin;
	const struct plan_params *p = &pm;
	double *sat = NULL, *riders = NULL;
	int ret = -1;

	memset(out, 0, sizeof(*out));
	out->w = w;
	out->h = h;
	if (!(p->target > 0.0) || p->cost_job < 0.0 || !(p->cost_sample > 0.0) ||
	    p->max_regions < 1 || p->tile < 1) {
		errbuf_printf(err, errlen, "bad planning parameters");
		return -1;
	}
	pm.cost_sat = NULL;
	pm.cost_sat_w = w;
	if (pm.cost_map) {
		if (!(sat = map_table(pm.cost_map, w, h))) {
			errbuf_printf(err, errlen, "out of memory planning a %dx%d image", w, h);
			return -1;
		}
		pm.cost_sat = sat;
	}
	gain = calloc(npx, sizeof(*gain));
	cand = malloc(npx * sizeof(*cand));
	mark = malloc(npx);
	ps = calloc(npx, 1);
	out->scale = calloc(npx, sizeof(float));
	out->chosen = calloc(npx, sizeof(float));
	if (!gain || !cand || !mark || !ps || !out->scale || !out->chosen) {
		errbuf_printf(err, errlen, "out of memory planning a %dx%d image", w, h);
		goto out;
	}
	double sum = 0.0;
	for (size_t i = 0; i < npx; i++)
		sum += e[i];
	out->est_relmse = npx ? sum / (double)npx : 0.0;
	out->est_after = out->est_relmse;
	if (out->est_relmse <= p->target) {
		out->outcome = PLAN_TARGET_MET;
		ret = 0;
		goto out;
	}

	/* POV-Ray holds a region render's whole s W x s H frame in memory and
	 * writes it out, so the scale is capped by the frame's size */
	int smax = 16;
	while (smax > 2 && (double)smax * smax * w * h > PLAN_MAX_FRAME &&
	       !plan_grid_scale(p, w, h, smax))
		smax /= 2;
	size_t nc = 0;
	for (size_t i = 0; i < npx; i++) {
		int s = plan_next_scale(p, acc, i);
		if (!s || s > smax)
			continue;
		double n = acc->px[i * ACC_NCH + ACC_SAMPLES], m = (double)s * s;
		double g = e[i] * m / (n + m);
		if (g < p->min_gain * p->target)
			continue;
		cand[nc].i = i;
		cand[nc].s = s;
		cand[nc].gain = g;
		cand[nc].score = g / (m * map_at(p, i));
		nc++;
	}
	qsort(cand, nc, sizeof(*cand), by_score);

	/* take pixels at their next scales until the predicted error meets
	 * target * margin, or near the target what PLAN_REALIZED asks, or
	 * the samples alone would exceed the budget */
	const double near = out->est_relmse - (out->est_relmse - p->target) / PLAN_REALIZED;
	const double goal_px = near > p->target * p->margin ? near : p->target * p->margin;
	const double goal = goal_px * (double)npx;
	const double cap = p->budget > 0.0 ? p->budget : INFINITY;
	double total0 = out->est_relmse * (double)npx, spend0 = 0.0;
	/* the dearest gain taken, seconds a unit: what a pixel a rectangle
	 * takes along is worth a unit of its gain */
	double lambda0 = 0.0;
	size_t taken = 0;
	for (; taken < nc && total0 > goal; taken++) {
		const struct cand *c = &cand[taken];
		double cs = p->cost_sample * c->s * c->s * map_at(p, c->i);
		if (spend0 + cs > cap)
			break;
		spend0 += cs;
		total0 -= c->gain;
		if (c->gain > 0.0 && cs / c->gain > lambda0)
			lambda0 = cs / c->gain;
		gain[c->i] = c->gain;
		ps[c->i] = (unsigned char)c->s;
	}
	if (!taken) {
		out->outcome = nc ? PLAN_NO_BUDGET : PLAN_NO_GAIN;
		ret = 0;
		goto out;
	}

	/*
	 * Then, in a pass that may be the last (p->fill), with the goal unmet
	 * and the share of the budget unspent, take the chosen pixels on to
	 * later scales, the best gain per cost first.  The rectangles cost more
	 * than the pixels (they cover their neighbours too): while they would
	 * cost more than the budget, or than the share allows, what the
	 * upgrades may spend is bisected between a share that fit and one that
	 * did not.
	 */
	const double limit = p->fill > 0.0 && (p->budget <= 0.0 || 1.25 * p->fill < p->budget)
				     ? 1.25 * p->fill
				     : p->budget;
	double upto = p->fill < cap ? p->fill : cap, lo = spend0, hi = INFINITY;
	const int upgrading = total0 > goal && spend0 < upto;
	/* the riders' table (pack_all()), without a budget only */
	if (!(p->budget > 0.0) &&
	    !(riders = malloc(((size_t)w + 1) * ((size_t)h + 1) * sizeof(*riders)))) {
		errbuf_printf(err, errlen, "out of memory planning a %dx%d image", w, h);
		goto out;
	}
	/*
	 * The upgrades in the order a heap of each chosen pixel's next one
	 * gives them, none skipped (order, made as far as an attempt asks).
	 * An attempt takes them in that order while they fit what it may
	 * spend; one that does not fit ends its pixel's (dead): the pixels
	 * left give their upgrades in the same order as without the dead
	 * ones, each pixel's next entering as its last is taken, so the
	 * attempts need not each build a heap of their own.
	 */
	if (upgrading && (!(up.heap = malloc(taken * sizeof(*up.heap))) || !(dead = malloc(npx)))) {
		errbuf_printf(err, errlen, "out of memory planning a %dx%d image", w, h);
		goto out;
	}
	for (size_t t = 0; upgrading && t < taken; t++) {
		struct upgrade u;
		size_t i = cand[t].i;
		if (next_upgrade(p, acc, i, e[i], ps[i], smax, &u))
			heap_push(up.heap, &up.nh, u);
	}
	for (int attempt = 0;; attempt++) {
		double total = total0, spend = spend0, lambda = lambda0;
		if (upgrading)
			memset(dead, 0, npx);
		for (size_t q = 0; upgrading && total > goal && spend < upto; q++) {
			const int more = q < up.n ? 1 : order_next(p, acc, e, smax, &up);
			if (more < 0) {
				errbuf_printf(err, errlen, "out of memory planning a %dx%d image", w,
					      h);
				goto out;
			}
			if (!more)
				break;
			const struct upgrade *u = &up.order[q];
			if (dead[u->i])
				continue;
			if (spend + u->cost > upto) {
				dead[u->i] = 1;
				continue;
			}
			spend += u->cost;
			total -= u->gain;
			if (u->gain > 0.0 && u->cost / u->gain > lambda)
				lambda = u->cost / u->gain;
			gain[u->i] += u->gain;
			ps[u->i] = (unsigned char)u->to;
		}
		/* riders count without a budget (riders is NULL under one):
		 * what they would cost beyond it is cut again by value
		 * (fit_budget()), and at the dearest gain taken they are worth
		 * at most what they cost (a pixel not taken gains less for its
		 * cost than any taken) */
		if (pack_all(p, acc, e, cand, taken, ps, gain, lambda, riders, mark, out)) {
			errbuf_printf(err, errlen, "out of memory packing regions");
			goto out;
		}
		if (spend == spend0 || attempt == 7)
			break;
		double c = 0.0;
		for (size_t k = 0; k < out->nregions; k++)
			c += out->regions[k].cost;
		if (c <= limit) {
			lo = upto;
			if (hi == INFINITY || hi - lo < 0.1 * hi || attempt >= 6)
				break;
		} else {
			hi = upto;
		}
		if (attempt >= 6)
			upto = lo;	/* the last attempt: the most that fit */
		else if (lo == spend0)
			upto = spend0 + (spend - spend0) * 0.8 * limit / c;
		else
			upto = 0.5 * (lo + hi);
		/* back to the pixels at their next scales */
		for (size_t t = 0; t < taken; t++) {
			ps[cand[t].i] = (unsigned char)cand[t].s;
			gain[cand[t].i] = cand[t].gain;
		}
		free(out->regions);
		out->regions = NULL;
		out->nregions = 0;
	}

	/* over the budget: the least worth goes (fit_budget() leaves at most
	 * the budget); over the cap: the regions worth least per cost */
	if (fit_budget(p, out, ps, gain)) {
		errbuf_printf(err, errlen, "out of memory packing regions");
		goto out;
	}
	qsort(out->regions, out->nregions, sizeof(*out->regions), by_value);
	while (out->nregions > (size_t)p->max_regions)
		out->nregions--;
	if (!out->nregions) {
		out->outcome = PLAN_NO_BUDGET;
		ret = 0;
		goto out;
	}
	if (split_regions(p, out, ps, gain)) {
		errbuf_printf(err, errlen, "out of memory packing regions");
		goto out;
	}
	qsort(out->regions, out->nregions, sizeof(*out->regions), by_position);
	for (size_t k = 0; k < out->nregions; k++)
		out->regions[k].frame = plan_grid_scale(p, w, h, out->regions[k].scale) ? ACC_GRID_FRAME
											: 0;

	/* what the kept regions do */
	double gained = 0.0;
	for (size_t k = 0; k < out->nregions; k++) {
		const struct plan_region *r = &out->regions[k];
		for (int y = r->y0; y <= r->y1; y++)
			for (int x = r->x0; x <= r->x1; x++) {
				size_t i = (size_t)y * w + x;
				if (accum_has_scale(acc, i, r->scale) || out->scale[i] == r->scale)
					continue;
				double n = acc->px[i * ACC_NCH + ACC_SAMPLES];
				double m = (double)r->scale * r->scale;
				if (out->scale[i] == 0.0f) {
					out->pixels++;
					gained += e[i] * m / (n + m);
				}
				out->scale[i] = (float)r->scale;
				out->samples += m;
				if (gain[i] > 0.0)
					out->chosen[i] = 1.0f;
			}
		out->cost += r->cost;
	}
	for (size_t i = 0; i < npx; i++)
		out->chosen_pixels += out->chosen[i] > 0.0f;
	out->est_after = (out->est_relmse * (double)npx - gained) / (double)npx;
	if (out->est_after < 0.0)
		out->est_after = 0.0;
	out->outcome = PLAN_REFINE;
	if (p->budget > 0.0 && out->est_after > goal_px &&
	    out->est_relmse - out->est_after < p->min_pass_gain * out->est_relmse) {
		out->outcome = PLAN_LITTLE_GAIN;
		free(out->regions);
		out->regions = NULL;
		out->nregions = 0;
	}
	ret = 0;
out:
	free(gain);
	free(cand);
	free(mark);
	free(ps);
	free(up.heap);
	free(up.order);
	free(dead);
	free(sat);
	free(riders);
	if (ret)
		plan_release(out);
	return ret;
}

/*
 * focal_blur at 160x120 under render's --budget 8 planned its fourth pass
 * at 11.4 and 11.7 core-s for a budget of 10.0 (its renders at scale 16,
 * each frame 2560x1920), ran 0.1 to 0.2 s past the deadline, and ended at
 * 8.15 and 8.21 s (two runs by hand, 2026-12-05; in the full sweep of 09:07
 * UTC two of three runs ended at 8.19 and 8.31 s).  Planned again once for
 * all the excess less, runs ended at 7.27 to 7.54 s with a fifth more
 * error; for half of it, at 7.30 to 7.96 s in five runs, but at 7.95 to
 * 8.22 in four others, whose second plan, for 9.5 core-s, was the first
 * again (its regions fitted 9.5 as they had 10.1, and split the same):
 * so again, each time for half the excess less, up to PLAN_SPLIT_TRIES.
 */
int plan_make_from(const struct image *acc, const double *e, const struct plan_params *p,
		   struct plan *out, char *err, size_t errlen)
{
	if (make_once(acc, e, p, out, err, errlen))
		return -1;
	out->budget = p->budget > 0.0 ? p->budget : 0.0;
	struct plan_params q = *p;
	for (int k = 0; k < PLAN_SPLIT_TRIES && out->outcome == PLAN_REFINE && p->budget > 0.0 &&
			out->cost > PLAN_SPLIT_OVER * p->budget;
	     k++) {
		q.budget -= 0.5 * (out->cost - p->budget);
		if (q.fill > q.budget)
			q.fill = q.budget;
		if (!(q.budget > 0.0)) {	/* nothing fits: no regions */
			free(out->regions);
			out->regions = NULL;
			out->nregions = 0;
			out->outcome = PLAN_NO_BUDGET;
			out->budget = q.budget;
			return 0;
		}
		plan_release(out);
		if (make_once(acc, e, &q, out, err, errlen))
			return -1;
		out->budget = q.budget;
	}
	return 0;
}

void plan_release(struct plan *pl)
{
	free(pl->scale);
	free(pl->chosen);
	free(pl->regions);
	memset(pl, 0, sizeof(*pl));
}

void plan_job(const struct pov_job *base, const struct plan_region *r, const char *output,
	      struct pov_region *region, const char **extra, struct pov_job *job)
{
	const int grid = r->frame > 0 && r->scale >= 4;
	int s = r->frame > 0 ? r->frame : accum_render_factor(r->scale);
	*job = *base;
	job->output = output;
	job->width = base->width * s;
	job->height = base->height * s;
	region->x0 = r->x0 * s;
	region->y0 = r->y0 * s;
	region->x1 = (r->x1 + 1) * s - 1;
	region->y1 = (r->y1 + 1) * s - 1;
	job->region = region;
	for (size_t k = 0; k < base->nextra; k++)
		extra[k] = base->extra[k];
	job->extra = extra;
	job->nextra = base->nextra;
	if (r->scale == ACC_AA) {
		/* POV-Ray's own adaptive antialiasing, jittered (accum.h) */
		static const char *const depth[] = { "+R1", "+R2", "+R3", "+R4", "+R5" };
		_Static_assert(ACC_AA_DEPTH == 5, "a +R for every depth");
		const int d = accum_aa_depth(r->depth);
		const int di = (d >= 1 && d <= ACC_AA_DEPTH ? d : ACC_AA_DEPTH_V1) - 1;
		if (r->frame > 0 && accum_for_spread(r->edges)) {
			const struct accum_spread sp = accum_spread_render(r->edges, r->depth);
			extra[job->nextra++] = "+AM1";
			extra[job->nextra++] = sp.a;
			extra[job->nextra++] = sp.r;
		} else {
			extra[job->nextra++] = "+AM2";
			extra[job->nextra++] = r->frame > 0 ? "+A0.1" : "+A0.0";
			extra[job->nextra++] = r->frame <= 0 ? "+R4" : depth[di];
		}
		extra[job->nextra++] = "+J";
	} else if (grid) {
		/* every pixel of the render supersampled (accum.h) */
		extra[job->nextra++] = "+AM1";
		extra[job->nextra++] = "+A0.0";
		int k = r->scale / s;
		extra[job->nextra++] = k == 2 ? "+R2" : k == 4 ? "+R4" : "+R8";
		extra[job->nextra++] = "+J0.75";
	} else {
		extra[job->nextra++] = "-A";	/* our samples are the s x s grid */
	}
}

/* The header line's start; the files before it ended with "scale output"
 * and had no depth and edges columns (read as 0 0). */
#define REGIONS_HEADER "# povpress regions: pass x0 y0 x1 y1 scale output depth edges"
#define REGIONS_HEADER_V1 "# povpress regions: pass x0 y0 x1 y1 scale output"

int plan_regions_write(FILE *f, const struct plan *pl, int pass, char *const *outputs)
{
	fprintf(f, "%s (pixels 0-based, inclusive; depth and edges: an antialiased render "
		"in scale 2's place, its +R, and 1 if taken for edges, 2 for spread error (+AM1), "
		"3 at +A0.1 +R3, 4 at +A0.3 +R2, 5 and 6 at +A0.03 +R5 and +R6, 0 for a few "
		"pixels; else 0 0)\n",
		REGIONS_HEADER);
	for (size_t k = 0; k < pl->nregions; k++)
		if (strchr(outputs[k], '\n'))
			return -1;	/* the format is one region per line */
	for (size_t k = 0; k < pl->nregions; k++) {
		const struct plan_region *r = &pl->regions[k];
		fprintf(f, "%d\t%d\t%d\t%d\t%d\t%d\t%s\t%d\t%d\n", pass, r->x0, r->y0, r->x1,
			r->y1, r->scale, outputs[k], r->depth, r->edges);
	}
	return ferror(f) ? -1 : 0;
}

void plan_output_name(char *buf, size_t len, const char *dir, int pass, size_t k, int scale)
{
	if (scale == ACC_AA)
		snprintf(buf, len, "%s/p%02d-r%03zu-aa.exr", dir, pass, k);
	else
		snprintf(buf, len, "%s/p%02d-r%03zu-s%d.exr", dir, pass, k, scale);
}

int plan_regions_save(const char *path, const struct plan *pl, int pass, char *const *outputs,
		      char *err, size_t errlen)
{
	char tmp[PATH_MAX + 16];
	FILE *f = file_begin(path, tmp, sizeof tmp, err, errlen);
	if (!f)
		return -1;
	if (plan_regions_write(f, pl, pass, outputs)) {
		file_abort(f, tmp);
		errbuf_printf(err, errlen, "cannot write '%s': an output path has a newline", path);
		return -1;
	}
	return file_commit(f, tmp, path, err, errlen);
}

int plan_merge_file(struct image *acc, const char *path, const struct plan_region *g, int pass,
		    long *folded, char *err, size_t errlen)
{
	if (g->depth)
		return accum_merge_aa_file(acc, path, g->scale, g->depth, g->edges, g->x0, g->y0,
					   g->x1, g->y1, pass, folded, err, errlen);
	return accum_merge_file(acc, path, g->scale, g->x0, g->y0, g->x1, g->y1, pass, folded,
				err, errlen);
}

/* A region line's last two fields, depth and edges, into r, cut off s (the
 * output and them); -1 if they are missing or out of range. */
static int regions_tail(char *s, struct plan_region *r)
{
	char *t2 = strrchr(s, '\t');
	if (!t2 || t2 == s)
		return -1;
	*t2 = '\0';
	char *t1 = strrchr(s, '\t'), *end;
	if (!t1 || t1 == s)
		return -1;
	*t1 = '\0';
	if (!isdigit((unsigned char)t1[1]) || !isdigit((unsigned char)t2[1]))
		return -1;	/* no sign or space */
	errno = 0;
	long d = strtol(t1 + 1, &end, 10);
	if (*end || errno || d > ACC_AA_DEPTH)
		return -1;
	long e = strtol(t2 + 1, &end, 10);
	if (*end || errno || e < ACC_AA_FOR_FEW || e > ACC_AA_FOR_SPREAD_R6)
		return -1;
	if ((d || e) && (r->scale != ACC_AA || !d))
		return -1;	/* only an antialiased render has them */
	r->depth = (int)d;
	r->edges = (int)e;
	return 0;
}

int plan_regions_read(const char *path, struct plan_region **regions, char ***outputs,
		      int **passes, size_t *n, char *err, size_t errlen)
{
	FILE *f = fopen(path, "r");
	char line[8192];
	size_t cnt = 0, alloc = 0;
	int lineno = 0, tail = 1;	/* but under the old header */

	*regions = NULL;
	*outputs = NULL;
	*passes = NULL;
	*n = 0;
	if (!f) {
		errbuf_printf(err, errlen, "cannot open '%s': %s", path, strerror(errno));
		return -1;
	}
	while (fgets(line, sizeof line, f)) {
		lineno++;
		size_t len = strlen(line);
		if (len && line[len - 1] == '\n')
			line[--len] = '\0';
		if (len && line[len - 1] == '\r')
			line[--len] = '\0';	/* a file edited elsewhere */
		if (!strncmp(line, REGIONS_HEADER_V1, strlen(REGIONS_HEADER_V1)))
			tail = !strncmp(line, REGIONS_HEADER, strlen(REGIONS_HEADER));
		if (!len || line[0] == '#')
			continue;
		struct plan_region r = {0};
		int pass, off = 0;
		/* the output is everything after the sixth tab, spaces and all,
		 * up to the last two tabs where the header names depth and edges */
		if (sscanf(line, "%d\t%d\t%d\t%d\t%d\t%d%n", &pass, &r.x0, &r.y0, &r.x1, &r.y1,
			   &r.scale, &off) != 6 || !off || line[off] != '\t' || !line[++off] ||
		    (tail && regions_tail(line + off, &r))) {
			if (tail)
				errbuf_printf(err, errlen, "'%s' line %d: expected \"pass x0 y0 x1 y1 "
					      "scale output depth edges\" separated by tabs (depth 0 "
					      "to %d, edges 0 to 4; 0 0 unless the scale is 0)", path,
					      lineno, ACC_AA_DEPTH);
			else
				errbuf_printf(err, errlen, "'%s' line %d: expected \"pass x0 y0 x1 y1 "
					      "scale output\" separated by tabs", path, lineno);
			goto fail;
		}
		if (cnt == alloc) {
			alloc = alloc ? 2 * alloc : 16;
			void *a = realloc(*regions, alloc * sizeof(**regions));
			void *b = a ? realloc(*outputs, alloc * sizeof(**outputs)) : NULL;
			if (a)
				*regions = a;
			if (b)
				*outputs = b;
			void *c = b ? realloc(*passes, alloc * sizeof(**passes)) : NULL;
			if (c)
				*passes = c;
			if (!c) {
				errbuf_printf(err, errlen, "out of memory reading '%s'", path);
				goto fail;
			}
		}
		(*regions)[cnt] = r;
		(*passes)[cnt] = pass;
		(*outputs)[cnt] = strdup(line + off);
		if (!(*outputs)[cnt]) {
			errbuf_printf(err, errlen, "out of memory reading '%s'", path);
			goto fail;
		}
		cnt++;
	}
	if (ferror(f)) {
		errbuf_printf(err, errlen, "cannot read '%s': %s", path, strerror(errno));
		goto fail;
	}
	fclose(f);
	*n = cnt;
	return 0;
fail:
	fclose(f);
	for (size_t k = 0; k < cnt; k++)
		free((*outputs)[k]);
	free(*regions);
	free(*outputs);
	free(*passes);
	*regions = NULL;
	*outputs = NULL;
	*passes = NULL;
	return -1;
}

/* qsort() order for plan_error_where(): the largest first */
static int by_descending(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return x < y ? 1 : x > y ? -1 : 0;
}

/* The sum of the largest share of the sorted values v (k of them, of n
 * pixels; at least one). */
static double top_sum(const double *v, size_t k, size_t n, double share)
{
	size_t m = (size_t)(share * (double)n), top = m ? m : 1;
	double big = 0.0;
	for (size_t i = 0; i < top && i < k; i++)
		big += v[i];
	return big;
}

/* The errors e (n pixels) that are finite and positive, largest first,
 * into a new array of *k (you free() it; NULL when memory runs out), and
 * their sum into *all. */
static double *sorted_errors(const double *e, size_t n, size_t *k, double *all)
{
	double *v = malloc(n * sizeof(*v));
	*k = 0;
	*all = 0.0;
	if (!v)
		return NULL;
	for (size_t i = 0; i < n; i++)
		if (isfinite(e[i]) && e[i] > 0.0) {
			v[(*k)++] = e[i];
			*all += e[i];
		}
	qsort(v, *k, sizeof(*v), by_descending);
	return v;
}

unsigned plan_error_where(const double *e, size_t n)
{
	size_t k;
	double all, *v = sorted_errors(e, n, &k, &all);
	if (!v)
		return 0;	/* the default samplers serve either way */
	unsigned where = 0;
	if (all > 0.0 && top_sum(v, k, n, PLAN_SPARSE_SHARE) >= 0.5 * all)
		where |= PLAN_ERROR_FEW;
	if (all > 0.0 && top_sum(v, k, n, PLAN_EDGE_SHARE) >= PLAN_EDGE_FRAC * all)
		where |= PLAN_ERROR_EDGES;
	free(v);
	return where;
}

double plan_top_sum(const double *e, size_t n, double share, double *all)
{
	size_t k;
	double sum, *v = sorted_errors(e, n, &k, &sum);
	if (all)
		*all = sum;
	if (!v)
		return 0.0;
	const double big = top_sum(v, k, n, share);
	free(v);
	return big;
}

int plan_sparse_error(const double *e, size_t n)
{
	return (plan_error_where(e, n) & PLAN_ERROR_FEW) != 0;
}

int plan_edge_error(const double *e, size_t n)
{
	return (plan_error_where(e, n) & PLAN_ERROR_EDGES) != 0;
}
