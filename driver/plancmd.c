/*
 * plancmd.c - `povpress plan` and `povpress merge`: the render loop's
 * planning and merging steps as commands of their own, so that region
 * renders can run anywhere (sh, xargs -P, GNU parallel, a farm).
 */
#include "driver/accum.h"
#include "driver/args.h"
#include "driver/commands.h"
#include "driver/errbuf.h"
#include "driver/files.h"
#include "driver/image.h"
#include "driver/plan.h"
#include "driver/povray.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char plan_usage[] =
	"usage: povpress plan ANALYSIS.exr --scene SCENE.pov -o DIR [--state ACCUM.exr]\n"
	"                     [--pass N] [--target RELMSE] [--budget SECONDS]\n"
	"                     [--cost-job SECONDS] [--cost-sample SECONDS]\n"
	"                     [--max-regions N] [--sampler auto|grid|scale|jitter]\n"
	"                     [--threads N]\n"
	"                     [--radiosity FILE]\n"
	"                     [-- POVRAY_OPTIONS...]\n"
	"\n"
	"Decide which pixels need more samples and write, into DIR:\n"
	"  mask.exr      per pixel: samples (samples requested), scale (the resolution\n"
	"                scale it is rendered at, 0: none), chosen (1 where the\n"
	"                planner chose the pixel; rectangles also cover some others)\n"
	"  regions.tsv   the packed rectangles: pass x0 y0 x1 y1 scale output depth\n"
	"                edges (the last two 0 but for render's antialiased renders)\n"
	"  jobs.txt      one complete povray command line per region, for sh,\n"
	"                'xargs -P N -I{} sh -c {}' or GNU parallel\n"
	"Then run the jobs and fold their images in with 'povpress merge'.\n"
	"\n"
	"ANALYSIS.exr is 'povpress analyze' output for the current image (its R, G, B\n"
	"and error channels are used).  The image size is the analysis's.\n"
	"\n"
	"options:\n"
	"  --scene FILE        the scene the jobs render (required)\n"
	"  -o, --outdir DIR    where the files go, created if missing (required)\n"
	"  --state FILE        the accumulation ('povpress merge' output): samples so far\n"
	"                      and scales used (default: one sample per pixel)\n"
	"  --pass N            pass number, used in file names (default 1)\n"
	"  --target RELMSE     estimated relMSE to plan for (default 0.001)\n"
	"  --budget SECONDS    cost this pass may spend, in CPU seconds (default none)\n"
	"  --cost-job S        cost of one POV-Ray run (default 0.05; 'render' measures\n"
	"                      it on the base pass and reports it)\n"
	"  --cost-sample S     cost of one sample (default 2e-6; measured likewise)\n"
	"  --max-regions N     at most N rectangles (default 8)\n"
	"  --sampler S         how scales 4, 8 and 16 are rendered, as in 'render': auto\n"
	"                      (default: grid where scaling's frame would exceed 1\n"
	"                      Mpixel; render's antialiased scale 2, where the error\n"
	"                      sits in few pixels or at edges (and its target for\n"
	"                      such a pass at edges), and its choice of jitter,\n"
	"                      where samples are cheap, are render's alone), grid (twice\n"
	"                      the size with +AM1 +A0.0\n"
	"                      +R(scale/2) +J0.75), scale (scale times the size, no\n"
	"                      antialiasing) or jitter (grid, and no scale 2)\n"
	"  --threads N         POV-Ray threads per job, +WT (default 1)\n"
	"  --radiosity FILE    radiosity data the base pass saved (+RFO): jobs load it\n"
	"  -- OPTIONS          passed to every POV-Ray job (as given to the base pass)\n"
	"Every job also gets Declare=POVPRESS_PASS=N (the base pass had 0), which a\n"
	"scene can test to load what its base pass saved (radiosity, photons).\n"
	"  -h, --help          this text\n"
	"\n"
	"Prints the outcome and the estimated relMSE; exits 0 also when nothing needs\n"
	"rendering (then jobs.txt is empty).\n";

static const char merge_usage[] =
	"usage: povpress merge ACCUM.exr REGIONS.tsv -o NEW.exr [--skip-missing]\n"
	"       povpress merge --init BASE.exr -o ACCUM.exr\n"
	"\n"
	"Fold finished region renders into an accumulation: every sample a pixel has\n"
	"so far, as their mean (R, G, B), count (samples), variance (var.R/G/B), the\n"
	"pass that last refined it (pass) and the resolution scales it has (scales).\n"
	"A pixel that already has a region's scale keeps its samples (the same sample\n"
	"positions again would add nothing).  --init makes the accumulation of a base\n"
	"render (one sample per pixel).  R, G, B of an accumulation are the image.\n"
	"A region of scale 0 is an antialiased render: at scale 1 (render --sampler\n"
	"aa), folded as the samples it proves worth; or at twice the size (render's\n"
	"auto in scale 2's place, depth 3 to 5: its +R), a pixel with one sample\n"
	"taking it as the cells POV-Ray cut it into (16 where its render pixels\n"
	"agree, up to 64 at +R3 and 256 at +R4, and for a few pixels at +R5 too;\n"
	"taken for edges, edges 1, up to 1024 at +R5, and their spread measures\n"
	"its noise; taken for spread error, POV-Ray's +AM1: edges 2 at +A0.03 and\n"
	"a grid of 2^(depth-1) a side, edges 3 at +A0.1 +R3 and edges 4 at +A0.3\n"
	"+R2, 36 and 16 samples a pixel it subdivided) and every pixel as having had\n"
	"scale 2, as render folds it.  A regions file without the depth and edges\n"
	"columns (before povpress recorded them) has each such render taken as +R4\n"
	"for a few pixels.\n"
	"\n"
	"options:\n"
	"  -o, --output FILE   the new accumulation (may be ACCUM.exr itself)\n"
	"  --init FILE         start from this base render instead\n"
	"  --skip-missing      a region whose image is missing keeps its previous\n"
	"                      estimate (with a warning) instead of failing\n"
	"  -h, --help          this text\n";

/* The analysis's fit (R, G, B) and error, w*h*3 and w*h floats. */
static int read_analysis(const char *path, struct image *img, float **fit, float **press,
			 char *err, size_t errlen)
{
	if (image_read_exr(path, img, err, errlen))
		return -1;
	int ir = image_channel(img, "R"), ig = image_channel(img, "G"),
	    ib = image_channel(img, "B"), ie = image_channel(img, "error");
	if (ir < 0 || ig < 0 || ib < 0 || ie < 0) {
		errbuf_printf(err, errlen, "'%s' is not an analysis: it needs R, G, B and error "
			      "channels (write one with 'povpress analyze')", path);
		return -1;
	}
	size_t n = (size_t)img->w * img->h;
	*fit = malloc(n * 3 * sizeof(float));
	*press = malloc(n * sizeof(float));
	if (!*fit || !*press) {
		errbuf_printf(err, errlen, "out of memory");
		return -1;
	}
	for (size_t i = 0; i < n; i++) {
		const float *p = img->px + i * img->nch;
		(*fit)[3 * i] = p[ir];
		(*fit)[3 * i + 1] = p[ig];
		(*fit)[3 * i + 2] = p[ib];
		(*press)[i] = p[ie];
	}
	return 0;
}

int cmd_plan(int argc, char **argv)
{
	const char *in = NULL, *outdir = NULL, *scene = NULL, *state = NULL, *radiosity = NULL;
	int pass = 1, threads = 1;
	struct plan_params pp;
	plan_params_init(&pp);
	pp.max_regions = 8;
	pp.grid = PLAN_GRID_LARGE;
	int i = 1;
	for (; i < argc; i++) {
		const char *a = argv[i];
		int more = i + 1 < argc;
		if (!strcmp(a, "--")) {
			i++;
			break;
		} else if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
			fputs(plan_usage, stdout);
			return 0;
		} else if (a[0] == '-' && a[1] && !more) {
			fprintf(stderr, "povpress plan: unknown option or missing value '%s'\n%s", a,
				plan_usage);
			return 2;
		} else if (!strcmp(a, "-o") || !strcmp(a, "--outdir")) {
			outdir = argv[++i];
		} else if (!strcmp(a, "--scene")) {
			scene = argv[++i];
		} else if (!strcmp(a, "--state")) {
			state = argv[++i];
		} else if (!strcmp(a, "--radiosity")) {
			radiosity = argv[++i];
		} else if (!strcmp(a, "--pass")) {
			if (args_int(argv[++i], 0, 99, &pass))
				goto bad;
		} else if (!strcmp(a, "--threads")) {
			if (args_int(argv[++i], 1, 1024, &threads))
				goto bad;
		} else if (!strcmp(a, "--sampler")) {
			const char *m = argv[++i];
			if ((pp.grid = plan_grid_parse(m)) < 0) {
				fprintf(stderr,
					"povpress plan: --sampler takes auto, grid, scale or jitter, not '%s'\n",
					m);
				return 2;
			}
		} else if (!strcmp(a, "--max-regions")) {
			if (args_int(argv[++i], 1, 100000, &pp.max_regions))
				goto bad;
		} else if (!strcmp(a, "--target")) {
			if (args_double(argv[++i], 1e-12, 1e6, &pp.target))
				goto bad;
		} else if (!strcmp(a, "--budget")) {
			if (args_double(argv[++i], 1e-6, 1e9, &pp.budget))
				goto bad;
		} else if (!strcmp(a, "--cost-job")) {
			if (args_double(argv[++i], 0.0, 1e6, &pp.cost_job))
				goto bad;
		} else if (!strcmp(a, "--cost-sample")) {
			if (args_double(argv[++i], 1e-15, 1e3, &pp.cost_sample))
				goto bad;
		} else if (a[0] == '-' && a[1]) {
			fprintf(stderr, "povpress plan: unknown option '%s'\n%s", a, plan_usage);
			return 2;
		} else if (!in) {
			in = a;
		} else {
			fprintf(stderr, "povpress plan: unexpected argument '%s' (POV-Ray options go "
				"after --)\n%s", a, plan_usage);
			return 2;
		}
		continue;
bad:
		fprintf(stderr, "povpress plan: bad value '%s' for %s\n", argv[i], a);
		return 2;
	}
	if (!in || !outdir || !scene) {
		fprintf(stderr, "povpress plan: %s\n%s",
			!in ? "no analysis given" : !outdir ? "no output directory given (-o DIR)" :
							      "no scene given (--scene SCENE.pov)",
			plan_usage);
		return 2;
	}

	char err[1024], tmp[PATH_MAX + 16], path[PATH_MAX];
	int rc = 1;
	struct image an = {0}, acc = {0}, mask = {0};
	float *fit = NULL, *press = NULL;
	struct plan pl = {0};
	char **outs = NULL;
	const char **extra = NULL;
	if (read_analysis(in, &an, &fit, &press, err, sizeof err))
		goto fail;
	if (state) {
		if (accum_read(state, &acc, err, sizeof err))
			goto fail;
		if (acc.w != an.w || acc.h != an.h) {
			errbuf_printf(err, sizeof err, "state '%s' is %dx%d but the analysis is %dx%d",
				      state, acc.w, acc.h, an.w, an.h);
			goto fail;
		}
	} else {
		/* one sample per pixel, valued as the fit */
		struct image rgb = {0};
		static const char *const n3[3] = { "R", "G", "B" };
		if (image_init(&rgb, an.w, an.h, 3, n3, err, sizeof err))
			goto fail;
		memcpy(rgb.px, fit, sizeof(float) * 3 * (size_t)an.w * an.h);
		int r2 = accum_from_base(&rgb, in, &acc, err, sizeof err);
		image_release(&rgb);
		if (r2)
			goto fail;
	}
	if (file_mkdirs(outdir, "directory", err, sizeof err))
		goto fail;
	if (plan_make(&acc, press, fit, &pp, &pl, err, sizeof err))
		goto fail;

	/* mask.exr */
	static const char *const mnames[3] = { "samples", "scale", "chosen" };
	if (image_init(&mask, an.w, an.h, 3, mnames, err, sizeof err))
		goto fail;
	for (size_t k = 0; k < (size_t)an.w * an.h; k++) {
		mask.px[3 * k] = pl.scale[k] * pl.scale[k];
		mask.px[3 * k + 1] = pl.scale[k];
		mask.px[3 * k + 2] = pl.chosen[k];
	}
	snprintf(path, sizeof path, "%s/mask.exr", outdir);
	if (image_write_exr(path, &mask, err, sizeof err))
		goto fail;

	/* the jobs */
	size_t nextra = (size_t)(argc - i);
	outs = calloc(pl.nregions + 1, sizeof(char *));
	extra = calloc(nextra + 4, sizeof(char *));
	const char **jextra = calloc(nextra + 4, sizeof(char *));
	if (!outs || !extra || !jextra) {
		free(jextra);
		errbuf_printf(err, sizeof err, "out of memory");
		goto fail;
	}
	struct pov_job base = {0};
	base.scene = scene;
	base.width = an.w;
	base.height = an.h;
	base.threads = threads;
	base.workdir = outdir;
	base.extra = extra;
	for (size_t k = 0; k < nextra; k++)
		extra[k] = argv[i + (int)k];
	base.nextra = nextra;
	char passno[16];
	snprintf(passno, sizeof passno, "%d", pass);
	const struct pov_define pd = { "POVPRESS_PASS", passno };
	base.defines = &pd;
	base.ndefines = 1;
	base.radiosity = radiosity;
	base.radiosity_mode = POV_RAD_LOAD;
	snprintf(path, sizeof path, "%s/jobs.txt", outdir);
	FILE *f = file_begin(path, tmp, sizeof tmp, err, sizeof err);
	if (!f) {
		free(jextra);
		goto fail;
	}
	for (size_t k = 0; k < pl.nregions; k++) {
		char name[PATH_MAX];
		plan_output_name(name, sizeof name, outdir, pass, k, pl.regions[k].scale);
		outs[k] = strdup(name);
		struct pov_region reg;
		struct pov_job job;
		char *line = NULL;
		if (!outs[k]) {
			errbuf_printf(err, sizeof err, "out of memory");
		} else {
			plan_job(&base, &pl.regions[k], outs[k], &reg, jextra, &job);
			if (pov_shell_line(&job, &line, err, sizeof err) == 0) {
				fprintf(f, "%s\n", line);
				free(line);
				continue;
			}
		}
		file_abort(f, tmp);
		free(jextra);
		goto fail;
	}
	free(jextra);
	if (file_commit(f, tmp, path, err, sizeof err))
		goto fail;
	snprintf(path, sizeof path, "%s/regions.tsv", outdir);
	if (plan_regions_save(path, &pl, pass, outs, err, sizeof err))
		goto fail;
	printf("%s: estimated relMSE %.6g (target %.6g)", plan_outcome_name(pl.outcome),
	       pl.est_relmse, pp.target);
	if (pl.outcome == PLAN_REFINE)
		printf(", %zu regions, %ld pixels (%ld chosen), %.0f samples, predicted relMSE "
		       "%.6g, cost %.3g s", pl.nregions, pl.pixels, pl.chosen_pixels, pl.samples,
		       pl.est_after, pl.cost);
	printf("\n");
	rc = 0;
	goto done;
fail:
	fprintf(stderr, "povpress plan: %s\n", err);
done:
	if (outs)
		for (size_t k = 0; k < pl.nregions; k++)
			free(outs[k]);
	free(outs);
	free(extra);
	plan_release(&pl);
	free(fit);
	free(press);
	image_release(&an);
	image_release(&acc);
	image_release(&mask);
	return rc;
}

int cmd_merge(int argc, char **argv)
{
	const char *accp = NULL, *regp = NULL, *outp = NULL, *init = NULL;
	int skip = 0;
	for (int i = 1; i < argc; i++) {
		const char *a = argv[i];
		int more = i + 1 < argc;
		if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
			fputs(merge_usage, stdout);
			return 0;
		} else if (!strcmp(a, "--skip-missing")) {
			skip = 1;
		} else if ((!strcmp(a, "-o") || !strcmp(a, "--output")) && more) {
			outp = argv[++i];
		} else if (!strcmp(a, "--init") && more) {
			init = argv[++i];
		} else if (a[0] == '-' && a[1]) {
			fprintf(stderr, "povpress merge: unknown option or missing value '%s'\n%s", a,
				merge_usage);
			return 2;
		} else if (!accp) {
			accp = a;
		} else if (!regp) {
			regp = a;
		} else {
			fprintf(stderr, "povpress merge: unexpected argument '%s'\n%s", a, merge_usage);
			return 2;
		}
	}
	if (!outp || (init ? accp != NULL : (!accp || !regp))) {
		fprintf(stderr, "povpress merge: %s\n%s",
			!outp ? "no output given (-o FILE)" :
			init ? "--init takes no accumulation or regions" :
			       "give an accumulation and a regions file (or --init BASE.exr)",
			merge_usage);
		return 2;
	}
	char err[1024];
	int rc = 1;
	struct image acc = {0}, img = {0};
	struct plan_region *regs = NULL;
	char **outs = NULL;
	int *passes = NULL;
	size_t n = 0;
	if (init) {
		if (image_read_exr(init, &img, err, sizeof err) ||
		    accum_from_base(&img, init, &acc, err, sizeof err) ||
		    image_write_exr(outp, &acc, err, sizeof err))
			goto fail;
		rc = 0;
		goto done;
	}
	if (accum_read(accp, &acc, err, sizeof err) ||
	    plan_regions_read(regp, &regs, &outs, &passes, &n, err, sizeof err))
		goto fail;
	long total = 0;
	int missing = 0;
	for (size_t k = 0; k < n; k++) {
		const struct plan_region *g = &regs[k];
		long folded = 0;
		char why[900];
		if (access(outs[k], F_OK) && skip) {
			fprintf(stderr, "povpress merge: warning: '%s' is missing; its pixels keep "
				"their samples\n", outs[k]);
			missing++;
			continue;
		}
		if (plan_merge_file(&acc, outs[k], g, passes[k], &folded, why, sizeof why)) {
			errbuf_printf(err, sizeof err, "region %zu of '%s' (%s): %s", k + 1, regp,
				      outs[k], why);
			goto fail;
		}
		total += folded;
	}
	if (image_write_exr(outp, &acc, err, sizeof err))
		goto fail;
	printf("merged %zu regions (%d missing): %ld pixels took new samples\n", n - missing,
	       missing, total);
	rc = 0;
	goto done;
fail:
	fprintf(stderr, "povpress merge: %s\n", err);
done:
	for (size_t k = 0; k < n; k++)
		free(outs[k]);
	free(outs);
	free(regs);
	free(passes);
	image_release(&acc);
	image_release(&img);
	return rc;
}
