/*
 * render.c - `povpress render`: the adaptive re-rendering loop.
 *
 * base pass -> [analyse -> plan -> region renders -> merge]* -> final image,
 * error map and report.  Everything that lets a run continue lives in the
 * work directory: the accumulation (accum.exr, rewritten whole after every
 * pass), the cost model and the passes so far (progress.txt) and what the
 * run was asked to do (run.txt, which --resume checks).  The output image
 * is rewritten after every pass, always through a temporary file, so an
 * interrupted run leaves either no output or a complete image of its best
 * result so far.
 */
#define _XOPEN_SOURCE 700	/* realpath */
#include "driver/accum.h"
#include "driver/args.h"
#include "driver/commands.h"
#include "driver/denoise.h"
#include "driver/errbuf.h"
#include "driver/files.h"
#include "driver/image.h"
#include "driver/metrics.h"
#include "driver/plan.h"
#include "driver/povray.h"
#include "driver/scene.h"
#include "regression/lpr.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <stdint.h>
#include <string.h>
#include <strings.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static const char usage[] =
	"usage: povpress render SCENE.pov -o OUT.exr [-W w] [-H h] [--target RELMSE]\n"
	"                       [--budget SECONDS] [--max-passes N] [--jobs N]\n"
	"                       [--prelaunch auto|on|off]\n"
	"                       [--workdir DIR] [--keep-workdir] [--resume]\n"
	"                       [--error-map FILE] [--report FILE.json]\n"
	"                       [--final auto|blend|samples|reconstruction]\n"
	"                       [--radiosity-scale K]\n"
	"                       [--sampler auto|grid|scale|aa|jitter]\n"
	"                       [-q|-v]\n"
	"                       [-- POVRAY_OPTIONS...]\n"
	"\n"
	"Render SCENE.pov through POV-Ray adaptively: a base pass at one sample per\n"
	"pixel, then passes that estimate every pixel's error by local regression\n"
	"(PRESS) and re-render only the regions worth it at scales 2, 4, 8 and 16\n"
	"(4, then about 16, 64 and 256 new samples per pixel), until the estimated\n"
	"image relMSE reaches the target, the budget is spent, the passes run out, or\n"
	"no pixel would gain (under a budget: a pass would gain less than 1%).\n";

/* (two strings: C11 promises no more than 4095 characters in one) */
static const char usage_options[] =
	"\n"
	"options:\n"
	"  -o, --output FILE     final image, float RGB EXR (required)\n"
	"  -W, --width N         image width (default 640)\n"
	"  -H, --height N        image height (default 480)\n"
	"  --target RELMSE       estimated relMSE to stop at (default 0.001)\n"
	"  --budget SECONDS      wall-clock seconds to stop within (default: none;\n"
	"                        region renders still running when only the time\n"
	"                        to merge, analyse and write the final image is\n"
	"                        left are stopped, keeping the blocks they had\n"
	"                        finished, but one about to finish is left\n"
	"                        up to 0.3 s (7.5% of the budget) to write its\n"
	"                        image; a base pass still running at its end is\n"
	"                        stopped and the run fails, with no image; its\n"
	"                        passes cost each pixel as the base pass's progress\n"
	"                        and the region renders before them measured it)\n"
	"  --max-passes N        refinement passes after the base pass (default 8)\n"
	"  --prelaunch auto|on|off\n"
	"                        start each pass's likely region renders during the\n"
	"                        pass before (the first's, or a radiosity scene's\n"
	"                        radiosity pass, with the base pass), to\n"
	"                        wait before the scene, and let the pass take those\n"
	"                        its plan matches: it saves POV-Ray's start-up wait\n"
	"                        (about 0.3 s, which povwait.so cuts to 0.01-0.03 s);\n"
	"                        auto (the default): only without povwait.so, and\n"
	"                        then under a --budget (a radiosity pass always)\n"
	"  --jobs N              POV-Ray processes at once (default 4 per core: without\n"
	"                        povwait.so each invocation waits 0.3 to 0.7 s on\n"
	"                        POV-Ray itself)\n"
	"  --timeout SECONDS     per POV-Ray run; one retry after a crash or timeout\n"
	"                        (default: 60 + 10 x the dearest region's predicted cost)\n"
	"  --cost-job S          the planner's cost of one POV-Ray run, seconds, and\n"
	"  --cost-sample S       of one sample (default: measured on the base pass,\n"
	"                        without a --budget rounded to powers of two; the\n"
	"                        report has them; given, a budget's cost map starts\n"
	"                        at 1, not at the base pass's progress)\n"
	"  --radiosity-scale K   if the scene has radiosity, re-render the whole frame\n"
	"                        at K x the size on one thread for the radiosity\n"
	"                        solution and keep its K x K samples per pixel (1, 2, 4\n"
	"                        or 8; default: the smallest power of two making it\n"
	"                        1280+ pixels wide, at most 4 and 1280x960 pixels\n"
	"                        (but 480+ wide); under a --budget: 480+ wide, at\n"
	"                        most 4, or a larger one when its pass fits on one\n"
	"                        thread (up to 1280 wide, 1280x960 pixels and 8\n"
	"                        times the image), else lowered (4, 3, 2) until it\n"
	"                        fits; 0: no such pass)\n"
	"  --workdir DIR         keep intermediate files here (default OUT.exr.work)\n"
	"  --keep-workdir        do not remove the work directory after success\n"
	"  --resume              continue the run the work directory holds\n"
	"  --error-map FILE      error map EXR (default OUT.errors.exr): error,\n"
	"                        relerror, samples, order, bandwidth, pass, scales,\n"
	"                        fit (the share of the regression's fit OUT.exr\n"
	"                        holds), cost (a sample's cost there over the\n"
	"                        frame's mean, under a budget; else 1)\n"
	"  --report FILE         JSON report of every pass (default: none)\n";
static const char usage_options2[] =
	"  --sampler S           how pixels get their samples: auto (default: grid for\n"
	"                        the scales whose scaled frame would exceed 1 Mpixel,\n"
	"                        scale below, or 8 Mpixels for a scene whose file has\n"
	"                        focal blur (aperture and blur_samples), where\n"
	"                        POV-Ray's antialiasing converges slowly; where the\n"
	"                        estimated error sits in a few pixels, 0.1% of them\n"
	"                        holding half of it, as at highlights, or after the\n"
	"                        base pass at edges, 5% of them holding two thirds\n"
	"                        (not with radiosity or focal blur), scale 2 as\n"
	"                        one render at twice the size with POV-Ray's\n"
	"                        +AM2 +A0.1 +J, +R5 in few pixels, +R4 at edges\n"
	"                        (less where a budget would not fit it); where it\n"
	"                        is spread and the frame at\n"
	"                        scale 4 takes less than 0.7 s on\n"
	"                        the cores, as jitter, or where it takes more and\n"
	"                        a sample costs at most 1.5 microseconds (2 under\n"
	"                        a budget, measured, not rounded), scale 2\n"
	"                        as one render at twice the size with POV-Ray's\n"
	"                        +AM1 +A0.03 +R4 +J (under a budget +R6 or +R5\n"
	"                        where those fit, lighter ones where +R4 does\n"
	"                        not); scale throughout where the\n"
	"                        file sets assumed_gamma other than 1, in whose\n"
	"                        encoding POV-Ray's antialiasing averages), grid\n"
	"                        (scales 4, 8 and 16 as renders at twice the size with\n"
	"                        POV-Ray's +AM1 +A0.0 +R(scale/2) +J0.75: scale x\n"
	"                        scale jittered samples), scale (resolution scaling\n"
	"                        throughout: the render is scale times the size,\n"
	"                        which POV-Ray pays for per render whatever the\n"
	"                        region), aa (scaling,\n"
	"                        and for pixels with 21+ samples first, once per\n"
	"                        pixel, POV-Ray's antialiasing, +AM2 +A0 +R4 +J,\n"
	"                        weighted by what it proves worth), or jitter (no\n"
	"                        scale-2 pass: scales 4, 8 and 16 as grid renders, so\n"
	"                        every sample added to the base pass is jittered); see\n"
	"                        the README\n"
	"  --final MODE          what OUT.exr holds per pixel: auto (default: the\n"
	"                        blend below, filtered by non-local means weighted\n"
	"                        by each pixel's measured noise), blend (the\n"
	"                        samples' mean, blended with the regression's fit\n"
	"                        by the two's predicted errors where the pixel's\n"
	"                        noise is measured, like its neighbours', and the\n"
	"                        two agree), samples (the mean of the pixel's\n"
	"                        samples), or reconstruction (the fit everywhere);\n"
	"                        see the README\n"
	"  -q, --quiet           no progress display\n"
	"  -v, --verbose         progress and details, even when stderr is not a terminal\n"
	"  -h, --help            this text\n"
	"  -- OPTIONS            passed to every POV-Ray run (e.g. Declare=AreaN=4 +WT1);\n"
	"                        antialiasing options are overridden in region renders\n"
	"\n"
	"Environment: POVPRESS_POVRAY, the POV-Ray binary (default: povray in PATH);\n"
	"POVPRESS_POVWAIT, the library preloaded into POV-Ray to cut its polling\n"
	"waits (default: povwait.so next to povpress; 0 or empty: none).\n"
	"\n"
	"Exit status: 0 done, 1 failure, 2 bad usage, 130 interrupted (the output then\n"
	"holds the best image so far, or does not exist; --resume continues, with the\n"
	"blocks the interrupted pass's renders had finished).\n";

static double now_s(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/*
 * now_s() at the process's start, for the budget's clock: a user's `time`
 * counts from the exec, and the dynamic loader, the option parsing and the
 * checks before the run take 10 to 30 ms (`strace -tt`: 8 ms to the first
 * stat of the scene, 34 ms to the run's start, under strace).  In the full
 * sweep of 2026-12-03 13:27 UTC one budget run of 99 (focal_blur, 8 s)
 * ended 9 ms late by bash's `time` while its own clock, started after those
 * checks, gave it 7.88 s.  From /proc/self/stat's start time (in clock
 * ticks since boot, rounded down: the age is at most one tick too long);
 * fallback now_s() where that cannot be read or makes no sense.
 */
static double process_start_s(void)
{
	const double now = now_s();
	struct timespec bt;
	long hz = sysconf(_SC_CLK_TCK);
	FILE *f = fopen("/proc/self/stat", "r");
	if (!f)
		return now;
	char buf[1024];
	size_t n = fread(buf, 1, sizeof buf - 1, f);
	fclose(f);
	buf[n] = '\0';
	/* the command's name, field 2, is in parentheses and may hold spaces:
	 * count from the last ')'; starttime is field 22 */
	const char *p = strrchr(buf, ')');
	unsigned long long start = 0;
	int field = 2;
	for (; p && *p && field < 22; p++)
		if (*p == ' ')
			field++;
	if (!p || field != 22 || sscanf(p, "%llu", &start) != 1 || hz <= 0 ||
	    clock_gettime(CLOCK_BOOTTIME, &bt))
		return now;
	const double age = bt.tv_sec + bt.tv_nsec * 1e-9 - (double)start / (double)hz;
	return age >= 0.0 && age < 1.0 ? now - age : now;
}

static double self_cpu(void)
{
	struct rusage ru;
	if (getrusage(RUSAGE_SELF, &ru))
		return 0.0;
	return ru.ru_utime.tv_sec + ru.ru_utime.tv_usec * 1e-6 + ru.ru_stime.tv_sec +
	       ru.ru_stime.tv_usec * 1e-6;
}

/* --prelaunch, its values in the order of their names */
enum { PRE_OFF, PRE_AUTO, PRE_ON };
static const char *const prelaunch_names[] = { "off", "auto", "on" };
/* --final's, in enum accum_final's order */
static const char *const final_names[] = { "auto", "samples", "reconstruction", "blend" };
#define PRE_KINDS 3	/* scale 2, scale 4 as a grid render, antialiased */
#define PRE_BANDS 8
#define PRE_MAX (PRE_KINDS * PRE_BANDS)
/* An early render's wait from its gate to its image, less its CPU, until
 * one is measured: 0.05 to 0.07 s at 160x120 (a taken render took 0.086 s
 * from its gate to its image on thin_geometry, against 0.36 to 0.42 s
 * from a fresh start) */
#define PRE_LATENCY 0.1

struct pass_rec {
	int pass;
	double wall_s, cpu_s, driver_cpu_s;
	int invocations, regions, failed;
	long pixels;
	double samples;
	double est_relmse;
	double planned_relmse;	/* the plan's prediction of est_relmse (NaN: none,
				 * or a pass resumed; not in progress.txt) */
	double analysis_s;
	int prelaunched;	/* regions taken from renders started early */
	int stopped;		/* region renders stopped at the budget's end (not
				 * in progress.txt) */
	long kept;		/* their pixels folded in from the blocks they
				 * finished (not in progress.txt) */
};

struct run {
	/* options */
	const char *scene, *out, *workdir, *error_map, *report;
	char povdir[PATH_MAX];	/* workdir as POV-Ray can be told it */
	char radfile[PATH_MAX + 16];	/* the radiosity data region renders load (from
					 * the radiosity pass, else the base pass) */
	int w, h, max_passes, jobs, quiet, verbose, keep, resume, user_workdir;
	double target, budget, timeout;
	double user_cost_job, user_cost_sample;	/* 0: measure */
	int user_rad_scale;	/* --radiosity-scale: -1 choose, 0 no radiosity pass */
	int grid;		/* --sampler: which scales are grid renders,
				 * PLAN_GRID_* (plan.h); PLAN_GRID_LARGE is
				 * auto, the only one the run may change
				 * (run_grid()) */
	int aa;			/* --sampler aa (grid PLAN_GRID_NEVER) */
	int prelaunch;		/* --prelaunch: PRE_AUTO, PRE_ON, PRE_OFF */
	enum accum_final final;
	int filter;		/* --final auto: the blend, filtered (denoise.h) */
	const char *const *extra;
	size_t nextra;
	/* state */
	int cores, tty;
	char path[PATH_MAX];
	double t0;
	double prev_wall;	/* wall seconds of the passes before a resume */
	double cost_job, cost_sample, latency;
	double cost_sample_measured;	/* cost_sample before rounding (radiosity_time()) */
	double tail;		/* the base pass's wait on POV-Ray's exit */
	double pretrace_s;	/* the base pass's radiosity pretrace, CPU s */
	double rad_rays;	/* the base pass's radiosity rays after the
				 * pretrace, per pixel (plan_radiosity_trace()) */
	int radiosity;
	int rad_scale;		/* the scale the radiosity solution was computed at */
	int jittered;		/* --sampler auto chose PLAN_GRID_ONLY for the run
				 * (one_step()) */
	int focal;		/* --sampler auto and the scene has focal blur
				 * (scene_focal_blur()): resolution scaling up to
				 * PLAN_FOCAL_FRAME, no jitter */
	double gamma;		/* the scene's assumed_gamma where it is not 1
				 * (scene_assumed_gamma()), else 0: under
				 * --sampler auto resolution scaling only, no
				 * antialiased render (run_grid()) */
	int rad_named;		/* the scene file's text holds "radiosity"
				 * (scene_keys): its radiosity pass starts with
				 * the base pass (prelaunch_first()) */
	struct pass_rec *passes;
	size_t npasses;
	const char *stop;
	struct image acc;
	double *est;		/* w*h: each pixel's estimated relative error, from
				 * the latest analysis of acc (plan_pixel_errors()),
				 * the blend's where the final image takes some of
				 * the fit */
	double *noise;		/* w*h: the noise part of the samples' (ditto) */
	float *take;		/* w*h: the share of the fit the final image
				 * takes (accum_final_choose()) */
	long took;		/* how many pixels take some */
	/* progress while a pool runs */
	int pool_done, pool_total, pool_pass;
	/* the next pass's guessed renders, started early (--prelaunch) */
	struct pov_prelaunch *pre;
	struct plan_region pre_reg[PRE_MAX];
	size_t npre;
	int pre_pass;		/* the pass they are for */
	unsigned pre_rad;	/* or, bit k set: the radiosity pass at scale k
				 * (prelaunch_radiosity()) */
	float *cost_map;	/* under a budget, w*h: each pixel's cost a
				 * sample over cost_sample, as its region
				 * renders measured it (learn_costs()); else
				 * NULL */
	int cost_learnt;	/* region renders the map has learnt from */
	double pre_latency;	/* an early render's wait from its gate to its
				 * image, less its CPU (measured; PRE_LATENCY
				 * until then) */
	double write_s;		/* the last pass's writes of its work directory
				 * and image, wall seconds (final_reserve()) */
	double comp_s;		/* the image's one compressed write before the
				 * end, wall seconds (0: none yet) */
	double renders_end;	/* when the last pass's renders ended (now_s()) */
	double tail_s;		/* from then to the end of its writes: merges,
				 * analysis, writes (0: no region pass yet) */
	double read_s;		/* the base pass's image read and folded, wall
				 * seconds (0: not measured, as on --resume) */
};

static void print_usage(FILE *f)
{
	fputs(usage, f);
	fputs(usage_options, f);
	fputs(usage_options2, f);
}

static void progress(struct run *r, const char *fmt, ...)
	__attribute__((format(printf, 2, 3)));

static void progress(struct run *r, const char *fmt, ...)
{
	if (r->quiet || (!r->tty && !r->verbose))
		return;
	va_list ap;
	va_start(ap, fmt);
	if (r->tty)
		fputs("\r\033[K", stderr);
	vfprintf(stderr, fmt, ap);
	va_end(ap);
	if (!r->tty)
		fputc('\n', stderr);
	fflush(stderr);
}

static void progress_end(struct run *r)
{
	if (!r->quiet && r->tty)
		fputc('\n', stderr);
}

static const char *wpath(struct run *r, const char *name)
{
	snprintf(r->path, sizeof r->path, "%s/%s", r->workdir, name);
	return r->path;
}

static double elapsed(const struct run *r)
{
	return r->prev_wall + now_s() - r->t0;
}

/* Seconds from now to a render's deadline: the budget's end less reserve,
 * at least 0.01 s; 0 (none) without a budget. */
static double deadline_in(const struct run *r, double reserve)
{
	if (!(r->budget > 0.0))
		return 0.0;
	double left = r->budget - elapsed(r) - reserve;
	return left < 0.01 ? 0.01 : left;
}

/* Remove the work directory's files (ours only: nothing below it is a
 * directory but POV-Ray's link targets, which are links). */
static void remove_workdir(const char *dir)
{
	DIR *d = opendir(dir);
	if (!d)
		return;
	struct dirent *e;
	char p[PATH_MAX];
	while ((e = readdir(d))) {
		if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
			continue;
		snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
		unlink(p);
	}
	closedir(d);
	rmdir(dir);
}

/* What the run was asked to do, for --resume to check. */
static int run_identity(const struct run *r, char *buf, size_t len)
{
	char scene[PATH_MAX];
	if (!realpath(r->scene, scene))
		snprintf(scene, sizeof scene, "%s", r->scene);
	int n = snprintf(buf, len, "scene %s\nsize %dx%d\n", scene, r->w, r->h);
	for (size_t k = 0; k < r->nextra && n > 0 && (size_t)n < len; k++)
		n += snprintf(buf + n, len - n, "povray %s\n", r->extra[k]);
	return n > 0 && (size_t)n < len ? 0 : -1;
}

static int add_pass(struct run *r, const struct pass_rec *p)
{
	void *q = realloc(r->passes, (r->npasses + 1) * sizeof(*r->passes));
	if (!q)
		return -1;
	r->passes = q;
	r->passes[r->npasses++] = *p;
	return 0;
}

/* progress.txt: the cost model, then one line per pass. */
static int save_progress(struct run *r, char *err, size_t errlen)
{
	size_t cap = 256 + r->npasses * 256;
	char *s = malloc(cap);
	if (!s) {
		errbuf_printf(err, errlen, "out of memory");
		return -1;
	}
	int n = snprintf(s, cap, "model %.17g %.17g %.17g %d %d %d\n", r->cost_job,
			 r->cost_sample, r->latency, r->radiosity, r->rad_scale, r->jittered);
	for (size_t k = 0; k < r->npasses; k++) {
		const struct pass_rec *p = &r->passes[k];
		n += snprintf(s + n, cap - n, "pass %d %.6f %.6f %.6f %d %d %d %ld %.17g %.9g %.6f\n",
			      p->pass, p->wall_s, p->cpu_s, p->driver_cpu_s, p->invocations,
			      p->regions, p->failed, p->pixels, p->samples, p->est_relmse,
			      p->analysis_s);
	}
	int rc = file_write_text(wpath(r, "progress.txt"), s, err, errlen);
	free(s);
	return rc;
}

static int load_progress(struct run *r, char *err, size_t errlen)
{
	char *s = file_read_text(wpath(r, "progress.txt"));
	if (!s) {
		errbuf_printf(err, errlen, "cannot resume: '%s' has no finished base pass",
			      r->workdir);
		return -1;
	}
	int ok = 0;
	for (char *save = NULL, *line = strtok_r(s, "\n", &save); line;
	     line = strtok_r(NULL, "\n", &save)) {
		if (sscanf(line, "model %lf %lf %lf %d %d %d", &r->cost_job, &r->cost_sample,
			   &r->latency, &r->radiosity, &r->rad_scale, &r->jittered) >= 4) {
			ok |= 1;
			continue;
		}
		struct pass_rec p = { .planned_relmse = NAN };
		if (sscanf(line, "pass %d %lf %lf %lf %d %d %d %ld %lf %lf %lf", &p.pass, &p.wall_s,
			   &p.cpu_s, &p.driver_cpu_s, &p.invocations, &p.regions, &p.failed,
			   &p.pixels, &p.samples, &p.est_relmse, &p.analysis_s) == 11) {
			if (add_pass(r, &p))
				break;
			ok |= 2;
		}
	}
	free(s);
	if (ok != 3) {
		errbuf_printf(err, errlen, "cannot resume: '%s' is damaged", wpath(r, "progress.txt"));
		return -1;
	}
	for (size_t k = 0; k < r->npasses; k++)
		r->prev_wall += r->passes[k].wall_s;
	return 0;
}

/* The POV-Ray job every render of this run starts from. */
static void base_job(const struct run *r, struct pov_job *job, const char **extra,
		     int threads)
{
	memset(job, 0, sizeof(*job));
	job->scene = r->scene;
	job->width = r->w;
	job->height = r->h;
	job->threads = threads;
	job->extra = extra;
	job->nextra = r->nextra;
	job->workdir = r->povdir;
	/* region renders load the radiosity the base pass saved */
	job->radiosity = r->radiosity ? r->radfile : NULL;
	job->radiosity_mode = POV_RAD_LOAD;
	for (size_t k = 0; k < r->nextra; k++)
		extra[k] = r->extra[k];
}

/* A region render's job of pass `pass` (base_job() on one thread, and
 * POVPRESS_PASS declared); passno and pd hold what it points to. */
static void pass_job(const struct run *r, int pass, struct pov_job *job, const char **extra,
		     char passno[16], struct pov_define *pd)
{
	base_job(r, job, extra, 1);
	snprintf(passno, 16, "%d", pass);
	pd->name = "POVPRESS_PASS";
	pd->value = passno;
	job->defines = pd;
	job->ndefines = 1;
	/* under a budget, how far a render stopped at its end got, and
	 * whether it is about to finish (pov_pool_opts' finish_s); stopped
	 * at the deadline or by an interruption, the blocks it finished,
	 * kept */
	job->progress = r->budget > 0.0;
	job->salvage = 1;
}

static void on_done(void *arg, size_t index, const struct pov_result *res)
{
	struct run *r = arg;
	(void)index;
	(void)res;
	r->pool_done++;
	if (r->tty && !r->quiet)
		progress(r, "pass %d: %d/%d region renders, %.1f s", r->pool_pass, r->pool_done,
			 r->pool_total, elapsed(r));
}

/* A render's output is whole once its last row reads (POV-Ray writes the
 * rows in order and the line offsets last): for a region render the pool
 * need not wait for POV-Ray to exit. */
static int output_whole(void *arg, size_t index, const char *path)
{
	(void)arg;
	(void)index;
	char err[256];
	int w, h, oy;
	struct image img = {0};
	if (image_exr_size(path, &w, &h, err, sizeof err) ||
	    image_read_exr_rows(path, h - 1, h - 1, &img, &oy, err, sizeof err))
		return 0;
	image_release(&img);
	return 1;
}

/* For a whole-frame render: note when its output was written (whole). */
static int note_written(void *arg, size_t index, const char *path)
{
	if (!output_whole(NULL, index, path))
		return 0;
	*(double *)arg = now_s();
	return 1;
}

/* ... and end it once POV-Ray has printed its render time: the statistics
 * the run needs come just after the image (not with radiosity, whose file
 * comes later: such a render ends at its exit). */
static int stats_printed(void *arg, size_t index, const char *log)
{
	(void)arg;
	(void)index;
	return pov_render_time_printed(log);
}

/* The pixels' errors (r->est, r->noise, the image's estimate in *est) from
 * the analysis res of r->acc, and how much of the fit the image written
 * takes per pixel. */
static int estimate(struct run *r, const struct lpr_result *res, double *est, char *err,
		    size_t errlen)
{
	if (plan_pixel_errors_threads(&r->acc, res->error, res->fit, r->est, r->noise, est, r->cores,
				      err, errlen))
		return -1;
	r->took = accum_final_choose(&r->acc, res->fit, res->error, res->leverage, r->noise,
				     r->final, r->take, NULL);
	return 0;
}

/* The analysis the planner and the final image use. */
static int analyse(struct run *r, struct lpr_result *res, char *err, size_t errlen)
{
	size_t npx = (size_t)r->w * r->h;
	float *rgb = malloc(npx * 3 * sizeof(float));
	if (!rgb) {
		errbuf_printf(err, errlen, "out of memory");
		return -1;
	}
	for (size_t i = 0; i < npx; i++) {
		const float *o = r->acc.px + i * ACC_NCH;
		for (int c = 0; c < 3; c++)
			rgb[3 * i + c] = o[ACC_SAMPLES] > 0.0f ? o[c] : NAN;
	}
	struct lpr_params p;
	lpr_params_init(&p);
	struct lpr_image li = { r->w, r->h, 3, rgb };
	char lerr[256];
	int rc = lpr_analyze(&li, NULL, &p, res, lerr, sizeof lerr);
	if (rc)
		errbuf_printf(err, errlen, "cannot analyse the image: %s", lerr);
	free(rgb);
	return rc;
}

/*
 * The final image into out->px: the samples' means blended with the fit
 * (accum_final_image()), and with filter (under --final auto) the blend
 * filtered by non-local means weighted by each pixel's noise (denoise.h).
 * With est (the blend's per-pixel relative errors, r->est) each filtered
 * pixel's estimate becomes the filter's: the blend's estimate less its
 * noise part u (at most all of it), plus the larger of the filtered noise
 * (sum w_q^2 V_q / (sum w_q)^2) and Stein's unbiased estimate of the
 * filtered value's squared error, (F - B)^2 - V + 2 V w_p / sum w_q (B the
 * blend, V its noise, per channel relative to B^2 + 0.01, mean over R, G,
 * B), which also charges what the filter moved the value beyond the noise.
 */
static int final_image(struct run *r, const struct lpr_result *res, int filter, double *est,
		       struct image *out, char *err, size_t errlen)
{
	static const char *const rgb_names[3] = { "R", "G", "B" };
	const size_t npx = (size_t)r->w * r->h;
	if (image_init(out, r->w, r->h, 3, rgb_names, err, errlen))
		return -1;
	accum_final_image(&r->acc, res->fit, r->take, out->px);
	if (!filter)
		return 0;
	/* the filtered noise and each pixel's own weight only for est */
	float *var = malloc(npx * 3 * sizeof(float)), *f = malloc(npx * 3 * sizeof(float));
	float *vf = est ? malloc(npx * 3 * sizeof(float)) : NULL;
	float *self = est ? malloc(npx * sizeof(float)) : NULL;
	int rc = -1;
	if (!var || !f || (est && (!vf || !self))) {
		errbuf_printf(err, errlen, "out of memory filtering the final image");
		goto out;
	}
	for (size_t i = 0; i < npx; i++) {
		double v[3];
		accum_noise_var(&r->acc, i, r->noise[i], v);
		for (int c = 0; c < 3; c++)
			var[3 * i + c] = (float)v[c];
	}
	struct denoise_params dp;
	denoise_params_init(&dp);
	dp.nthreads = r->cores;
	if (denoise_nlm(r->w, r->h, out->px, var, &dp, f, vf, self, err, errlen))
		goto out;
	for (size_t i = 0; est && i < npx; i++) {	/* est: the estimate follows */
		double u = 0.0, vn = 0.0, sure = 0.0;
		for (int c = 0; c < 3; c++) {
			double b = out->px[3 * i + c], s = b * b + METRICS_RELMSE_EPS;
			double d = (double)f[3 * i + c] - b, v = var[3 * i + c];
			u += v / s / 3.0;
			vn += vf[3 * i + c] / s / 3.0;
			sure += (d * d - v + 2.0 * v * self[i]) / s / 3.0;
		}
		double e = est[i] - (u < est[i] ? u : est[i]);
		est[i] = e + (sure > vn ? sure : vn);
	}
	memcpy(out->px, f, npx * 3 * sizeof(float));
	rc = 0;
out:
	free(var);
	free(f);
	free(vf);
	free(self);
	if (rc)
		image_release(out);
	return rc;
}

/*
 * OUT.exr: after each pass (so that it holds the best image so far,
 * whatever happens next) uncompressed, since the next pass or the end
 * rewrites it; the last one compressed (compress), and under a budget the
 * first too, whose time final_reserve() takes for the last's.  Uncompressed, the
 * in-between writes at 160x120 took 0.0008 CPU s against PIZ's 0.0105.
 */
static int write_output(struct run *r, const struct lpr_result *res, int filter, double *est,
			int compress, char *err, size_t errlen)
{
	struct image out = {0};
	if (final_image(r, res, filter, est, &out, err, errlen))
		return -1;
	int rc = compress ? image_write_exr(r->out, &out, err, errlen)
		      : image_write_exr_raw(r->out, &out, err, errlen);
	image_release(&out);
	return rc;
}

static int write_error_map(struct run *r, const struct lpr_result *res, char *err,
			   size_t errlen)
{
	static const char *const names[] = {
		"error", "relerror", "samples", "order", "bandwidth", "pass", "scales", "fit",
		"cost",
	};
	enum { NCH = sizeof names / sizeof names[0] };
	struct image m = {0};
	size_t npx = (size_t)r->w * r->h;
	const double *e = r->est;
	if (image_init(&m, r->w, r->h, NCH, names, err, errlen))
		return -1;
	for (size_t i = 0; i < npx; i++) {
		const float *o = r->acc.px + i * ACC_NCH;
		float *q = m.px + i * NCH;
		q[0] = (float)(e[i] * accum_error_scale(&r->acc, i, res->fit + 3 * i));
		q[1] = (float)e[i];
		q[2] = o[ACC_SAMPLES];
		q[3] = res->order[i];
		q[4] = res->bandwidth[i];
		q[5] = o[ACC_PASS];
		q[6] = o[ACC_SCALES];
		q[7] = r->take[i];
		q[8] = r->cost_map ? r->cost_map[i] : 1.0f;
	}
	int rc = image_write_exr(r->error_map, &m, err, errlen);
	image_release(&m);
	return rc;
}

static void json_str(FILE *f, const char *s)
{
	fputc('"', f);
	for (; *s; s++) {
		unsigned char c = (unsigned char)*s;
		if (c == '"' || c == '\\')
			fprintf(f, "\\%c", c);
		else if (c < 0x20)
			fprintf(f, "\\u%04x", c);
		else
			fputc(c, f);
	}
	fputc('"', f);
}

/* Whether --sampler auto goes by resolution scaling alone for the scene's
 * assumed_gamma (scene_assumed_gamma()). */
static int gamma_scaling(const struct run *r)
{
	return r->gamma > 0.0 && r->grid == PLAN_GRID_LARGE;
}

/* The PLAN_GRID_* mode the run goes by: --sampler's, PLAN_GRID_NEVER where
 * auto meets a scene's assumed_gamma (gamma_scaling()), or PLAN_GRID_ONLY
 * where it chose jitter (one_step()); the stored choice holds while
 * --sampler is auto (a resumed run may give another). */
static int run_grid(const struct run *r)
{
	if (gamma_scaling(r))
		return PLAN_GRID_NEVER;
	return r->jittered && r->grid == PLAN_GRID_LARGE ? PLAN_GRID_ONLY : r->grid;
}

/* The cost map's mean, for the report: 1 without a budget. */
static double cost_map_mean(const struct run *r)
{
	if (!r->cost_map)
		return 1.0;
	const size_t npx = (size_t)r->w * r->h;
	double sum = 0.0;
	for (size_t i = 0; i < npx; i++)
		sum += r->cost_map[i];
	return npx ? sum / (double)npx : 1.0;
}

static int write_report(struct run *r, double est, char *err, size_t errlen)
{
	char tmp[PATH_MAX + 16];
	FILE *f = file_begin(r->report, tmp, sizeof tmp, err, errlen);
	if (!f)
		return -1;
	double tw = 0, tc = 0, td = 0, ts = 0;
	long tp = 0;
	int ti = 0, tf = 0;
	fputs("{\n  \"scene\": ", f);
	json_str(f, r->scene);
	fprintf(f, ",\n  \"width\": %d,\n  \"height\": %d,\n  \"target\": %.6g,\n", r->w, r->h,
		r->target);
	fprintf(f, "  \"budget\": %.6g,\n  \"stop\": ", r->budget);
	json_str(f, r->stop ? r->stop : "");
	fprintf(f, ",\n  \"cost_model\": {\"job_s\": %.17g, \"sample_s\": %.17g, "
		"\"latency_s\": %.6g, \"scale\": %.4g, \"learnt\": %d},\n  \"radiosity\": %s,\n"
		"  \"radiosity_scale\": %d,\n  \"focal_blur\": %s,\n  \"assumed_gamma\": %g,\n"
		"  \"povwait\": %s,\n"
		"  \"sampler\": \"%s\",\n  \"sampler_chosen\": \"%s\",\n  \"prelaunch\": \"%s\",\n"
		"  \"final\": \"%s\",\n  \"passes\": [\n",
		r->cost_job, r->cost_sample, r->latency, cost_map_mean(r), r->cost_learnt,
		r->radiosity ? "true" : "false",
		r->rad_scale, r->focal ? "true" : "false", r->gamma > 0.0 ? r->gamma : 1.0,
		pov_wait_library() ? "true" : "false",
		r->aa ? "aa" : plan_grid_name(r->grid),
		r->aa ? "aa" : plan_grid_name(run_grid(r)),
		prelaunch_names[r->prelaunch],
		r->final == ACC_FINAL_AUTO && !r->filter ? "blend" : final_names[r->final]);
	for (size_t k = 0; k < r->npasses; k++) {
		const struct pass_rec *p = &r->passes[k];
		fprintf(f, "    {\"pass\": %d, \"wall_s\": %.3f, \"cpu_s\": %.3f, "
			"\"driver_cpu_s\": %.3f, \"invocations\": %d, \"regions\": %d, "
			"\"failed\": %d, \"pixels\": %ld, \"samples\": %.0f, "
			"\"est_relmse\": %.6g, ",
			p->pass, p->wall_s, p->cpu_s, p->driver_cpu_s, p->invocations, p->regions,
			p->failed, p->pixels, p->samples, p->est_relmse);
		if (isfinite(p->planned_relmse))
			fprintf(f, "\"planned_relmse\": %.6g, ", p->planned_relmse);
		else
			fputs("\"planned_relmse\": null, ", f);
		fprintf(f, "\"analysis_s\": %.3f, \"prelaunched\": %d, \"stopped\": %d, "
			"\"kept\": %ld}%s\n", p->analysis_s, p->prelaunched, p->stopped, p->kept,
			k + 1 < r->npasses ? "," : "");
		tw += p->wall_s;
		tc += p->cpu_s;
		td += p->driver_cpu_s;
		ti += p->invocations;
		tf += p->failed;
		tp += p->pixels;
		ts += p->samples;
	}
	fprintf(f, "  ],\n  \"totals\": {\"passes\": %zu, \"wall_s\": %.3f, \"cpu_s\": %.3f, "
		"\"driver_cpu_s\": %.3f, \"all_cpu_s\": %.3f, \"invocations\": %d, "
		"\"failed\": %d, \"pixels\": %ld, \"samples\": %.0f, "
		"\"samples_per_pixel\": %.4g, \"est_relmse\": %.6g, \"own_cpu_s\": %.3f, "
		"\"elapsed_s\": %.3f}\n}\n",
		r->npasses, tw, tc, td, tc + td, ti, tf, tp, ts, ts / ((double)r->w * r->h), est,
		self_cpu(), elapsed(r));
	return file_commit(f, tmp, r->report, err, errlen);
}

/* x rounded to the nearest anchor * 2^k (geometrically). */
static double quantise(double x, double anchor)
{
	return anchor * exp2(round(log2(x / anchor)));
}

/* Whether the radiosity pass at scale k was started early (r->pre). */
static int rad_prelaunched(const struct run *r, int k)
{
	return k >= 0 && k < 32 && (r->pre_rad >> k & 1u);
}

static const struct pov_define pass0 = { "POVPRESS_PASS", "0" };

/* whole_frame()'s job; extra has room for r->nextra + 1. */
static void frame_job(const struct run *r, int k, int threads, const char *out,
		      const char *radfile, struct pov_job *job, const char **extra)
{
	base_job(r, job, extra, threads);
	job->width = r->w * k;
	job->height = r->h * k;
	job->output = out;
	job->defines = &pass0;
	job->ndefines = 1;
	extra[job->nextra++] = "-A";
	job->radiosity = radfile;
	job->radiosity_mode = POV_RAD_SAVE;
}

/*
 * Render the whole frame at scale k (antialiasing off, POVPRESS_PASS=0) on
 * the given threads into out, saving the radiosity data to radfile: the
 * base pass and the radiosity pass.  what names it in messages; deadline is
 * seconds from now to stop POV-Ray at (0: none), a render stopped there an
 * error; with progress, POV-Ray's progress lines are kept in res.  Returns
 * 0, -1 on failure (err says why), POV_INTERRUPTED.
 */
static int whole_frame(struct run *r, int k, int threads, const char *out,
		       const char *radfile, const char *what, double deadline, int progress,
		       struct pov_result *res, char *err, size_t errlen)
{
	const char **extra = calloc(r->nextra + 8, sizeof(char *));
	if (!extra) {
		errbuf_printf(err, errlen, "out of memory");
		return -1;
	}
	struct pov_job job;
	frame_job(r, k, threads, out, radfile, &job, extra);
	job.progress = progress;
	struct pov_pool_opts po;
	pov_pool_opts_init(&po);
	po.max_jobs = 1;
	/* the radiosity pass, if it was started early at this scale (a pool
	 * given the early renders stops those it does not take: not the base
	 * pass's) */
	po.prelaunched = rad_prelaunched(r, k) ? r->pre : NULL;
	po.timeout_s = r->timeout > 0 ? r->timeout : 0.0;
	po.deadline_s = deadline;
	double written = 0.0;
	po.ready = note_written;
	po.ready_log = stats_printed;
	po.arg = &written;
	int rc = pov_pool_run(&job, 1, &po, res, err, errlen);
	/* how long POV-Ray took to exit after writing its image: region
	 * renders do not wait for that */
	r->tail = written > 0.0 ? now_s() - written : 0.0;
	free(extra);
	if (rc == POV_INTERRUPTED) {
		errbuf_printf(err, errlen, "interrupted during the %s", what);
		return POV_INTERRUPTED;
	}
	if (rc)
		return -1;
	if (res->status == POV_CANCELLED && deadline > 0.0) {
		/* how far it got, by its progress lines: the time the whole
		 * frame would take at its rate so far, for the user's next
		 * budget; none while POV-Ray still parsed or set up (Debian's
		 * camera/mesh_camera/meshcam_ortho_demo.pov under 8 s) */
		char far[160] = "";
		const struct pov_progress *last =
			res->nprogress ? &res->progress[res->nprogress - 1] : NULL;
		if (last && res->progress_total > 0 && last->done > 0 && last->t > 0.0) {
			const double f = (double)last->done / (double)res->progress_total;
			snprintf(far, sizeof far, " (it rendered %.0f%% of its pixels in %.1f s; "
				 "at that rate the frame alone takes about %.0f s)", 100.0 * f,
				 last->t, ceil(last->t / f));
		} else {
			snprintf(far, sizeof far, " (it rendered no pixel: POV-Ray was still "
				 "parsing or preparing the scene)");
		}
		errbuf_printf(err, errlen, "the %s of '%s' (%dx%d) did not finish within the "
			      "budget of %g s%s: there is no image to refine; give a larger "
			      "--budget or a smaller -W/-H", what, r->scene, r->w * k, r->h * k,
			      r->budget, far);
		return -1;
	}
	if (res->status != POV_OK) {
		errbuf_printf(err, errlen, "the %s of '%s' (%dx%d) failed: %s", what, r->scene,
			      r->w * k, r->h * k, res->message);
		return -1;
	}
	return 0;
}

/*
 * The frame POV-Ray computes the radiosity solution on.  Its pretrace
 * places samples by fractions of the frame, and on a small frame they are
 * too coarse: on scenes/radiosity_room.pov, a 640x480 render loading a
 * solution computed on a 160x120 frame has relMSE 2.3e-3, on 320x240
 * 1.3e-3, on 480x360 1.1e-3, on 640x480 1.0e-3, on 1280x960 0.9e-3
 * (scripts/radiosity_solution.sh).  So the solution comes from the whole
 * frame scaled by the smallest power of two that makes it at least 480
 * pixels wide, at most 4.
 *
 * Without a budget, by the smallest that makes it at least RAD_TARGET_WIDTH
 * wide, at most 4 and at most RAD_BIG_PIXELS: 4 at 160x120 as before, 4 at
 * 320x240 (2 before), 2 at 640x480 (1 before).  The solution's error is a
 * floor the region renders cannot take off, and a target run at those
 * sizes lasts long enough for POV-Ray to render its frame at that scale
 * whole: on radiosity_room at 320x240 the runs with 640x480's solution
 * stopped at relMSE 1.6e-3 to 8.8e-4 in 1.1 to 6.1 CPU s (--target 3e-3
 * to 1e-4), where POV-Ray's scale 4 has 5.0e-4 in 3.0 s; with 1280x960's
 * at 5.0e-4 to 4.1e-4 in 3.4 to 4.7 s; at 640x480 (--target 3e-3 and
 * 3e-4) 1.2e-3 and 9.5e-4 in 3.1 and 8.2 s became 7.3e-4 and 4.9e-4 in
 * 4.1 and 6.9 s, POV-Ray's scale 2 7.3e-4 in 3.6 s (against a render
 * of 3840x2880 on one thread, 2026-12-04; the README, *Scene
 * consistency*, says how uncertain such references are).
 * Under a budget radiosity_big() takes the larger frame where it fits, and
 * the smaller one stays the fallback.
 */
#define RAD_TARGET_WIDTH 1280
#define RAD_BIG_PIXELS (1280.0 * 960.0)	/* and as many pixels (a tall image) */
static int radiosity_scale(const struct run *r)
{
	if (r->user_rad_scale >= 0)
		return r->user_rad_scale;
	int k = 1;
	while (k < 4 && k * r->w < 480)
		k *= 2;
	while (r->budget <= 0.0 && k < 4 && k * r->w < RAD_TARGET_WIDTH &&
	       4.0 * k * k * r->w * r->h <= RAD_BIG_PIXELS)
		k *= 2;
	return k;
}

/*
 * Under a budget, the frame may be larger still: up to 1280 pixels wide
 * (8 at 160x120, 4 at 320x240, 2 at 640x480), taken by radiosity_pass()
 * when its one-thread pass fits the budget.  The solution is the error
 * region renders cannot remove, and the estimate does not see it: on
 * radiosity_room at 160x120 the solution from 1280x960 left relMSE 6.6e-4
 * under --budget 4 and 6.3e-4 under --budget 8 (2026-12-04),
 * where runs with the one from 640x480 stop at 7.7e-4 whatever the budget
 * (the sweep of 2026-12-04 01:33), and POV-Ray's scale 8 has 6.7e-4 in
 * 3.0 CPU s.  Returns 0 when there is no larger frame to take.
 */
#define RAD_BIG_WIDTH 1280	/* and at most RAD_BIG_PIXELS */
#define RAD_BIG_SCALE 8	/* and at most 8 times the image (the scales past
			 * it the loop renders at next: up to 16) */
/* The larger frame's pass is taken without RAD_MARGIN: on radiosity_room at
 * 160x120 under --budget 4 (eight runs, 2026-12-04) it was predicted at 2.8
 * to 2.9 s and took 2.6 to 2.8 s in the five that took it (relMSE 6.6e-4 to
 * 6.7e-4, the runs ending by 3.9 s); in the other three the base pass's
 * cost a sample, higher, predicted 4.2 to 4.4 s, and scale 4 ran (7.8e-4).
 * With the margin it would not fit --budget 4 at all. */
#define RAD_BIG_MARGIN 1.0
/* ... but where the base pass shot radiosity rays after its pretrace, the
 * price of the larger frame rests on plan_radiosity_trace()'s model, which
 * put its fits' scale 8 at 0.93 to 1.06 times the trace: Debian's
 * radiosity/radiosity2.pov at 160x120 under --budget 2 took the 1280x960
 * pass without a margin in one run of three and ended at 2.14 s. */
#define RAD_RAYS_MARGIN 1.15
static int radiosity_big(const struct run *r)
{
	if (r->budget <= 0.0 || r->user_rad_scale >= 0)
		return 0;
	const int k = radiosity_scale(r);
	int big = k;
	while (2 * big <= RAD_BIG_SCALE && 2 * big * r->w <= RAD_BIG_WIDTH &&
	       4.0 * big * big * r->w * r->h <= RAD_BIG_PIXELS)
		big *= 2;
	return big > k ? big : 0;
}

/* What the radiosity pass at scale k should take, wall seconds: by the
 * measured cost of a sample, not the plan's rounded one, which is up to
 * 1.4 times off either way (radiosity_room at 160x120, --budget 2: the
 * measurement 2.65e-6 s, rounded to 1.91e-6, predicted scale 4 to fit and
 * the run ended at 2.22 s).  The pass is not stopped at the budget's end:
 * stopped, it leaves only the base pass's image (1.05e-2 there against
 * scale 3's 1.63e-3).  Started afresh, scale 3 there ended the run at 1.91
 * to 2.20 s, and under a reserve for what follows it gave way to scale 2
 * (3.6e-3); started early (prelaunch_radiosity()), it waits only from its
 * gate, and ends the run at about 1.8 s with the reserve kept. */
#define RAD_MARGIN 1.2	/* radiosity_pass(): the prediction's margin */
/* A core's share of its time a whole-frame render on several has (Debian's
 * gamma/gamma_showcase.pov at 320x240: 3.0 s wall on one thread, 1.73 to
 * 1.83 s on two) */
#define RAD_CORE_SHARE 0.85
static double radiosity_time(const struct run *r, int k, int threads)
{
	/* a whole-frame render waits for POV-Ray's exit: the latency and the
	 * tail the region renders do not wait on; one started early (on one
	 * thread) waits only from its gate */
	const double lat = threads == 1 && rad_prelaunched(r, k) ? r->pre_latency : r->latency;
	/* its CPU before its exit: the pretrace, then the trace */
	const double work = r->pretrace_s + plan_radiosity_trace(r->cost_sample_measured,
								 (double)r->w * r->h, r->rad_rays, k);
	return lat + r->tail + (threads > 1 ? work / (RAD_CORE_SHARE * threads) : work);
}

/*
 * The radiosity pass, after a base pass that found radiosity: the whole
 * frame at scale k on one thread, antialiasing off, saving its radiosity
 * solution for the region renders.  Its k x k samples per pixel replace the base pass's
 * one (which was shaded with the coarser solution).  Returns 0 when done
 * or skipped (it would not end within the budget, or at scale 1 on one core
 * would repeat the base pass), -1 on failure,
 * POV_INTERRUPTED.
 */
static int radiosity_pass(struct run *r, int k, struct pass_rec *p, char *err, size_t errlen)
{
	/* under a budget, a solution on a smaller frame beats none: the region
	 * renders would load the base pass's (radiosity_room at 160x120,
	 * --budget 2: relMSE 3.6e-3 in 0.52 CPU s with scale 2's, 4.1e-3 to
	 * 6.1e-3 in 0.83 to 1.1 s with the base pass's); scale 4 gives way to
	 * 3 before 2 (POV-Ray's scale 3 alone had 1.6e-3 in 0.47 CPU s, where
	 * the pass at scale 2 left 3.6e-3); a --radiosity-scale stands */
	/* what follows the pass before the run can end: the analysis, the
	 * filter and the writes (0.05 to 0.07 s at 160x120 on radiosity_room,
	 * about 0.45 s at 640x480), with room to spare: the scale-3 pass
	 * predicted to end within --budget 2 with nothing after it ended its
	 * run at 2.13 to 2.20 s in one sweep's three runs */
	const double after = 0.1 + 2e-6 * (double)r->w * r->h;
	/* and the pass may take longer than predicted: started early at scale
	 * 4 there, predicted to end the run by 1.85 s, it ended it at 2.00 to
	 * 2.04 s (the larger solution's write is not in the prediction, nor
	 * was the radiosity pretrace then).  The margin guards the step from 4 to 3,
	 * whose image (1.63e-3 there) is a fair fallback, not the one from 3
	 * to 2: scale 2's (3.6e-3) is more than twice POV-Ray's own scale 3 at
	 * that CPU, and with the margin one run in six took it */
	const int big = radiosity_big(r);
	int took_big = 0;
	if (big > k) {
		const double tbig = radiosity_time(r, big, 1);
		const double m = r->rad_rays > 0.0 ? RAD_RAYS_MARGIN : RAD_BIG_MARGIN;
		if (elapsed(r) + m * tbig + after <= r->budget)
			k = big, took_big = 1;
		else if (r->verbose)
			fprintf(stderr, "povpress render: radiosity pass not at scale %d: it would "
				"take about %.1f s (pretrace %.2f s, %.3g s a sample, %.2g radiosity "
				"rays a pixel), and %.1f s are left\n", big, tbig, r->pretrace_s,
				r->cost_sample_measured, r->rad_rays, r->budget - elapsed(r) - after);
	}
	/* at scale 1 the pass repeats, on one thread, a base pass that ran on
	 * several; on one core it would repeat it exactly */
	if (!took_big && k == 1 && r->cores == 1)
		return 0;
	while (!took_big && r->budget > 0.0 && r->user_rad_scale < 0 && k > 2 &&
	       elapsed(r) + (k > 3 ? RAD_MARGIN : 1.0) * radiosity_time(r, k, 1) + after >
		       r->budget)
		k--;	/* radiosity_scale() chooses at most 4 */
	int threads = 1;
	double predicted = radiosity_time(r, k, 1);
	const double room = r->budget - elapsed(r) - after;
	if (r->budget > 0.0 && predicted > room && !took_big) {
		/* (the larger frame was found to fit on one thread a moment
		 * ago: never on every core) */
		/* on every core, when one would not do: the solution then
		 * differs from run to run (below), but no pass leaves the
		 * base pass's, computed on every core on the smallest frame
		 * (Debian's gamma/gamma_showcase.pov at 160x120: relMSE 0.091
		 * with it, 1.0e-3 with a solution on 320x240 on one thread
		 * (one run) or two (three)); not at scale 1, where that would
		 * be the base pass again */
		threads = r->cores > 1 && k > 1 ? r->cores : 1;
		predicted = radiosity_time(r, k, threads);
		if (threads == 1 || predicted > room) {
			if (r->verbose)
				fprintf(stderr, "povpress render: no radiosity pass: it would take "
					"about %.1f s, and %.1f s are left for it\n",
					predicted, room > 0.0 ? room : 0.0);
			return 0;
		}
	}
	char out[PATH_MAX], rad[PATH_MAX + 16];
	snprintf(out, sizeof out, "%s", wpath(r, "radiosity.exr"));
	snprintf(rad, sizeof rad, "%s/radiosity-new.rca", r->workdir);
	struct pov_result res = {0};
	struct image img = {0}, acc = {0};
	double t = now_s();
	progress(r, "radiosity pass: %dx%d (%d x %d samples per pixel) for the radiosity "
		 "solution%s, about %.1f s", r->w * k, r->h * k, k, k,
		 threads > 1 ? " on every core" : "", predicted);
	/* one thread but where that would not fit the budget: on several
	 * POV-Ray computes another solution every run, some much worse
	 * (radiosity_room at 640x480: relMSE 0.8e-3 to 2.6e-3 in three runs
	 * on two threads, 1.0e-3 on one; the same script) */
	int ret = whole_frame(r, k, threads, out, rad, "radiosity pass", 0.0, 0, &res, err,
			      errlen);
	if (ret)
		goto out;
	ret = -1;
	if (image_read_exr(out, &img, err, errlen) ||
	    image_init(&acc, r->w, r->h, ACC_NCH, accum_names, err, errlen))
		goto out;
	/* a fresh accumulation that counts the scales below k as done: the
	 * next samples come at the next power of two past k, at positions none
	 * of these has (scale 3's are at 1/6, 1/2 and 5/6 of a pixel) */
	uint32_t below = 0;
	for (int s = 1; s < k; s *= 2)
		below |= 1u << s;
	for (size_t i = 0; i < (size_t)r->w * r->h; i++) {
		acc.px[i * ACC_NCH + ACC_SCALES] = (float)below;
		acc.px[i * ACC_NCH + ACC_DIFF] = NAN;
	}
	long folded = 0;
	if (accum_merge_region(&acc, &img, 0, k, 0, 0, r->w - 1, r->h - 1, 0, &folded, err,
			       errlen) ||
	    accum_split_diff(&acc, &img, k, err, errlen))
		goto out;
	if (rename(rad, r->radfile)) {
		errbuf_printf(err, errlen, "cannot rename '%s' to '%s': %s", rad, r->radfile,
			      strerror(errno));
		goto out;
	}
	image_release(&r->acc);
	r->acc = acc;
	memset(&acc, 0, sizeof acc);
	r->rad_scale = k;
	p->wall_s += now_s() - t;
	p->cpu_s += res.cpu_s;
	p->invocations += res.attempts;
	p->regions++;
	p->samples += (double)folded * k * k;
	ret = 0;
out:
	image_release(&acc);
	image_release(&img);
	unlink(out);
	unlink(rad);	/* renamed to r->radfile when the pass succeeded */
	pov_result_release(&res);
	return ret;
}

/*
 * --prelaunch.  POV-Ray waits about 0.3 s on itself before it reads the
 * scene (povray.h, pov_prelaunch_start()), and every region render of a
 * pass with it.  A pass's renders can be started before its plan exists,
 * during the pass before (the base pass for the first), if they are
 * guessed: bands of whole rows of one kind of render (a scale and whether
 * it is a grid render, or POV-Ray's antialiasing in scale 2's place), each
 * waiting at its gate.  A pass takes the bands of its main kind (the most
 * pixels) that its regions of that kind touch, when they cost at most half
 * a latency on the cores more than those regions (prelaunch_cover()), and
 * leaves its other regions to the next pass; the rest are stopped, having
 * used about 0.01 CPU s each.  The first pass's guesses: each kind the
 * sampler allows (scale 2 over the frame where samples are dear; scale 4 as
 * a grid render where --sampler auto goes straight to it; antialiasing
 * where the error sits in few pixels), in min(cores, jobs) bands; a later
 * pass's: the next scale of the pass before's main kind, in twice as many.
 */

/* Whether POV-Ray option a, one of the user's, may set what switch sw
 * (+sw or -sw, its start) or INI key `key` sets: it is the switch, holds
 * the key, or is an INI file, which may hold it. */
static int user_sets(const char *a, const char *sw, const char *key)
{
	const size_t n = strlen(a), ns = strlen(sw), nk = strlen(key);
	if ((a[0] == '+' || a[0] == '-') && !strncasecmp(a + 1, sw, ns))
		return 1;
	for (size_t i = 0; i + nk <= n; i++)
		if (!strncasecmp(a + i, key, nk))
			return 1;
	return n > 4 && !strcasecmp(a + n - 4, ".ini");
}
static int is_user_header(const char *a)
{
	return user_sets(a, "hi", "include_header");
}

struct pre_kind {
	int scale, frame, depth, edges;
};

/* Whether region g is of kind k (frame 0 or ACC_GRID_FRAME alike; an
 * antialiased render of the same depth, and for edges or not alike). */
static int of_kind(const struct plan_region *g, struct pre_kind k)
{
	return g->scale == k.scale && (g->frame > 0) == (k.frame > 0) && g->depth == k.depth &&
	       g->edges == k.edges;
}

/* The kind of plan pl's regions with the most pixels, their pixels in
 * *area (0 when pl has none), their predicted cost in *cost and their
 * count in *n. */
static struct pre_kind main_kind(const struct plan *pl, long *area, double *cost, int *n)
{
	struct pre_kind best = { 0, 0, 0, 0 };
	*area = 0;
	*cost = 0.0;
	*n = 0;
	for (size_t k = 0; k < pl->nregions; k++) {
		struct pre_kind kind = { pl->regions[k].scale, pl->regions[k].frame,
					 pl->regions[k].depth, pl->regions[k].edges };
		long a = 0;
		double c = 0.0;
		int m = 0;
		for (size_t j = 0; j < pl->nregions; j++) {
			const struct plan_region *g = &pl->regions[j];
			if (!of_kind(g, kind))
				continue;
			a += plan_region_area(g);
			c += g->cost;
			m++;
		}
		if (a > *area) {
			best = kind;
			*area = a;
			*cost = c;
			*n = m;
		}
	}
	return best;
}

/* Whether renders may be started early now, budget or not: --prelaunch on,
 * or auto without povwait.so (which cuts the wait they save: with it, at
 * --budget 2, 4 and 8 the nine scenes' relMSE was as low or lower without
 * them in 32 of 36 runs by turns, README), none running, and no header of
 * the user's (or an INI file that may set one), whose place the gate would
 * take. */
static int may_prelaunch_any(const struct run *r)
{
	if (r->prelaunch == PRE_OFF || (r->prelaunch == PRE_AUTO && pov_wait_library()) ||
	    r->pre)
		return 0;
	for (size_t k = 0; k < r->nextra; k++)
		if (is_user_header(r->extra[k]))
			return 0;
	return 1;
}

/* The same for guessed region renders: --prelaunch on, or auto under a
 * budget (a guess not taken costs its start-up). */
static int may_prelaunch(const struct run *r)
{
	if (r->prelaunch == PRE_AUTO && !(r->budget > 0.0))
		return 0;
	return may_prelaunch_any(r);
}

/* Start nb bands of each of the nk kinds for pass `pass` (r->pre). */
static void prelaunch_start(struct run *r, int pass, const struct pre_kind *kinds, int nk, int nb)
{
	if (!may_prelaunch(r) || nk < 1)
		return;
	if (nk > PRE_KINDS)
		nk = PRE_KINDS;
	if (nb > r->jobs)
		nb = r->jobs;
	if (nb > PRE_BANDS)
		nb = PRE_BANDS;
	if (nb > r->h)
		nb = r->h;
	if (nb < 1)
		nb = 1;
	struct pov_job jobs[PRE_MAX];
	struct pov_region regs[PRE_MAX];
	char outs[PRE_MAX][PATH_MAX];
	const char **extras = calloc((size_t)PRE_MAX * (r->nextra + 4) + r->nextra + 4,
				     sizeof(char *));
	if (!extras)
		return;
	const char **bextra = extras + (size_t)PRE_MAX * (r->nextra + 4);
	struct pov_job base;
	char passno[16];
	struct pov_define pd;
	pass_job(r, pass, &base, bextra, passno, &pd);
	size_t n = 0;
	for (int t = 0; t < nk; t++) {
		for (int b = 0; b < nb; b++) {
			struct plan_region *g = &r->pre_reg[n];
			memset(g, 0, sizeof(*g));
			g->x0 = 0;
			g->x1 = r->w - 1;
			g->y0 = (int)((long)b * r->h / nb);
			g->y1 = (int)((long)(b + 1) * r->h / nb) - 1;
			g->scale = kinds[t].scale;
			g->frame = kinds[t].frame;
			g->depth = kinds[t].depth;
			g->edges = kinds[t].edges;
			plan_output_name(outs[n], sizeof outs[n], r->workdir, pass, n, g->scale);
			plan_job(&base, g, outs[n], &regs[n], extras + n * (r->nextra + 4), &jobs[n]);
			n++;
		}
	}
	char err[512];
	if (pov_prelaunch_start(jobs, n, r->povdir, &r->pre, err, sizeof err) == 0) {
		r->npre = n;
		r->pre_pass = pass;
	} else if (r->verbose) {
		fprintf(stderr, "povpress render: no renders started early: %s\n", err);
	}
	free(extras);
}

/*
 * For a scene whose file mentions radiosity: the radiosity pass started
 * during the base pass, waiting at its gate, at each scale it may take
 * (radiosity_scale()'s, and under a budget radiosity_big()'s and the
 * smaller ones down to 2 that radiosity_pass() may fall back to;
 * --radiosity-scale's alone).  The pass
 * then begins from the gate, not from POV-Ray's start-up: on
 * radiosity_room at 160x120 under --budget 2 the run's scale-3 pass ended
 * its run at 1.92 to 2.20 s when it started afresh (see the README).  The
 * renders not taken are stopped after the radiosity pass (base_pass()).
 */
static void prelaunch_radiosity(struct run *r)
{
	const int top = radiosity_scale(r);
	/* without a budget too: the one scale it renders at is taken whenever
	 * the scene has radiosity, and saves POV-Ray's start-up wait
	 * (radiosity_room at 160x120, --target 3e-3: 1.99 to 2.15 s wall
	 * against 2.23 to 2.34 s with --prelaunch off, the same image) */
	const int big = radiosity_big(r);
	if (!may_prelaunch_any(r) || (top < 2 && big < 2))
		return;
	const int low = r->user_rad_scale < 0 && r->budget > 0.0 ? 2 : top;
	enum { NRAD = 4 };
	struct pov_job jobs[NRAD];
	const size_t ne = r->nextra + 1;	/* frame_job() adds one */
	const char **extras = calloc(NRAD * ne, sizeof(char *));
	char out[PATH_MAX], rad[PATH_MAX + 16];
	snprintf(out, sizeof out, "%s", wpath(r, "radiosity.exr"));
	snprintf(rad, sizeof rad, "%s/radiosity-new.rca", r->workdir);
	unsigned mask = 0;
	size_t n = 0;
	if (extras && big > top) {
		frame_job(r, big, 1, out, rad, &jobs[n], extras + n * ne);
		mask |= 1u << big;
		n++;
	}
	for (int k = top; extras && k >= low && n < NRAD; k--, n++) {
		frame_job(r, k, 1, out, rad, &jobs[n], extras + n * ne);
		mask |= 1u << k;
	}
	char err[512];
	if (n && pov_prelaunch_start(jobs, n, r->povdir, &r->pre, err, sizeof err) == 0)
		r->pre_rad = mask;
	else if (n && r->verbose)
		fprintf(stderr, "povpress render: no radiosity pass started early: %s\n", err);
	free(extras);
}

/* The first pass's guesses, started with the base pass: none for a scene
 * with radiosity, whose region renders load the solution the radiosity pass
 * saves (the early ones could not; stopped, they would only have slowed
 * the base pass), but its radiosity pass. */
static void prelaunch_first(struct run *r)
{
	if (r->rad_named) {
		prelaunch_radiosity(r);
		return;
	}
	struct pre_kind kinds[PRE_KINDS];
	int nk = 0;
	if (r->grid != PLAN_GRID_ONLY)
		kinds[nk++] = (struct pre_kind){ 2, 0, 0, 0 };
	if (run_grid(r) != PLAN_GRID_NEVER && !r->focal)	/* one_step()'s jitter */
		kinds[nk++] = (struct pre_kind){ 4, ACC_GRID_FRAME, 0, 0 };
	if (run_grid(r) == PLAN_GRID_LARGE && !r->aa)	/* a few pixels' (of_kind()) */
		kinds[nk++] = (struct pre_kind){ ACC_AA, ACC_GRID_FRAME, ACC_AA_DEPTH, 0 };
	prelaunch_start(r, 1, kinds, nk, r->cores);
}

/* The next pass's guess from this pass's plan pl (pp its parameters): the
 * scale after its main kind's. */
static void prelaunch_next(struct run *r, int pass, const struct plan *pl,
			   const struct plan_params *pp)
{
	long best_area;
	double best_cost;
	int nbest;
	struct pre_kind best = main_kind(pl, &best_area, &best_cost, &nbest);
	int s = best.scale == ACC_AA ? 4 : 2 * best.scale;
	if (!best_area || s > accum_scales[ACC_NSCALES - 1])
		return;
	struct plan_params next = *pp;
	next.grid = run_grid(r);
	const int frame = plan_grid_scale(&next, r->w, r->h, s) ? ACC_GRID_FRAME : 0;
	struct pre_kind kind = { s, frame, 0, 0 };
	if (!kind.frame && (double)s * s * r->w * r->h > PLAN_MAX_FRAME)
		return;	/* a frame no region render gets */
	prelaunch_start(r, pass, &kind, 1, 2 * r->cores);
}

/* Stop the early renders none took; returns the CPU seconds they used. */
static double prelaunch_end(struct run *r)
{
	double cpu = pov_prelaunch_end(r->pre);
	r->pre = NULL;
	r->npre = 0;
	r->pre_rad = 0;
	return cpu;
}

/*
 * Whether plan pl of pass `pass` takes early renders: its main kind of
 * region is one of them, and the bands of that kind its regions touch cost
 * at most half a latency on the cores more than those regions (a pixel
 * costing what it costs in them).  Then pl's regions become those bands,
 * each with its index in r->pre_reg in idx[], and the count is returned;
 * else 0 and pl is unchanged.
 */
static size_t prelaunch_cover(struct run *r, int pass, struct plan *pl, size_t **idx)
{
	*idx = NULL;
	if (!r->pre || r->pre_pass != pass || !pl->nregions)
		return 0;
	long area;
	double cost;
	int nk;
	const struct pre_kind K = main_kind(pl, &area, &cost, &nk);
	const double job = r->cost_job;	/* as the plan costs it */
	double per_px = (cost - nk * job) / (double)area;
	if (per_px < 0.0)
		per_px = 0.0;
	size_t *sel = malloc(r->npre * sizeof(*sel));
	struct plan_region *regs = malloc(r->npre * sizeof(*regs));
	if (!sel || !regs) {
		free(sel);
		free(regs);
		return 0;
	}
	size_t m = 0;
	long px = 0;
	for (size_t b = 0; b < r->npre; b++) {
		const struct plan_region *band = &r->pre_reg[b];
		if (!of_kind(band, K))
			continue;
		int touched = 0;
		for (size_t k = 0; k < pl->nregions && !touched; k++) {
			const struct plan_region *g = &pl->regions[k];
			touched = of_kind(g, K) && g->y1 >= band->y0 && g->y0 <= band->y1;
		}
		if (!touched)
			continue;
		long a = plan_region_area(band);
		sel[m] = b;
		regs[m] = *band;
		regs[m].cost = job + per_px * (double)a;
		px += a;
		m++;
	}
	double cover = (double)m * job + per_px * (double)px;
	if (!m || cover > cost + 0.5 * r->latency * r->cores) {
		free(sel);
		free(regs);
		return 0;
	}
	free(pl->regions);
	pl->regions = regs;
	pl->nregions = m;
	pl->pixels = px;
	const int f = K.scale == ACC_AA ? ACC_GRID_FRAME : K.scale;
	pl->samples = (double)px * f * f;
	pl->cost = cover;
	*idx = sel;
	return m;
}

/*
 * Under a budget, the cost map's start (1 everywhere until now, the base
 * pass being one render) from the base pass's progress lines: POV-Ray
 * renders a frame in blocks of POV_BLOCK x POV_BLOCK pixels handed to its
 * threads row by row from the top, and prints "Rendered N of M pixels" as
 * each ends; its frontend passes the lines on in batches, and the pool
 * keeps each read's count and time (res->progress).  A block's cost is the
 * time the count took to pass over its pixels (interpolated between the
 * reads), smoothed over BLOCK_SMOOTH blocks either side in that order (a
 * block ends out of order by up to the threads' count), over the frame's
 * mean; the blocks before the first read take the first measured one's.
 * Where the base pass printed no lines (map_wanted(); --cost-sample: a
 * plan that timing does not move), the reads' steps are not mostly whole
 * blocks, or there are fewer than MAP_MIN_READS reads (glossy_reflection
 * at 320x240: 17), the map stays 1.  Debian's textures/finishes/var_refl at
 * 640x480 (`povray +W640 +H480 -A +WT2`, its lines timed as read): the
 * upper half's 153,600 pixels in 0.04 s, the lower half's in 0.15 s; at
 * twice the size on one thread (+SR/+ER halves) 0.38 and 1.16 CPU s.  The
 * map priced both halves at the mean, and pass 1's renders of the lower
 * half ran into the deadline.
 */
#define POV_BLOCK 32
#define MAP_MIN_READS 16
#define BLOCK_SMOOTH 2
#define COST_MIN 0.02
#define COST_MAX 50.0
/* Whether a run's base pass should print its progress lines for
 * base_cost_map(): under a budget, the cost of a sample measured, a frame
 * of blocks enough for MAP_MIN_READS reads of them (at 160x120, 20 blocks,
 * glossy_reflection's came in 8 reads; elsewhere the lines would only cost
 * POV-Ray's frontend their printing), the blocks' size and order
 * POV-Ray's defaults (not +BS, +RP or +RS, the block step, of the user's). */
static int map_wanted(const struct run *r)
{
	const long blocks = (long)((r->w + POV_BLOCK - 1) / POV_BLOCK) *
			    ((r->h + POV_BLOCK - 1) / POV_BLOCK);
	if (!r->cost_map || r->user_cost_sample > 0.0 || blocks < 4 * MAP_MIN_READS)
		return 0;
	for (size_t k = 0; k < r->nextra; k++)
		if (user_sets(r->extra[k], "bs", "render_block_size") ||
		    user_sets(r->extra[k], "rp", "render_pattern") ||
		    user_sets(r->extra[k], "rs", "render_block_step"))
			return 0;
	return 1;
}

static int base_cost_map(struct run *r, const struct pov_result *res)
{
	const struct pov_progress *pg = res->progress;
	const size_t np = res->nprogress;
	const long all = (long)r->w * r->h;
	if (!map_wanted(r) || np < MAP_MIN_READS || res->progress_total != all)
		return 0;
	/* the reads' steps mostly whole blocks (a last row's are not) */
	long full = 0;
	for (size_t i = 1; i < np; i++)
		if ((pg[i].done - pg[i - 1].done) % ((long)POV_BLOCK * POV_BLOCK) == 0)
			full++;
	if (full < (long)(np / 2))
		return 0;
	const int bw = (r->w + POV_BLOCK - 1) / POV_BLOCK, bh = (r->h + POV_BLOCK - 1) / POV_BLOCK;
	const int nb = bw * bh;
	double *rate = calloc((size_t)nb, sizeof(*rate)), *sm = calloc((size_t)nb, sizeof(*sm));
	long *npx = calloc((size_t)nb, sizeof(*npx));
	if (!rate || !sm || !npx) {
		free(rate);
		free(sm);
		free(npx);
		return 0;
	}
	/* the time at which the count passed p: the lines interpolated,
	 * before the first line the first's */
	size_t at = 0;
	long before = 0;
	int first = -1;
	for (int b = 0; b < nb; b++) {
		const int bx = b % bw, by = b / bw;
		const int wx = (bx + 1) * POV_BLOCK > r->w ? r->w - bx * POV_BLOCK : POV_BLOCK;
		const int wy = (by + 1) * POV_BLOCK > r->h ? r->h - by * POV_BLOCK : POV_BLOCK;
		npx[b] = (long)wx * wy;
		const long p0 = before, p1 = before + npx[b];
		before = p1;
		if (p0 < pg[0].done)
			continue;	/* before the first line */
		double tt[2];
		const long pp[2] = { p0, p1 };
		for (int e = 0; e < 2; e++) {
			while (at + 1 < np && pg[at + 1].done < pp[e])
				at++;
			if (at + 1 >= np) {
				tt[e] = pg[np - 1].t;
			} else {
				const double f = (double)(pp[e] - pg[at].done) /
						 (double)(pg[at + 1].done - pg[at].done);
				tt[e] = pg[at].t + (f < 0.0 ? 0.0 : f > 1.0 ? 1.0 : f) *
							   (pg[at + 1].t - pg[at].t);
			}
		}
		rate[b] = (tt[1] - tt[0]) / (double)npx[b];
		if (first < 0)
			first = b;
	}
	double sum = 0.0;
	if (first >= 0) {
		for (int b = 0; b < first; b++)
			rate[b] = rate[first];
		for (int b = 0; b < nb; b++) {
			double s = 0.0, wsum = 0.0;
			for (int d = -BLOCK_SMOOTH; d <= BLOCK_SMOOTH; d++)
				if (b + d >= 0 && b + d < nb) {
					s += rate[b + d] * (double)npx[b + d];
					wsum += (double)npx[b + d];
				}
			sm[b] = s / wsum;
			sum += sm[b] * (double)npx[b];
		}
	}
	const double mean = sum / (double)all;
	const int ok = first >= 0 && mean > 0.0;
	for (int y = 0; ok && y < r->h; y++)
		for (int x = 0; x < r->w; x++) {
			const double v = sm[(y / POV_BLOCK) * bw + x / POV_BLOCK] / mean;
			r->cost_map[(size_t)y * r->w + x] =
				(float)(v < COST_MIN ? COST_MIN : v > COST_MAX ? COST_MAX : v);
		}
	free(rate);
	free(sm);
	free(npx);
	return ok;
}

/* The base pass: the whole image, one sample per pixel. */
static int base_pass(struct run *r, char *err, size_t errlen)
{
	char out[PATH_MAX];
	snprintf(out, sizeof out, "%s", wpath(r, "base.exr"));
	struct pov_result res = {0};
	double t = now_s(), c = self_cpu();
	progress(r, "base pass: %dx%d, 1 sample per pixel", r->w, r->h);
	if (gamma_scaling(r) && r->verbose)
		fprintf(stderr, "povpress render: the scene's assumed_gamma is %g, in whose encoding "
				"POV-Ray's antialiasing averages: resolution scaling only\n",
			r->gamma);
	prelaunch_first(r);
	/* one sample at each pixel centre; radiosity, if the scene has any, is
	 * saved for the region renders */
	/* Under a budget the base pass is stopped at its end: POV-Ray writes no
	 * image when stopped, and with no base pass there is nothing to refine
	 * (a scene whose base pass takes minutes, given --budget 20, would
	 * otherwise run for minutes) */
	int ret = whole_frame(r, 1, r->cores, out, r->radfile, "base pass", deadline_in(r, 0.0),
			      map_wanted(r),
			      &res, err, errlen);
	if (ret)
		goto out;
	ret = -1;
	struct image img = {0};
	const double tr = now_s();
	if (image_read_exr(out, &img, err, errlen))
		goto out;
	int rc = accum_from_base(&img, out, &r->acc, err, errlen);
	image_release(&img);
	if (rc)
		goto out;
	r->read_s = now_s() - tr;
	/* the cost model */
	const struct pov_stats *st = &res.stats;
	double trace = (st->have & POV_HAVE_TRACE) ? st->trace.cpu_s : res.cpu_s;
	/* camera samples: POV-Ray's "Rays" line counts reflected rays too,
	 * and its "Pixels" line the radiosity pretrace's pixels, whose time
	 * is the radiosity time's, not the trace's: the trace's samples are
	 * the frame's (Debian's gamma/gamma_showcase.pov at 160x120 counts
	 * 29809 pixels; so costed, its radiosity pass at scale 2 was
	 * predicted at 1.2 s and took 2.7 s on one thread) */
	const double rays = st->pixels > 0 && !(st->have & POV_HAVE_RADIOSITY) ?
				    (double)(st->pixels + st->samples) :
				    (double)r->w * r->h;
	r->cost_sample = trace / rays;
	if (base_cost_map(r, &res) && r->verbose) {
		float lo = INFINITY, hi = 0.0f;
		for (size_t i = 0; i < (size_t)r->w * r->h; i++) {
			lo = r->cost_map[i] < lo ? r->cost_map[i] : lo;
			hi = r->cost_map[i] > hi ? r->cost_map[i] : hi;
		}
		progress(r, "base pass: a sample's cost from its progress lines (over %.2f s), "
			 "%.2g to %.2g times the frame's mean",
			 res.progress[res.nprogress - 1].t - res.progress[0].t, lo, hi);
	}
	/* the pretrace, which the radiosity pass repeats on one thread */
	r->pretrace_s = (st->have & POV_HAVE_RADIOSITY) ? st->radiosity.cpu_s : 0.0;
	r->rad_rays = (st->have & POV_HAVE_RADIOSITY) && (st->have & POV_HAVE_RAD_RAYS) ?
			      (double)st->rad_final_rays / ((double)r->w * r->h) : 0.0;
	if (!(r->cost_sample > 1e-9))
		r->cost_sample = 1e-9;
	double setup = res.cpu_s - trace;
	r->latency = res.wall_s - ((st->have & POV_HAVE_TRACE) ? st->trace.wall_s : 0.0) -
		     ((st->have & POV_HAVE_PARSE) ? st->parse.wall_s : 0.0) -
		     ((st->have & POV_HAVE_RADIOSITY) ? st->radiosity.wall_s : 0.0);
	/* a region render's: the pool takes its image without waiting for
	 * POV-Ray's exit (output_whole()) */
	r->latency -= r->tail;
	if (r->latency < 0.0)
		r->latency = 0.0;
	r->radiosity = (st->have & POV_HAVE_RADIOSITY) != 0;
	/* Without a budget the plan depends on these only through their
	 * sizes, and timing noise must not change it from run to run (--jobs
	 * 1 -- +WT1 is meant to be reproducible): the per-sample and setup
	 * costs are rounded to powers of two.  Under a budget the plan spends
	 * measured time anyway, and the rounding's step of two changed plans
	 * on a measurement near a step's middle: Debian's var_refl at 640x480
	 * under --budget 3 measured 1.91e-6 s a sample rounded, not 9.54e-7,
	 * found POV-Ray's antialiasing too dear and ended at an estimated
	 * 2.6e-3, not 9.6e-4; granite's 0.125 s an invocation, not 0.0625,
	 * left a quarter of its frame at scale 2 (2026-12-05). */
	r->cost_sample_measured = r->cost_sample;
	if (r->budget <= 0.0)
		r->cost_sample = quantise(r->cost_sample, 1.0);
	/* a region render repeats the setup (parse, bounding, writing its
	 * frame): that is its cost.  It also waits on POV-Ray's latency, but
	 * asleep, and a pass whose regions all run at once (no more than
	 * --jobs) waits on it once whatever their number. */
	r->cost_job = setup <= 0.01 ? 0.01 : r->budget > 0.0 ? setup : quantise(setup, 1.0);
	if (r->user_cost_job > 0.0)
		r->cost_job = r->user_cost_job;
	if (r->user_cost_sample > 0.0) {	/* the cost of a sample at every scale */
		r->cost_sample = r->cost_sample_measured = r->user_cost_sample;
		r->rad_rays = 0.0;
	}
	struct pass_rec p = { .planned_relmse = NAN };
	p.pass = 0;
	p.wall_s = now_s() - t;
	p.cpu_s = res.cpu_s;
	p.invocations = res.attempts;
	p.regions = 1;
	p.pixels = (long)r->w * r->h;
	p.samples = (double)r->w * r->h;
	p.est_relmse = NAN;	/* filled in by the first analysis */
	/* early region renders would not load the solution; an early
	 * radiosity pass serves only a scene that has radiosity */
	if (r->radiosity != (r->pre_rad != 0))
		p.cpu_s += prelaunch_end(r);
	int k = r->radiosity ? radiosity_scale(r) : 0, rrc = 0;
	if (k)
		rrc = radiosity_pass(r, k, &p, err, errlen);
	if (r->pre_rad) {	/* the scales not taken stop */
		p.prelaunched = (int)pov_prelaunch_taken(r->pre);
		if (r->verbose)
			fprintf(stderr, "povpress render: the radiosity pass %s\n",
				p.prelaunched ? "was started early" : "took no render started early");
		p.cpu_s += prelaunch_end(r);
	}
	if (rrc == POV_INTERRUPTED || rrc < 0) {
		ret = rrc;
		goto out;
	}
	p.driver_cpu_s = self_cpu() - c;
	if (add_pass(r, &p)) {
		errbuf_printf(err, errlen, "out of memory");
		goto out;
	}
	if (r->verbose)
		fprintf(stderr, "povpress render: base pass %.2f s wall, %.2f s CPU; cost model: "
			"%.3g s per sample, %.3g s per invocation (latency %.2f s%s)%s\n",
			p.wall_s, p.cpu_s, r->cost_sample, r->cost_job, r->latency,
			pov_wait_library() ? ", waits cut by povwait.so" : "",
			r->radiosity ? "; radiosity saved for the region renders" : "");
	ret = 0;
out:
	pov_result_release(&res);
	return ret;
}

/* Pixels of region g that have had no antialiased render. */
static long lacking_aa(const struct run *r, const struct plan_region *g)
{
	long n = 0;
	for (int y = g->y0; y <= g->y1; y++)
		for (int x = g->x0; x <= g->x1; x++)
			n += !accum_has_scale(&r->acc, (size_t)y * r->w + x, ACC_AA);
	return n;
}

/* Whether plan pl has a region of scale 2. */
static int has_scale2(const struct plan *pl)
{
	for (size_t k = 0; k < pl->nregions; k++)
		if (pl->regions[k].scale == 2)
			return 1;
	return 0;
}

/* Whether the pixels' estimated error sits in a few pixels or, after the
 * base pass of a scene with neither radiosity (whose error is its
 * solution's) nor focal blur (where antialiasing's samples are worth a
 * quarter of scaling's), at edges (plan_error_where()).  A pass may ask
 * three times (one_step(), edge_target(), choose_samplers()): a sort of
 * w*h values, so kept in *memo (-1 until asked) for the pass: SPARSE_FEW,
 * SPARSE_EDGES (at edges and not in a few pixels: the pass's antialiased
 * renders are folded as taken for edges, accum_merge_aa_file()) or 0. */
enum { SPARSE_FEW = 1, SPARSE_EDGES = 2 };
static int sparse_error(const struct run *r, int *memo)
{
	if (*memo < 0) {
		const unsigned where = plan_error_where(r->est, (size_t)r->w * r->h);
		*memo = where & PLAN_ERROR_FEW ? SPARSE_FEW
			: r->npasses == 1 && !r->radiosity && !r->focal && (where & PLAN_ERROR_EDGES)
			? SPARSE_EDGES : 0;
	}
	return *memo;
}

/* pl's antialiased regions after the others, each part in its order: they
 * are folded last (choose_samplers()). */
static void aa_last(struct plan *pl)
{
	size_t m = 0;
	for (size_t k = 0; k < pl->nregions; k++) {
		struct plan_region g = pl->regions[k];
		if (g.scale == ACC_AA)
			continue;
		memmove(pl->regions + m + 1, pl->regions + m, (k - m) * sizeof(g));
		pl->regions[m++] = g;
	}
}

/*
 * The sampler of each region of a plan.  With --sampler auto, where the
 * error sits in a few pixels or at edges (sparse_error()), the regions of scale 2 are
 * rendered once at twice the image's size with POV-Ray's antialiasing,
 * +AM2 +A0.1 +J, +R5 in few pixels and +R4 at edges (frame ACC_GRID_FRAME;
 * less under a budget it would not fit, aa_depth(); ACC_AA_FIRST for how
 * they are folded, at edges ACC_AA_EDGE): it subdivides only where corners
 * differ, down to 1/32 of a pixel at a
 * highlight, where scale 2 gives every pixel of the rectangles 4 samples;
 * at twice the size its corners are scale 2's density where it does not
 * (at the image's size, stars between corners went unseen: a pixel's base
 * sample and render agreed on black, its estimate was 0).  hdr_highlights
 * at 160x120 and target 3e-3: relMSE 1.7e-3 in 1.0 CPU s with scale 2,
 * 3.1e-4 in 2.2 s so, where POV-Ray's own best at 2 CPU s has 4.7e-4; on the
 * scenes whose error is spread, rendering every scale-2 region so did not
 * help and under a 2 s budget was 15 to 22 times worse (see the README).
 * Fine regions (scale 8 or 16: their pixels have 21 samples or more) get
 * resolution scaling, or with --sampler aa POV-Ray's
 * own antialiasing (ACC_AA) for the regions most of whose pixels have had
 * none (once per pixel: its jitter pattern is the same every run).  The
 * antialiased regions go last, keeping their order, so that they are folded
 * after the scaled ones (their weight is measured against the means with
 * this pass's scaled samples), in render as in regions.tsv for merge.
 * Returns how many regions take scale 2's place.
 */
static size_t choose_samplers(const struct run *r, struct plan *pl, int *sparse)
{
	const int first = run_grid(r) == PLAN_GRID_LARGE && has_scale2(pl) &&
			  sparse_error(r, sparse);
	if (!first && !r->aa)
		return 0;
	size_t n = 0;
	for (size_t k = 0; k < pl->nregions; k++) {
		struct plan_region *g = &pl->regions[k];
		const int take = first ? g->scale == 2
				       : g->scale >= 8 && 2 * lacking_aa(r, g) >= plan_region_area(g);
		if (!take)
			continue;
		g->scale = ACC_AA;
		g->frame = first ? ACC_GRID_FRAME : 0;
		g->edges = first && *sparse == SPARSE_EDGES ? ACC_AA_FOR_EDGES : ACC_AA_FOR_FEW;
		g->depth = !first ? 0 : g->edges ? ACC_AA_EDGE_DEPTH : ACC_AA_DEPTH;
		n++;
	}
	aa_last(pl);
	return first ? n : 0;
}

/*
 * The CPU seconds an antialiased render in scale 2's place at POV-Ray's
 * depth d costs over region g, by the cost model pp: its corners,
 * ACC_GRID_FRAME^2 samples a pixel, and at each pixel whose colour
 * distance (the channels' absolute differences summed, as POV-Ray's
 * threshold measures it) to a neighbour in the row or column reaches
 * ACC_AA_THRESHOLD, EDGE_SAMPLES more at +R4 and half as many a level
 * less.  The pass is planned as the scale 2 it replaces, 4 samples a
 * pixel.  POV-Ray's subdivisions at twice the size of 160x120 (+AM2 +A0.1
 * +J, one thread) cost, over +R1's corners, per pixel so counted in a
 * render without antialiasing, in that render's CPU per pixel: at +R3 12
 * (Debian's lights/arealit3) to 66 (lights/shadows), at +R4 20 (arealit3)
 * to 120 (lights/arealit1); still_life 30 and 59, advanced/lamppost 47 and
 * 105, lights/soft 43 and 73 (one run each, 2026-12-02).  The margin in
 * aa_depth() covers the dearest.
 */
#define EDGE_SAMPLES 100.0
/* The pixels of region g of acc that count as edges for the cost above,
 * whose colour distance to a neighbour reaches t[j], for each of the n
 * thresholds into e[j], in one scan; edge_pixels() for one. */
static void edge_counts(const struct image *acc, const struct plan_region *g, const double *t,
			int n, long *e)
{
	for (int j = 0; j < n; j++)
		e[j] = 0;
	for (int y = g->y0; y <= g->y1; y++)
		for (int x = g->x0; x <= g->x1; x++) {
			const float *o = acc->px + ((size_t)y * acc->w + x) * ACC_NCH;
			double most = -1.0;	/* the largest distance to a neighbour */
			for (int k = 0; k < 4; k++) {
				const int nx = x + (k == 0) - (k == 1), ny = y + (k == 2) - (k == 3);
				if (nx < 0 || ny < 0 || nx >= acc->w || ny >= acc->h)
					continue;
				const float *q = acc->px + ((size_t)ny * acc->w + nx) * ACC_NCH;
				double dist = fabs((double)q[0] - o[0]) + fabs((double)q[1] - o[1]) +
					      fabs((double)q[2] - o[2]);
				most = dist > most ? dist : most;
			}
			for (int j = 0; j < n; j++)
				e[j] += most >= t[j];
		}
}

static long edge_pixels(const struct image *acc, const struct plan_region *g, double t)
{
	long e;
	edge_counts(acc, g, &t, 1, &e);
	return e;
}

/* The CPU seconds of an antialiased render in scale 2's place over region
 * g of an image w pixels wide, at cost_sample a sample (the cost map's
 * mean over g scaling it): its corners, ACC_GRID_FRAME^2 samples a pixel,
 * and `more` samples at each of its e edge pixels (edge_pixels()). */
static double aa_render_cost(const struct plan_params *pp, const struct plan_region *g, int w,
			     double cost_sample, long e, double more)
{
	const double f2 = (double)ACC_GRID_FRAME * ACC_GRID_FRAME;
	const double m = plan_region_map(pp, g, w) / (double)plan_region_area(g);
	return pp->cost_job + cost_sample * m * (f2 * (double)plan_region_area(g) + more * (double)e);
}

/* Whether region g is an antialiased render in scale 2's place taken for
 * edges or a few pixels: priced by edge_render_cost(), not as planned. */
static int priced_as_edges(const struct plan_region *g)
{
	return g->scale == ACC_AA && g->frame > 0 && !accum_for_spread(g->edges);
}

/* The cost above of region g, of an image w pixels wide, with e edge
 * pixels (edge_pixels()), at depth d. */
static double edge_render_cost(const struct plan_params *pp, const struct plan_region *g, int w,
			       long e, int d)
{
	return aa_render_cost(pp, g, w, pp->cost_sample, e, ldexp(EDGE_SAMPLES, d - 4));
}

/*
 * The depth of a pass's antialiased renders in scale 2's place: taken for
 * a few pixels ACC_AA_DEPTH (+R5), for edges ACC_AA_EDGE_DEPTH (+R4)
 * (choose_samplers()), or under a budget the deepest from there down to +R3
 * where EDGE_MARGIN times edge_render_cost() fits it
 * (pp->budget's core-seconds, or for the dearest render the wall time
 * `left`).  At +R4 still_life's edges erred a quarter of +R3's (1.56e-5 to
 * 4.5e-6 at --target 3e-3, 1.3 to 1.6 CPU s), hdr_highlights' highlights
 * three quarters (3.1e-4 to 2.3e-4 at 3e-3 and 1e-3, 3.6-4.1 to 4.7-5.2
 * CPU s), and starfield's stars between corners are no better found
 * (1.82e-3 to 1.86e-3 at 3e-3, 5.9e-4 to 6.5e-4 at 1e-3).  Under --budget
 * 2 a +R4 pass of Debian's advanced/lamppost, planned as scale 2 (0.4 s
 * for 11,416 pixels) and by
 * edge_render_cost() at 1.35 core-s, its dearest render 0.68 s, ran past
 * the deadline 1.56 s on and lost that render: relMSE 9.0e-4 against
 * +R3's 2.8e-5.  Where even EDGE_R3_MARGIN times +R3's cost is more than
 * the pass may spend, or its dearest render than the time left, *price is
 * set to +R3's cost and aa_some() keeps +R3 where it fits, the other
 * regions going back to the scale 2 they were planned as; the count of
 * those at +R3 is returned.  Debian's
 * advanced/bwstripe at 640x480 under --budget 3, every pixel an edge, ran
 * +R3 priced at 8.2 core-s against a share of 3.7, all four renders were
 * stopped at the deadline and the image was the base pass's, relMSE 0.40;
 * so, 0.026 (scale 2, then scale 4 at the stripes; POV-Ray alone at that
 * CPU 0.0067 by resolution scaling, 2026-12-04).  Its price counts
 * POV-Ray's samples well (at +R3 25 to 79 more a base pixel that differs
 * from a neighbour by 0.1 over twelve scenes at 320x240, POV-Ray's own
 * statistics, starfield's unseen stars aside) but not their cost:
 * hdr_highlights at 640x480 under --budget 3 priced its few-pixel +R3
 * renders at 2.9 core-s for a share of 3.0, a quarter of a 1280x960 frame
 * took 0.98 CPU s where its corners alone took 0.50 (the subdivided
 * samples, at its lamps, twice as dear), and 4 of 7 renders were lost
 * (relMSE 1.6e-3; all at scale 2, 1.1e-3 in two runs; by aa_some(), 7.2e-4
 * in three, none lost).  The
 * regions keep scale 2's cost for the plan (and the cost map learns
 * nothing from them: learn_costs()).
 */
#define EDGE_MARGIN 2.0
#define EDGE_R3_MARGIN 1.5
/* Whether a pass costing `cost` core-seconds, its dearest render `dearest`,
 * fits the pass's share pp->budget and the wall time `left` with `margin`. */
static int fits(double margin, double cost, double dearest, const struct plan_params *pp,
		double left)
{
	return margin * cost <= pp->budget && margin * dearest <= left;
}

/* Region g, an antialiased render in scale 2's place, back to the scale 2
 * it was planned as. */
static void back_to_scale2(struct plan_region *g)
{
	g->scale = 2;
	g->frame = 0;
	g->edges = 0;
	g->depth = 0;
}

/* aa_depth() where +R3 over all of a plan's antialiased regions does not
 * fit: the regions whose +R3 costs (c3, by region, from aa_depth(); NULL
 * when it ran out of memory: none) least more than their scale 2 keep it
 * while EDGE_R3_MARGIN times the pass (those at +R3, the rest at the
 * scale 2 they were planned as, pl's other regions aside) fits pp->budget
 * and their render `left`; the rest go back to scale 2, before the
 * antialiased ones (which are folded last: choose_samplers()).  Returns
 * how many keep +R3.  hdr_highlights at 640x480 under --budget 3: its
 * three lamps' renders, of 169 to 289 pixels, and two of the four
 * quarters of its floor at +R3, the other two at scale 2. */
static size_t aa_some(struct plan *pl, const struct plan_params *pp, const double *c3,
		      double left)
{
	const size_t n = pl->nregions;
	unsigned char *keep = calloc(n, 1);
	size_t kept = 0;
	if (!c3 || !keep) {	/* out of memory: all back at scale 2, in place */
		for (size_t k = 0; k < n; k++)
			if (pl->regions[k].depth)
				back_to_scale2(&pl->regions[k]);
		free(keep);
		return 0;
	}
	double total = 0.0;
	for (size_t k = 0; k < n; k++)
		if (pl->regions[k].depth)
			total += pl->regions[k].cost;
	for (;;) {	/* the least extra first; n is at most 2 max_regions */
		size_t b = n;
		for (size_t k = 0; k < n; k++)
			if (pl->regions[k].depth && !keep[k] &&
			    (b == n || c3[k] - pl->regions[k].cost < c3[b] - pl->regions[b].cost))
				b = k;
		if (b == n)
			break;
		const double extra = c3[b] - pl->regions[b].cost;
		if (!fits(EDGE_R3_MARGIN, total + extra, c3[b], pp, left))
			break;
		keep[b] = 1;
		total += extra;
	}
	/* the plan's scaled regions, those back at scale 2 (the antialiased
	 * ones being last), then those kept at +R3, each in their order */
	for (size_t k = 0; k < n; k++) {
		struct plan_region *g = &pl->regions[k];
		if (!g->depth)
			continue;
		if (keep[k]) {
			g->depth = 3;
			kept++;
		} else {
			back_to_scale2(g);
		}
	}
	aa_last(pl);
	free(keep);
	return kept;
}
static size_t aa_depth(const struct run *r, struct plan *pl, const struct plan_params *pp,
		       double left, double *price)
{
	int d = 0;
	*price = 0.0;
	for (size_t k = 0; k < pl->nregions; k++)
		d = pl->regions[k].depth > d ? pl->regions[k].depth : d;
	if (r->budget > 0.0 && d >= 3) {
		/* the pass's cost and its dearest render at each depth from 3
		 * to d, each region's edges counted once; each region's cost at
		 * +R3 for aa_some() */
		double sum[ACC_AA_DEPTH + 1] = { 0.0 }, worst[ACC_AA_DEPTH + 1] = { 0.0 };
		double *c3 = malloc(pl->nregions * sizeof(*c3));
		for (size_t k = 0; k < pl->nregions; k++) {
			if (!pl->regions[k].depth)
				continue;
			const long e = edge_pixels(&r->acc, &pl->regions[k], ACC_AA_THRESHOLD);
			for (int t = 3; t <= d; t++) {
				double c = edge_render_cost(pp, &pl->regions[k], r->acc.w, e, t);
				sum[t] += c;
				worst[t] = c > worst[t] ? c : worst[t];
				if (t == 3 && c3)
					c3[k] = c;
			}
		}
		while (d > 3 && !fits(EDGE_MARGIN, sum[d], worst[d], pp, left))
			d--;
		if (!fits(EDGE_R3_MARGIN, sum[3], worst[3], pp, left)) {
			*price = sum[3];
			const size_t kept = aa_some(pl, pp, c3, left);
			free(c3);
			return kept;
		}
		free(c3);
	}
	size_t n = 0;
	for (size_t k = 0; k < pl->nregions; k++)
		if (pl->regions[k].depth) {
			pl->regions[k].depth = d;
			n++;
		}
	return n;
}

/*
 * With --sampler auto, at the first refinement pass, where the error is
 * spread (not sparse_error()), the scene has neither radiosity nor focal
 * blur and its samples are cheap (r->cost_sample at most SPREAD_SAMPLE_S),
 * the regions of scale 2 become POV-Ray's +AM1 +A0.03 +R4 +J at twice the
 * size (ACC_AA_FOR_SPREAD in accum.h, which has the figures): on such
 * scenes at 640x480 scale 2's regular 4 samples over most of the frame lost
 * to POV-Ray's own antialiasing by 2.3 to 2.5 times, where its +AM1
 * supersamples only the render pixels that differ from a neighbour.  The
 * one_step() jitter takes the cheapest frames first (the frame at scale 4
 * under JITTER_FRAME_S), so this serves larger images.  Dearer samples
 * keep scale 2: on media (7.6e-6 s a sample) the render lost 4 times, and
 * glossy_reflection (3.8e-6) gained at a target only for 2.7 times the CPU.
 * The renders cost a sample a render pixel and accum_edge_cells(depth) more
 * at each pixel whose colour distance to a neighbour reaches the
 * threshold (soft_shadows at 640x480: 5.1 CPU s for 281,600 pixels, 85,840
 * of them such, at 0.87 microseconds a sample, 55 a pixel at +R4); the pass is
 * planned as scale 2, so under a budget the renders are taken at the
 * first of spread_levels (+R4, +A0.1 +R3, +R2 or +A0.3 +R2) where
 * SPREAD_MARGIN times that cost fits what the pass may spend (and the
 * level above it where that fits too: spread_mix()), priced at
 * the base pass's measured cost of a sample, not the plan's power of two
 * (soft_shadows' 0.87 microseconds went at times to 0.48, the +R2 renders
 * took twice their price, and three of seven were lost at the deadline of
 * --budget 2: relMSE 1.5e-3 to 2.7e-3 where scale 2 had 3.7e-4), with the
 * pass's other renders (thin_geometry at --budget 2, one run in ten: two
 * such renders beside four of scale 4, two renders lost, relMSE 1.1e-2
 * where the others had 5.7e-4).  The price came within 10% of the renders'
 * CPU at +R4 and 10 to 16% under at +R2 (soft_shadows and thin_geometry
 * at 640x480); so priced, 24 runs under --budget 2 and 3 lost none of
 * these renders (2026-12-04 21:55 UTC).  Returns how many regions it
 * changed, and in sums each level's price for the pass (0 where it did
 * not look).
 */
#define SPREAD_SAMPLE_S 1.5e-6
/*
 * The same under a budget, where r->cost_sample is as measured, not
 * rounded (without a budget 1.5e-6 takes a measured cost under 1.35e-6,
 * which rounds to 2^-20): a base pass's measurement moves by half from run
 * to run, and var_refl at 640x480 under --budget 6, 1.09e-6 to 1.17e-6 s a
 * sample, measured 1.58e-6 once in eight runs by hand (its base pass 0.57
 * CPU s against 0.41), kept scale 2 and ended at an estimated 1.1e-3 (the others
 * 1.5e-4 to 1.9e-4; 2026-12-05).  Halfway in the log to
 * glossy_reflection's 3.8e-6.
 */
#define SPREAD_SAMPLE_BUDGET_S 2.0e-6
/*
 * What a level's price is taken times against what the pass may spend.
 * The price missed the pass's CPU at every level:
 * over soft_shadows, thin_geometry and Debian's var_refl, noise_generator,
 * swirlbox and granite at 640x480 (`--budget 40 --target 1e-6
 * --max-passes 1`, each level forced by a scratch switch, 2026-12-05 02:40
 * UTC) the pass's POV-Ray CPU was 0.85 to 1.41 times the price, median
 * 1.17, thin_geometry and var_refl 1.26 to 1.41, and the lighter levels
 * took a margin of 1.4: at 1.25 thin_geometry under --budget 2 took +A0.1
 * +R3 priced at 1.7 core-s of 2.2, and in two runs of three one of its
 * four renders was stopped at the deadline (relMSE 4.8e-3 to 5.7e-3,
 * against 5.7e-4 by +R2).  Priced by the base pass's cost map
 * (base_cost_map()), the same runs on the six took 0.85 to 1.32 times the
 * price (median 1.15; without the map, the same build, 0.87 to 1.44;
 * 05:19 to 05:22 UTC), so every level takes SPREAD_MARGIN: by turns
 * against the build before at 640x480 under 2, 3 and 6 s (54 runs, 04:46
 * to 04:53 UTC) no render was lost at the deadline.
 */
#define SPREAD_MARGIN 1.25
/*
 * The renders a pass's scale-2 regions may become, in the order tried:
 * under a budget first the deeper +A0.03 +R6 and +R5 (ACC_AA_FOR_SPREAD_R6
 * and _R5, accum.h), then (without a budget, first) +A0.03 +R4
 * (ACC_AA_SPREAD_DEPTH, at SPREAD_R4), then under a budget that it does
 * not fit the lighter +A0.1 +R3 (ACC_AA_FOR_SPREAD_R3), +A0.03 +R2 and
 * +A0.3 +R2 (ACC_AA_FOR_SPREAD_FLOOR), each as its edges and depth
 * (accum_spread_render() has its threshold and cells).
 */
static const struct spread_level {
	int edges, depth;
} spread_levels[] = {
	{ ACC_AA_FOR_SPREAD_R6, ACC_AA_SPREAD_DEPTH },
	{ ACC_AA_FOR_SPREAD_R5, ACC_AA_SPREAD_DEPTH },
	{ ACC_AA_FOR_SPREAD, ACC_AA_SPREAD_DEPTH },
	{ ACC_AA_FOR_SPREAD_R3, ACC_AA_SPREAD_DEPTH },
	{ ACC_AA_FOR_SPREAD, 2 },
	{ ACC_AA_FOR_SPREAD_FLOOR, 2 },
};
/* NSPREAD levels, +A0.03 +R4 the one at SPREAD_R4 */
enum { NSPREAD = sizeof spread_levels / sizeof spread_levels[0], SPREAD_R4 = 2 };
/*
 * The margin of the deeper levels, +R6 and +R5.  No region of a pass that
 * fits +R4 but not +R5 whole moves up to +R5 (spread_mix() mixes the
 * levels from +R4 down, and +R5 whole with +R6).  A deeper pass takes
 * most of the budget, and a render of it stopped at the deadline keeps
 * only its finished blocks: with SPREAD_MARGIN and every move, Debian's
 * var_refl at 640x480 under --budget 12 took +R5 on two regions and +R6
 * on three, and one run of two by turns ended at relMSE 4.3e-4 against
 * 3.7e-5, likely a render stopped at the deadline (the pass's POV-Ray CPU
 * over its price at +R6 whole, --budget 40 --max-passes 1: var_refl 1.26,
 * thin_geometry 1.25, soft_shadows 1.10, granite 1.05, noise_generator
 * 0.86, swirlbox 0.69; 2026-12-05 12:30 UTC); with this margin and every
 * move, under --budget 6, where the moves from +R4 to +R5 were the only
 * difference, soft_shadows and swirlbox erred 1.21 and 1.17 times as much
 * (later passes had done better) and var_refl ended at 3.5e-4 against
 * 1.1e-4 in one run of two.  The moves from +R5 to +R6 alone: by turns
 * under 12 s (three runs each, 13:19 to 13:24 UTC) var_refl 0.82, swirlbox
 * 0.88, noise_generator 0.93, soft_shadows 1.02 times the relMSE.
 */
#define SPREAD_DEEP_MARGIN 1.4
/* The place in spread_levels of the render of edges and depth (NSPREAD
 * where none). */
static int spread_rank(int edges, int depth)
{
	int l = 0;
	while (l < NSPREAD && !(spread_levels[l].edges == edges && spread_levels[l].depth == depth))
		l++;
	return l;
}
/*
 * Below the first level a render is taken only where the pass so spends at
 * least this share of what it may, with the regions spread_mix() moved up
 * (until 2026-12-05 07:25 UTC the whole level's: noise_generator under 6 s,
 * +A0.1 +R3 whole at a share of 0.33 and +R4 whole just over, took scale 2
 * in runs where +R4 did not fit, relMSE 3.0e-5 to 3.3e-5 against 1.0e-5
 * where it did; with the mixed pass's share, 1.2e-5 in each of three runs
 * by turns, 07:25 to 07:30 UTC).  Where it would spend less, passes follow it, and
 * scale 2's smaller step lets them spread the budget over more pixels:
 * under --budget 6 at 640x480, Debian's textures/noise_generator,
 * textures/patterns/granite, textures/finishes/var_refl and advanced/
 * swirlbox took +R2 at shares of 0.30 to 0.48 and erred 1.04 to 1.66 times
 * as much as with scale 2 (one run each, 2026-12-04 22:25 UTC), where
 * soft_shadows and swirlbox under 3 s and thin_geometry under 2 s, at 0.52
 * to 0.78, erred 0.23 to 0.57 times as much.
 */
#define SPREAD_R2_SHARE 0.4

/* The margin of level l of spread_levels (NSPREAD: scale 2). */
static double level_margin(int l)
{
	return l < SPREAD_R4 ? SPREAD_DEEP_MARGIN : SPREAD_MARGIN;
}

/* Region k's margined price at level l of spread_levels (NSPREAD: the
 * scale 2 it was planned as; a region of another scale as planned), price
 * as spread_am1()'s. */
static double level_cost(const struct plan *pl, const double *price, size_t k, int l)
{
	if (pl->regions[k].scale != 2 || l >= NSPREAD)
		return SPREAD_MARGIN * pl->regions[k].cost;
	return level_margin(l) * price[k * NSPREAD + l];
}

/* The wall seconds pl's renders take on `slots` jobs at once, each
 * started in its order (the antialiased ones last: aa_last()) as a job
 * ends, region k taking level_cost() at level t, or t - 1 where up[k],
 * and lat (POV-Ray's start). */
static double mix_makespan(const struct plan *pl, const double *price, int t,
			   const unsigned char *up, int slots, double lat)
{
	double end[64] = { 0.0 }, last = 0.0;
	slots = slots < 1 ? 1 : slots > 64 ? 64 : slots;
	for (int part = 0; part < 2; part++)
		for (size_t k = 0; k < pl->nregions; k++) {
			const int l = up[k] ? t - 1 : t;
			const int aa = pl->regions[k].scale == 2 && l < NSPREAD;
			if (aa != part)
				continue;
			int s = 0;
			for (int j = 1; j < slots; j++)
				s = end[j] < end[s] ? j : s;
			end[s] += lat + level_cost(pl, price, k, l);
			last = end[s] > last ? end[s] : last;
		}
	return last;
}

/*
 * Where a pass's scale-2 regions fit level t of spread_levels whole (or
 * NSPREAD: none, they stay at scale 2) but not level t - 1, the regions
 * whose move up to t - 1 gains most of the plan's predicted gain a
 * core-second more of margined price take it (up[k] set), in that order,
 * while the pass fits what it may spend and its renders, each at its
 * margined price and POV-Ray's start lat, end within MIX_SLACK of `left`
 * less MIX_SPARE_S on `slots` jobs at once (mix_makespan(): a dear render
 * started last can outlast the others).  The mixed pass fills the budget
 * where the whole level left a step of it spare, and a render stopped at
 * the deadline loses all it did: without the slack and spare, under
 * --budget 2 at 640x480 one run in three of soft_shadows and
 * thin_geometry, two of noise_generator and every run of var_refl lost
 * renders (relMSE 1.3e-3 to 7.8e-3, against 7.6e-5 to 3.8e-4 in the
 * others' runs; 2026-12-05 03:32 to 03:41 UTC).  Regions move up to the
 * first level, +A0.03 +R4, too, though its price is the least sure: each
 * region of soft_shadows, thin_geometry, Debian's granite, var_refl,
 * noise_generator and swirlbox at 640x480 with +R4 forced (`povpress
 * render S --budget 40 --target 1e-6 --max-passes 1`, a scratch switch and
 * print, 2026-12-05 05:40 UTC) took 0.63 to 1.96 times its price, the
 * samples 0.50 to 0.96 times those priced (an edge pixel's four render
 * pixels are not all subdivided), a sample 0.86 to 2.18 times the cost
 * map's mean over its region (the edges' rays are dearer than the region's).
 * Before a stopped render kept its finished blocks (pass_job()'s salvage),
 * soft_shadows under --budget 3 took +R4 on two of four regions and lost a
 * render at the deadline in four runs of six (relMSE 1.4e-3 to 1.6e-3,
 * against 1.2e-4 with +A0.1 +R3 whole; 04:31 to 04:48 UTC), and the move
 * was priced at twice its price; since, at SPREAD_MARGIN, by turns against
 * that (three runs each under 3 and 6 s, the six, 07:15 to 07:21 UTC)
 * relMSE 0.92 times for 1.01 times the CPU, under 6 s var_refl, swirlbox and
 * noise_generator 0.81, 0.76 and 0.71, soft_shadows under 3 s 0.90.  Where
 * no level
 * fits (t NSPREAD), regions move up to the last level without
 * SPREAD_R2_SHARE's test: the pass then spends what it may on scale 2
 * and the moves together, not a small share of it.
 * Each level lies a step of the budget from the next (their prices 1.3 to
 * 2 times apart), and the first pass took it whole or not at all: swirlbox
 * (Debian's advanced/swirlbox) at 640x480 under --budget 2 priced +A0.3
 * +R2 at 1.79 core-s where the pass may spend 2.17, and rendered its four
 * regions at scale 2.  Returns the pass's price (unmargined) with the
 * regions moved up.
 */
struct mix_cand {
	size_t k;
	double more, score;
};
static int by_score_desc(const void *a, const void *b)
{
	const double x = ((const struct mix_cand *)a)->score,
		     y = ((const struct mix_cand *)b)->score;
	if (x != y)
		return (x < y) - (x > y);
	const size_t i = ((const struct mix_cand *)a)->k, j = ((const struct mix_cand *)b)->k;
	return (i > j) - (i < j);	/* in the plan's order, whatever qsort() does */
}
#define MIX_SLACK 0.85
#define MIX_SPARE_S 0.1
static double spread_mix(const struct plan *pl, const struct plan_params *pp, double left,
			 int slots, double lat, const double *price, const double sums[NSPREAD],
			 int t, unsigned char *up)
{
	const double m = level_margin(t);	/* t - 1's too: see spread_am1()'s mix */
	double total = m * (t < NSPREAD ? sums[t] : pl->cost);
	struct mix_cand *c = malloc(pl->nregions * sizeof(*c));
	if (!c)
		return total / m;	/* out of memory: level t whole */
	size_t nc = 0;
	for (size_t k = 0; k < pl->nregions; k++) {
		const struct plan_region *g = &pl->regions[k];
		if (g->scale != 2)
			continue;
		const double more = level_cost(pl, price, k, t - 1) - level_cost(pl, price, k, t);
		c[nc].k = k;
		c[nc].more = more;
		c[nc].score = more > 0.0 ? g->gain / more : INFINITY;
		nc++;
	}
	qsort(c, nc, sizeof(*c), by_score_desc);
	for (size_t i = 0; i < nc; i++) {
		if (!(total + c[i].more <= pp->budget))
			continue;
		up[c[i].k] = 1;
		if (mix_makespan(pl, price, t, up, slots, lat) <= MIX_SLACK * left - MIX_SPARE_S)
			total += c[i].more;
		else
			up[c[i].k] = 0;
	}
	free(c);
	return total / m;
}

static size_t spread_am1(const struct run *r, struct plan *pl, const struct plan_params *pp,
			 double left, int *sparse, double sums[NSPREAD])
{
	for (int t = 0; t < NSPREAD; t++)
		sums[t] = 0.0;
	if (run_grid(r) != PLAN_GRID_LARGE || r->aa || r->npasses != 1 || r->radiosity ||
	    r->focal ||
	    !(r->cost_sample <= (r->budget > 0.0 ? SPREAD_SAMPLE_BUDGET_S : SPREAD_SAMPLE_S)) ||
	    !has_scale2(pl) ||
	    sparse_error(r, sparse))
		return 0;
	/* each scale-2 region's price at each level, the pass's (sums) and
	 * its dearest render's; each region's pixels that differ from a
	 * neighbour by each level's threshold, in one scan */
	double *price = calloc(pl->nregions * NSPREAD, sizeof(*price));
	if (!price)
		return 0;
	struct accum_spread sp[NSPREAD];
	double th[NSPREAD], worst[NSPREAD] = { 0.0 };
	for (int t = 0; t < NSPREAD; t++) {
		sp[t] = accum_spread_render(spread_levels[t].edges, spread_levels[t].depth);
		th[t] = sp[t].threshold;
	}
	for (size_t k = 0; k < pl->nregions; k++) {
		const struct plan_region *g = &pl->regions[k];
		if (g->scale != 2) {	/* the pass's other renders, as planned */
			for (int t = 0; t < NSPREAD; t++)
				sums[t] += g->cost;
			continue;
		}
		long e[NSPREAD];
		edge_counts(&r->acc, g, th, NSPREAD, e);
		for (int t = 0; t < NSPREAD; t++) {
			const double c = aa_render_cost(pp, g, r->acc.w, r->cost_sample_measured,
							e[t], sp[t].cells);
			price[k * NSPREAD + t] = c;
			sums[t] += c;
			worst[t] = c > worst[t] ? c : worst[t];
		}
	}
	int t = r->budget > 0.0 ? 0 : SPREAD_R4, mix = 0;
	if (r->budget > 0.0) {
		while (t < NSPREAD &&
		       !fits(level_margin(t), sums[t], worst[t], pp, left))
			t++;
		/* moves up to t - 1 at t's margin, never from +R4 to the
		 * deeper levels (see SPREAD_DEEP_MARGIN) */
		mix = t > 0 && t != SPREAD_R4;
	}
	/* each scale-2 region's level: t, or t - 1 where spread_mix() so
	 * chose */
	unsigned char *up = mix ? calloc(pl->nregions, 1) : NULL;
	double total = t < NSPREAD ? sums[t] : pl->cost;	/* the pass's price */
	if (up)
		total = spread_mix(pl, pp, left,
				   r->jobs < (int)pl->nregions ? r->jobs : (int)pl->nregions,
				   r->latency, price, sums, t, up);
	if (r->budget > 0.0 && t > SPREAD_R4 && t < NSPREAD) {
		/* with the regions moved up, against SPREAD_R2_SHARE */
		if (!(total >= SPREAD_R2_SHARE * pp->budget)) {
			t = NSPREAD;	/* see SPREAD_R2_SHARE */
			free(up);
			up = NULL;
		}
	}
	size_t n = 0;
	for (size_t k = 0; k < pl->nregions; k++) {
		struct plan_region *g = &pl->regions[k];
		const int l = up && up[k] ? t - 1 : t;
		if (g->scale != 2 || l >= NSPREAD)
			continue;
		g->scale = ACC_AA;
		g->frame = ACC_GRID_FRAME;
		g->edges = spread_levels[l].edges;
		g->depth = spread_levels[l].depth;
		/* its price, for the progress display's guess and the
		 * renders' timeout */
		pl->cost += price[k * NSPREAD + l] - g->cost;
		g->cost = price[k * NSPREAD + l];
		n++;
	}
	if (up && t == NSPREAD && n)
		aa_last(pl);
	free(up);
	free(price);
	return n;
}

/* The -v line of spread_am1()'s prices, sums, against what the pass may
 * spend. */
static void spread_prices(struct run *r, int pass, const double sums[NSPREAD], double may)
{
	char what[256];
	int at = 0;
	for (int l = 0; l < NSPREAD && at >= 0 && at < (int)sizeof(what); l++) {
		const struct accum_spread sp =
			accum_spread_render(spread_levels[l].edges, spread_levels[l].depth);
		at += snprintf(what + at, sizeof(what) - (size_t)at, "%s%.2f%s at %s %s",
			       l ? ", " : "", sums[l], l ? "" : " core-s", sp.a, sp.r);
	}
	progress(r, "pass %d: the error is spread: POV-Ray's +AM1 over the scale-2 regions "
		 "about %s; the pass may spend %.2f", pass, what, may);
}

/*
 * Whether --sampler auto should go from the base pass straight to scale 4,
 * jittered (PLAN_GRID_ONLY, as --sampler jitter), for the rest of the run:
 * at the first refinement pass, where the error is spread (not
 * sparse_error()), the scene has no radiosity, and the whole frame
 * at scale 4, 16 samples a pixel, takes less than JITTER_FRAME_S on the
 * cores.  There jittering every pixel is cheap, and no regular grid of
 * scale 2 aliases into the mean or hides an edge from the estimate: on
 * soft_shadows at 160x120 (2026-11-22, one run each) target 3e-3 reached
 * relMSE 2.1e-4 in 0.58 CPU s, against 3.1e-4 in 0.72-0.81 s by scale 2
 * then 4, whose regular grids alias on the far checkerboard and whose
 * difference at the horizon put the estimate at 7 times the true error;
 * and by scale 2 it can stop early: at --target 3e-3 at relMSE 5.9e-3 on an
 * estimate of 2.5e-3 (2026-12-01, the horizon in the top tenth of a pixel
 * row, below scale 2's grid, holding 4.9e-3 of it), where jittered it
 * reached 2.1e-4 to 3e-4 in 1.2 to 1.3 CPU s.  Where samples are dear
 * (focal_blur: 1.2 CPU s for the frame at scale 4 on the faster machine of
 * 2026-12-01; glossy_reflection 2.3 s, media 2.3 to 4.7 s) the small step of
 * scale 2 lets the loop stop sooner or share a budget over more pixels:
 * forced there, --budget 2 erred 2.0 (glossy_reflection) and 4.4 (media)
 * times as much.  The rule was once the frame against twice the cores'
 * wait on POV-Ray's latency in a pass, 0.3 to 0.36 s on both machines
 * measured (0.6 to 0.7 s a core); povwait.so cut that wait to 0.01 to 0.03
 * s, and the scale-2 path came back with its early stop, so the frame is
 * now held to the time the wait stood for.
 */
#define JITTER_FRAME_S 0.7
static int one_step(const struct run *r, int *sparse)
{
	const double frame4 = 16.0 * r->cost_sample * (double)r->w * r->h;
	return run_grid(r) == PLAN_GRID_LARGE && r->npasses == 1 && !r->radiosity && !r->focal &&
	       frame4 < JITTER_FRAME_S * r->cores && !sparse_error(r, sparse);
}

/*
 * What a pass keeps of the budget after its renders, wall seconds: what
 * the last region pass took from its renders' end to its image written
 * (merging the renders, the analysis, the writes; before the first, the
 * base pass's analysis and writes, and the merge of renders at twice the
 * image's size over the frame, ACC_GRID_FRAME^2 times the base pass's image
 * read and folded: without it the first pass's renders at 640x480 ended
 * 0.36 to 0.46 s before the run, for a reserve of 0.38 to 0.49, and runs
 * under 6 s ended at 5.98 to 6.04 s, 2026-12-05), then the final stage:
 * under --final auto the filter (measured at 0.3 to 0.45 of an analysis:
 * 0.14 s against 0.28 to 0.45 s at 640x480 on two cores, 2026-11-23), the
 * image compressed (the passes write it uncompressed, but for the first,
 * timed for this) and the error map beside it (MAP_SHARE as long: its 8
 * channels took 1.18 to 1.19 times the image's time to write at 160x120
 * and 640x480), and 0.1 s.  With the analysis and 0.1 s alone,
 * soft_shadows at 640x480 under --budget 4 ended at 4.2 s without the
 * filter, 4.4 to 4.6 s with it (the final stage 0.4 s, the merges 0.13 s).
 */
#define FILTER_SHARE 0.5
#define MAP_SHARE 1.2
static double final_reserve(const struct run *r)
{
	const double a = r->passes[r->npasses - 1].analysis_s;
	const double tail = r->tail_s > 0.0 ? r->tail_s
					     : a + r->write_s + ACC_GRID_FRAME * ACC_GRID_FRAME * r->read_s;
	return tail + (r->filter ? FILTER_SHARE * a : 0.0) + (1.0 + MAP_SHARE) * r->comp_s + 0.1;
}

/*
 * Under a budget, the cost map from what a pass's region renders took: a
 * region's CPU less its invocation's, over its samples' cost by the map,
 * scales its pixels' costs (within 1/LEARN_MAX and LEARN_MAX a pass, the
 * map within COST_MIN and COST_MAX; a factor below 1 by its square root),
 * so that the next plans cost each pixel as its own renders did, not at
 * the base pass's average.  A render stopped at the deadline took at least
 * its CPU: its pixels' costs grow when that is more than planned.  Not
 * learnt from: antialiased renders (planned at scale 2's cost, rendered
 * otherwise: aa_depth()), renders retried or started early, and those
 * planned at under LEARN_MIN seconds of samples, whose CPU is mostly
 * POV-Ray's start.  A pixel in regions of two scales takes their factors'
 * geometric mean.  The base pass's
 * one frame gives the map's start, 1 everywhere.  A sample of
 * glossy_reflection's reflecting floor costs 14 times one of its sky and
 * wall (the lower and upper halves at twice 160x120, `povray
 * scenes/glossy_reflection.pov +W320 +H240 -A +SR121 +ER240 +WT1`, 1.13
 * and 0.08 CPU s, 2026-12-02): planned at the frame's average, its pass 2
 * under --budget 3 took twice its plan on the floor and lost one or two of
 * five or six region renders at the deadline in each of four runs; the
 * global correction the map replaced (the pass's CPU over its plan, for
 * every pixel) learnt nothing where pass 1 was the frame.
 */
#define LEARN_MAX 8.0
#define LEARN_MIN 0.02
static void learn_costs(struct run *r, const struct plan_params *pp, const struct plan *pl,
			const struct pov_result *res)
{
	if (!r->cost_map)
		return;
	const size_t npx = (size_t)r->w * r->h;
	const double px = (double)npx;
	double lo = INFINITY, hi = 0.0;
	int nl = 0;
	/* each pixel's factors' log sum and count: where regions of two
	 * scales overlap, each measured its cost against the map as it was,
	 * and the pixel takes their geometric mean, not their product */
	double *ls = calloc(npx, sizeof(*ls));
	unsigned short *nf = calloc(npx, sizeof(*nf));
	if (!ls || !nf) {	/* out of memory: the map stays as it was */
		free(ls);
		free(nf);
		return;
	}
	for (size_t k = 0; k < pl->nregions; k++) {
		const struct plan_region *g = &pl->regions[k];
		if (g->scale == ACC_AA || res[k].attempts != 1 || res[k].prelaunched)
			continue;
		/* the samples' cost by the map, not the region's cost less
		 * its job: an early render's band is costed at its plan's
		 * mean (prelaunch_cover()) */
		const double planned = pp->cost_sample * g->scale * g->scale *
				       plan_region_map(pp, g, r->w),
			     used = res[k].cpu_s - plan_job_cost(pp, g->scale, px);
		if (!(planned >= LEARN_MIN) || !(used > 0.0))
			continue;
		double q = used / planned;
		if (res[k].status != POV_OK && !(res[k].status == POV_CANCELLED && q > 1.0))
			continue;
		q = q < 1.0 / LEARN_MAX ? 1.0 / LEARN_MAX : q > LEARN_MAX ? LEARN_MAX : q;
		lo = q < lo ? q : lo;
		hi = q > hi ? q : hi;
		nl++;
		/* cheaper than planned, halfway (in the log): a region's mean
		 * hides its dear parts, and a later render of those planned
		 * too cheap runs into the deadline and is lost */
		const double lq = q < 1.0 ? 0.5 * log(q) : log(q);
		for (int y = g->y0; y <= g->y1; y++)
			for (int x = g->x0; x <= g->x1; x++) {
				const size_t i = (size_t)y * r->w + x;
				ls[i] += lq;
				nf[i]++;
			}
	}
	for (size_t i = 0; i < npx; i++) {
		if (!nf[i])
			continue;
		double v = r->cost_map[i] * exp(ls[i] / nf[i]);
		r->cost_map[i] = (float)(v < COST_MIN ? COST_MIN : v > COST_MAX ? COST_MAX : v);
	}
	free(ls);
	free(nf);
	r->cost_learnt += nl;
	if (nl == 1 && r->verbose)
		progress(r, "pass %d: 1 region render took %.2g times its planned CPU, its "
			 "pixels' costs so scaled", r->pool_pass, lo);
	else if (nl && r->verbose)
		progress(r, "pass %d: %d region renders took %.2g to %.2g times their planned "
			 "CPU, their pixels' costs so scaled", r->pool_pass, nl, lo, hi);
}

/*
 * The target the first refinement pass plans for where the error sits at
 * edges (sparse_error(): its antialiased render in scale 2's place), no
 * budget set and the base pass's estimate above the target: at most what
 * is left once EDGE_TAKE of the top PLAN_EDGE_SHARE of the pixels' error
 * is taken off, so that the pass takes the edges whole.  Planned for the
 * target alone, the pass takes just enough of the dearest pixels for its
 * prediction to reach a share of the target (plan_params' margin), and a
 * base pass whose estimate stood just above a loose target got a few
 * edges and stopped (still_life at 320x240, --target 3e-3: the base pass's
 * estimate 4.4e-3, 1342 pixels chosen, relMSE 2.3e-4 in 1.8 CPU s in the
 * quick sweep at 320x240 of 2026-12-04 10:06, 13 times POV-Ray's best at
 * that CPU, `+AM2 +A0.3 +R3` at twice the size, 1.7e-5 in 1.2 s; 2.6e-4 by
 * hand); with the rule 5662 chosen, 1.8e-6 in 2.6 s, as at --target 1e-3.  Debian's lights/arealit3 there:
 * 9.3e-5 and 1.5e-4 in 1.9 s (1.9 and 3.1 times POV-Ray's `+AM2 +A0.1 +R3`,
 * 4.9e-5 in 0.83 s) became 1.6e-5 in 5.1 s (1.02 times `+AM2 +A0.1 +R4` at
 * twice the size, 1.5e-5 in 3.7 s).  Deterministic runs of the bundled
 * scenes at 160x120 (3e-3 and 1e-3), where the bases' estimates stand
 * further above the targets, give the same images; see the README.
 */
#define EDGE_TAKE 0.75
static double edge_target(const struct run *r, int *sparse)
{
	if (r->budget > 0.0 || r->npasses != 1 || run_grid(r) != PLAN_GRID_LARGE ||
	    sparse_error(r, sparse) != SPARSE_EDGES)
		return r->target;
	const size_t n = (size_t)r->w * r->h;
	double all;
	const double top = plan_top_sum(r->est, n, PLAN_EDGE_SHARE, &all);
	if (!(all / (double)n > r->target))
		return r->target;	/* met: no pass */
	const double t = (all - EDGE_TAKE * top) / (double)n;
	if (!(t > 0.0 && t < r->target))
		return r->target;
	if (r->verbose)
		fprintf(stderr, "povpress render: pass 1 plans for an estimated relMSE of %.3g, "
			"the edges whole, below the target\n", t);
	return t;
}

/*
 * The progress line of a pass's naa antialiased renders in scale 2's
 * place (pl's regions of scale ACC_AA and frame ACC_GRID_FRAME): why, and
 * how, the lighter renders for spread error by their options, the others
 * by depth; where spread_mix() gave the regions two levels, each with its
 * count, the lighter first.
 */
static void aa_progress(struct run *r, int pass, const struct plan *pl, size_t naa)
{
	struct { int edges, depth; size_t n; } lv[2] = { { 0, 0, 0 }, { 0, 0, 0 } };
	int nl = 0;
	for (size_t k = 0; k < pl->nregions; k++) {
		const struct plan_region *g = &pl->regions[k];
		if (g->scale != ACC_AA || g->frame != ACC_GRID_FRAME)
			continue;
		int l = 0;
		while (l < nl && !(lv[l].edges == g->edges && lv[l].depth == g->depth))
			l++;
		if (l == nl && nl < 2) {
			lv[nl].edges = g->edges;
			lv[nl].depth = g->depth;
			nl++;
		}
		if (l < nl)
			lv[l].n++;
	}
	char how[2][32], all[96];
	for (int l = 0; l < nl; l++) {
		const struct accum_spread sp = accum_spread_render(lv[l].edges, lv[l].depth);
		/* by depth only the +A0.03 render at a depth of its own */
		if (accum_for_spread(lv[l].edges) && (nl > 1 || lv[l].edges != ACC_AA_FOR_SPREAD))
			snprintf(how[l], sizeof(how[l]), "%s %s", sp.a, sp.r);
		else
			snprintf(how[l], sizeof(how[l]), "depth %d", lv[l].depth);
	}
	if (nl > 1) {
		/* the lighter level is the later one in spread_levels */
		const int a = spread_rank(lv[0].edges, lv[0].depth) <
			      spread_rank(lv[1].edges, lv[1].depth);
		snprintf(all, sizeof(all), "%zu at %s and %zu at %s", lv[a].n, how[a],
			 lv[!a].n, how[!a]);
	} else {
		snprintf(all, sizeof(all), "%s", nl ? how[0] : "");
	}
	const int edges = nl ? lv[0].edges : 0;
	progress(r, "pass %d: the estimated error %s: %zu region%s by POV-Ray's "
		 "antialiasing (+AM%d) in place of scale 2, %s", pass,
		 accum_for_spread(edges) ? "is spread and samples are cheap"
		 : edges ? "sits at edges" : "sits in few pixels",
		 naa, naa == 1 ? "" : "s", accum_for_spread(edges) ? 1 : 2, all);
}

/*
 * One refinement pass from the error estimate r->est.  Returns 0 when a
 * pass ran, PASS_STOP when the planner stopped the run (r->stop says why),
 * -1 on failure, POV_INTERRUPTED when a signal came.
 */
enum { PASS_STOP = 2 };
/* A region render's frame, CPU seconds a pixel: an 8 x 8 region of
 * smooth_empty in a 1280x960 frame took 0.15 CPU s, in 2560x1920 0.52 s,
 * in 160x120 0.02 s (2026-12-01, `povray ... +SC +EC +SR +ER -A`); 6.5e-8
 * on the sweep's machine.  Planned for where frames may reach 8 Mpixels
 * (focal blur): there, without it, a pass at scale 8 of focal_blur at
 * 160x120 under --budget 8 took 5.6 s for a plan of 4.0, one of its six
 * renders stopped at the deadline, and three runs of eleven ended at 8.01
 * to 8.06 s. */
#define FRAME_COST 1e-7
#define MIN_PASS_GAIN 0.01
/*
 * How long past its deadline a pass's region render that will have
 * rendered its pixels by then is left to end (pov_pool_opts' finish_s),
 * at most FINISH_SHARE of the budget.  Stopped at the deadline, a render
 * keeps only the blocks it finished (pass_job()'s salvage; before that it
 * lost all it did): Debian's textures/finishes/var_refl at 640x480 under
 * --budget 2, one run in four, lost a render that had rendered all its
 * pixels and was writing its image (its progress lines, 2026-12-05):
 * estimated relMSE 9.0e-3, the others 2.6e-3 to 2.8e-3.  POV-Ray
 * wrote the image of a region render at 1280x960 and exited 0.06 to 0.32 s
 * after its last progress line (var_refl's lower half at +AM1 +A0.3 +R2,
 * swirlbox's upper half without antialiasing, two runs each, with
 * povwait.so); the pool takes the image as it is closed, before the exit.
 */
#define FINISH_S 0.3
#define FINISH_SHARE 0.075
/*
 * The share of the cores' time up to the deadline a pass may plan for its
 * region renders: a first pass's renders took 0.93 to 0.96 of their wall
 * on the two cores (granite, var_refl, noise_generator, swirlbox,
 * soft_shadows and thin_geometry at 640x480 under --budget 2 and 3,
 * 2026-12-05), a pass of a few small renders 0.76 to 0.81.  A plan's price
 * misses too (a region at +A0.03 +R4 took 0.63 to 1.96 times its price),
 * and a render stopped at the deadline leaves the blocks it had not
 * finished at their samples before: var_refl there under --budget 6
 * planned 9.1 core-s, its renders ended 4.3 to 5.3 s after the pass
 * began against a deadline of 5.0 (seven runs by hand).
 */
#define PASS_EFFICIENCY 0.9

static int refine_pass(struct run *r, int pass, char *err, size_t errlen)
{
	double t = now_s(), c = self_cpu();
	/* what a pass keeps of the budget after its renders; its renders'
	 * deadline is the rest */
	const double reserve = final_reserve(r);
	int sparse = -1;	/* sparse_error(), once a pass asks */
	const int choose = !r->jittered && one_step(r, &sparse);
	int fit = 2;	/* passes that still fit the budget, this one included */
	size_t naa;
	/* renders started early for this pass: taken, or stopped (their CPU) */
	double pre_cpu = 0.0;
	size_t *pre_idx = NULL;
	struct pov_prelaunch *pre = NULL;
	int early = r->pre && r->pre_pass == pass;
	struct plan_params pp;
	struct plan pl;
	for (;;) {
		/* the wait this pass's renders begin with: POV-Ray's start-up,
		 * or, for renders started early, their gate's */
		const double lat = early ? r->pre_latency : r->latency;
		plan_params_init(&pp);
		pp.target = edge_target(r, &sparse);
		pp.cost_job = r->cost_job;
		pp.cost_sample = r->cost_sample;
		pp.cost_map = r->cost_map;
		pp.max_regions = r->jobs > 8 ? r->jobs : 8;
		if (r->budget > 0.0) {
			double left = r->budget - elapsed(r);
			/* in core-seconds, up to the renders' deadline (the
			 * reserve kept for the merges, the analysis and the
			 * final image) less the latency of the pass's last
			 * round of jobs; no pass when the deadline would not
			 * leave one render its latency and setup */
			pp.budget = (left - lat - reserve) * r->cores * PASS_EFFICIENCY;
			if (pp.budget <= 0.0 || left - reserve < lat + r->cost_job) {
				r->stop = "budget spent";
				return PASS_STOP;
			}
			/* the passes that still fit, this one and the next ones
			 * each waiting on POV-Ray's latency and the analysis:
			 * when only one or two do, this pass takes its share of
			 * the budget even past the pixels' next scales */
			fit = 1 + (int)floor((left - 0.2 - lat - reserve) / (r->latency + reserve));
			if (fit <= 2)
				pp.fill = fit <= 1 ? pp.budget : pp.budget / fit;
		}
		pp.grid = choose ? PLAN_GRID_ONLY : run_grid(r);
		if (r->focal) {	/* scaled frames up to 8 Mpixels: their cost shows */
			pp.grid_frame = PLAN_FOCAL_FRAME;
			pp.cost_frame = FRAME_COST;
		}
		if (gamma_scaling(r))	/* scaled frames at every scale */
			pp.cost_frame = FRAME_COST;
		pp.min_split = r->budget > 0.0 ? 2 * r->cores : r->cores;
		/* under a budget, a pass that leaves the target unmet and
		 * would take less than 1% of the error off is not worth
		 * POV-Ray's wait (a budget's last seconds: ten pixels) */
		pp.min_pass_gain = MIN_PASS_GAIN;
		if (plan_make_from(&r->acc, r->est, &pp, &pl, err, errlen))
			return -1;
		pp.budget = pl.budget;	/* less where its splits ran past it */
		if (pl.outcome != PLAN_REFINE) {
			r->stop = plan_outcome_name(pl.outcome);
			plan_release(&pl);
			return PASS_STOP;
		}
		const double left = r->budget > 0.0 ? r->budget - elapsed(r) - reserve - lat : 0.0;
		naa = choose_samplers(r, &pl, &sparse);
		if (naa) {
			double price;
			const size_t all = naa;
			naa = aa_depth(r, &pl, &pp, left, &price);
			if (price > 0.0)
				progress(r, "pass %d: antialiasing in all %zu regions would not "
					 "fit the budget even at +R3 (about %.1f core-s): %zu at "
					 "+R3, the rest at scale 2", pass, all, price, naa);
		} else {
			double sums[NSPREAD];
			naa = spread_am1(r, &pl, &pp, left, &sparse, sums);
			if (r->verbose && r->budget > 0.0 && sums[0] > 0.0)
				spread_prices(r, pass, sums, pp.budget);
		}
		if (!early || prelaunch_cover(r, pass, &pl, &pre_idx))
			break;
		/* the early renders do not serve this plan: plan again for
		 * renders that wait on POV-Ray's start-up */
		plan_release(&pl);
		pre_cpu += prelaunch_end(r);
		early = 0;
	}
	if (choose) {	/* made once a pass runs on it */
		r->jittered = 1;
		progress(r, "pass %d: the frame at scale 4 takes less than %.1f s on the cores: "
			 "no scale 2, scale 4 and up jittered", pass, JITTER_FRAME_S);
	}
	if (pre_idx) {
		pre = r->pre;
		r->pre = NULL;
		naa = 0;	/* in scale 2's place, as choose_samplers() counts */
		for (size_t k = 0; k < pl.nregions; k++)
			naa += pl.regions[k].scale == ACC_AA && pl.regions[k].frame > 0;
		progress(r, "pass %d: %zu region renders started %s", pass, pl.nregions,
			 pass == 1 ? "with the base pass" : "during the pass before");
	} else {
		pre_cpu += prelaunch_end(r);	/* for another pass, or none */
	}
	size_t n = pl.nregions;
	struct pov_job *jobs = calloc(n, sizeof(*jobs));
	struct pov_region *regs = calloc(n, sizeof(*regs));
	const char **extras = calloc(n * (r->nextra + 4), sizeof(char *));
	char **outs = calloc(n, sizeof(char *));
	struct pov_result *results = calloc(n, sizeof(*results));
	const char **bextra = calloc(r->nextra + 4, sizeof(char *));
	int ret = -1;
	if (!jobs || !regs || !extras || !outs || !results || !bextra) {
		errbuf_printf(err, errlen, "out of memory");
		goto out;
	}
	struct pov_job base;
	char passno[16];
	struct pov_define pd;
	pass_job(r, pass, &base, bextra, passno, &pd);
	for (size_t k = 0; k < n; k++) {
		char name[PATH_MAX];
		plan_output_name(name, sizeof name, r->workdir, pass, pre_idx ? pre_idx[k] : k,
				 pl.regions[k].scale);
		outs[k] = strdup(name);
		if (!outs[k]) {
			errbuf_printf(err, errlen, "out of memory");
			goto out;
		}
		plan_job(&base, &pl.regions[k], outs[k], &regs[k], extras + k * (r->nextra + 4),
			 &jobs[k]);
	}
	/* what this pass renders, for inspection and for running elsewhere */
	if (plan_regions_save(wpath(r, "regions.tsv"), &pl, pass, outs, err, errlen))
		goto out;
	/* the pass's CPU by the cost model, its edge renders' and its dearest
	 * render's: +AM2 in scale 2's place is planned as scale 2, but priced
	 * by its modelled cost (at 640x480 Debian's advanced/bwstripe, edges
	 * everywhere, took 21 CPU s a render planned at 0.3 s) */
	double priced = 0.0, aa_priced = 0.0, worst = 0.0;
	for (size_t k = 0; k < n; k++) {
		const struct plan_region *g = &pl.regions[k];
		const int edge = priced_as_edges(g);
		const double gc = edge ? edge_render_cost(&pp, g, r->acc.w,
							  edge_pixels(&r->acc, g, ACC_AA_THRESHOLD),
							  accum_aa_depth(g->depth))
				       : g->cost;
		priced += gc;
		aa_priced += edge ? gc : 0.0;
		worst = gc > worst ? gc : worst;
	}
	struct pov_pool_opts po;
	pov_pool_opts_init(&po);
	po.max_jobs = r->jobs < (int)n ? r->jobs : (int)n;
	po.timeout_s = r->timeout;
	if (po.timeout_s <= 0.0) {
		/* a minute plus ten times what the dearest region should cost:
		 * a region at scale 16 can cost far more than the base pass */
		po.timeout_s = 60.0 + 10.0 * worst;
	}
	po.on_done = on_done;
	po.ready = output_whole;
	po.arg = r;
	po.prelaunched = pre;
	/* the next pass's likely renders wait through their start-up while
	 * this pass renders (not when this is the last pass that fits) */
	if (fit > 1)
		prelaunch_next(r, pass + 1, &pl, &pp);
	if (r->budget > 0.0) {
		/* the budget holds even when the cost model is wrong (a region
		 * of glossy floor costs more per sample than the frame's
		 * average: glossy_reflection at --budget 8 ended at 10.9 s):
		 * regions still rendering when only the analysis's time is
		 * left are stopped, the blocks they finished kept (the rest
		 * is lost); but those
		 * that will have rendered their pixels within half of FINISH_S
		 * (of FINISH_SHARE of the budget at most) are left that long */
		po.deadline_s = deadline_in(r, reserve);
		po.finish_s = FINISH_S < FINISH_SHARE * r->budget ? FINISH_S
								 : FINISH_SHARE * r->budget;
	}
	r->pool_done = 0;
	r->pool_total = (int)n;
	r->pool_pass = pass;
	/* the pass should take its CPU over the cores, or the latency of its
	 * rounds of jobs, whichever is longer */
	double rounds = ceil((double)n / po.max_jobs);
	double cpu_wall = (priced - (double)n * r->cost_job) / (n < (size_t)r->cores ? (double)n :
								   r->cores);
	double guess = rounds * r->latency > cpu_wall ? rounds * r->latency : cpu_wall;
	if (naa)
		aa_progress(r, pass, &pl, naa);
	progress(r, "pass %d: %zu region%s, %ld pixels (%ld chosen), %.0f samples, about %.1f s",
		 pass, n, n == 1 ? "" : "s", pl.pixels, pl.chosen_pixels, pl.samples,
		 guess + r->latency);
	int rc = pov_pool_run(jobs, n, &po, results, err, errlen);
	r->renders_end = now_s();
	struct pass_rec p = {0};
	p.prelaunched = (int)pov_prelaunch_taken(pre);
	p.cpu_s = pre_cpu + pov_prelaunch_end(pre);
	pre = NULL;
	if (rc < 0)
		goto out;
	p.pass = pass;
	char how_far[128] = "";
	size_t at_far = 0;
	for (size_t k = 0; k < n; k++) {
		const struct plan_region *g = &pl.regions[k];
		const struct pov_result *q = &results[k];
		const int s = g->scale;
		long folded = 0;
		p.cpu_s += q->cpu_s;
		p.invocations += q->attempts;
		if (q->status == POV_CANCELLED && rc != POV_INTERRUPTED) {
			p.stopped++;	/* the budget's deadline */
			const double f = q->nprogress && q->progress_total > 0
				? (double)q->progress[q->nprogress - 1].done /
					  (double)q->progress_total : 0.0;
			char one[16] = "not started";
			if (q->attempts)
				snprintf(one, sizeof(one), "%.0f%%", 100.0 * f);
			if (at_far < sizeof(how_far))
				at_far += (size_t)snprintf(how_far + at_far, sizeof(how_far) - at_far,
							   "%s%s", at_far ? ", " : "", one);
		}
		if (q->status == POV_OK) {
			if (plan_merge_file(&r->acc, outs[k], g, pass, &folded, err, errlen)) {
				fprintf(stderr, "povpress render: pass %d, region %d,%d-%d,%d: %s\n",
					pass, g->x0, g->y0, g->x1, g->y1, err);
				p.failed++;
				continue;
			}
			p.regions++;
			if (!r->keep)
				unlink(outs[k]);
		} else if (q->status != POV_CANCELLED) {
			p.failed++;
			fprintf(stderr, "povpress render: pass %d, region %d,%d-%d,%d: %s%s%s\n", pass,
				g->x0, g->y0, g->x1, g->y1, pov_status_name(q->status),
				q->message[0] ? ": " : "", q->message);
			continue;
		} else if (!q->partial_pixels) {
			continue;
		} else if (accum_merge_partial(&r->acc, &q->partial, q->partial_oy, s, g->depth,
					       g->edges, g->x0, g->y0, g->x1, g->y1, pass, &folded,
					       err, errlen)) {
			/* stopped at the deadline or by an interruption: the blocks
			 * it finished */
			fprintf(stderr, "povpress render: pass %d, region %d,%d-%d,%d: the blocks it "
				"finished: %s\n", pass, g->x0, g->y0, g->x1, g->y1, err);
			continue;
		} else {
			p.kept += folded;
		}
		p.pixels += folded;
		/* an antialiased render's samples: one per render pixel, its
		 * subdivisions not counted (POV-Ray's statistics come after the
		 * image, which the pool takes without waiting for them) */
		const int f = g->frame > 0 ? g->frame : 1;
		p.samples += (double)folded * (s != ACC_AA ? s * s : f * f);
	}
	learn_costs(r, &pp, &pl, results);
	if (r->verbose && aa_priced > 0.0) {
		/* POV-Ray's subdivisions are priced by edge_render_cost(), a
		 * model that took 0.64 to 6.2 times its price over seven scenes
		 * (README, On scenes it was not tuned for) */
		double used = 0.0;
		for (size_t k = 0; k < n; k++)
			if (priced_as_edges(&pl.regions[k]))
				used += results[k].cpu_s;
		progress(r, "pass %d: its antialiased renders took %.2f CPU s, priced at %.2f",
			 pass, used, aa_priced);
	}
	if (rc == POV_INTERRUPTED && p.kept) {
		progress(r, "pass %d: interrupted, %ld pixels kept from the blocks its stopped "
			 "renders had finished", pass, p.kept);
		progress_end(r);
	}
	if (p.stopped) {
		progress(r, "pass %d: %d of %zu region renders stopped at the budget's end "
			 "(done: %s of their pixels; %ld pixels kept)", pass, p.stopped, n, how_far,
			 p.kept);
		progress_end(r);
	}
	/* what a region render waits on besides its CPU, for the budget's
	 * next passes: less than the base pass's latency, since the pool does
	 * not wait for POV-Ray to exit (output_whole()); counted on the
	 * renders' share of the cores (pov_results_latency()) */
	double lat[2];
	pov_results_latency(results, n, r->cores, lat);
	if (lat[0] < INFINITY)
		r->latency = lat[0] > 0.0 ? lat[0] : 0.0;
	if (lat[1] < INFINITY)
		r->pre_latency = lat[1] > 0.0 ? lat[1] : 0.0;
	p.wall_s = now_s() - t;
	p.driver_cpu_s = self_cpu() - c;
	p.est_relmse = NAN;
	p.planned_relmse = pl.est_after;
	if (add_pass(r, &p)) {
		errbuf_printf(err, errlen, "out of memory");
		goto out;
	}
	if (image_write_exr_raw(wpath(r, "accum.exr"), &r->acc, err, errlen) ||
	    save_progress(r, err, errlen))
		goto out;
	ret = rc == POV_INTERRUPTED ? POV_INTERRUPTED : 0;
	if (ret)
		errbuf_printf(err, errlen, "interrupted in pass %d", pass);
out:
	for (size_t k = 0; k < n; k++) {
		if (results)
			pov_result_release(&results[k]);
		if (outs)
			free(outs[k]);
	}
	free(jobs);
	free(regs);
	free(extras);
	free(outs);
	free(results);
	free(bextra);
	free(pre_idx);
	pov_prelaunch_end(pre);
	plan_release(&pl);
	return ret;
}

/* Check that path's directory exists and is writable, before any work. */
static int check_writable(const char *what, const char *path, char *err, size_t errlen)
{
	char dir[PATH_MAX];
	snprintf(dir, sizeof dir, "%s", path);
	char *slash = strrchr(dir, '/');
	if (!slash)
		snprintf(dir, sizeof dir, ".");
	else if (slash == dir)
		dir[1] = '\0';
	else
		*slash = '\0';
	struct stat st;
	if (stat(dir, &st) || !S_ISDIR(st.st_mode)) {
		errbuf_printf(err, errlen, "cannot write %s '%s': directory '%s' does not exist",
			      what, path, dir);
		return -1;
	}
	if (access(dir, W_OK | X_OK)) {
		errbuf_printf(err, errlen, "cannot write %s '%s': %s", what, path,
			      strerror(errno));
		return -1;
	}
	if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
		errbuf_printf(err, errlen, "cannot write %s '%s': it is a directory", what, path);
		return -1;
	}
	return 0;
}

/* The index of v among the n names, or -1. */
static int name_index(const char *v, const char *const *names, int n)
{
	for (int k = 0; k < n; k++)
		if (!strcmp(v, names[k]))
			return k;
	return -1;
}

int cmd_render(int argc, char **argv)
{
	struct run r;
	memset(&r, 0, sizeof r);
	r.t0 = process_start_s();	/* the budget counts from the exec */
	r.w = 640;
	r.h = 480;
	r.target = 1e-3;
	r.max_passes = 8;
	r.final = ACC_FINAL_AUTO;
	r.filter = 1;
	r.rad_scale = 1;
	r.user_rad_scale = -1;
	r.grid = PLAN_GRID_LARGE;
	r.prelaunch = PRE_AUTO;
	r.pre_latency = PRE_LATENCY;
	char emap[PATH_MAX], wdir[PATH_MAX];

	int i = 1;
	for (; i < argc; i++) {
		const char *a = argv[i];
		int more = i + 1 < argc;
		if (!strcmp(a, "--")) {
			i++;
			break;
		} else if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
			print_usage(stdout);
			return 0;
		} else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
			r.quiet = 1;
		} else if (!strcmp(a, "-v") || !strcmp(a, "--verbose")) {
			r.verbose = 1;
		} else if (!strcmp(a, "--keep-workdir")) {
			r.keep = 1;
		} else if (!strcmp(a, "--resume")) {
			r.resume = 1;
		} else if (!more && a[0] == '-') {
			fprintf(stderr, "povpress render: unknown option or missing value '%s'\n", a);
			print_usage(stderr);
			return 2;
		} else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
			r.out = argv[++i];
		} else if (!strcmp(a, "-W") || !strcmp(a, "--width")) {
			if (args_int(argv[++i], 1, 65535, &r.w))
				goto bad;
		} else if (!strcmp(a, "-H") || !strcmp(a, "--height")) {
			if (args_int(argv[++i], 1, 65535, &r.h))
				goto bad;
		} else if (!strcmp(a, "--target")) {
			if (args_double(argv[++i], 1e-12, 1e6, &r.target))
				goto bad;
		} else if (!strcmp(a, "--budget")) {
			if (args_double(argv[++i], 1e-3, 1e9, &r.budget))
				goto bad;
		} else if (!strcmp(a, "--prelaunch")) {
			if ((r.prelaunch = name_index(argv[++i], prelaunch_names, 3)) < 0)
				goto bad;
		} else if (!strcmp(a, "--cost-job")) {
			if (args_double(argv[++i], 1e-9, 1e6, &r.user_cost_job))
				goto bad;
		} else if (!strcmp(a, "--cost-sample")) {
			if (args_double(argv[++i], 1e-15, 1e3, &r.user_cost_sample))
				goto bad;
		} else if (!strcmp(a, "--radiosity-scale")) {
			if (args_int(argv[++i], 0, 8, &r.user_rad_scale) ||
			    (r.user_rad_scale & (r.user_rad_scale - 1)))
				goto bad;
		} else if (!strcmp(a, "--timeout")) {
			if (args_double(argv[++i], 1e-3, 1e9, &r.timeout))
				goto bad;
		} else if (!strcmp(a, "--max-passes")) {
			if (args_int(argv[++i], 0, 1000, &r.max_passes))
				goto bad;
		} else if (!strcmp(a, "--jobs") || !strcmp(a, "-j")) {
			if (args_int(argv[++i], 1, 1024, &r.jobs))
				goto bad;
		} else if (!strcmp(a, "--workdir")) {
			r.workdir = argv[++i];
			r.user_workdir = 1;
		} else if (!strcmp(a, "--error-map")) {
			r.error_map = argv[++i];
		} else if (!strcmp(a, "--report")) {
			r.report = argv[++i];
		} else if (!strcmp(a, "--sampler")) {
			const char *m = argv[++i];
			r.aa = !strcmp(m, "aa");
			r.grid = r.aa ? PLAN_GRID_NEVER : plan_grid_parse(m);
			if (r.grid < 0)
				goto bad;
		} else if (!strcmp(a, "--final")) {
			int f = name_index(argv[++i], final_names, 4);
			if (f < 0)
				goto bad;
			/* blend: auto's blend, not filtered */
			r.final = f == 3 ? ACC_FINAL_AUTO : (enum accum_final)f;
			r.filter = f == 0;
		} else if (a[0] == '-' && a[1]) {
			fprintf(stderr, "povpress render: unknown option '%s'\n", a);
			print_usage(stderr);
			return 2;
		} else if (!r.scene) {
			r.scene = a;
		} else {
			fprintf(stderr, "povpress render: unexpected argument '%s' (POV-Ray options go "
				"after --)\n", a);
			print_usage(stderr);
			return 2;
		}
		continue;
bad:
		fprintf(stderr, "povpress render: bad value '%s' for %s\n", argv[i], a);
		return 2;
	}
	r.extra = (const char *const *)argv + i;
	r.nextra = (size_t)(argc - i);
	if (!r.scene || !r.out) {
		fprintf(stderr, "povpress render: %s\n",
			!r.scene ? "no scene given" : "no output given (-o OUT.exr)");
		print_usage(stderr);
		return 2;
	}
	if (!r.error_map) {
		size_t len = strlen(r.out);
		if (len > 4 && !strcmp(r.out + len - 4, ".exr"))
			len -= 4;
		snprintf(emap, sizeof emap, "%.*s.errors.exr", (int)len, r.out);
		r.error_map = emap;
	}
	if (!r.workdir) {
		snprintf(wdir, sizeof wdir, "%s.work", r.out);
		r.workdir = wdir;
	}
	snprintf(r.radfile, sizeof r.radfile, "%s/radiosity.rca", r.workdir);
	r.cores = pov_cpu_count();
	if (!r.jobs)
		r.jobs = 4 * r.cores;
	r.tty = isatty(2);

	char err[1024];
	int ret = 1;
	struct lpr_result res = {0};
	struct scene_keys keys;
	if (scene_read(r.scene, &keys)) {	/* a regular file, readable */
		errbuf_printf(err, sizeof err, "cannot read scene '%s': %s", r.scene,
			      scene_strerror(errno));
		goto fail_early;
	}
	r.rad_named = keys.radiosity;
	r.focal = r.grid == PLAN_GRID_LARGE && !r.aa && scene_focal_blur(&keys);
	r.gamma = scene_assumed_gamma(&keys);
	{
		struct pov_job probe = { .scene = r.scene };
		char bin[PATH_MAX];
		if (pov_find_binary(&probe, bin, sizeof bin, err, sizeof err))
			goto fail_early;
	}
	if (check_writable("output", r.out, err, sizeof err) ||
	    check_writable("error map", r.error_map, err, sizeof err) ||
	    (r.report && check_writable("report", r.report, err, sizeof err)))
		goto fail_early;
	if (pov_signals_catch(err, sizeof err))
		goto fail_early;

	char ident[8192];
	if (run_identity(&r, ident, sizeof ident)) {
		errbuf_printf(err, sizeof err, "too many POV-Ray options");
		goto fail;
	}
	int first_pass = 1;
	/* under a budget, the cost map, 1 everywhere until the base pass's
	 * progress lines (base_cost_map()) or a pass's renders set it */
	if (r.budget > 0.0) {
		r.cost_map = malloc((size_t)r.w * r.h * sizeof *r.cost_map);
		if (!r.cost_map) {
			errbuf_printf(err, sizeof err, "out of memory");
			goto fail;
		}
		for (size_t q = 0; q < (size_t)r.w * r.h; q++)
			r.cost_map[q] = 1.0f;
	}
	if (r.resume) {
		char *old = file_read_text(wpath(&r, "run.txt"));
		if (!old) {
			errbuf_printf(err, sizeof err, "cannot resume: no run in work directory '%s'",
				      r.workdir);
			goto fail;
		}
		int same = !strcmp(old, ident);
		free(old);
		if (!same) {
			errbuf_printf(err, sizeof err, "cannot resume: work directory '%s' holds a "
				      "run of another scene, size or POV-Ray options (see its run.txt)",
				      r.workdir);
			goto fail;
		}
		if (load_progress(&r, err, sizeof err) ||
		    accum_read(wpath(&r, "accum.exr"), &r.acc, err, sizeof err))
			goto fail;
		if (r.acc.w != r.w || r.acc.h != r.h) {
			errbuf_printf(err, sizeof err, "cannot resume: the accumulation in '%s' is "
				      "%dx%d", r.workdir, r.acc.w, r.acc.h);
			goto fail;
		}
		first_pass = r.passes[r.npasses - 1].pass + 1;
		progress(&r, "resuming after pass %d (%.1f s so far)", first_pass - 1, r.prev_wall);
	} else {
		if (file_mkdirs(r.workdir, "work directory", err, sizeof err)) {
			free(r.cost_map);
			goto fail_early;
		}
		/* a fresh run: forget a previous one here */
		unlink(wpath(&r, "progress.txt"));
		unlink(wpath(&r, "accum.exr"));
		if (file_write_text(wpath(&r, "run.txt"), ident, err, sizeof err) ||
		    pov_safe_dir(r.workdir, r.povdir, sizeof r.povdir, err, sizeof err))
			goto fail;
		int brc = base_pass(&r, err, sizeof err);
		if (brc && !r.user_workdir && !r.keep)
			remove_workdir(r.workdir);	/* nothing in it worth resuming */
		if (brc == POV_INTERRUPTED)
			goto interrupted;
		if (brc)
			goto fail;
		if (image_write_exr_raw(wpath(&r, "accum.exr"), &r.acc, err, sizeof err) ||
		    save_progress(&r, err, sizeof err))
			goto fail;
	}

	if (pov_safe_dir(r.workdir, r.povdir, sizeof r.povdir, err, sizeof err))
		goto fail;

	r.est = malloc((size_t)r.w * r.h * sizeof(*r.est));
	r.noise = malloc((size_t)r.w * r.h * sizeof(*r.noise));
	r.take = malloc((size_t)r.w * r.h * sizeof *r.take);
	if (!r.est || !r.noise || !r.take) {
		errbuf_printf(err, sizeof err, "out of memory");
		goto fail;
	}

	/* refinement passes */
	int pass = first_pass;
	for (;;) {
		double ta = now_s();
		lpr_result_release(&res);
		if (analyse(&r, &res, err, sizeof err))
			goto fail;
		size_t npx = (size_t)r.w * r.h;
		double est;
		if (estimate(&r, &res, &est, err, sizeof err))
			goto fail;
		long left = 0;
		for (size_t k = 0; k < npx; k++)
			left += r.est[k] > r.target;
		struct pass_rec *last = &r.passes[r.npasses - 1];
		last->est_relmse = est;
		last->analysis_s = now_s() - ta;
		last->wall_s += last->analysis_s;
		double tw = now_s();
		/* compressed once, to time it for a budget's final reserve;
		 * without a budget only the end compresses */
		const int timed = r.budget > 0.0 && r.comp_s == 0.0;
		if (save_progress(&r, err, sizeof err) ||
		    write_output(&r, &res, 0, NULL, timed, err, sizeof err))
			goto fail;
		r.write_s = now_s() - tw;
		if (timed)
			r.comp_s = r.write_s > 1e-6 ? r.write_s : 1e-6;
		if (r.renders_end > 0.0)
			r.tail_s = now_s() - r.renders_end;
		double el = elapsed(&r);
		if (r.budget > 0.0)
			progress(&r, "pass %d: estimated relMSE %.3g (target %.3g), %ld pixels above "
				 "it, %.1f s elapsed, %.1f s left", last->pass, est, r.target, left, el,
				 r.budget - el > 0 ? r.budget - el : 0.0);
		else
			progress(&r, "pass %d: estimated relMSE %.3g (target %.3g), %ld pixels above "
				 "it, %.1f s elapsed", last->pass, est, r.target, left, el);
		progress_end(&r);
		if (pov_signal_received())
			goto interrupted;
		if (pass > r.max_passes) {
			r.stop = "max passes";
			break;
		}
		int rc = refine_pass(&r, pass, err, sizeof err);
		if (rc == POV_INTERRUPTED) {
			/* what finished is merged and saved: show it */
			lpr_result_release(&res);
			double e_int;
			if (analyse(&r, &res, err, sizeof err) == 0 &&
			    estimate(&r, &res, &e_int, err, sizeof err) == 0)
				write_output(&r, &res, r.filter, NULL, 1, err, sizeof err);
			goto interrupted;
		}
		if (rc < 0)
			goto fail;
		if (rc == PASS_STOP)
			break;
		pass++;
	}

	r.passes[r.npasses - 1].cpu_s += prelaunch_end(&r);	/* guesses for a pass not run */

	/* the final image, error map and report.  The planner and the stop
	 * went by the samples' errors; the error map and the estimate are the
	 * final image's: under --final auto, the blend's predicted error where it
	 * takes some of the fit (under --final reconstruction, still the
	 * samples') */
	r.took = accum_final_choose(&r.acc, res.fit, res.error, res.leverage, r.noise, r.final,
				    r.take, r.est);
	if (write_output(&r, &res, r.filter, r.est, 1, err, sizeof err))
		goto fail;
	double est = 0.0;
	for (size_t k = 0; k < (size_t)r.w * r.h; k++)
		est += r.est[k];
	est /= (double)r.w * r.h;
	if (write_error_map(&r, &res, err, sizeof err))
		goto fail;
	if (r.report && write_report(&r, est, err, sizeof err))
		goto fail;
	if (!r.quiet && (r.tty || r.verbose)) {
		double cpu = self_cpu();	/* povpress's own, and its POV-Ray runs' */
		for (size_t k = 0; k < r.npasses; k++)
			cpu += r.passes[k].cpu_s;
		fprintf(stderr, "povpress render: %s after %zu passes: estimated relMSE %.3g, "
			"%.1f s, %.1f CPU s; wrote %s", r.stop, r.npasses - 1, est, elapsed(&r), cpu,
			r.out);
		if (r.final == ACC_FINAL_AUTO)
			fprintf(stderr, " (%ld of %d pixels blended with the fit)", r.took,
				r.w * r.h);
		fputc('\n', stderr);
	}
	if (!r.keep && !r.user_workdir) {
		remove_workdir(r.workdir);
		if (strcmp(r.povdir, r.workdir))
			unlink(r.povdir);	/* the link pov_safe_dir() made */
	}
	ret = 0;
	goto done;

interrupted:
	progress_end(&r);
	fprintf(stderr, "povpress render: interrupted (signal %d); %s; the work is in '%s' "
		"(--resume continues)\n", pov_signal_received(),
		access(r.out, F_OK) == 0 ? "the output holds the best image so far" :
					   "no output written",
		r.workdir);
	ret = 130;
	goto done;
fail:
	progress_end(&r);
	fprintf(stderr, "povpress render: %s\n", err);
	ret = 1;
	goto done;
fail_early:
	fprintf(stderr, "povpress render: %s\n", err);
	return 1;
done:
	prelaunch_end(&r);
	pov_signals_restore();
	lpr_result_release(&res);
	image_release(&r.acc);
	free(r.passes);
	free(r.est);
	free(r.noise);
	free(r.take);
	free(r.cost_map);
	return ret;
}
