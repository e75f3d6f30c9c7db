/*
 * test_povray.c - unit tests for driver/povray.c (the POV-Ray runner).
 *
 * Argument vectors, shell lines and statistics are checked without
 * POV-Ray, the statistics against output captured from povray 3.7.0.10
 * (tests/data/povray/).  The pool is checked with a fake "povray" shell
 * script where only the runner's behaviour matters (concurrency, crashes,
 * error extraction), and with the real povray where POV-Ray's matters
 * (paths with spaces and quotes, regions, parse errors, timeouts, signals).
 * A missing povray fails the tests rather than skipping them.
 *
 * Files go in a fresh mkdtemp() directory whose own name has a space.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "driver/image.h"
#include "driver/povray.h"
#include "driver/povstate.h"
#include "tests/testutil.h"

#define DATA "tests/data/povray/"

static char fake_bin[PATH_MAX];

static void write_file(const char *path, const char *text)
{
	FILE *f = fopen(path, "w");

	if (!f)
		fail_msg("cannot write '%s': %s", path, strerror(errno));
	fputs(text, f);
	fclose(f);
}

/* A malloc'd copy of a whole file, or NULL. */
static char *read_file(const char *path)
{
	FILE *f = fopen(path, "rb");
	char *s;
	long n;

	if (!f)
		return NULL;
	fseek(f, 0, SEEK_END);
	n = ftell(f);
	fseek(f, 0, SEEK_SET);
	s = malloc((size_t)n + 1);
	assert_non_null(s);
	assert_int_equal(fread(s, 1, (size_t)n, f), (size_t)n);
	s[n] = '\0';
	fclose(f);
	return s;
}

static int exists(const char *path)
{
	struct stat st;

	return lstat(path, &st) == 0;
}

/* Run line with /bin/sh -c, output discarded; its exit status or -1. */
static int sh_c(const char *line)
{
	pid_t pid;
	int st;

	fflush(NULL);
	pid = fork();
	assert_true(pid >= 0);
	if (pid == 0) {
		if (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr))
			_exit(126);
		execl("/bin/sh", "sh", "-c", line, (char *)NULL);
		_exit(127);
	}
	assert_int_equal(waitpid(pid, &st, 0), pid);
	return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static void pause_s(double s)
{
	struct timespec ts = { (time_t)s, (long)((s - (double)(time_t)s) * 1e9) };

	while (nanosleep(&ts, &ts) && errno == EINTR)
		;
}

static double now_s(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void mkdir_p(const char *path)
{
	if (mkdir(path, 0755) && errno != EEXIST)
		fail_msg("cannot make '%s': %s", path, strerror(errno));
}

/* Live processes whose command line contains tag (letters, digits, '-'). */
static int count_procs(const char *tag)
{
	char cmd[256], line[64];
	FILE *p;
	int n = 0;

	/* "[x]rest" matches tag but not the shell running pgrep. */
	snprintf(cmd, sizeof(cmd), "pgrep -c -f -- '[%c]%s'", tag[0], tag + 1);
	p = popen(cmd, "r");
	assert_non_null(p);
	if (fgets(line, sizeof(line), p))
		n = atoi(line);
	pclose(p);
	return n;
}

/* Wait up to timeout_s until count_procs(tag) == want; returns the count. */
static int wait_procs(const char *tag, int want, double timeout_s)
{
	double end = now_s() + timeout_s;
	int n;

	while ((n = count_procs(tag)) != want && now_s() < end)
		pause_s(0.05);
	return n;
}

static const char tiny_scene[] =
	"#version 3.7;\n"
	"global_settings { assumed_gamma 1.0 }\n"
	"#include \"tiny_colours.inc\"\n"
	"background { color rgb <0.2, 0.3, 0.4> }\n"
	"camera { location <0, 0, -3> look_at 0 }\n"
	"light_source { <2, 4, -3> color rgb 1 }\n"
	"sphere { 0, 1 pigment { color Tiny_Colour } }\n";

/* The scene, with its include beside it, in dir; returns the scene path. */
static const char *make_tiny_scene(char *path, size_t len, const char *dir, const char *name)
{
	char inc[PATH_MAX];

	mkdir_p(dir);
	if (snprintf(inc, sizeof(inc), "%s/tiny_colours.inc", dir) >= (int)sizeof(inc) ||
	    snprintf(path, len, "%s/%s", dir, name) >= (int)len)
		fail_msg("path too long in '%s'", dir);
	write_file(inc, "#declare Tiny_Colour = rgb <1, 0.5, 0.2>;\n");
	write_file(path, tiny_scene);
	return path;
}

/* job: render a tiny scene, made as name in scratch directory sub, into
 * sub/outname at w x h; scene and out are PATH_MAX buffers for the paths. */
static void tiny_job(struct pov_job *job, char *scene, char *out, const char *sub,
		     const char *name, const char *outname, int w, int h)
{
	char dir[PATH_MAX], rel[PATH_MAX];

	memset(job, 0, sizeof(*job));
	make_tiny_scene(scene, PATH_MAX, scratch(dir, sizeof(dir), sub), name);
	snprintf(rel, sizeof(rel), "%s/%s", sub, outname);
	job->scene = scene;
	job->output = scratch(out, PATH_MAX, rel);
	job->width = w;
	job->height = h;
}

/* A scene that takes well over 10 s at 640x480 with +AM2 +A0 +R4. */
static const char slow_scene[] =
	"#version 3.7;\n"
	"global_settings { assumed_gamma 1.0 }\n"
	"camera { location <0, 2, -6> look_at 0 focal_point 0 aperture 0.5 blur_samples 100 }\n"
	"light_source { <2, 4, -3> color rgb 1 area_light x, z, 16, 16 jitter adaptive 0 }\n"
	"#for (i, 0, 40)\n"
	"  sphere { <mod(i, 7) - 3, 0, div(i, 7) - 2>, 0.4\n"
	"    pigment { color rgb <1, 0.5, 0.2> } finish { reflection 0.3 } }\n"
	"#end\n"
	"plane { y, -0.5 pigment { checker } }\n";

static const char *const slow_extra[] = { "+AM2", "+A0.0", "+R4" };

static void slow_job(struct pov_job *job, const char *scene, const char *out)
{
	memset(job, 0, sizeof(*job));
	job->scene = scene;
	job->output = out;
	job->width = 640;
	job->height = 480;
	job->threads = 1;
	job->extra = slow_extra;
	job->nextra = 3;
}

/*
 * A stand-in for povray, steered by $FAKE_MODE:
 *   args     write its arguments, NUL-terminated, to $FAKE_ARGS; make the output
 *   sleep    append "start end" wall times to $FAKE_LOG around a 0.3 s sleep
 *   fixture  copy $FAKE_FIXTURE to stderr and exit 1
 *   segv     kill itself with SIGSEGV
 *   noout    exit 0 without writing anything
 *   linger   write the output and a line, then sleep 1 s before exiting 0
 */
static const char fake_script[] =
	"#!/bin/sh\n"
	"out=\n"
	"for a in \"$@\"; do\n"
	"  case \"$a\" in +O*) out=${a#+O}; out=${out#\\\"}; out=${out%\\\"};; esac\n"
	"done\n"
	"case \"$FAKE_MODE\" in\n"
	"args) for a in \"$@\"; do printf '%s\\0' \"$a\"; done > \"$FAKE_ARGS\"; : > \"$out\";;\n"
	"sleep) s=$(date +%s.%N); sleep 0.3; e=$(date +%s.%N); echo \"$s $e\" >> \"$FAKE_LOG\";"
	" : > \"$out\";;\n"
	"fixture) cat \"$FAKE_FIXTURE\" >&2; exit 1;;\n"
	"segv) kill -SEGV $$;;\n"
	"noout) exit 0;;\n"
	"linger) echo whole > \"$out\"; echo 'Render Time: done' >&2; sleep 1; exit 0;;\n"
	"progress) printf 'Rendered 50 of 100 pixels (50%%)\\r' >&2;"
	" printf 'Rendered 10 of 100 pix' >&2; sleep 0.2;"
	" printf 'els (10%%)\\rRendered 40 of 100 pixels (40%%)\\r' >&2; sleep 0.2;"
	" printf 'Rendered 100 of 100 pixels (100%%)\\n' >&2; : > \"$out\";;\n"
	"finish) printf 'Rendered 10 of 100 pixels (10%%)\\r' >&2; sleep 0.1;"
	" printf 'Rendered 100 of 100 pixels (100%%)\\r' >&2; sleep 0.3; : > \"$out\";;\n"
	"slow) printf 'Rendered 10 of 100 pixels (10%%)\\r' >&2; sleep 0.1;"
	" printf 'Rendered 20 of 100 pixels (20%%)\\r' >&2; sleep 1; : > \"$out\";;\n"
	"*) exit 3;;\n"
	"esac\n";

static int setup_dir(void **state)
{
	(void)state;
	snprintf(scratch_dir, sizeof(scratch_dir), "/tmp/povpress test povray.XXXXXX");
	if (!mkdtemp(scratch_dir))
		return -1;
	snprintf(fake_bin, sizeof(fake_bin), "%s/fake-povray", scratch_dir);
	write_file(fake_bin, fake_script);
	if (chmod(fake_bin, 0755))
		return -1;
	unsetenv("POVPRESS_POVRAY");
	return 0;
}

static int teardown_dir(void **state)
{
	(void)state;
	return run("rm -rf '%s'", scratch_dir) == 0 ? 0 : -1;
}

static void assert_contains(const char *s, const char *part)
{
	if (!s || !strstr(s, part))
		fail_msg("\"%s\" does not contain \"%s\"", s ? s : "(null)", part);
}

static void assert_argv(char **argv, const char *const *want, int n)
{
	for (int i = 0; i < n; i++) {
		if (!argv[i])
			fail_msg("argv ends at %d, wanted '%s'", i, want[i]);
		if (strcmp(argv[i], want[i]))
			fail_msg("argv[%d] is '%s', wanted '%s'", i, argv[i], want[i]);
	}
	if (argv[n])
		fail_msg("argv has an extra element '%s'", argv[n]);
}

/* Run jobs in a pool; returns pov_pool_run()'s value. */
static int run_pool(const struct pov_job *jobs, size_t n, int max_jobs, double timeout_s,
		    int retries, struct pov_result *res)
{
	struct pov_pool_opts o;
	char err[512] = "";
	int rc;

	pov_pool_opts_init(&o);
	o.max_jobs = max_jobs;
	o.timeout_s = timeout_s;
	o.grace_s = 1.0;
	o.retries = retries;
	rc = pov_pool_run(jobs, n, &o, res, err, sizeof(err));
	if (rc < 0)
		print_message("pool: %s\n", err);
	return rc;
}

static void release_all(struct pov_result *res, size_t n)
{
	for (size_t i = 0; i < n; i++)
		pov_result_release(&res[i]);
}

/* ---- argument vectors --------------------------------------------------- */

static void test_argv_order_and_quoting(void **state)
{
	char dir[PATH_MAX], scene[PATH_MAX], out[PATH_MAX], want_l[PATH_MAX + 8],
	     want_i[PATH_MAX + 8], want_o[PATH_MAX + 8], err[512];
	static const struct pov_define defs[] = { { "AreaN", "5" }, { "Jitter", "-0.25" } };
	static const char *const extra[] = { "+AM2", "+A0.1", "+W32" };
	struct pov_job job = { 0 };
	char **argv;
	int argc;

	(void)state;
	make_tiny_scene(scene, sizeof(scene), scratch(dir, sizeof(dir), "argv dir"), "a b.pov");
	scratch(out, sizeof(out), "argv dir/out put.exr");
	job.scene = scene;
	job.output = out;
	job.width = 64;
	job.height = 48;
	job.threads = 3;
	job.defines = defs;
	job.ndefines = 2;
	job.extra = extra;
	job.nextra = 3;
	assert_int_equal(pov_argv_build(&job, &argv, &argc, err, sizeof(err)), 0);
	snprintf(want_l, sizeof(want_l), "+L\"%s\"", dir);
	snprintf(want_i, sizeof(want_i), "+I\"%s\"", scene);
	snprintf(want_o, sizeof(want_o), "+O\"%s\"", out);
	const char *const want[] = { "povray", "-D", "+FE", "-GR", "-V", "+W64", "+H48", "+WT3",
				     want_l, want_i, want_o, "Declare=AreaN=5",
				     "Declare=Jitter=-0.25", "+AM2", "+A0.1", "+W32" };
	assert_int_equal(argc, 16);
	assert_argv(argv, want, 16);
	pov_argv_free(argv);

	/* The binary: job->povray, then $POVPRESS_POVRAY, then "povray". */
	setenv("POVPRESS_POVRAY", "/opt/pov/bin/povray", 1);
	assert_int_equal(pov_argv_build(&job, &argv, NULL, err, sizeof(err)), 0);
	assert_string_equal(argv[0], "/opt/pov/bin/povray");
	pov_argv_free(argv);
	job.povray = "my-povray";
	assert_int_equal(pov_argv_build(&job, &argv, NULL, err, sizeof(err)), 0);
	assert_string_equal(argv[0], "my-povray");
	pov_argv_free(argv);
	unsetenv("POVPRESS_POVRAY");
	pov_argv_free(NULL);
}

/* The radiosity file: +RFO or +RFI and +RF"file" after +O; a directory
 * POV-Ray cannot be told is reached through a link. */
static void test_argv_radiosity(void **state)
{
	char scene[PATH_MAX], out[PATH_MAX], work[PATH_MAX], rad[PATH_MAX],
	     odd[PATH_MAX], want[PATH_MAX + 8], target[PATH_MAX], err[512];
	struct pov_job job = { 0 };
	char **argv;
	int argc;

	(void)state;
	tiny_job(&job, scene, out, "rad", "s.pov", "o.exr", 16, 12);
	mkdir_p(scratch(work, sizeof(work), "rad/work"));
	job.workdir = work;
	job.radiosity = scratch(rad, sizeof(rad), "rad/r.rca");
	job.radiosity_mode = POV_RAD_SAVE;
	assert_int_equal(pov_argv_build(&job, &argv, &argc, err, sizeof(err)), 0);
	snprintf(want, sizeof(want), "+RF\"%s\"", rad);
	assert_int_equal(argc, 12);
	assert_string_equal(argv[10], "+RFO");
	assert_string_equal(argv[11], want);
	pov_argv_free(argv);

	job.radiosity_mode = POV_RAD_LOAD;
	mkdir_p(scratch(odd, sizeof(odd), "rad/say \"cheese\""));
	job.radiosity = scratch(rad, sizeof(rad), "rad/say \"cheese\"/r.rca");
	assert_int_equal(pov_argv_build(&job, &argv, &argc, err, sizeof(err)), 0);
	assert_string_equal(argv[10], "+RFI");
	assert_true(strncmp(argv[11], "+RF\"", 4) == 0);
	/* one pair of quotes, none inside */
	assert_true(strchr(argv[11] + 4, '"') == argv[11] + strlen(argv[11]) - 1);
	/* the link's directory is the odd one */
	snprintf(want, sizeof(want), "%s", argv[11] + 4);
	want[strlen(want) - 1] = '\0';			/* the closing quote */
	*strrchr(want, '/') = '\0';			/* the link itself */
	ssize_t n = readlink(want, target, sizeof(target) - 1);
	assert_true(n > 0);
	target[n] = '\0';
	size_t tl = strlen(target), ol = strlen("/say \"cheese\"");
	assert_true(tl > ol);
	assert_string_equal(target + tl - ol, "/say \"cheese\"");
	pov_argv_free(argv);

	/* a mode that is neither fails; so does an unsafe file name */
	job.radiosity_mode = 0;
	assert_int_equal(pov_argv_build(&job, &argv, NULL, err, sizeof(err)), -1);
	assert_non_null(strstr(err, "neither saved nor loaded"));
	job.radiosity_mode = POV_RAD_LOAD;
	job.radiosity = scratch(rad, sizeof(rad), "rad/r\".rca");
	assert_int_equal(pov_argv_build(&job, &argv, NULL, err, sizeof(err)), -1);
	assert_non_null(strstr(err, "radiosity file"));
}

static void test_argv_region(void **state)
{
	char dir[PATH_MAX], scene[PATH_MAX], out[PATH_MAX], err[512];
	struct pov_job job = { 0 };
	struct pov_region r;
	char **argv;
	int argc;
	static const struct {
		int w, h;
		struct pov_region r;
		const char *sc, *ec, *sr, *er;
	} cases[] = {
		{ 64, 48, { 8, 4, 23, 11 }, "+SC9", "+EC24", "+SR5", "+ER12" },
		/* POV-Ray reads an end of 1 as the fraction 1.0, the last column */
		{ 64, 48, { 0, 0, 0, 0 }, "+SC1", "+EC1.5", "+SR1", "+ER1.5" },
		{ 64, 48, { 63, 47, 63, 47 }, "+SC64", "+EC64", "+SR48", "+ER48" },
		{ 64, 48, { 0, 1, 63, 1 }, "+SC1", "+EC64", "+SR2", "+ER2" },
		{ 1, 1, { 0, 0, 0, 0 }, "+SC1", "+EC1", "+SR1", "+ER1" },
	};

	(void)state;
	make_tiny_scene(scene, sizeof(scene), scratch(dir, sizeof(dir), "region"), "r.pov");
	job.scene = scene;
	job.output = scratch(out, sizeof(out), "region/r.exr");
	for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
		job.width = cases[k].w;
		job.height = cases[k].h;
		r = cases[k].r;
		job.region = &r;
		assert_int_equal(pov_argv_build(&job, &argv, &argc, err, sizeof(err)), 0);
		assert_string_equal(argv[7], cases[k].sc);
		assert_string_equal(argv[8], cases[k].ec);
		assert_string_equal(argv[9], cases[k].sr);
		assert_string_equal(argv[10], cases[k].er);
		assert_int_equal(argc, 14);
		pov_argv_free(argv);
	}
	/* Whole image: no region options at all. */
	job.region = NULL;
	assert_int_equal(pov_argv_build(&job, &argv, &argc, err, sizeof(err)), 0);
	assert_int_equal(argc, 10);
	for (int i = 0; i < argc; i++)
		assert_true(strncmp(argv[i], "+S", 2) && strncmp(argv[i], "+E", 2));
	pov_argv_free(argv);
}

static void test_argv_bad_jobs(void **state)
{
	char dir[PATH_MAX], scene[PATH_MAX], out[PATH_MAX], p[PATH_MAX], err[512];
	struct pov_job job = { 0 }, j;
	struct pov_region r;
	struct pov_define d;
	char **argv = (char **)&job;	/* must come back NULL */

	(void)state;
	tiny_job(&job, scene, out, "bad", "s.pov", "o.exr", 32, 24);

	j = job;
	j.scene = scratch(p, sizeof(p), "bad/missing.pov");
	assert_int_equal(pov_argv_build(&j, &argv, NULL, err, sizeof(err)), -1);
	assert_null(argv);
	assert_contains(err, "cannot read scene '");
	assert_contains(err, "missing.pov': No such file or directory");

	j = job;
	j.output = scratch(p, sizeof(p), "bad/no such dir/o.exr");
	assert_int_equal(pov_argv_build(&j, &argv, NULL, err, sizeof(err)), -1);
	assert_contains(err, "no such dir/o.exr': No such file or directory");

	j = job;
	j.height = 0;
	assert_int_equal(pov_argv_build(&j, &argv, NULL, err, sizeof(err)), -1);
	assert_contains(err, "32x0");

	j = job;
	r = (struct pov_region){ 0, 0, 32, 5 };	/* x1 is past the last column */
	j.region = &r;
	assert_int_equal(pov_argv_build(&j, &argv, NULL, err, sizeof(err)), -1);
	assert_contains(err, "region 0,0-32,5 of a 32x24 image");
	r = (struct pov_region){ 5, 0, 4, 5 };	/* empty */
	assert_int_equal(pov_argv_build(&j, &argv, NULL, err, sizeof(err)), -1);

	j = job;
	d = (struct pov_define){ "Name", "\"text\"" };
	j.defines = &d;
	j.ndefines = 1;
	assert_int_equal(pov_argv_build(&j, &argv, NULL, err, sizeof(err)), -1);
	assert_contains(err, "bad declare 'Name=\"text\"'");
	d = (struct pov_define){ "2x", "1" };
	assert_int_equal(pov_argv_build(&j, &argv, NULL, err, sizeof(err)), -1);
	d = (struct pov_define){ "X", "1 2" };
	assert_int_equal(pov_argv_build(&j, &argv, NULL, err, sizeof(err)), -1);

	/* A double quote in the path needs a work directory for a link. */
	j = job;
	make_tiny_scene(p, sizeof(p), scratch(dir, sizeof(dir), "bad/q\"dir"), "s.pov");
	j.scene = p;
	assert_int_equal(pov_argv_build(&j, &argv, NULL, err, sizeof(err)), -1);
	assert_contains(err, "cannot pass '");
	assert_contains(err, "q\"dir/s.pov' to povray");
	assert_contains(err, "no work directory");
	assert_null(argv);
}

/* Paths POV-Ray cannot take go through links in the work directory. */
static void test_argv_links(void **state)
{
	char dir[PATH_MAX], scene[PATH_MAX], out[PATH_MAX], work[PATH_MAX], err[512];
	char target[PATH_MAX], expect[PATH_MAX + 8];
	struct stat st_link, st_real;
	struct pov_job job = { 0 };
	char **argv, **again;
	ssize_t n;

	(void)state;
	tiny_job(&job, scene, out, "quo\"te \xc3\xa9", "sc\"ene.pov", "out.exr", 16, 12);
	scratch(dir, sizeof(dir), "quo\"te \xc3\xa9");
	mkdir_p(scratch(work, sizeof(work), "work"));
	job.workdir = work;
	assert_int_equal(pov_argv_build(&job, &argv, NULL, err, sizeof(err)), 0);
	/* +L, +I, +O: every path POV-Ray sees is printable ASCII without '"'
	 * inside the quotes, and each link leads to the real thing. */
	for (int i = 7; i <= 9; i++) {
		const char *a = argv[i];
		size_t len = strlen(a);
		char path[PATH_MAX];

		assert_true(a[0] == '+' && a[2] == '"' && a[len - 1] == '"');
		snprintf(path, sizeof(path), "%.*s", (int)(len - 4), a + 3);
		for (const char *c = path; *c; c++)
			assert_true(*c >= 0x20 && *c < 0x7f && *c != '"');
		assert_true(!strncmp(path, work, strlen(work)));
		if (a[1] == 'O') {
			/* the output's directory is linked, not the file */
			char *slash = strrchr(path, '/');

			assert_string_equal(slash, "/out.exr");
			*slash = '\0';
		}
		n = readlink(path, target, sizeof(target) - 1);
		assert_true(n > 0);
		target[n] = '\0';
		assert_int_equal(target[0], '/');
		assert_int_equal(stat(target, &st_link), 0);
		assert_int_equal(stat(a[1] == 'I' ? scene : dir, &st_real), 0);
		assert_true(st_link.st_ino == st_real.st_ino && st_link.st_dev == st_real.st_dev);
	}
	/* The same paths reuse the same links. */
	assert_int_equal(pov_argv_build(&job, &again, NULL, err, sizeof(err)), 0);
	for (int i = 0; argv[i]; i++)
		assert_string_equal(argv[i], again[i]);
	pov_argv_free(again);
	pov_argv_free(argv);

	/* An output name POV-Ray cannot take, or one without ".exr", gets a
	 * stand-in beside it. */
	job.output = scratch(out, sizeof(out), "quo\"te \xc3\xa9/it's \"out\"");
	assert_int_equal(pov_argv_build(&job, &argv, NULL, err, sizeof(err)), 0);
	assert_contains(argv[9], "/.povpress-");
	assert_contains(argv[9], ".exr\"");
	pov_argv_free(argv);
	job.output = scratch(out, sizeof(out), "plain.EXR");
	assert_int_equal(pov_argv_build(&job, &argv, NULL, err, sizeof(err)), 0);
	snprintf(expect, sizeof(expect), "+O\"%s/.povpress-", scratch_dir);
	assert_true(!strncmp(argv[9], expect, strlen(expect)));
	pov_argv_free(argv);

	/* A work directory that is itself unsafe is refused. */
	job.workdir = dir;
	assert_int_equal(pov_argv_build(&job, &argv, NULL, err, sizeof(err)), -1);
	assert_contains(err, "cannot use work directory");
}

/* ---- shell lines ---------------------------------------------------------- */

static void test_shell_line_words(void **state)
{
	char scene[PATH_MAX], out[PATH_MAX], err[512], want[PATH_MAX * 2];
	static const char *const extra[] = { "+A0.1", "Antialias_Depth=3" };
	struct pov_job job = { 0 };
	char *line;

	(void)state;
	tiny_job(&job, scene, out, "shell it's", "s.pov", "o.exr", 16, 12);
	job.extra = extra;
	job.nextra = 2;
	assert_int_equal(pov_shell_line(&job, &line, err, sizeof(err)), 0);
	/* plain words stay bare; the rest is single-quoted with ' as '\'' */
	snprintf(want, sizeof(want), "povray -D +FE -GR -V +W16 +H12 '+L\"%s/shell it'\\''s\"' ",
		 scratch_dir);
	if (strncmp(line, want, strlen(want)))
		fail_msg("line \"%s\" does not start with \"%s\"", line, want);
	assert_contains(line, " +A0.1 Antialias_Depth=3");
	assert_null(strstr(line, "&&"));
	assert_int_equal(line[strlen(line) - 1], '3');	/* no newline */
	free(line);
}

/* The line, run by sh, gives the binary exactly the vector of pov_argv_build. */
static void test_shell_line_round_trip_args(void **state)
{
	char scene[PATH_MAX], out[PATH_MAX], args[PATH_MAX], work[PATH_MAX];
	char err[512];
	static const char *const extra[] = { "+A0.1", "Odd=$HOME `x` \\ ; |&", "" };
	struct pov_job job = { 0 };
	char *line, *got, **argv;
	int argc;
	size_t pos = 0;

	(void)state;
	tiny_job(&job, scene, out, "rt 'q' \"d\" $x", "s c.pov", "o.exr", 16, 12);
	mkdir_p(scratch(work, sizeof(work), "work"));
	job.extra = extra;
	job.nextra = 3;
	job.workdir = work;
	job.povray = fake_bin;
	assert_int_equal(pov_shell_line(&job, &line, err, sizeof(err)), 0);
	assert_int_equal(pov_argv_build(&job, &argv, &argc, err, sizeof(err)), 0);
	scratch(args, sizeof(args), "args.bin");
	setenv("FAKE_MODE", "args", 1);
	setenv("FAKE_ARGS", args, 1);
	assert_int_equal(sh_c(line), 0);
	got = read_file(args);
	assert_non_null(got);
	/* $0 is the script; then argv[1..] in order, NUL-terminated */
	for (int i = 1; i < argc; i++) {
		assert_string_equal(got + pos, argv[i]);
		pos += strlen(argv[i]) + 1;
	}
	free(got);
	free(line);
	pov_argv_free(argv);
}

/* The line renders for real: spaces, a single quote, and a name without
 * ".exr" (a stand-in renamed by the line's mv). */
static void test_shell_line_renders(void **state)
{
	char scene[PATH_MAX], out[PATH_MAX], err[512];
	struct pov_job job = { 0 };
	struct image img = { 0 };
	char *line;

	(void)state;
	tiny_job(&job, scene, out, "sh render's dir", "the scene.pov", "final image", 24, 16);
	assert_int_equal(pov_shell_line(&job, &line, err, sizeof(err)), 0);
	assert_contains(line, " && mv -f -- ");
	assert_int_equal(sh_c(line), 0);
	assert_true(exists(out));
	assert_int_equal(image_read_exr(out, &img, err, sizeof(err)), 0);
	assert_int_equal(img.w, 24);
	assert_int_equal(img.h, 16);
	image_release(&img);
	free(line);
}

/* ---- statistics ----------------------------------------------------------- */

/* The text of fixture DATA NAME (the caller frees it). */
static char *fixture(const char *name)
{
	char path[256];
	char *text;

	snprintf(path, sizeof(path), DATA "%s", name);
	text = read_file(path);
	if (!text)
		fail_msg("cannot read fixture '%s'", path);
	return text;
}

static void parse_fixture(const char *name, struct pov_stats *st, int want_rc)
{
	char *text = fixture(name);

	assert_int_equal(pov_stats_parse(text, st), want_rc);
	free(text);
}

/* The render time printed, through the trace's CPU line, without radiosity. */
static void test_render_time_printed(void **state)
{
	char *text, *cut;

	(void)state;
	text = fixture("noaa.txt");
	assert_true(pov_render_time_printed(text));
	/* up to the trace time's CPU line, without its end: not yet */
	cut = strstr(strstr(text, "Trace Time:"), "CPU-seconds total");
	assert_non_null(cut);
	cut[strlen("CPU-seconds total")] = '\0';
	assert_false(pov_render_time_printed(text));
	*strstr(text, "Render Time:") = '\0';
	assert_false(pov_render_time_printed(text));
	free(text);
	text = fixture("radiosity.txt");
	assert_false(pov_render_time_printed(text));
	free(text);
	text = fixture("photons.txt");
	assert_true(pov_render_time_printed(text));
	free(text);
}

static void test_stats_no_aa(void **state)
{
	struct pov_stats st;

	(void)state;
	parse_fixture("noaa.txt", &st, 0);
	assert_int_equal(st.have, POV_HAVE_PARSE | POV_HAVE_BOUNDING | POV_HAVE_TRACE |
				  POV_HAVE_PIXELS | POV_HAVE_RAYS);
	assert_int_equal(st.rad_final_rays, 0);
	assert_int_equal(st.pixels, 3072);
	assert_int_equal(st.samples, 0);
	assert_float_equal(st.samples_per_pixel, 0.0, 0);
	assert_int_equal(st.rays, 3072);
	assert_int_equal(st.rays_saved, 0);
	assert_float_equal(st.parse.wall_s, 0.004, 1e-12);
	assert_int_equal(st.parse.threads, 1);
	assert_float_equal(st.trace.wall_s, 0.011, 1e-12);
	assert_float_equal(st.trace.cpu_s, 0.005, 1e-12);
	assert_int_equal(st.trace.threads, 2);
	assert_float_equal(st.photon.wall_s, 0.0, 0);
	assert_float_equal(st.radiosity.wall_s, 0.0, 0);
}

static void test_stats_aa(void **state)
{
	struct pov_stats st;

	(void)state;
	parse_fixture("aa.txt", &st, 0);
	assert_int_equal(st.pixels, 3300);
	assert_int_equal(st.samples, 24524);
	assert_float_equal(st.samples_per_pixel, 7.43, 1e-12);
	assert_int_equal(st.rays, 27824);	/* pixels + samples */
	assert_float_equal(st.trace.wall_s, 0.070, 1e-12);
	assert_float_equal(st.trace.cpu_s, 0.033, 1e-12);
}

/* The default console (option summaries, \r progress lines) and a region. */
static void test_stats_verbose_region(void **state)
{
	struct pov_stats st;

	(void)state;
	parse_fixture("region-verbose.txt", &st, 0);
	assert_int_equal(st.pixels, 153);
	assert_int_equal(st.samples, 2179);
	assert_float_equal(st.samples_per_pixel, 14.24, 1e-12);
	assert_int_equal(st.rays, 2332);
	assert_float_equal(st.trace.wall_s, 0.012, 1e-12);
}

static void test_stats_radiosity_photons(void **state)
{
	struct pov_stats st;

	(void)state;
	parse_fixture("radiosity.txt", &st, 0);
	assert_true(st.have & POV_HAVE_RADIOSITY);
	assert_false(st.have & POV_HAVE_PHOTON);
	assert_float_equal(st.radiosity.wall_s, 0.028, 1e-12);
	assert_float_equal(st.radiosity.cpu_s, 0.015, 1e-12);
	assert_float_equal(st.trace.wall_s, 0.023, 1e-12);
	assert_int_equal(st.pixels, 5577);
	assert_int_equal(st.rays, 20347);
	/* the render proper shot none of its radiosity rays: "Radiosity
	 * Depth 0 rays shot: 14770" and "Radiosity sample rays shot" are the
	 * pretrace's and the total */
	assert_true(st.have & POV_HAVE_RAD_RAYS);
	assert_int_equal(st.rad_final_rays, 0);
	assert_int_equal(pov_stats_parse("Radiosity (final) rays shot:           409045\n"
					 "Pixels:  10   Samples:  0   Smpls/Pxl: 0.00\n"
					 "  Trace Time:  0 hours  0 minutes  0 seconds (0.5 seconds)\n"
					 "    using 1 thread(s) with 0.5 CPU-seconds total\n", &st), 0);
	assert_int_equal(st.rad_final_rays, 409045);

	parse_fixture("photons.txt", &st, 0);
	assert_true(st.have & POV_HAVE_PHOTON);
	assert_false(st.have & POV_HAVE_RADIOSITY);
	assert_float_equal(st.photon.wall_s, 0.002, 1e-12);
	assert_int_equal(st.photon.threads, 5);
	/* "Refracted Rays: 774" is not the ray count */
	assert_int_equal(st.rays, 4192);
	assert_float_equal(st.trace.wall_s, 0.019, 1e-12);
}

static void test_stats_missing_and_odd(void **state)
{
	struct pov_stats st;

	(void)state;
	parse_fixture("parse-error.txt", &st, -1);
	assert_false(st.have & (POV_HAVE_PIXELS | POV_HAVE_TRACE));
	assert_int_equal(pov_stats_parse(NULL, &st), -1);
	assert_int_equal(st.have, 0);
	assert_int_equal(pov_stats_parse("", &st), -1);

	/* Long times, "-" for no pixels, no final newline, CRLF. */
	assert_int_equal(pov_stats_parse(
		"Pixels:                0   Samples:               0   Smpls/Pxl: -\r\n"
		"Rays:         1234567890   Saved:                12   Max Level: 1/5\r\n"
		"  Trace Time:       1 hours  2 minutes  5 seconds (3725.500 seconds)\r\n"
		"              using 16 thread(s) with 59000.250 CPU-seconds total", &st), 0);
	assert_int_equal(st.pixels, 0);
	assert_float_equal(st.samples_per_pixel, 0.0, 0);
	assert_int_equal(st.rays, 1234567890LL);
	assert_int_equal(st.rays_saved, 12);
	assert_float_equal(st.trace.wall_s, 3725.5, 1e-9);
	assert_float_equal(st.trace.cpu_s, 59000.25, 1e-9);
	assert_int_equal(st.trace.threads, 16);
}

/* ---- pool sizing and the binary ------------------------------------------ */

static void test_pool_size(void **state)
{
	int jobs, threads;

	(void)state;
	pov_pool_size(8, 100, 0, &jobs, &threads);
	assert_int_equal(jobs, 8);
	assert_int_equal(threads, 1);
	pov_pool_size(8, 1, 0, &jobs, &threads);	/* one big job: all cores */
	assert_int_equal(jobs, 1);
	assert_int_equal(threads, 8);
	pov_pool_size(8, 3, 0, &jobs, &threads);
	assert_int_equal(jobs, 3);
	assert_int_equal(threads, 2);
	pov_pool_size(8, 100, 2, &jobs, &threads);	/* --jobs 2 */
	assert_int_equal(jobs, 2);
	assert_int_equal(threads, 4);
	pov_pool_size(2, 100, 6, &jobs, &threads);	/* more jobs than cores, asked for */
	assert_int_equal(jobs, 6);
	assert_int_equal(threads, 1);
	pov_pool_size(0, 0, 0, &jobs, &threads);
	assert_int_equal(jobs, 1);
	assert_int_equal(threads, 1);
	for (int c = 1; c <= 16; c++)
		for (size_t n = 1; n <= 20; n++) {
			pov_pool_size(c, n, 0, &jobs, &threads);
			assert_true(jobs >= 1 && threads >= 1 && jobs * threads <= c);
		}
	assert_true(pov_cpu_count() >= 1);
}

static void test_missing_binary(void **state)
{
	char scene[PATH_MAX], out[PATH_MAX], path[PATH_MAX], err[512];
	struct pov_job job = { 0 };
	struct pov_result res[2];
	struct pov_pool_opts o;
	char *old_path = getenv("PATH") ? strdup(getenv("PATH")) : NULL;

	(void)state;
	tiny_job(&job, scene, out, "nobin", "s.pov", "o.exr", 8, 8);
	pov_pool_opts_init(&o);

	/* Not on PATH. */
	setenv("PATH", "/nonexistent-bin:/also-not-here", 1);
	assert_int_equal(pov_find_binary(&job, path, sizeof(path), err, sizeof(err)), -1);
	assert_contains(err, "cannot run 'povray': No such file or directory");
	assert_contains(err, "POVPRESS_POVRAY");
	err[0] = '\0';
	assert_int_equal(pov_pool_run(&job, 1, &o, res, err, sizeof(err)), -1);
	assert_contains(err, "cannot run 'povray': No such file or directory");
	assert_int_equal(res[0].attempts, 0);
	if (old_path)
		setenv("PATH", old_path, 1);
	free(old_path);
	assert_int_equal(pov_find_binary(&job, path, sizeof(path), err, sizeof(err)), 0);
	assert_true(path[0] == '/');

	/* Named by the environment. */
	setenv("POVPRESS_POVRAY", "/nonexistent-dir/povray-3.7", 1);
	assert_int_equal(pov_pool_run(&job, 1, &o, res, err, sizeof(err)), -1);
	assert_contains(err, "cannot run '/nonexistent-dir/povray-3.7' (from POVPRESS_POVRAY): "
			     "No such file or directory");
	unsetenv("POVPRESS_POVRAY");

	/* Named by the job, and not executable. */
	job.povray = scene;
	assert_int_equal(pov_pool_run(&job, 1, &o, res, err, sizeof(err)), -1);
	assert_contains(err, "Permission denied");
	assert_contains(err, "s.pov'");
	assert_false(exists(out));
}

/* ---- the pool with a fake povray ------------------------------------------ */

static void count_done(void *arg, size_t index, const struct pov_result *res)
{
	int *calls = arg;

	(void)res;
	calls[index]++;
}

/* n 8 x 8 jobs of the fake POV-Ray on scene, their outputs DIR/o<k>.exr in
 * the scratch directory (paths into outs). */
static void fake_jobs(struct pov_job *jobs, int n, char outs[][PATH_MAX], const char *scene,
		      const char *dir)
{
	for (int k = 0; k < n; k++) {
		char name[64];

		snprintf(name, sizeof(name), "%s/o%d.exr", dir, k);
		memset(&jobs[k], 0, sizeof(jobs[k]));
		jobs[k].scene = scene;
		jobs[k].output = scratch(outs[k], sizeof(outs[k]), name);
		jobs[k].width = 8;
		jobs[k].height = 8;
		jobs[k].povray = fake_bin;
	}
}

/* Never more than K children at once, and K reached. */
static void test_pool_limit(void **state)
{
	enum { N = 7, K = 3 };
	char dir[PATH_MAX], scene[PATH_MAX], log[PATH_MAX], err[512];
	char outs[N][PATH_MAX];
	struct pov_job jobs[N];
	struct pov_result res[N];
	struct pov_pool_opts o;
	double s[N], e[N];
	int calls[N] = { 0 }, maxlive = 0;
	FILE *f;

	(void)state;
	make_tiny_scene(scene, sizeof(scene), scratch(dir, sizeof(dir), "limit"), "s.pov");
	scratch(log, sizeof(log), "limit/times.log");
	unlink(log);
	setenv("FAKE_MODE", "sleep", 1);
	setenv("FAKE_LOG", log, 1);
	fake_jobs(jobs, N, outs, scene, "limit");
	pov_pool_opts_init(&o);
	o.max_jobs = K;
	o.on_done = count_done;
	o.arg = calls;
	assert_int_equal(pov_pool_run(jobs, N, &o, res, err, sizeof(err)), 0);
	for (int i = 0; i < N; i++) {
		assert_int_equal(res[i].status, POV_OK);
		assert_int_equal(res[i].attempts, 1);
		assert_int_equal(calls[i], 1);
		assert_true(exists(outs[i]));
		assert_true(res[i].wall_s >= 0.3);
		assert_true(res[i].end_s - res[i].start_s >= 0.3);
	}
	/* The children's own clocks. */
	f = fopen(log, "r");
	assert_non_null(f);
	for (int i = 0; i < N; i++)
		assert_int_equal(fscanf(f, "%lf %lf", &s[i], &e[i]), 2);
	fclose(f);
	for (int i = 0; i < N; i++) {
		int live = 0;

		for (int k = 0; k < N; k++)
			live += s[k] <= s[i] && s[i] < e[k];
		if (live > maxlive)
			maxlive = live;
	}
	assert_int_equal(maxlive, K);
	/* The same from the pool's records. */
	maxlive = 0;
	for (int i = 0; i < N; i++) {
		int live = 0;

		for (int k = 0; k < N; k++)
			live += res[k].start_s <= res[i].start_s && res[i].start_s < res[k].end_s;
		if (live > maxlive)
			maxlive = live;
	}
	assert_int_equal(maxlive, K);
	release_all(res, N);
}

/* The ready callback: counts its calls, checks the file, says accept. */
struct ready_log {
	int calls, accept;
	char path[PATH_MAX];
};

static int ready_cb(void *arg, size_t index, const char *path)
{
	struct ready_log *l = arg;
	char buf[16] = { 0 };
	FILE *f = fopen(path, "r");

	(void)index;
	l->calls++;
	snprintf(l->path, sizeof(l->path), "%s", path);
	assert_non_null(f);
	assert_non_null(fgets(buf, sizeof(buf), f));
	fclose(f);
	assert_string_equal(buf, "whole\n");
	return l->accept;
}

static int log_says_done(void *arg, size_t index, const char *log)
{
	(void)arg;
	(void)index;
	return strstr(log, "Render Time: done") != NULL;
}

static int log_says_never(void *arg, size_t index, const char *log)
{
	(void)arg;
	(void)index;
	return strstr(log, "something POV-Ray never prints") != NULL;
}

/* A job whose output is whole is done without waiting for the exit when
 * the callback accepts it; when it does not, the pool waits. */
static void test_pool_ready(void **state)
{
	char dir[PATH_MAX], scene[PATH_MAX], out[1][PATH_MAX], err[512];
	struct pov_job job = { 0 };
	struct pov_result res;
	struct pov_pool_opts o;
	struct ready_log l = { 0 };

	(void)state;
	make_tiny_scene(scene, sizeof(scene), scratch(dir, sizeof(dir), "ready"), "s.pov");
	setenv("FAKE_MODE", "linger", 1);
	fake_jobs(&job, 1, out, scene, "ready");
	pov_pool_opts_init(&o);
	o.ready = ready_cb;
	o.arg = &l;
	l.accept = 1;
	assert_int_equal(pov_pool_run(&job, 1, &o, &res, err, sizeof(err)), 0);
	assert_int_equal(res.status, POV_OK);
	assert_int_equal(res.exit_status, 0);
	assert_int_equal(res.term_signal, 0);
	assert_int_equal(l.calls, 1);
	assert_true(res.wall_s < 0.9);
	assert_true(exists(out[0]));
	pov_result_release(&res);

	l.calls = 0;
	l.accept = 0;
	assert_int_equal(pov_pool_run(&job, 1, &o, &res, err, sizeof(err)), 0);
	assert_int_equal(res.status, POV_OK);
	assert_int_equal(l.calls, 1);
	assert_true(res.wall_s >= 1.0);
	assert_true(exists(out[0]));
	pov_result_release(&res);

	/* accepted, and done when the console says so: at once when it says
	 * what ready_log wants, at the exit when it never does */
	l.calls = 0;
	l.accept = 1;
	o.ready_log = log_says_done;
	assert_int_equal(pov_pool_run(&job, 1, &o, &res, err, sizeof(err)), 0);
	assert_int_equal(res.status, POV_OK);
	assert_int_equal(res.exit_status, 0);
	assert_true(res.wall_s < 0.9);
	pov_result_release(&res);
	o.ready_log = log_says_never;
	assert_int_equal(pov_pool_run(&job, 1, &o, &res, err, sizeof(err)), 0);
	assert_int_equal(res.status, POV_OK);
	assert_int_equal(l.calls, 2);
	assert_true(res.wall_s >= 1.0);
	pov_result_release(&res);
	o.ready_log = NULL;

	/* no output, no call */
	l.calls = 0;
	setenv("FAKE_MODE", "noout", 1);
	assert_int_equal(pov_pool_run(&job, 1, &o, &res, err, sizeof(err)), 0);
	assert_int_equal(res.status, POV_FAILED);
	assert_int_equal(l.calls, 0);
	pov_result_release(&res);
}

/* For a job with progress, POV-Ray's progress lines as they were read: a line
 * split across two reads is read whole, a count that falls starts again
 * (the 50 before the 10), of the lines read at once only the last is kept
 * (the 40, not the 10), and each has the time it came; without it, none.
 * A job's progress asks POV-Ray for them (+V, not -V). */
static void test_pool_progress(void **state)
{
	char dir[PATH_MAX], scene[PATH_MAX], out[1][PATH_MAX], err[512];
	struct pov_job job = { 0 };
	struct pov_result res;
	struct pov_pool_opts o;
	char **argv;
	int argc, plus = 0, minus = 0;

	(void)state;
	make_tiny_scene(scene, sizeof(scene), scratch(dir, sizeof(dir), "progress"), "s.pov");
	setenv("FAKE_MODE", "progress", 1);
	fake_jobs(&job, 1, out, scene, "progress");
	pov_pool_opts_init(&o);
	job.progress = 1;
	assert_int_equal(pov_pool_run(&job, 1, &o, &res, err, sizeof(err)), 0);
	assert_int_equal(res.status, POV_OK);
	assert_int_equal(res.nprogress, 2);
	assert_int_equal(res.progress_total, 100);
	assert_int_equal(res.progress[0].done, 40);
	assert_int_equal(res.progress[1].done, 100);
	assert_true(res.progress[0].t >= 0.15);
	assert_true(res.progress[1].t >= res.progress[0].t + 0.15);
	pov_result_release(&res);
	assert_null(res.progress);

	job.progress = 0;
	assert_int_equal(pov_pool_run(&job, 1, &o, &res, err, sizeof(err)), 0);
	assert_int_equal(res.status, POV_OK);
	assert_int_equal(res.nprogress, 0);
	assert_null(res.progress);
	pov_result_release(&res);

	for (int p = 0; p < 2; p++) {
		job.progress = p;
		assert_int_equal(pov_argv_build(&job, &argv, &argc, err, sizeof(err)), 0);
		for (int i = 0; i < argc; i++) {
			plus += p == 1 && !strcmp(argv[i], "+V");
			minus += p == 0 && !strcmp(argv[i], "-V");
			assert_false(p == 1 && !strcmp(argv[i], "-V"));
			assert_false(p == 0 && !strcmp(argv[i], "+V"));
		}
		pov_argv_free(argv);
	}
	assert_int_equal(plus, 1);
	assert_int_equal(minus, 1);
}

/* At the deadline, with opts.finish_s and progress: a job whose lines say
 * it has rendered its pixels (writing its image: 0.3 s more) is left
 * finish_s to end, and ends well; without finish_s it is stopped; one
 * whose lines say it has 1.6 s of pixels left is stopped at once. */
static void test_pool_finish(void **state)
{
	char dir[PATH_MAX], scene[PATH_MAX], out[1][PATH_MAX], err[512];
	struct pov_job job = { 0 };
	struct pov_result res;
	struct pov_pool_opts o;

	(void)state;
	make_tiny_scene(scene, sizeof(scene), scratch(dir, sizeof(dir), "finish"), "s.pov");
	fake_jobs(&job, 1, out, scene, "finish");
	job.progress = 1;
	pov_pool_opts_init(&o);
	o.deadline_s = 0.2;
	o.finish_s = 0.5;
	setenv("FAKE_MODE", "finish", 1);
	double t = now_s();
	assert_int_equal(pov_pool_run(&job, 1, &o, &res, err, sizeof(err)), 0);
	t = now_s() - t;
	assert_int_equal(res.status, POV_OK);
	assert_true(exists(out[0]));
	assert_true(t >= 0.35 && t < 0.7);
	pov_result_release(&res);

	o.finish_s = 0.0;
	t = now_s();
	assert_int_equal(pov_pool_run(&job, 1, &o, &res, err, sizeof(err)), 0);
	t = now_s() - t;
	assert_int_equal(res.status, POV_CANCELLED);
	assert_false(exists(out[0]));
	assert_true(t < 0.35);
	pov_result_release(&res);

	o.finish_s = 0.5;
	setenv("FAKE_MODE", "slow", 1);
	t = now_s();
	assert_int_equal(pov_pool_run(&job, 1, &o, &res, err, sizeof(err)), 0);
	t = now_s() - t;
	assert_int_equal(res.status, POV_CANCELLED);
	assert_non_null(strstr(res.message, "deadline"));
	assert_false(exists(out[0]));
	assert_true(t < 0.45);
	assert_int_equal(res.nprogress, 2);
	assert_int_equal(res.progress[1].done, 20);
	pov_result_release(&res);
}

/* A deadline: the job running then is killed, those not started are not;
 * all are reported cancelled, the one done before it keeps its result. */
static void test_pool_deadline(void **state)
{
	char dir[PATH_MAX], scene[PATH_MAX], log[PATH_MAX], out[4][PATH_MAX], err[512];
	struct pov_job jobs[4];
	struct pov_result res[4];
	struct pov_pool_opts o;

	(void)state;
	make_tiny_scene(scene, sizeof(scene), scratch(dir, sizeof(dir), "deadline"), "s.pov");
	setenv("FAKE_MODE", "sleep", 1);	/* 0.3 s each */
	setenv("FAKE_LOG", scratch(log, sizeof(log), "deadline/log"), 1);
	fake_jobs(jobs, 4, out, scene, "deadline");
	pov_pool_opts_init(&o);
	o.max_jobs = 1;
	o.deadline_s = 0.45;
	double t = now_s();
	assert_int_equal(pov_pool_run(jobs, 4, &o, res, err, sizeof(err)), 0);
	t = now_s() - t;
	assert_true(t < 0.8);	/* not 1.2 s */
	assert_int_equal(res[0].status, POV_OK);
	assert_true(exists(out[0]));
	for (int k = 1; k < 4; k++) {
		assert_int_equal(res[k].status, POV_CANCELLED);
		assert_non_null(strstr(res[k].message, "deadline"));
		assert_false(exists(out[k]));
	}
	assert_int_equal(res[1].attempts, 1);	/* killed */
	assert_int_equal(res[2].attempts, 0);	/* never started */
	assert_int_equal(res[3].attempts, 0);
	release_all(res, 4);
	/* without one, all four run */
	o.deadline_s = 0.0;
	assert_int_equal(pov_pool_run(jobs, 4, &o, res, err, sizeof(err)), 0);
	for (int k = 0; k < 4; k++)
		assert_int_equal(res[k].status, POV_OK);
	release_all(res, 4);
}

static void test_pool_crash_retry_and_no_output(void **state)
{
	char scene[PATH_MAX], out[PATH_MAX];
	struct pov_job job = { 0 };
	struct pov_result res;

	(void)state;
	tiny_job(&job, scene, out, "crash", "s.pov", "o.exr", 8, 8);
	job.povray = fake_bin;

	setenv("FAKE_MODE", "segv", 1);
	assert_int_equal(run_pool(&job, 1, 1, 0, 1, &res), 0);
	assert_int_equal(res.status, POV_CRASHED);
	assert_int_equal(res.attempts, 2);	/* retried once */
	assert_int_equal(res.term_signal, SIGSEGV);
	assert_int_equal(res.exit_status, -1);
	assert_contains(res.message, "killed by signal 11");
	pov_result_release(&res);
	assert_int_equal(run_pool(&job, 1, 1, 0, 0, &res), 0);
	assert_int_equal(res.attempts, 1);	/* retries 0 */
	pov_result_release(&res);

	/* Exit 0 but no file: a failure, not retried. */
	write_file(out, "stale");	/* removed before the attempt */
	setenv("FAKE_MODE", "noout", 1);
	assert_int_equal(run_pool(&job, 1, 1, 0, 1, &res), 0);
	assert_int_equal(res.status, POV_FAILED);
	assert_int_equal(res.attempts, 1);
	assert_int_equal(res.exit_status, 0);
	assert_contains(res.message, "povray did not write '");
	assert_false(exists(out));
	pov_result_release(&res);
	pov_result_release(&res);	/* a zeroed result is a no-op */
}

/* POV-Ray's messages, from captured output played back by the fake. */
static void test_pool_error_messages(void **state)
{
	static const struct {
		const char *fixture, *want, *not;
	} cases[] = {
		{ "parse-error.txt",
		  "(exit status 1) on '%s': File '/tmp/my scenes/bad.pov' line 5: Parse Error: "
		  "No matching } in 'pigment', undeclared identifier 'colr' found instead", NULL },
		{ "include-error.txt",
		  "File '/tmp/missing_include.pov' line 2: Parse Error: Cannot open include file "
		  "nonexistent.inc.", "Possible" },
		{ "bad-region.txt", "Fatal error in renderer: Invalid end column or row", NULL },
		{ "bad-option.txt", "Problem with option setting; Failed to parse command-line "
				    "option", "user configuration" },
	};
	char scene[PATH_MAX], out[PATH_MAX], path[PATH_MAX], want[512];
	struct pov_job job = { 0 };
	struct pov_result res;
	size_t base;

	(void)state;
	tiny_job(&job, scene, out, "msgs", "s.pov", "o.exr", 8, 8);
	job.povray = fake_bin;
	setenv("FAKE_MODE", "fixture", 1);
	assert_non_null(getcwd(path, sizeof(path) - 64));
	base = strlen(path);
	for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); k++) {
		snprintf(path + base, sizeof(path) - base, "/" DATA "%s", cases[k].fixture);
		setenv("FAKE_FIXTURE", path, 1);
		assert_int_equal(run_pool(&job, 1, 1, 0, 1, &res), 0);
		assert_int_equal(res.status, POV_FAILED);
		assert_int_equal(res.attempts, 1);
		assert_int_equal(res.exit_status, 1);
		snprintf(want, sizeof(want), cases[k].want, scene);
		assert_contains(res.message, want);
		if (cases[k].not && strstr(res.message, cases[k].not))
			fail_msg("\"%s\" contains \"%s\"", res.message, cases[k].not);
		assert_non_null(res.log);
		pov_result_release(&res);
	}
}

/* ---- render state files ------------------------------------------------- */

/* A growing byte buffer for a state file made by hand. */
struct bytes {
	unsigned char *p;
	size_t n, cap;
};

static void put(struct bytes *b, const void *v, size_t n)
{
	if (b->n + n > b->cap) {
		b->cap = 2 * (b->n + n);
		b->p = realloc(b->p, b->cap);
		assert_non_null(b->p);
	}
	memcpy(b->p + b->n, v, n);
	b->n += n;
}

static void put32(struct bytes *b, uint32_t v)
{
	unsigned char q[4] = { (unsigned char)(v >> 24), (unsigned char)(v >> 16),
			       (unsigned char)(v >> 8), (unsigned char)v };
	put(b, q, 4);
}

/* A block's message as POV-Ray writes it: its pixels (5 floats each, the
 * colour value(x, y, c) then filter and transmit) over columns l..r, rows
 * t..b, count the floats it claims (0: the right count). */
static void put_block(struct bytes *b, int l, int t, int r, int bt, uint32_t count)
{
	const uint32_t n = (uint32_t)((r - l + 1) * (bt - t + 1) * 5);
	put(b, "POVRAYMS", 8);
	put32(b, 0x370);
	put32(b, 20 + 4 * n);
	put(b, "RAWSOBJE\0\0\0\x0dOCLATYPE\0\0\0\x04PixD", 28);
	put(b, "PBloVFL4", 8);
	put32(b, count ? count : n);
	for (int y = t; y <= bt; y++)
		for (int x = l; x <= r; x++)
			for (int c = 0; c < 5; c++) {
				float f = c < 3 ? (float)(x + 100 * y + 0.25 * c) : 0.0f;
				uint32_t u;
				memcpy(&u, &f, 4);
				put32(b, u);
			}
	static const char *const key[4] = { "LeftINT4", "Top INT4", "RighINT4", "BottINT4" };
	const int v[4] = { l, t, r, bt };
	put(b, "PiIdINT4", 8);
	put32(b, 4);
	put32(b, 7);
	for (int k = 0; k < 4; k++) {
		put(b, key[k], 8);
		put32(b, 4);
		put32(b, (uint32_t)v[k]);
	}
}

/* pov_results_latency(): a render's wall less the wall its CPU took with
 * the cores shared among the renders running alongside it. */
static void result_at(struct pov_result *r, double s, double e, double cpu)
{
	memset(r, 0, sizeof(*r));
	r->status = POV_OK;
	r->attempts = 1;
	r->start_s = s;
	r->end_s = e;
	r->wall_s = e - s;
	r->cpu_s = cpu;
}

static void test_results_latency(void **state)
{
	(void)state;
	struct pov_result res[6];
	double lat[2];

	/* four renders at once on two cores, each half its wall on a core:
	 * 0.1 s, where wall less CPU alone reads 1.05 */
	for (int k = 0; k < 4; k++)
		result_at(&res[k], 0.0, 2.0, 0.95);
	pov_results_latency(res, 4, 2, lat);
	assert_float_equal(lat[0], 0.1, 1e-9);
	assert_true(isinf(lat[1]));
	/* alone, or with no more renders than cores: wall less CPU */
	pov_results_latency(res, 1, 2, lat);
	assert_float_equal(lat[0], 1.05, 1e-9);
	pov_results_latency(res, 2, 2, lat);
	assert_float_equal(lat[0], 1.05, 1e-9);

	/* partly overlapping on one core: the first shares it half its
	 * life (1.5 renders on average: 2 - 1.5 x 1.0), the second too
	 * (2 - 1.5 x 1.5); the least */
	result_at(&res[0], 0.0, 2.0, 1.0);
	result_at(&res[1], 1.0, 3.0, 1.5);
	pov_results_latency(res, 2, 1, lat);
	assert_float_equal(lat[0], -0.25, 1e-9);

	/* failed, retried and never started renders do not count, but a
	 * failed one still shares the cores; a taken render goes to lat[1] */
	result_at(&res[0], 0.0, 1.0, 0.2);	/* alone: 0.8 */
	result_at(&res[1], 0.0, 1.0, 0.1);
	res[1].status = POV_FAILED;
	result_at(&res[2], 0.0, 1.0, 0.05);
	res[2].attempts = 2;
	memset(&res[3], 0, sizeof(res[3]));
	result_at(&res[4], 0.5, 1.0, 0.3);	/* four running: 0.5 - 0.3 x 4 */
	res[4].prelaunched = 1;
	pov_results_latency(res, 5, 1, lat);
	assert_float_equal(lat[1], 0.5 - 0.3 * 4.0, 1e-9);
	/* the first: 1 + 1 + 1 + 0.5 render-seconds over 1 s on one core */
	assert_float_equal(lat[0], 1.0 - 0.2 * 3.5, 1e-9);
	res[0].status = POV_TIMED_OUT;
	res[4].prelaunched = 0;
	res[4].attempts = 2;
	pov_results_latency(res, 5, 1, lat);
	assert_true(isinf(lat[0]) && isinf(lat[1]));
}

/*
 * pov_state_parse: the blocks of a render state file, each pixel once, in
 * the rows asked for; a block cut short at the end, one whose count does not
 * match its size and one outside the frame left out; a file that is not a
 * state file an error; pov_state_path() names it as POV-Ray does.
 */
static void test_state_parse(void **state)
{
	struct bytes b = { 0 };
	struct image img;
	int oy;
	long px;
	char err[256], path[64];

	(void)state;
	static const char head[] = "POV-Ray Render State File\0\0\0" "0001 options...";
	put(&b, head, sizeof(head) - 1);
	put_block(&b, 0, 0, 3, 1, 0);	/* 4 x 2 */
	put_block(&b, 4, 0, 7, 1, 0);
	put_block(&b, 4, 0, 7, 1, 0);	/* again: counted once */
	put_block(&b, 0, 2, 3, 3, 41);	/* a wrong count */
	put_block(&b, 8, 2, 11, 3, 0);	/* outside an 8-wide frame */
	put_block(&b, 0, 4, 3, 5, 0);
	put_block(&b, 4, 4, 7, 5, 0);
	const size_t cut = b.n - 30;	/* the last block cut short */
	assert_int_equal(pov_state_parse(b.p, cut, "s", 8, 6, 0, 5, &img, &oy, &px, err,
					 sizeof(err)), 0);
	assert_int_equal(oy, 0);
	assert_int_equal(img.w, 8);
	assert_int_equal(img.h, 6);
	assert_int_equal(px, 8 + 8 + 8);
	for (int y = 0; y < 6; y++)
		for (int x = 0; x < 8; x++) {
			const float *q = img.px + ((size_t)y * 8 + x) * 3;
			const int have = y < 2 || (y >= 4 && x < 4);
			for (int c = 0; c < 3; c++)
				if (have)
					assert_true(q[c] == (float)(x + 100 * y + 0.25 * c));
				else
					assert_true(isnan(q[c]));
		}
	image_release(&img);
	/* rows 1 to 4 only; the whole last block now */
	assert_int_equal(pov_state_parse(b.p, b.n, "s", 8, 6, 1, 4, &img, &oy, &px, err,
					 sizeof(err)), 0);
	assert_int_equal(oy, 1);
	assert_int_equal(img.h, 4);
	assert_int_equal(px, 8 + 8);
	assert_true(img.px[((size_t)3 * 8 + 6) * 3 + 1] == (float)(6 + 400 + 0.25));
	assert_true(isnan(img.px[((size_t)1 * 8 + 0) * 3]));
	image_release(&img);
	/* no whole block: no pixels, not an error */
	assert_int_equal(pov_state_parse(b.p, 60, "s", 8, 6, 0, 5, &img, &oy, &px, err,
					 sizeof(err)), 0);
	assert_int_equal(px, 0);
	image_release(&img);
	/* not a state file; rows outside the frame */
	assert_int_equal(pov_state_parse((const unsigned char *)"EXR v2", 6, "x.exr", 8, 6, 0, 5,
					 &img, &oy, &px, err, sizeof(err)), -1);
	assert_non_null(strstr(err, "'x.exr' is not a POV-Ray render state file"));
	assert_null(img.px);
	assert_int_equal(pov_state_parse(b.p, b.n, "s", 8, 6, 2, 6, &img, &oy, &px, err,
					 sizeof(err)), -1);
	assert_int_equal(pov_state_read("/nonexistent/a.pov-state", 8, 6, 0, 5, &img, &oy, &px,
					err, sizeof(err)), -1);
	assert_non_null(strstr(err, "/nonexistent/a.pov-state"));
	assert_int_equal(pov_state_path("dir.v2/p01-r003-aa.exr", path, sizeof(path)), 0);
	assert_string_equal(path, "dir.v2/p01-r003-aa.pov-state");
	assert_int_equal(pov_state_path("dir.v2/noext", path, sizeof(path)), 0);
	assert_string_equal(path, "dir.v2/noext.pov-state");
	assert_int_equal(pov_state_path("dir/long-name.exr", path, 8), -1);
	free(b.p);
}

/* ---- the pool with the real povray ---------------------------------------- */

static void assert_pixel(const struct image *img, int x, int y, int nonzero)
{
	int any = 0;

	for (int c = 0; c < img->nch; c++)
		any |= img->px[((size_t)y * img->w + x) * img->nch + c] != 0.0f;
	if (any != nonzero)
		fail_msg("pixel (%d, %d) is %s", x, y, any ? "not black" : "black");
}

/* A scene with an include beside it, in a directory with a space; and the
 * same in directories with a double quote and non-ASCII bytes. */
static void test_render_awkward_paths(void **state)
{
	char d0[PATH_MAX], d1[PATH_MAX], s0[PATH_MAX], s1[PATH_MAX], o0[PATH_MAX],
	     o1[PATH_MAX], work[PATH_MAX], err[512];
	struct pov_job jobs[2];
	struct pov_result res[2];
	struct image img = { 0 };

	(void)state;
	make_tiny_scene(s0, sizeof(s0), scratch(d0, sizeof(d0), "my scenes"), "tiny scene.pov");
	make_tiny_scene(s1, sizeof(s1), scratch(d1, sizeof(d1), "say \"cheese\" \xc3\xa9"),
			"it's \"tiny\".pov");
	mkdir_p(scratch(work, sizeof(work), "work"));
	memset(jobs, 0, sizeof(jobs));
	jobs[0].scene = s0;
	jobs[0].output = scratch(o0, sizeof(o0), "my scenes/out image.exr");
	jobs[1].scene = s1;
	jobs[1].output = scratch(o1, sizeof(o1), "say \"cheese\" \xc3\xa9/\"out\" \xc3\xa9.exr");
	jobs[1].workdir = work;
	for (int i = 0; i < 2; i++) {
		jobs[i].width = 32;
		jobs[i].height = 24;
		jobs[i].threads = 1;
	}
	write_file(o1, "stale");
	assert_int_equal(run_pool(jobs, 2, 2, 20, 0, res), 0);
	for (int i = 0; i < 2; i++) {
		if (res[i].status != POV_OK)
			fail_msg("job %d: %s\n%s", i, res[i].message, res[i].log ? res[i].log : "");
		assert_int_equal(res[i].exit_status, 0);
		assert_true(res[i].wall_s > 0.05 && res[i].wall_s < 20);
		assert_true(res[i].cpu_s > 0 && res[i].cpu_s < 20);
		assert_true(res[i].stats.have & POV_HAVE_TRACE);
		assert_int_equal(res[i].stats.pixels, 32 * 24);
		assert_int_equal(res[i].stats.trace.threads, 1);
		assert_contains(res[i].log, "POV-Ray finished");
		assert_string_equal(res[i].message, "");
		assert_int_equal(image_read_exr(jobs[i].output, &img, err, sizeof(err)), 0);
		assert_int_equal(img.w, 32);
		assert_int_equal(img.h, 24);
		assert_int_equal(img.nch, 3);
		assert_pixel(&img, 0, 0, 1);	/* background */
		assert_pixel(&img, 16, 12, 1);	/* sphere */
		image_release(&img);
	}
	/* No stand-in or state file is left beside the output. */
	assert_int_equal(count_entries(d1, "povpress"), 0);
	assert_int_equal(count_entries(d1, "pov-state"), 0);
	assert_int_equal(count_entries(d1, ".exr"), 1);
	release_all(res, 2);
}

static void test_render_region(void **state)
{
	char dir[PATH_MAX], scene[PATH_MAX], o0[PATH_MAX], o1[PATH_MAX], err[512];
	struct pov_region r0 = { 8, 4, 23, 11 }, r1 = { 0, 2, 0, 3 };
	struct pov_job jobs[2];
	struct pov_result res[2];
	struct image img = { 0 };

	(void)state;
	make_tiny_scene(scene, sizeof(scene), scratch(dir, sizeof(dir), "region render"), "s.pov");
	memset(jobs, 0, sizeof(jobs));
	for (int i = 0; i < 2; i++) {
		jobs[i].scene = scene;
		jobs[i].width = 32;
		jobs[i].height = 24;
		jobs[i].threads = 1;
	}
	jobs[0].output = scratch(o0, sizeof(o0), "region render/r0.exr");
	jobs[0].region = &r0;
	jobs[1].output = scratch(o1, sizeof(o1), "region render/r1.exr");
	jobs[1].region = &r1;	/* one column: POV-Ray's "+EC1" trap */
	assert_int_equal(run_pool(jobs, 2, 2, 20, 0, res), 0);
	assert_int_equal(res[0].status, POV_OK);
	assert_int_equal(res[1].status, POV_OK);
	assert_int_equal(res[0].stats.pixels, 16 * 8);
	assert_int_equal(res[1].stats.pixels, 2);

	for (int i = 0; i < 2; i++) {
		const struct pov_region *r = jobs[i].region;

		assert_int_equal(image_read_exr(jobs[i].output, &img, err, sizeof(err)), 0);
		assert_int_equal(img.w, 32);	/* full size */
		assert_int_equal(img.h, 24);
		for (int y = 0; y < img.h; y++)
			for (int x = 0; x < img.w; x++)
				assert_pixel(&img, x, y, x >= r->x0 && x <= r->x1 && y >= r->y0 &&
							 y <= r->y1);
		image_release(&img);
	}
	release_all(res, 2);
}

/*
 * A render stopped at the pool's deadline with salvage: the blocks it
 * finished come back in its result, as a render of them alone has them
 * (within the halves of POV-Ray's OpenEXR output), NaN elsewhere, and its
 * state file is gone; without salvage, none.
 */
/* A scene of about 3.4 s of tracing on one thread in salvage_region at
 * 256x192 with salvage_aa, its first two blocks 0.17 s (2026-12-05). */
static const char salvage_scene[] =
	"#version 3.7;\n"
	"global_settings { assumed_gamma 1.0 }\n"
	"camera { location <0, 3, -2.5> look_at <0, 0.3, 0> }\n"
	"light_source { <3, 5, -3> rgb 1 area_light <2, 0, 0>, <0, 0, 2>, 10, 10 jitter }\n"
	"plane { y, 0 pigment { checker rgb 1 rgb 0.2 scale 0.3 } }\n"
	"sphere { <0, 0.6, 0>, 0.6 pigment { rgb <1, 0.5, 0.2> } finish { reflection 0.3 } }\n";
static const char *const salvage_aa[] = { "+AM1", "+A0.0", "+R3" };
static const struct pov_region salvage_region = { 16, 16, 239, 175 };

static void salvage_job(struct pov_job *job, const char *scene, const char *out)
{
	memset(job, 0, sizeof(*job));
	job->scene = scene;
	job->output = out;
	job->width = 256;
	job->height = 192;
	job->region = &salvage_region;
	job->threads = 1;
	job->extra = salvage_aa;
	job->nextra = 3;
	job->salvage = 1;
}

static void test_render_salvage(void **state)
{
	const struct pov_region r = salvage_region, first = { 16, 16, 79, 47 };
	char dir[PATH_MAX], scene[PATH_MAX], out[PATH_MAX], part[PATH_MAX], err[512];
	struct pov_job job;
	struct pov_result res;
	struct pov_pool_opts o;
	struct image img = { 0 };
	int oy;

	(void)state;
	mkdir_p(scratch(dir, sizeof(dir), "salvage"));
	write_file(scratch(scene, sizeof(scene), "salvage/slow.pov"), salvage_scene);
	salvage_job(&job, scene, scratch(out, sizeof(out), "salvage/r.exr"));
	pov_pool_opts_init(&o);
	o.max_jobs = 1;
	o.deadline_s = 2.0;
	assert_int_equal(pov_pool_run(&job, 1, &o, &res, err, sizeof(err)), 0);
	assert_int_equal(res.status, POV_CANCELLED);
	const long all = (long)(r.x1 - r.x0 + 1) * (r.y1 - r.y0 + 1);
	if (!(res.partial_pixels >= 2 * 32 * 32 && res.partial_pixels < all))
		fail_msg("%ld pixels kept of %ld", res.partial_pixels, all);
	assert_int_equal(res.partial.w, 256);
	assert_int_equal(res.partial_oy, r.y0);
	assert_int_equal(res.partial.h, r.y1 - r.y0 + 1);
	assert_false(exists(out));
	assert_int_equal(count_entries(dir, "pov-state"), 0);
	/* the first two blocks, rendered alone */
	job.output = scratch(part, sizeof(part), "salvage/first.exr");
	job.region = &first;
	job.salvage = 0;
	o.deadline_s = 0.0;
	struct pov_result whole;
	assert_int_equal(pov_pool_run(&job, 1, &o, &whole, err, sizeof(err)), 0);
	assert_int_equal(whole.status, POV_OK);
	assert_int_equal(image_read_exr_rows(part, first.y0, first.y1, &img, &oy, err, sizeof(err)),
			 0);
	long n = 0, checked = 0;
	for (int y = 0; y < res.partial.h; y++)
		for (int x = 0; x < res.partial.w; x++) {
			const float *q = res.partial.px + ((size_t)y * res.partial.w + x) * 3;
			const int Y = y + res.partial_oy;
			if (isnan(q[0])) {
				assert_true(isnan(q[1]) && isnan(q[2]));
				continue;
			}
			n++;
			assert_true(x >= r.x0 && x <= r.x1);
			if (x > first.x1 || Y > first.y1)
				continue;
			for (int c = 0; c < 3; c++) {
				const float v = img.px[((size_t)(Y - oy) * img.w + x) * img.nch +
						       image_channel(&img, c == 0 ? "R" : c == 1 ? "G" : "B")];
				if (!(fabsf(q[c] - v) <= 1e-3f * fabsf(v) + 1e-4f))
					fail_msg("pixel (%d, %d) channel %d: %g kept, %g rendered", x, Y,
						 c, q[c], v);
			}
			checked++;
		}
	assert_int_equal(n, res.partial_pixels);
	assert_int_equal(checked, 2 * 32 * 32);
	image_release(&img);
	pov_result_release(&whole);
	pov_result_release(&res);
	/* without salvage, nothing is kept */
	job.output = out;
	job.region = &r;
	o.deadline_s = 1.5;
	assert_int_equal(pov_pool_run(&job, 1, &o, &res, err, sizeof(err)), 0);
	assert_int_equal(res.status, POV_CANCELLED);
	assert_int_equal(res.partial_pixels, 0);
	assert_null(res.partial.px);
	assert_int_equal(count_entries(dir, "pov-state"), 0);
	pov_result_release(&res);
}

static void test_render_parse_error(void **state)
{
	static const char bad[] =
		"#version 3.7;\n"
		"global_settings { assumed_gamma 1.0 }\n"
		"camera { location <0, 0, -3> look_at 0 }\n"
		"sphere { 0, 1 pigment { color rgb 1 } }\n"
		"sphere { 0, 1 pigment { colr rgb 1 } }\n";
	char d0[PATH_MAX], d1[PATH_MAX], s0[PATH_MAX], s1[PATH_MAX], o0[PATH_MAX],
	     o1[PATH_MAX], work[PATH_MAX], want[PATH_MAX + 64];
	struct pov_job jobs[2];
	struct pov_result res[2];

	(void)state;
	mkdir_p(scratch(d0, sizeof(d0), "broken scenes"));
	mkdir_p(scratch(d1, sizeof(d1), "broken \"scenes\""));
	mkdir_p(scratch(work, sizeof(work), "work"));
	write_file(scratch(s0, sizeof(s0), "broken scenes/bad one.pov"), bad);
	write_file(scratch(s1, sizeof(s1), "broken \"scenes\"/bad.pov"), bad);
	memset(jobs, 0, sizeof(jobs));
	jobs[0].scene = s0;
	jobs[0].output = scratch(o0, sizeof(o0), "broken scenes/o.exr");
	jobs[1].scene = s1;
	jobs[1].output = scratch(o1, sizeof(o1), "broken \"scenes\"/o.exr");
	jobs[1].workdir = work;
	for (int i = 0; i < 2; i++) {
		jobs[i].width = 16;
		jobs[i].height = 12;
	}
	assert_int_equal(run_pool(jobs, 2, 2, 20, 1, res), 0);
	for (int i = 0; i < 2; i++) {
		assert_int_equal(res[i].status, POV_FAILED);
		assert_int_equal(res[i].attempts, 1);	/* a parse error is not retried */
		assert_int_equal(res[i].exit_status, 1);
		/* POV-Ray's own words, with the path the user gave, not a link */
		snprintf(want, sizeof(want), "File '%s' line 5: Parse Error: No matching } in "
			 "'pigment', undeclared identifier 'colr' found instead", jobs[i].scene);
		assert_contains(res[i].message, want);
		assert_null(strstr(res[i].message, "povpress-"));
		assert_false(exists(jobs[i].output));
	}
	release_all(res, 2);
}

/* A render that would take over 10 s, a 1 s timeout: killed, retried once,
 * killed again, and nothing left running or on disk. */
static void test_timeout_kills(void **state)
{
	char dir[PATH_MAX], scene[PATH_MAX], out[PATH_MAX], tag[64], name[128], st[PATH_MAX];
	struct pov_job job;
	struct pov_result res;
	double t;

	(void)state;
	snprintf(tag, sizeof(tag), "povpress-timeout-%d", (int)getpid());
	mkdir_p(scratch(dir, sizeof(dir), "slow"));
	write_file(scratch(scene, sizeof(scene), "slow/slow.pov"), slow_scene);
	snprintf(name, sizeof(name), "slow/%s.exr", tag);
	slow_job(&job, scene, scratch(out, sizeof(out), name));
	t = now_s();
	assert_int_equal(run_pool(&job, 1, 1, 1.0, 1, &res), 0);
	t = now_s() - t;
	assert_int_equal(res.status, POV_TIMED_OUT);
	assert_int_equal(res.attempts, 2);
	assert_contains(res.message, "timed out after 1 s");
	/* two attempts of 1 s, each stopped within the 1 s grace */
	assert_true(t >= 2.0 && t < 6.0);
	assert_true(res.wall_s >= 2.0 && res.wall_s < 6.0);
	assert_true(res.cpu_s > 0.2);
	assert_int_equal(count_procs(tag), 0);
	assert_false(exists(out));
	snprintf(name, sizeof(name), "slow/%s.pov-state", tag);
	assert_false(exists(scratch(st, sizeof(st), name)));
	pov_result_release(&res);
}

/*
 * In a child process: run three slow jobs two at a time; exit 42 if the pool
 * reported POV_INTERRUPTED with the signal, the two running jobs cancelled
 * and the third never started.
 */
static void interrupted_child(const char *scene, const char *tag, int want_sig)
{
	char outs[3][PATH_MAX];
	struct pov_job jobs[3];
	struct pov_result res[3];
	struct pov_pool_opts o;
	char err[512];
	int rc, ok;

	for (int i = 0; i < 3; i++) {
		snprintf(outs[i], sizeof(outs[i]), "%s/slow/%s-%d.exr", scratch_dir, tag, i);
		slow_job(&jobs[i], scene, outs[i]);
	}
	pov_pool_opts_init(&o);
	o.max_jobs = 2;
	o.grace_s = 2.0;
	rc = pov_pool_run(jobs, 3, &o, res, err, sizeof(err));
	ok = rc == POV_INTERRUPTED && pov_signal_received() == want_sig &&
	     res[0].status == POV_CANCELLED && res[1].status == POV_CANCELLED &&
	     res[0].attempts == 1 && res[1].attempts == 1 && res[2].status == POV_CANCELLED &&
	     res[2].attempts == 0 && strstr(res[2].message, "not started");
	if (!ok)
		fprintf(stderr, "child: rc %d sig %d: %s / %s / %s\n", rc, pov_signal_received(),
			res[0].message, res[1].message, res[2].message);
	_exit(ok ? 42 : 1);
}

static void signal_during_pool(int sig)
{
	char dir[PATH_MAX], scene[PATH_MAX], tag[64];
	pid_t pid;
	int st = 0, n;
	double t;

	snprintf(tag, sizeof(tag), "povpress-sig%d-%d", sig, (int)getpid());
	mkdir_p(scratch(dir, sizeof(dir), "slow"));
	write_file(scratch(scene, sizeof(scene), "slow/slow.pov"), slow_scene);
	fflush(NULL);
	pid = fork();
	assert_true(pid >= 0);
	if (pid == 0)
		interrupted_child(scene, tag, sig);
	n = wait_procs(tag, 2, 10.0);
	if (n != 2) {
		kill(pid, SIGKILL);
		waitpid(pid, &st, 0);
		fail_msg("%d povray children running, wanted 2", n);
	}
	pause_s(0.3);	/* well into the render */
	t = now_s();
	kill(pid, sig);
	while (waitpid(pid, &st, WNOHANG) == 0 && now_s() - t < 10)
		pause_s(0.02);
	t = now_s() - t;
	if (!WIFEXITED(st)) {
		kill(pid, SIGKILL);
		waitpid(pid, &st, 0);
		fail_msg("the pool process did not exit after signal %d", sig);
	}
	assert_int_equal(WEXITSTATUS(st), 42);
	assert_true(t < 4.0);	/* stopped within seconds */
	assert_int_equal(count_procs(tag), 0);
}

/*
 * A render with salvage stopped by SIGINT: in a child process, one job of
 * the salvage scene; exit 42 if the pool reported POV_INTERRUPTED and the
 * job cancelled with some of its pixels kept, not all.
 */
static void salvaged_child(const char *scene, const char *out)
{
	struct pov_job job;
	struct pov_result res;
	struct pov_pool_opts o;
	char err[512];

	salvage_job(&job, scene, out);
	pov_pool_opts_init(&o);
	o.max_jobs = 1;
	o.grace_s = 2.0;
	const int rc = pov_pool_run(&job, 1, &o, &res, err, sizeof(err));
	const long all = (long)(salvage_region.x1 - salvage_region.x0 + 1) *
			 (salvage_region.y1 - salvage_region.y0 + 1);
	const int ok = rc == POV_INTERRUPTED && res.status == POV_CANCELLED &&
		       res.partial_pixels >= 32 * 32 && res.partial_pixels < all &&
		       res.partial.w == 256 && res.partial_oy == salvage_region.y0;
	if (!ok)
		fprintf(stderr, "child: rc %d, %s, %ld pixels kept\n", rc, res.message,
			res.partial_pixels);
	_exit(ok ? 42 : 1);
}

/* SIGINT 1.5 s into the render (0.6 s of POV-Ray's start, then its first
 * blocks): the pool keeps the blocks it finished, its state file goes. */
static void test_sigint_salvages(void **state)
{
	char dir[PATH_MAX], scene[PATH_MAX], out[PATH_MAX], tag[64], name[128];
	pid_t pid;
	int st = 0;

	(void)state;
	snprintf(tag, sizeof(tag), "povpress-salvage-%d", (int)getpid());
	mkdir_p(scratch(dir, sizeof(dir), "salvage-int"));
	write_file(scratch(scene, sizeof(scene), "salvage-int/slow.pov"), salvage_scene);
	snprintf(name, sizeof(name), "salvage-int/%s.exr", tag);
	scratch(out, sizeof(out), name);
	fflush(NULL);
	pid = fork();
	assert_true(pid >= 0);
	if (pid == 0)
		salvaged_child(scene, out);
	if (wait_procs(tag, 1, 10.0) != 1) {
		kill(pid, SIGKILL);
		waitpid(pid, &st, 0);
		fail_msg("no povray child running");
	}
	pause_s(1.5);
	kill(pid, SIGINT);
	double t = now_s();
	while (waitpid(pid, &st, WNOHANG) == 0 && now_s() - t < 10)
		pause_s(0.02);
	if (!WIFEXITED(st)) {
		kill(pid, SIGKILL);
		waitpid(pid, &st, 0);
		fail_msg("the pool process did not exit after SIGINT");
	}
	assert_int_equal(WEXITSTATUS(st), 42);
	assert_int_equal(count_procs(tag), 0);
	assert_int_equal(count_entries(dir, "pov-state"), 0);
	assert_false(exists(out));
}

static void test_sigint_stops_pool(void **state)
{
	(void)state;
	signal_during_pool(SIGINT);
}

static void test_sigterm_stops_pool(void **state)
{
	(void)state;
	signal_during_pool(SIGTERM);
}

/* Even a SIGKILLed povpress leaves no povray behind (PR_SET_PDEATHSIG). */
static void test_sigkill_leaves_no_orphans(void **state)
{
	char dir[PATH_MAX], scene[PATH_MAX], tag[64];
	pid_t pid;
	int st, n;

	(void)state;
	snprintf(tag, sizeof(tag), "povpress-kill-%d", (int)getpid());
	mkdir_p(scratch(dir, sizeof(dir), "slow"));
	write_file(scratch(scene, sizeof(scene), "slow/slow.pov"), slow_scene);
	fflush(NULL);
	pid = fork();
	assert_true(pid >= 0);
	if (pid == 0)
		interrupted_child(scene, tag, SIGINT);
	n = wait_procs(tag, 2, 10.0);
	kill(pid, SIGKILL);
	waitpid(pid, &st, 0);
	assert_int_equal(n, 2);
	assert_true(WIFSIGNALED(st) && WTERMSIG(st) == SIGKILL);
	assert_int_equal(wait_procs(tag, 0, 3.0), 0);
}

/* A signal caught before the pool starts (the caller's own catch) stops it
 * before anything runs. */
static void test_signal_before_pool(void **state)
{
	char scene[PATH_MAX], out[PATH_MAX], err[512];
	struct pov_job job = { 0 };
	struct pov_result res;
	struct pov_pool_opts o;
	struct sigaction before, after;

	(void)state;
	tiny_job(&job, scene, out, "early", "s.pov", "o.exr", 8, 8);
	job.povray = fake_bin;
	sigaction(SIGINT, NULL, &before);
	assert_int_equal(pov_signals_catch(err, sizeof(err)), 0);
	assert_int_equal(pov_signal_received(), 0);
	raise(SIGINT);
	assert_int_equal(pov_signal_received(), SIGINT);
	pov_pool_opts_init(&o);
	assert_int_equal(pov_pool_run(&job, 1, &o, &res, err, sizeof(err)), POV_INTERRUPTED);
	assert_int_equal(res.status, POV_CANCELLED);
	assert_int_equal(res.attempts, 0);
	assert_false(exists(out));
	pov_signals_restore();
	sigaction(SIGINT, NULL, &after);
	assert_true(after.sa_handler == before.sa_handler);
	pov_result_release(&res);
}

/* Pre-launched renders: the ones a pool's jobs match are taken and begin at
 * their gate, without POV-Ray's start-up wait, rendering what a fresh
 * start renders; the one no job matches is stopped; no gate, process or
 * output of theirs is left. */
static void test_prelaunch(void **state)
{
	char dir[PATH_MAX], scene[PATH_MAX], gates[PATH_MAX], other[PATH_MAX], fresh[PATH_MAX],
	     err[512];
	char outs[3][PATH_MAX];
	struct pov_region regs[3] = { { 0, 0, 31, 11 }, { 0, 12, 31, 23 }, { 4, 4, 9, 9 } };
	struct pov_job jobs[3], pool[3];
	struct pov_result res[3], fres;
	struct pov_pool_opts o;
	struct pov_prelaunch *pre = NULL;
	struct image a = { 0 }, b = { 0 };

	(void)state;
	make_tiny_scene(scene, sizeof(scene), scratch(dir, sizeof(dir), "prelaunch"), "s.pov");
	mkdir_p(scratch(gates, sizeof(gates), "prelaunch/gates"));
	memset(jobs, 0, sizeof(jobs));
	for (int k = 0; k < 3; k++) {
		char name[64];

		snprintf(name, sizeof(name), "prelaunch/p%d.exr", k);
		jobs[k].scene = scene;
		jobs[k].output = scratch(outs[k], sizeof(outs[k]), name);
		jobs[k].width = 32;
		jobs[k].height = 24;
		jobs[k].threads = 1;
		jobs[k].region = &regs[k];
	}
	assert_int_equal(pov_prelaunch_start(jobs, 3, gates, &pre, err, sizeof(err)), 0);
	assert_int_equal(count_procs("prelaunch/gates/gate-"), 3);
	pause_s(1.0);	/* through POV-Ray's start-up, to the gate */
	for (int k = 0; k < 3; k++)
		assert_false(exists(outs[k]));	/* waiting there */
	/* jobs 1 and 0 as they were; job 2's region into another file */
	pool[0] = jobs[1];
	pool[1] = jobs[0];
	pool[2] = jobs[2];
	pool[2].output = scratch(other, sizeof(other), "prelaunch/other.exr");
	pov_pool_opts_init(&o);
	o.max_jobs = 3;
	o.prelaunched = pre;
	assert_int_equal(pov_pool_run(pool, 3, &o, res, err, sizeof(err)), 0);
	for (int k = 0; k < 3; k++)
		assert_int_equal(res[k].status, POV_OK);
	assert_int_equal(res[0].prelaunched, 1);
	assert_int_equal(res[1].prelaunched, 1);
	assert_int_equal(res[2].prelaunched, 0);
	assert_int_equal(pov_prelaunch_taken(pre), 2);
	/* from the gate to the image, against a start from nothing */
	print_message("prelaunch: gate to image %.3f and %.3f s, a fresh start %.3f s\n",
		      res[0].wall_s, res[1].wall_s, res[2].wall_s);
	assert_true(res[0].wall_s < res[2].wall_s && res[1].wall_s < res[2].wall_s);
	assert_true(pov_prelaunch_end(pre) >= 0.0);
	assert_int_equal(count_procs("prelaunch/gates/gate-"), 0);
	assert_false(exists(outs[2]));
	DIR *d = opendir(gates);
	assert_non_null(d);
	int left = 0;
	for (struct dirent *e; (e = readdir(d));)
		left += e->d_name[0] != '.';
	closedir(d);
	assert_int_equal(left, 0);
	/* a taken render's image is a fresh render's */
	pool[0].output = scratch(fresh, sizeof(fresh), "prelaunch/fresh.exr");
	assert_int_equal(run_pool(pool, 1, 1, 20, 0, &fres), 0);
	assert_int_equal(fres.status, POV_OK);
	assert_int_equal(image_read_exr(outs[1], &a, err, sizeof(err)), 0);
	assert_int_equal(image_read_exr(fresh, &b, err, sizeof(err)), 0);
	assert_int_equal(a.w * a.h * a.nch, b.w * b.h * b.nch);
	assert_memory_equal(a.px, b.px, (size_t)a.w * a.h * a.nch * sizeof(*a.px));
	image_release(&a);
	image_release(&b);
	pov_result_release(&fres);
	release_all(res, 3);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_argv_order_and_quoting),
		cmocka_unit_test(test_argv_radiosity),
		cmocka_unit_test(test_argv_region),
		cmocka_unit_test(test_argv_bad_jobs),
		cmocka_unit_test(test_argv_links),
		cmocka_unit_test(test_shell_line_words),
		cmocka_unit_test(test_shell_line_round_trip_args),
		cmocka_unit_test(test_shell_line_renders),
		cmocka_unit_test(test_render_time_printed),
		cmocka_unit_test(test_stats_no_aa),
		cmocka_unit_test(test_stats_aa),
		cmocka_unit_test(test_stats_verbose_region),
		cmocka_unit_test(test_stats_radiosity_photons),
		cmocka_unit_test(test_stats_missing_and_odd),
		cmocka_unit_test(test_pool_size),
		cmocka_unit_test(test_missing_binary),
		cmocka_unit_test(test_pool_limit),
		cmocka_unit_test(test_pool_ready),
		cmocka_unit_test(test_pool_crash_retry_and_no_output),
		cmocka_unit_test(test_pool_error_messages),
		cmocka_unit_test(test_state_parse),
		cmocka_unit_test(test_render_awkward_paths),
		cmocka_unit_test(test_render_region),
		cmocka_unit_test(test_prelaunch),
		cmocka_unit_test(test_render_parse_error),
		cmocka_unit_test(test_render_salvage),
		cmocka_unit_test(test_timeout_kills),
		cmocka_unit_test(test_results_latency),
		cmocka_unit_test(test_pool_deadline),
		cmocka_unit_test(test_pool_progress),
		cmocka_unit_test(test_pool_finish),
		cmocka_unit_test(test_sigint_stops_pool),
		cmocka_unit_test(test_sigint_salvages),
		cmocka_unit_test(test_sigterm_stops_pool),
		cmocka_unit_test(test_sigkill_leaves_no_orphans),
		cmocka_unit_test(test_signal_before_pool),
	};

	return cmocka_run_group_tests(tests, setup_dir, teardown_dir);
}
