/*
 * povray.c - run POV-Ray 3.7: command lines, statistics, a bounded pool of
 * concurrent renders.  See povray.h for the contract.
 *
 * What POV-Ray 3.7.0.10 does that shapes this file (measured on Debian 12):
 *
 * - It writes everything (banner, options, warnings, errors, statistics)
 *   to stderr, nothing to stdout, word-wrapped at 80 columns: a message
 *   longer than that continues on the next line, which starts with the
 *   space the break replaced (or, with no space in the last 20 columns, the
 *   line is cut at exactly 80).  Error messages are unwrapped before they
 *   are reported.
 * - A parse error reads "File '/path/a.pov' line 5: Parse Error: ...".
 * - +SC/+EC/+SR/+ER values in [0, 1] are fractions of the image size, so
 *   "+EC1" means the last column, not the first.  A 1-based end of 1 is
 *   therefore written "1.5", which POV-Ray reads as a pixel number and
 *   truncates to 1.
 * - SIGTERM makes POV-Ray cancel the render and exit (status 2) in under
 *   half a second; it writes no image and leaves "<stem>.pov-state" beside
 *   the output, which holds the blocks it finished (also when SIGKILL
 *   follows: var_refl's +AM1 render at 1280x960, killed by SIGKILL 0.6 s in
 *   and by SIGTERM and SIGKILL 0.05 s apart, left 290,240 and 312,960
 *   pixels, each equal to the whole render's within its OpenEXR halves;
 *   2026-12-05).  A job with salvage has them read before the file goes.
 */
#define _GNU_SOURCE	/* pipe2, wait4, sched_getaffinity, prctl */

#include "driver/errbuf.h"
#include "driver/povray.h"
#include "driver/povstate.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/prctl.h>
#include <sys/inotify.h>
#endif

#define POV_LOG_MAX (1u << 20)	/* console output kept per attempt (its tail) */
#define POV_MAX_SIZE 1000000	/* largest +W / +H accepted */
#define POV_MAX_THREADS 4096
#define DEADLINE_GRACE_S 0.05	/* SIGTERM to SIGKILL for a job past the deadline */
#define POV_TICK_S 0.1		/* longest wait between checks of the children */

extern char **environ;

/* malloc'd printf; NULL when out of memory. */
static char *xprintf(const char *fmt, ...)
{
	va_list ap;
	int n;
	char *s;

	va_start(ap, fmt);
	n = vsnprintf(NULL, 0, fmt, ap);
	va_end(ap);
	if (n < 0)
		return NULL;
	s = malloc((size_t)n + 1);
	if (!s)
		return NULL;
	va_start(ap, fmt);
	vsnprintf(s, (size_t)n + 1, fmt, ap);
	va_end(ap);
	return s;
}

/*
 * The environment POV-Ray runs in: ours, with povwait.so (driver/povwait/)
 * preloaded, which cuts the polling waits POV-Ray spends most of a small
 * render's wall time on.  The library is the one next to the povpress
 * executable, or $POVPRESS_POVWAIT's (a path; "0" or empty: none).  Built
 * once, before any render starts, and never changed.
 */
static pthread_once_t env_once = PTHREAD_ONCE_INIT;
static char **env_pov;			/* NULL: environ */
static char env_lib[PATH_MAX];		/* the library preloaded, or "" */

static void env_build(void)
{
	const char *set = getenv("POVPRESS_POVWAIT");
	const char *old = getenv("LD_PRELOAD");
	char exe[PATH_MAX];
	size_t n = 0, k = 0;
	char **envp;
	char *pre;

	if (set) {
		if (!*set || strcmp(set, "0") == 0)
			return;
		if (strlen(set) >= sizeof(env_lib))
			return;
		strcpy(env_lib, set);
	} else {
		ssize_t len = readlink("/proc/self/exe", exe, sizeof(exe) - 1);
		char *slash;

		if (len <= 0)
			return;
		exe[len] = '\0';
		slash = strrchr(exe, '/');
		if (!slash || (size_t)(slash - exe) + sizeof("/povwait.so") > sizeof(env_lib))
			return;
		memcpy(env_lib, exe, (size_t)(slash - exe));
		strcpy(env_lib + (slash - exe), "/povwait.so");
	}
	/* ld.so splits LD_PRELOAD at spaces and colons */
	if (access(env_lib, R_OK) || strpbrk(env_lib, " :")) {
		env_lib[0] = '\0';
		return;
	}
	while (environ[n])
		n++;
	envp = calloc(n + 2, sizeof(*envp));
	pre = old && *old ? xprintf("LD_PRELOAD=%s:%s", env_lib, old) : xprintf("LD_PRELOAD=%s", env_lib);
	if (!envp || !pre) {
		free(envp);
		free(pre);
		env_lib[0] = '\0';
		return;
	}
	for (size_t i = 0; i < n; i++)
		if (strncmp(environ[i], "LD_PRELOAD=", 11) != 0)
			envp[k++] = environ[i];
	envp[k++] = pre;
	envp[k] = NULL;
	env_pov = envp;
}

static char **pov_environ(void)
{
	pthread_once(&env_once, env_build);
	return env_pov ? env_pov : environ;
}

const char *pov_wait_library(void)
{
	pthread_once(&env_once, env_build);
	return env_lib[0] ? env_lib : NULL;
}

static double now_s(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- growing byte buffer -------------------------------------------- */

struct buf {
	char *p;
	size_t len, cap;
};

/* Append n bytes; with limit > 0, keep only the last limit bytes. */
static int buf_add(struct buf *b, const char *s, size_t n, size_t limit)
{
	if (limit && n >= limit) {
		s += n - limit;
		n = limit;
		b->len = 0;
	} else if (limit && b->len + n > limit) {
		size_t drop = b->len + n - limit;

		memmove(b->p, b->p + drop, b->len - drop);
		b->len -= drop;
	}
	if (b->len + n + 1 > b->cap) {
		size_t cap = b->cap ? b->cap : 256;
		char *p;

		while (cap < b->len + n + 1)
			cap *= 2;
		p = realloc(b->p, cap);
		if (!p)
			return -1;
		b->p = p;
		b->cap = cap;
	}
	memcpy(b->p + b->len, s, n);
	b->len += n;
	b->p[b->len] = '\0';
	return 0;
}

static int buf_str(struct buf *b, const char *s)
{
	return buf_add(b, s, strlen(s), 0);
}

/* ---- paths ------------------------------------------------------------ */

/* POV-Ray takes a path in double quotes when every byte is printable
 * ASCII other than the double quote itself. */
static int path_safe(const char *p)
{
	if (!*p)
		return 0;
	for (; *p; p++) {
		unsigned char c = (unsigned char)*p;

		if (c < 0x20 || c > 0x7e || c == '"')
			return 0;
	}
	return 1;
}

static uint64_t fnv1a(const char *s)
{
	uint64_t h = 1469598103934665603ull;

	for (; *s; s++) {
		h ^= (unsigned char)*s;
		h *= 1099511628211ull;
	}
	return h;
}

/* Split path into a malloc'd directory ("." when there is none) and a
 * pointer to its last component (empty when path ends in '/'). */
static char *split_path(const char *path, const char **base)
{
	const char *slash = strrchr(path, '/');

	if (!slash) {
		*base = path;
		return strdup(".");
	}
	*base = slash + 1;
	if (slash == path)
		return strdup("/");
	return strndup(path, (size_t)(slash - path));
}

/*
 * Make (or reuse) workdir/povpress-<hash of target><suffix>, a symbolic
 * link to target (an absolute path), for what (the path as the user gave
 * it, for messages).  *link_out is malloc'd.
 */
static int make_link(const char *workdir, const char *target, const char *suffix,
		     const char *what, char **link_out, char *err, size_t errlen)
{
	char *link;
	char have[PATH_MAX + 1];
	struct stat st;
	ssize_t n;

	*link_out = NULL;
	if (!workdir || !*workdir) {
		errbuf_printf(err, errlen, "cannot pass '%s' to povray: the path has a double quote "
		     "or a non-ASCII byte, and no work directory was given for a link", what);
		return -1;
	}
	if (!path_safe(workdir)) {
		errbuf_printf(err, errlen, "cannot use work directory '%s': its own path has a double "
		     "quote or a non-ASCII byte", workdir);
		return -1;
	}
	link = xprintf("%s/povpress-%016llx%s", workdir, (unsigned long long)fnv1a(target),
		       suffix);
	if (!link) {
		errbuf_printf(err, errlen, "out of memory");
		return -1;
	}
	for (int tries = 0; tries < 2; tries++) {
		if (symlink(target, link) == 0) {
			*link_out = link;
			return 0;
		}
		if (errno != EEXIST)
			break;
		n = readlink(link, have, sizeof(have) - 1);
		if (n >= 0) {
			have[n] = '\0';
			if (!strcmp(have, target)) {
				*link_out = link;
				return 0;
			}
		}
		/* A stale link of ours (hash collision or a moved target): replace
		 * it, but never anything that is not a link. */
		if (lstat(link, &st) || !S_ISLNK(st.st_mode) || unlink(link)) {
			errno = EEXIST;
			break;
		}
	}
	errbuf_printf(err, errlen, "cannot make link '%s' to '%s': %s", link, what, strerror(errno));
	free(link);
	return -1;
}

int pov_path_safe(const char *path)
{
	return path_safe(path);
}

int pov_safe_dir(const char *dir, char *out, size_t outlen, char *err, size_t errlen)
{
	char real[PATH_MAX];

	if (path_safe(dir)) {
		if (snprintf(out, outlen, "%s", dir) >= (int)outlen) {
			errbuf_printf(err, errlen, "directory '%s': path too long", dir);
			return -1;
		}
		return 0;
	}
	if (!realpath(dir, real)) {
		errbuf_printf(err, errlen, "cannot use directory '%s': %s", dir, strerror(errno));
		return -1;
	}
	const char *tmp = getenv("TMPDIR");
	if (!tmp || !*tmp || !path_safe(tmp))
		tmp = "/tmp";
	char *link = NULL;
	int rc = make_link(tmp, real, ".d", dir, &link, err, errlen);
	if (rc)
		return -1;
	if (snprintf(out, outlen, "%s", link) >= (int)outlen) {
		errbuf_printf(err, errlen, "directory '%s': path too long", link);
		rc = -1;
	}
	free(link);
	return rc;
}

/* ---- commands ------------------------------------------------------- */

#define MAX_SUBS 4

/* A job made ready to run: the vector and the files around it. */
struct cmd {
	char **argv;
	int argc, cap;
	char *povout;		/* the file POV-Ray writes, as it is told */
	char *final;		/* where povout is renamed on success, or NULL */
	char *state;		/* povout's .pov-state file */
	const char *output;	/* job->output */
	const char *scene;	/* job->scene */
	char *sub_from[MAX_SUBS]; /* links POV-Ray sees ... */
	char *sub_to[MAX_SUBS];	/* ... and the paths they stand for */
	int nsubs;
};

static void cmd_release(struct cmd *c)
{
	if (c->argv) {
		for (int i = 0; i < c->argc; i++)
			free(c->argv[i]);
		free(c->argv);
	}
	free(c->povout);
	free(c->final);
	free(c->state);
	for (int i = 0; i < c->nsubs; i++) {
		free(c->sub_from[i]);
		free(c->sub_to[i]);
	}
	memset(c, 0, sizeof(*c));
}

/* Append s (taken over; NULL means out of memory). */
static int cmd_push(struct cmd *c, char *s)
{
	if (!s)
		return -1;
	if (c->argc + 2 > c->cap) {
		int cap = c->cap ? 2 * c->cap : 32;
		char **a = realloc(c->argv, (size_t)cap * sizeof(*a));

		if (!a) {
			free(s);
			return -1;
		}
		c->argv = a;
		c->cap = cap;
	}
	c->argv[c->argc++] = s;
	c->argv[c->argc] = NULL;
	return 0;
}

static int cmd_sub(struct cmd *c, const char *from, const char *to)
{
	if (c->nsubs == MAX_SUBS)
		return 0;
	c->sub_from[c->nsubs] = strdup(from);
	c->sub_to[c->nsubs] = strdup(to);
	c->nsubs++;
	return c->sub_from[c->nsubs - 1] && c->sub_to[c->nsubs - 1] ? 0 : -1;
}

static const char *binary_name(const struct pov_job *job, int *from_env)
{
	const char *env = getenv("POVPRESS_POVRAY");

	*from_env = 0;
	if (job->povray && *job->povray)
		return job->povray;
	if (env && *env) {
		*from_env = 1;
		return env;
	}
	return "povray";
}

static int valid_identifier(const char *s)
{
	if (!s || !(isalpha((unsigned char)*s) || *s == '_'))
		return 0;
	for (s++; *s; s++)
		if (!(isalnum((unsigned char)*s) || *s == '_'))
			return 0;
	return 1;
}

static int valid_number(const char *s)
{
	char *end;
	double v;

	if (!s || !*s || isspace((unsigned char)*s))
		return 0;
	errno = 0;
	v = strtod(s, &end);
	return !errno && *end == '\0' && isfinite(v);
}

/* An end column or row, 1-based, as POV-Ray reads it (see the top). */
static char *region_end(const char *opt, int end1, int size)
{
	if (end1 == 1 && size > 1)
		return xprintf("%s1.5", opt);
	return xprintf("%s%d", opt, end1);
}

/*
 * Where POV-Ray writes: the output's directory (or a link to it) and the
 * output's name, or a stand-in when the name is unsafe or lacks ".exr".
 */
static int plan_output(const struct pov_job *job, struct cmd *c, char *err, size_t errlen)
{
	const char *base;
	char *dir = split_path(job->output, &base);
	char *odir = NULL, *real = NULL, *link = NULL, *name = NULL;
	struct stat st;
	size_t blen = strlen(base);
	int rc = -1;

	if (!dir) {
		errbuf_printf(err, errlen, "out of memory");
		return -1;
	}
	if (!blen || !strcmp(base, ".") || !strcmp(base, "..")) {
		errbuf_printf(err, errlen, "cannot write '%s': not a file name", job->output);
		goto out;
	}
	if (stat(dir, &st) || (S_ISDIR(st.st_mode) && access(dir, W_OK | X_OK))) {
		errbuf_printf(err, errlen, "cannot write '%s': %s", job->output, strerror(errno));
		goto out;
	}
	if (!S_ISDIR(st.st_mode)) {
		errbuf_printf(err, errlen, "cannot write '%s': '%s' is not a directory", job->output, dir);
		goto out;
	}
	if (path_safe(dir)) {
		odir = dir;
		dir = NULL;
	} else {
		real = realpath(dir, NULL);
		if (!real) {
			errbuf_printf(err, errlen, "cannot write '%s': %s", job->output, strerror(errno));
			goto out;
		}
		if (make_link(job->workdir, real, ".d", dir, &link, err, errlen))
			goto out;
		if (cmd_sub(c, link, dir))
			goto oom;
		odir = link;
		link = NULL;
	}
	if (path_safe(base) && blen > 4 && !strcmp(base + blen - 4, ".exr")) {
		name = strdup(base);
	} else {
		name = xprintf(".povpress-%016llx.exr", (unsigned long long)fnv1a(job->output));
		c->final = strdup(job->output);
		if (!c->final)
			goto oom;
	}
	if (!name)
		goto oom;
	c->povout = xprintf("%s/%s", odir, name);
	if (!c->povout)
		goto oom;
	const size_t sl = strlen(c->povout) + sizeof(".pov-state");
	c->state = malloc(sl);
	if (!c->state || pov_state_path(c->povout, c->state, sl))
		goto oom;
	rc = 0;
	goto out;
oom:
	errbuf_printf(err, errlen, "out of memory");
out:
	free(dir);
	free(odir);
	free(real);
	free(link);
	free(name);
	return rc;
}

/* The scene (+I) and its directory (+L), linked when unsafe. */
static int plan_scene(const struct pov_job *job, struct cmd *c, char **iarg, char **larg,
		      char *err, size_t errlen)
{
	const char *base;
	char *dir, *real = NULL;
	struct stat st;
	int rc = -1;

	*iarg = *larg = NULL;
	if (stat(job->scene, &st) || access(job->scene, R_OK)) {
		errbuf_printf(err, errlen, "cannot read scene '%s': %s", job->scene, strerror(errno));
		return -1;
	}
	if (!S_ISREG(st.st_mode)) {
		errbuf_printf(err, errlen, "cannot read scene '%s': not a regular file", job->scene);
		return -1;
	}
	dir = split_path(job->scene, &base);
	if (!dir)
		goto oom;
	if (path_safe(job->scene)) {
		*iarg = strdup(job->scene);
	} else {
		real = realpath(job->scene, NULL);
		if (!real) {
			errbuf_printf(err, errlen, "cannot read scene '%s': %s", job->scene, strerror(errno));
			goto out;
		}
		if (make_link(job->workdir, real, ".pov", job->scene, iarg, err, errlen))
			goto out;
		if (cmd_sub(c, *iarg, job->scene))
			goto oom;
		free(real);
		real = NULL;
	}
	if (!*iarg)
		goto oom;
	if (path_safe(dir)) {
		*larg = strdup(dir);
	} else {
		real = realpath(dir, NULL);
		if (!real) {
			errbuf_printf(err, errlen, "cannot read scene '%s': %s", job->scene, strerror(errno));
			goto out;
		}
		if (make_link(job->workdir, real, ".d", dir, larg, err, errlen))
			goto out;
		if (cmd_sub(c, *larg, dir))
			goto oom;
	}
	if (!*larg)
		goto oom;
	rc = 0;
	goto out;
oom:
	errbuf_printf(err, errlen, "out of memory");
out:
	if (rc) {
		free(*iarg);
		free(*larg);
		*iarg = *larg = NULL;
	}
	free(dir);
	free(real);
	return rc;
}

/* The radiosity file (+RF) as POV-Ray can be told it: the path, or its
 * directory linked when unsafe.  *out is malloc'd. */
static int plan_radiosity(const struct pov_job *job, struct cmd *c, char **out, char *err,
			  size_t errlen)
{
	const char *base;
	char *dir, *real = NULL, *link = NULL;
	int rc = -1;

	*out = NULL;
	if (path_safe(job->radiosity)) {
		*out = strdup(job->radiosity);
		if (!*out)
			errbuf_printf(err, errlen, "out of memory");
		return *out ? 0 : -1;
	}
	dir = split_path(job->radiosity, &base);
	if (!dir) {
		errbuf_printf(err, errlen, "out of memory");
		return -1;
	}
	if (!*base || !path_safe(base)) {
		errbuf_printf(err, errlen, "cannot pass radiosity file '%s' to povray: its name has "
			      "a double quote or a non-ASCII byte", job->radiosity);
		goto out;
	}
	real = realpath(dir, NULL);
	if (!real) {
		errbuf_printf(err, errlen, "cannot use radiosity file '%s': %s", job->radiosity,
			      strerror(errno));
		goto out;
	}
	if (make_link(job->workdir, real, ".d", dir, &link, err, errlen))
		goto out;
	*out = xprintf("%s/%s", link, base);
	if (!*out || cmd_sub(c, link, dir)) {
		errbuf_printf(err, errlen, "out of memory");
		goto out;
	}
	rc = 0;
out:
	if (rc) {
		free(*out);
		*out = NULL;
	}
	free(dir);
	free(real);
	free(link);
	return rc;
}

static int cmd_build(const struct pov_job *job, struct cmd *c, char *err, size_t errlen)
{
	const struct pov_region *r = job->region;
	char *iarg = NULL, *larg = NULL, *rarg = NULL;
	int from_env;

	memset(c, 0, sizeof(*c));
	if (!job->scene || !*job->scene || !job->output || !*job->output) {
		errbuf_printf(err, errlen, "a render job needs a scene and an output");
		return -1;
	}
	c->scene = job->scene;
	c->output = job->output;
	if (job->width < 1 || job->height < 1 || job->width > POV_MAX_SIZE ||
	    job->height > POV_MAX_SIZE) {
		errbuf_printf(err, errlen, "cannot render '%s' at %dx%d: bad image size", job->scene,
		     job->width, job->height);
		return -1;
	}
	if (r && (r->x0 < 0 || r->y0 < 0 || r->x0 > r->x1 || r->y0 > r->y1 ||
		  r->x1 >= job->width || r->y1 >= job->height)) {
		errbuf_printf(err, errlen, "cannot render region %d,%d-%d,%d of a %dx%d image", r->x0,
		     r->y0, r->x1, r->y1, job->width, job->height);
		return -1;
	}
	if (job->threads < 0 || job->threads > POV_MAX_THREADS) {
		errbuf_printf(err, errlen, "bad thread count %d", job->threads);
		return -1;
	}
	for (size_t i = 0; i < job->ndefines; i++) {
		const struct pov_define *d = &job->defines[i];

		if (!valid_identifier(d->name) || !valid_number(d->value)) {
			errbuf_printf(err, errlen, "bad declare '%s=%s': POV-Ray takes an identifier and "
			     "a number", d->name ? d->name : "", d->value ? d->value : "");
			return -1;
		}
	}
	for (size_t i = 0; i < job->nextra; i++) {
		if (!job->extra[i]) {
			errbuf_printf(err, errlen, "extra povray option %zu is missing", i + 1);
			return -1;
		}
	}
	if (job->radiosity && job->radiosity_mode != POV_RAD_SAVE &&
	    job->radiosity_mode != POV_RAD_LOAD) {
		errbuf_printf(err, errlen, "radiosity file '%s' is neither saved nor loaded",
			      job->radiosity);
		return -1;
	}
	if (plan_scene(job, c, &iarg, &larg, err, errlen) || plan_output(job, c, err, errlen) ||
	    (job->radiosity && plan_radiosity(job, c, &rarg, err, errlen)))
		goto fail;

	if (cmd_push(c, strdup(binary_name(job, &from_env))) || cmd_push(c, strdup("-D")) ||
	    cmd_push(c, strdup("+FE")) || cmd_push(c, strdup("-GR")) ||
	    cmd_push(c, strdup(job->progress ? "+V" : "-V")) ||
	    cmd_push(c, xprintf("+W%d", job->width)) ||
	    cmd_push(c, xprintf("+H%d", job->height)))
		goto oom;
	if (r && (cmd_push(c, xprintf("+SC%d", r->x0 + 1)) ||
		  cmd_push(c, region_end("+EC", r->x1 + 1, job->width)) ||
		  cmd_push(c, xprintf("+SR%d", r->y0 + 1)) ||
		  cmd_push(c, region_end("+ER", r->y1 + 1, job->height))))
		goto oom;
	if (job->threads > 0 && cmd_push(c, xprintf("+WT%d", job->threads)))
		goto oom;
	if (cmd_push(c, xprintf("+L\"%s\"", larg)) || cmd_push(c, xprintf("+I\"%s\"", iarg)) ||
	    cmd_push(c, xprintf("+O\"%s\"", c->povout)))
		goto oom;
	if (rarg && (cmd_push(c, strdup(job->radiosity_mode == POV_RAD_SAVE ? "+RFO" : "+RFI")) ||
		     cmd_push(c, xprintf("+RF\"%s\"", rarg))))
		goto oom;
	for (size_t i = 0; i < job->ndefines; i++)
		if (cmd_push(c, xprintf("Declare=%s=%s", job->defines[i].name,
					job->defines[i].value)))
			goto oom;
	for (size_t i = 0; i < job->nextra; i++)
		if (cmd_push(c, strdup(job->extra[i])))
			goto oom;
	free(iarg);
	free(larg);
	free(rarg);
	return 0;
oom:
	errbuf_printf(err, errlen, "out of memory");
fail:
	free(iarg);
	free(larg);
	free(rarg);
	cmd_release(c);
	return -1;
}

int pov_argv_build(const struct pov_job *job, char ***argv_out, int *argc_out, char *err,
		   size_t errlen)
{
	struct cmd c;

	*argv_out = NULL;
	if (argc_out)
		*argc_out = 0;
	if (cmd_build(job, &c, err, errlen))
		return -1;
	*argv_out = c.argv;
	if (argc_out)
		*argc_out = c.argc;
	c.argv = NULL;
	c.argc = 0;
	cmd_release(&c);
	return 0;
}

void pov_argv_free(char **argv)
{
	if (!argv)
		return;
	for (char **a = argv; *a; a++)
		free(*a);
	free(argv);
}

/* Append s to b as one shell word. */
static int shell_word(struct buf *b, const char *s)
{
	static const char plain[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
				    "0123456789_@%+=:,./-";

	if (*s && strspn(s, plain) == strlen(s))
		return buf_str(b, s);
	if (buf_str(b, "'"))
		return -1;
	for (const char *p = s; *p; p++) {
		if (*p == '\'' ? buf_str(b, "'\\''") : buf_add(b, p, 1, 0))
			return -1;
	}
	return buf_str(b, "'");
}

int pov_shell_line(const struct pov_job *job, char **line_out, char *err, size_t errlen)
{
	struct cmd c;
	struct buf b = { 0 };
	int bad = 0;

	*line_out = NULL;
	if (cmd_build(job, &c, err, errlen))
		return -1;
	for (int i = 0; i < c.argc && !bad; i++)
		bad = (i && buf_str(&b, " ")) || shell_word(&b, c.argv[i]);
	if (!bad && c.final)
		bad = buf_str(&b, " && mv -f -- ") || shell_word(&b, c.povout) ||
		      buf_str(&b, " ") || shell_word(&b, c.final);
	cmd_release(&c);
	if (bad) {
		free(b.p);
		errbuf_printf(err, errlen, "out of memory");
		return -1;
	}
	*line_out = b.p;
	return 0;
}

int pov_find_binary(const struct pov_job *job, char *path, size_t pathlen, char *err,
		    size_t errlen)
{
	int from_env;
	const char *name = binary_name(job, &from_env);
	const char *how = from_env ? " (from POVPRESS_POVRAY)" : "";
	struct stat st;
	int e = ENOENT;

	if (strchr(name, '/')) {
		if (stat(name, &st))
			e = errno;
		else if (!S_ISREG(st.st_mode) || access(name, X_OK))
			e = EACCES;
		else if (strlen(name) < pathlen) {
			strcpy(path, name);
			return 0;
		} else
			e = ENAMETOOLONG;
		errbuf_printf(err, errlen, "cannot run '%s'%s: %s", name, how, strerror(e));
		return -1;
	}
	const char *p = getenv("PATH");

	if (!p || !*p)
		p = "/usr/local/bin:/usr/bin:/bin";
	while (1) {
		const char *colon = strchr(p, ':');
		size_t dlen = colon ? (size_t)(colon - p) : strlen(p);
		int n = dlen ? snprintf(path, pathlen, "%.*s/%s", (int)dlen, p, name)
			     : snprintf(path, pathlen, "%s", name);

		if (n > 0 && (size_t)n < pathlen && !stat(path, &st) && S_ISREG(st.st_mode)) {
			if (!access(path, X_OK))
				return 0;
			e = EACCES;
		}
		if (!colon)
			break;
		p = colon + 1;
	}
	path[0] = '\0';
	errbuf_printf(err, errlen, "cannot run '%s'%s: %s (looked in PATH; set POVPRESS_POVRAY to the "
	     "binary)", name, how, strerror(e));
	return -1;
}

/* ---- statistics ----------------------------------------------------- */

/* Copy the line at *p (cut to fit) into line and advance past it; at the
 * end of the text, line is "\n", which no line can be. */
static void next_line(const char **p, char *line, size_t len)
{
	size_t n;

	if (!**p) {
		snprintf(line, len, "\n");
		return;
	}
	n = strcspn(*p, "\r\n");
	snprintf(line, len, "%.*s", (int)(n < len ? n : len - 1), *p);
	*p += n;
	if (**p == '\r' && (*p)[1] == '\n')
		(*p)++;
	if (**p)
		(*p)++;
}

/* "Parse Time: 0 hours 0 minutes 0 seconds (0.004 seconds)" in line, and
 * "using 1 thread(s) with 0.000 CPU-seconds total" in next. */
static int parse_phase(const char *line, const char *next, struct pov_phase *ph)
{
	const char *open = strchr(line, '(');
	double wall;
	char *end;

	if (!open)
		return 0;	/* "No photons", "No radiosity" */
	errno = 0;
	wall = strtod(open + 1, &end);
	if (errno || end == open + 1 || strncmp(end, " seconds)", 9))
		return 0;
	memset(ph, 0, sizeof(*ph));
	ph->wall_s = wall;
	if (next) {
		int threads;
		double cpu;

		while (*next == ' ')
			next++;
		if (sscanf(next, "using %d thread(s) with %lf CPU-seconds total", &threads,
			   &cpu) == 2) {
			ph->threads = threads;
			ph->cpu_s = cpu;
		}
	}
	return 1;
}

/* The number after key in line, or -1 if absent. */
static long long field_ll(const char *line, const char *key)
{
	const char *k = strstr(line, key);
	char *end;
	long long v;

	if (!k)
		return -1;
	errno = 0;
	v = strtoll(k + strlen(key), &end, 10);
	if (errno || end == k + strlen(key))
		return -1;
	return v;
}

int pov_stats_parse(const char *text, struct pov_stats *st)
{
	static const struct {
		const char *key;
		unsigned bit;
		size_t off;
	} phases[] = {
		{ "Parse Time:", POV_HAVE_PARSE, offsetof(struct pov_stats, parse) },
		{ "Bounding Time:", POV_HAVE_BOUNDING, offsetof(struct pov_stats, bounding) },
		{ "Photon Time:", POV_HAVE_PHOTON, offsetof(struct pov_stats, photon) },
		{ "Radiosity Time:", POV_HAVE_RADIOSITY, offsetof(struct pov_stats, radiosity) },
		{ "Trace Time:", POV_HAVE_TRACE, offsetof(struct pov_stats, trace) },
	};
	char line[512], next[512];
	const char *p = text ? text : "";

	memset(st, 0, sizeof(*st));
	/* Each line is checked together with the one after it, which holds
	 * the "using N thread(s)" part of a time. */
	next_line(&p, line, sizeof(line));
	while (line[0] != '\n') {
		const char *s = line;

		next_line(&p, next, sizeof(next));
		while (*s == ' ')
			s++;
		for (size_t i = 0; i < sizeof(phases) / sizeof(phases[0]); i++) {
			if (!strncmp(s, phases[i].key, strlen(phases[i].key))) {
				struct pov_phase *ph = (struct pov_phase *)((char *)st + phases[i].off);

				if (parse_phase(s, next, ph))
					st->have |= phases[i].bit;
			}
		}
		/* "Pixels:" and "Rays:" start their lines; "Refracted Rays:" and
		 * the like do not. */
		if (!strncmp(line, "Pixels:", 7) && strstr(line, "Samples:")) {
			const char *spp = strstr(line, "Smpls/Pxl:");

			st->pixels = field_ll(line, "Pixels:");
			st->samples = field_ll(line, "Samples:");
			st->samples_per_pixel = spp ? strtod(spp + 10, NULL) : 0.0;
			st->have |= POV_HAVE_PIXELS;
		} else if (!strncmp(line, "Rays:", 5)) {
			st->rays = field_ll(line, "Rays:");
			st->rays_saved = field_ll(line, "Saved:");
			if (st->rays_saved < 0)
				st->rays_saved = 0;
			st->have |= POV_HAVE_RAYS;
		} else if (!strncmp(line, "Radiosity (final) rays shot:", 28)) {
			st->rad_final_rays = field_ll(line, "shot:");
			if (st->rad_final_rays >= 0)
				st->have |= POV_HAVE_RAD_RAYS;
		}
		memcpy(line, next, sizeof(line));
	}
	return (st->have & POV_HAVE_PIXELS) && (st->have & POV_HAVE_TRACE) ? 0 : -1;
}

int pov_render_time_printed(const char *text)
{
	const char *rt = strstr(text, "Render Time:");
	const char *tt = rt ? strstr(rt, "Trace Time:") : NULL;
	const char *cpu = tt ? strstr(tt, "CPU-seconds total") : NULL;
	const char *rad = rt ? strstr(rt, "Radiosity Time:") : NULL;
	const char *none = rad ? strstr(rad, "No radiosity") : NULL;

	return cpu && strchr(cpu, '\n') && rad && rad < tt && none && none < tt;
}

/* ---- POV-Ray's error messages --------------------------------------- */

/* Split text into lines, joining the continuations of POV-Ray's 80-column
 * word wrap.  Returns a NULL-terminated malloc'd array of malloc'd lines. */
static char **unwrap_lines(const char *text, size_t *count)
{
	char **lines = NULL;
	size_t n = 0, cap = 0, prevlen = 0;
	const char *p = text;

	*count = 0;
	while (*p) {
		size_t len = strcspn(p, "\r\n");
		int cont = n > 0 && ((prevlen == 80 && len > 0) ||
				     (prevlen > 60 && prevlen <= 80 && len > 1 && p[0] == ' ' &&
				      p[1] != ' '));

		if (cont) {
			size_t old = strlen(lines[n - 1]);
			char *l = realloc(lines[n - 1], old + len + 1);

			if (!l)
				goto oom;
			memcpy(l + old, p, len);
			l[old + len] = '\0';
			lines[n - 1] = l;
		} else if (len) {
			if (n + 2 > cap) {
				size_t c2 = cap ? 2 * cap : 64;
				char **a = realloc(lines, c2 * sizeof(*a));

				if (!a)
					goto oom;
				lines = a;
				cap = c2;
			}
			lines[n] = strndup(p, len);
			if (!lines[n])
				goto oom;
			lines[++n] = NULL;
		}
		prevlen = len;
		p += len;
		if (*p == '\r' && p[1] == '\n')
			p++;
		if (*p)
			p++;
	}
	*count = n;
	return lines;
oom:
	for (size_t i = 0; i < n; i++)
		free(lines[i]);
	free(lines);
	return NULL;
}

static int is_error_line(const char *l)
{
	return strstr(l, "Error") || strstr(l, "error") || !strncmp(l, "Cannot ", 7) ||
	       !strncmp(l, "Failed ", 7) || !strncmp(l, "Problem with ", 13);
}

/*
 * The lines worth reporting, best first: 1, parse errors proper (they carry
 * "File '...' line N:"); 2, other errors (fatal errors, option problems),
 * without the warnings POV-Ray calls "Possible Parse Error" and without the
 * generic "Cannot parse input" that follows every parse error; 3, any line
 * that looks like an error.
 */
static int in_tier(const char *l, int tier)
{
	const char *e;

	switch (tier) {
	case 1:
		e = strstr(l, "Parse Error:");
		return e && !(e - l >= 9 && !strncmp(e - 9, "Possible ", 9));
	case 2:
		return is_error_line(l) && !strstr(l, "Possible Parse Error") &&
		       strcmp(l, "Fatal error in parser: Cannot parse input.");
	default:
		return is_error_line(l);
	}
}

/* Replace every occurrence of from by to in the malloc'd *s. */
static void replace_all(char **s, const char *from, const char *to)
{
	struct buf b = { 0 };
	const char *p = *s, *hit;
	size_t flen = strlen(from);

	if (!flen || !strstr(p, from))
		return;
	while ((hit = strstr(p, from))) {
		if (buf_add(&b, p, (size_t)(hit - p), 0) || buf_str(&b, to)) {
			free(b.p);
			return;
		}
		p = hit + flen;
	}
	if (buf_str(&b, p)) {
		free(b.p);
		return;
	}
	free(*s);
	*s = b.p;
}

/*
 * The error POV-Ray printed, as one line: its "Parse Error" lines when
 * there are any (they carry "File '...' line N:"), else its other error
 * lines (fatal errors, option problems), else its last line.  Links are
 * replaced by the paths they stand for.
 */
static void error_summary(const char *log, const struct cmd *c, char *out, size_t outlen)
{
	size_t n, used = 0, last = (size_t)-1;
	char **lines = unwrap_lines(log ? log : "", &n);
	int tier = 0;

	out[0] = '\0';
	if (!lines)
		return;
	for (int t = 3; t >= 1; t--)
		for (size_t i = 0; i < n; i++)
			if (in_tier(lines[i], t)) {
				tier = t;
				break;
			}
	for (size_t i = 0; i < n; i++)
		if (strcmp(lines[i], "Render failed") && strcmp(lines[i], "POV-Ray finished") &&
		    strncmp(lines[i], "====", 4))
			last = i;
	for (size_t i = 0; i < n; i++) {
		if (tier ? !in_tier(lines[i], tier) : i != last)
			continue;
		for (int k = 0; k < c->nsubs; k++)
			replace_all(&lines[i], c->sub_from[k], c->sub_to[k]);
		if (used && used + 2 < outlen)
			used += (size_t)snprintf(out + used, outlen - used, "; ");
		if (used + 1 < outlen)
			used += (size_t)snprintf(out + used, outlen - used, "%s", lines[i]);
		if (used >= outlen)
			used = outlen - 1;
	}
	for (size_t i = 0; i < n; i++)
		free(lines[i]);
	free(lines);
}

/* ---- signals ---------------------------------------------------------- */

/*
 * Process-wide state, on purpose: a signal handler can reach nothing else.
 * caught_signal is all the handler touches.  The saved dispositions and
 * the nesting depth belong to the same machinery (they restore what the
 * handler replaced) and are guarded by sig_lock.
 */
static volatile sig_atomic_t caught_signal;
static pthread_mutex_t sig_lock = PTHREAD_MUTEX_INITIALIZER;
static int sig_depth;
static const int caught_signals[] = { SIGINT, SIGTERM, SIGHUP };
#define NCAUGHT ((int)(sizeof(caught_signals) / sizeof(caught_signals[0])))
static struct sigaction sig_saved[NCAUGHT];

static void on_signal(int sig)
{
	caught_signal = sig;
}

int pov_signals_catch(char *err, size_t errlen)
{
	struct sigaction sa;
	int rc = 0;

	pthread_mutex_lock(&sig_lock);
	if (sig_depth++ == 0) {
		caught_signal = 0;
		memset(&sa, 0, sizeof(sa));
		sa.sa_handler = on_signal;
		sigfillset(&sa.sa_mask);
		sa.sa_flags = 0;	/* no SA_RESTART: let poll() return at once */
		for (int i = 0; i < NCAUGHT; i++) {
			if (sigaction(caught_signals[i], &sa, &sig_saved[i])) {
				errbuf_printf(err, errlen, "cannot catch signal %d: %s", caught_signals[i],
				     strerror(errno));
				while (i-- > 0)
					sigaction(caught_signals[i], &sig_saved[i], NULL);
				sig_depth = 0;
				rc = -1;
				break;
			}
		}
	}
	pthread_mutex_unlock(&sig_lock);
	return rc;
}

void pov_signals_restore(void)
{
	pthread_mutex_lock(&sig_lock);
	if (sig_depth > 0 && --sig_depth == 0)
		for (int i = 0; i < NCAUGHT; i++)
			sigaction(caught_signals[i], &sig_saved[i], NULL);
	pthread_mutex_unlock(&sig_lock);
}

int pov_signal_received(void)
{
	return caught_signal;
}

/* ---- pool ------------------------------------------------------------- */

const char *pov_status_name(enum pov_status st)
{
	switch (st) {
	case POV_OK: return "ok";
	case POV_FAILED: return "failed";
	case POV_CRASHED: return "crashed";
	case POV_TIMED_OUT: return "timed out";
	case POV_NOT_RUN: return "not run";
	case POV_CANCELLED: return "cancelled";
	}
	return "unknown";
}

/*
 * A pass runs more renders than cores: its renders' wall less their CPU
 * alone read 0.4 to 0.8 s where POV-Ray's start-up took 0.03 to 0.05
 * (granite, var_refl, swirlbox and soft_shadows at 640x480 under
 * --budget 3 and 6 with povwait.so, 2026-12-05).
 */
void pov_results_latency(const struct pov_result *res, size_t n, int cores, double lat[2])
{
	lat[0] = lat[1] = INFINITY;
	for (size_t k = 0; k < n; k++) {
		const struct pov_result *a = &res[k];
		const int taken = a->prelaunched != 0;
		if (a->status != POV_OK || !(taken || a->attempts == 1) || !(a->end_s > a->start_s))
			continue;
		double with = 0.0;	/* render-seconds running alongside it */
		for (size_t j = 0; j < n; j++) {
			const double lo = res[j].start_s > a->start_s ? res[j].start_s : a->start_s,
				     hi = res[j].end_s < a->end_s ? res[j].end_s : a->end_s;
			if (res[j].end_s > res[j].start_s && hi > lo)
				with += hi - lo;
		}
		const double running = with / (a->end_s - a->start_s),
			     slow = running > cores ? running / cores : 1.0,
			     l = a->wall_s - a->cpu_s * slow;
		if (l < lat[taken])
			lat[taken] = l;
	}
}

void pov_result_release(struct pov_result *res)
{
	if (!res)
		return;
	free(res->log);
	free(res->progress);
	image_release(&res->partial);
	memset(res, 0, sizeof(*res));
}

int pov_cpu_count(void)
{
#ifdef CPU_COUNT
	cpu_set_t set;

	if (sched_getaffinity(0, sizeof(set), &set) == 0 && CPU_COUNT(&set) > 0)
		return CPU_COUNT(&set);
#endif
	long n = sysconf(_SC_NPROCESSORS_ONLN);

	return n > 0 ? (int)n : 1;
}

void pov_pool_size(int cores, size_t njobs, int requested, int *jobs_out, int *threads_out)
{
	size_t jobs;

	if (cores < 1)
		cores = 1;
	if (njobs < 1)
		njobs = 1;
	jobs = requested > 0 ? (size_t)requested : (size_t)cores;
	if (jobs > njobs)
		jobs = njobs;
	*jobs_out = (int)jobs;
	*threads_out = (size_t)cores / jobs > 0 ? (int)((size_t)cores / jobs) : 1;
}

void pov_pool_opts_init(struct pov_pool_opts *opts)
{
	int threads;

	memset(opts, 0, sizeof(*opts));
	pov_pool_size(pov_cpu_count(), (size_t)INT_MAX, 0, &opts->max_jobs, &threads);
	opts->timeout_s = 0;
	opts->grace_s = 2.0;
	opts->retries = 1;
}

enum { J_PENDING, J_RUNNING, J_DONE };
enum { STOP_NONE, STOP_TIMEOUT, STOP_CANCEL, STOP_DEADLINE };

struct pjob {
	struct cmd cmd;
	char *bin;		/* the resolved binary */
	int state;
	pid_t pid;
	int fd;			/* read end of the child's stdout + stderr, or -1 */
	double start, deadline, kill_at;
	double finish_by;	/* past the pool's deadline, left to end until
				 * then (opts->finish_s); 0: not */
	int stop;		/* STOP_*: why the pool is stopping it */
	int killed;		/* SIGKILL sent */
	int accepted;		/* ready() accepted its output */
	int early;		/* its output was whole before it exited: the
				 * pool killed it */
	int wd;			/* inotify watch of its output's directory */
	int gate;		/* a pre-launched job's gate FIFO (O_PATH), kept
				 * for a while after its release, or -1 */
	double released;	/* when its gate was opened */
	struct buf log;
	/* with its job's progress: the progress lines read so far
	 * (struct pov_result's), and the tail of the output they were last
	 * looked for in, for a line split across reads */
	int want_progress;
	struct pov_progress *prog;
	size_t nprog, capprog;
	long prog_total;
	double prog_since;	/* when the last line kept was first read */
	char carry[64];
	size_t ncarry;
	const struct pov_job *job;	/* the pool's job (NULL in a prelaunch
					 * set), for its salvage */
};

/* Move fd to 3 or above (so that dup2 onto 0, 1, 2 is a real copy). */
static int high_fd(int fd)
{
	int nfd;

	if (fd > 2)
		return fd;
	nfd = fcntl(fd, F_DUPFD_CLOEXEC, 3);
	close(fd);
	return nfd;
}

static void report(struct pov_result *res, enum pov_status st, const char *fmt, ...)
{
	va_list ap;

	res->status = st;
	va_start(ap, fmt);
	vsnprintf(res->message, sizeof(res->message), fmt, ap);
	va_end(ap);
}

/* Start one attempt of j.  On failure fills res (POV_NOT_RUN) and
 * returns -1. */
static int spawn(struct pjob *j, int devnull, double t0, struct pov_result *res)
{
	int out[2], ep[2], e = 0;
	sigset_t all, old;
	pid_t parent = getpid();
	char **envp = pov_environ();
	pid_t pid;
	ssize_t n;

	(void)parent;	/* used on Linux only */

	unlink(j->cmd.povout);
	if (j->cmd.final)
		unlink(j->cmd.final);
	if (pipe2(out, O_CLOEXEC)) {
		report(res, POV_NOT_RUN, "cannot start povray: pipe: %s", strerror(errno));
		return -1;
	}
	if (pipe2(ep, O_CLOEXEC)) {
		report(res, POV_NOT_RUN, "cannot start povray: pipe: %s", strerror(errno));
		close(out[0]);
		close(out[1]);
		return -1;
	}
	out[1] = high_fd(out[1]);
	ep[1] = high_fd(ep[1]);
	if (out[1] < 0 || ep[1] < 0) {
		report(res, POV_NOT_RUN, "cannot start povray: %s", strerror(errno));
		close(out[0]);
		close(ep[0]);
		if (out[1] >= 0)
			close(out[1]);
		if (ep[1] >= 0)
			close(ep[1]);
		return -1;
	}
	fcntl(out[0], F_SETFL, fcntl(out[0], F_GETFL) | O_NONBLOCK);

	j->start = now_s();
	/* No handler of ours may run in the child between fork and exec. */
	sigfillset(&all);
	pthread_sigmask(SIG_SETMASK, &all, &old);
	pid = fork();
	if (pid == 0) {
		/* The child: async-signal-safe calls only. */
		static const int reset[] = { SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE, SIGCHLD };
		struct sigaction dfl;
		sigset_t none;

		setpgid(0, 0);
#ifdef __linux__
		prctl(PR_SET_PDEATHSIG, SIGKILL);
		if (getppid() != parent)
			_exit(127);	/* the parent died before the request */
#endif
		memset(&dfl, 0, sizeof(dfl));
		dfl.sa_handler = SIG_DFL;
		for (size_t i = 0; i < sizeof(reset) / sizeof(reset[0]); i++)
			sigaction(reset[i], &dfl, NULL);
		sigemptyset(&none);
		sigprocmask(SIG_SETMASK, &none, NULL);
		if (dup2(devnull, 0) < 0 || dup2(out[1], 1) < 0 || dup2(out[1], 2) < 0) {
			e = errno;
		} else {
			execve(j->bin, j->cmd.argv, envp);
			e = errno;
		}
		if (write(ep[1], &e, sizeof(e)) < 0)
			_exit(127);
		_exit(127);
	}
	if (pid > 0)
		setpgid(pid, pid);	/* also here, so kill(-pid) works at once */
	else
		e = errno;
	pthread_sigmask(SIG_SETMASK, &old, NULL);
	close(out[1]);
	close(ep[1]);
	if (pid < 0) {
		close(out[0]);
		close(ep[0]);
		report(res, POV_NOT_RUN, "cannot start povray: fork: %s", strerror(e));
		return -1;
	}
	do
		n = read(ep[0], &e, sizeof(e));
	while (n < 0 && errno == EINTR);
	close(ep[0]);
	res->attempts++;
	if (res->attempts == 1)
		res->start_s = j->start - t0;
	if (n == (ssize_t)sizeof(e)) {
		int st;

		while (waitpid(pid, &st, 0) < 0 && errno == EINTR)
			;
		close(out[0]);
		res->end_s = now_s() - t0;
		report(res, POV_NOT_RUN, "cannot run '%s': %s", j->bin, strerror(e));
		return -1;
	}
	j->pid = pid;
	j->fd = out[0];
	j->state = J_RUNNING;
	j->stop = STOP_NONE;
	j->killed = 0;
	j->early = 0;
	j->accepted = 0;
	j->kill_at = 0;
	j->log.len = 0;
	if (j->log.p)
		j->log.p[0] = '\0';
	j->nprog = 0;
	j->ncarry = 0;
	j->finish_by = 0;
	return 0;
}

/* The "Rendered N of M pixels" lines in what j's child wrote just now,
 * chunk (n bytes), after what it wrote before past its last such line (a
 * line split across reads), at time t (seconds after the attempt started):
 * a count that falls (another phase's) starts again, one that does not
 * rise is not taken twice, and of the lines read within PROGRESS_BATCH_S
 * of the first of them only the last is kept, at its time (POV-Ray's frontend
 * passes them on in batches, up to 38 blocks' at 640x480, at times split
 * over two reads: the time between two batches is the later one's blocks',
 * shared). */
#define PROGRESS_BATCH_S 0.003
static void note_progress(struct pjob *j, const char *chunk, size_t n, double t)
{
	static const char key[] = "Rendered ";
	char data[sizeof(j->carry) + 8192 + 1];
	size_t len = j->ncarry;

	memcpy(data, j->carry, len);
	if (n > sizeof(data) - 1 - len) {
		chunk += n - (sizeof(data) - 1 - len);
		n = sizeof(data) - 1 - len;
	}
	memcpy(data + len, chunk, n);
	len += n;
	data[len] = '\0';
	size_t end = 0;
	for (const char *p = strstr(data, key); p; p = strstr(p + 1, key)) {
		long done, total;
		int used = 0;

		if (sscanf(p, "Rendered %ld of %ld pixels%n", &done, &total, &used) != 2 || !used)
			continue;
		end = (size_t)(p - data) + (size_t)used;
		if (j->nprog && done < j->prog[j->nprog - 1].done)
			j->nprog = 0;	/* a new run of lines */
		if (j->nprog && done == j->prog[j->nprog - 1].done)
			continue;	/* a count repeated */
		if (j->nprog && t - j->prog_since < PROGRESS_BATCH_S) {
			/* the read's last, or a batch split over reads */
			j->prog[j->nprog - 1].t = t;
			j->prog[j->nprog - 1].done = done;
			j->prog_total = total;
			continue;
		}
		if (j->nprog == j->capprog) {
			size_t cap = j->capprog ? 2 * j->capprog : 256;
			struct pov_progress *q = realloc(j->prog, cap * sizeof(*q));

			if (!q)
				break;	/* out of memory: no more lines */
			j->prog = q;
			j->capprog = cap;
		}
		j->prog_since = t;
		j->prog[j->nprog].t = t;
		j->prog[j->nprog++].done = done;
		j->prog_total = total;
	}
	if (len - end > sizeof(j->carry))
		end = len - sizeof(j->carry);
	j->ncarry = len - end;
	memcpy(j->carry, data + end, j->ncarry);
}

/* Read what the child has written; closes the pipe at end of file. */
static void drain(struct pjob *j)
{
	char chunk[8192];
	const double t = now_s() - j->start;	/* of all it reads now */

	while (j->fd >= 0) {
		ssize_t n = read(j->fd, chunk, sizeof(chunk));

		if (n > 0) {
			buf_add(&j->log, chunk, (size_t)n, POV_LOG_MAX);
			if (j->want_progress)
				note_progress(j, chunk, (size_t)n, t);
			continue;
		}
		if (n < 0 && errno == EINTR)
			continue;
		if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK)) {
			close(j->fd);
			j->fd = -1;
		}
		break;
	}
}

static void stop_job(struct pjob *j, int why, double now, double grace)
{
	if (j->stop == STOP_NONE || why == STOP_CANCEL)
		j->stop = why;
	if (!j->kill_at) {
		kill(-j->pid, SIGTERM);
		j->kill_at = now + grace;
	} else if (now + grace < j->kill_at) {
		j->kill_at = now + grace;	/* a deadline sooner than a timeout's grace */
	}
}

static const char *signame(int sig)
{
	const char *s = strsignal(sig);

	return s ? s : "unknown signal";
}

/* User + system seconds of a reaped child. */
static double rusage_cpu_s(const struct rusage *ru)
{
	return (double)ru->ru_utime.tv_sec + 1e-6 * (double)ru->ru_utime.tv_usec +
	       (double)ru->ru_stime.tv_sec + 1e-6 * (double)ru->ru_stime.tv_usec;
}

/* The blocks j finished before it was stopped, from its render state file,
 * into res->partial, where its job asked for them (pov_job.salvage); a file
 * that cannot be read gives none. */
static void salvage(const struct pjob *j, struct pov_result *res)
{
	const struct pov_job *job = j->job;
	char err[256];

	image_release(&res->partial);
	res->partial_pixels = 0;
	if (!job || !job->salvage ||
	    pov_state_read(j->cmd.state, job->width, job->height,
			   job->region ? job->region->y0 : 0,
			   job->region ? job->region->y1 : job->height - 1, &res->partial,
			   &res->partial_oy, &res->partial_pixels, err, sizeof(err)))
		return;
	if (!res->partial_pixels)
		image_release(&res->partial);
}

/* The child j has exited (not yet reaped): reap it and judge the attempt.
 * Returns 1 when the job should run again. */
static int finish(struct pjob *j, const struct pov_pool_opts *opts, double t0,
		  struct pov_result *res, int stopping)
{
	struct rusage ru;
	int status = 0;
	double end;
	struct stat st;
	char pov[700];

	if (j->gate >= 0) {
		close(j->gate);
		j->gate = -1;
	}
	/* The leader is a zombie, so its group id cannot be reused yet: sweep
	 * any other member of the group before reaping. */
	kill(-j->pid, SIGKILL);
	drain(j);
	if (j->fd >= 0) {
		close(j->fd);
		j->fd = -1;
	}
	memset(&ru, 0, sizeof(ru));
	while (wait4(j->pid, &status, 0, &ru) < 0 && errno == EINTR)
		;
	end = now_s();
	j->pid = 0;
	res->wall_s += end - j->start;
	res->end_s = end - t0;
	res->cpu_s += rusage_cpu_s(&ru);
	res->exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
	res->term_signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
	if (j->early && res->term_signal == SIGKILL) {
		res->exit_status = 0;	/* our kill, after a whole output */
		res->term_signal = 0;
	}
	pov_stats_parse(j->log.p, &res->stats);
	free(res->log);
	res->log = j->log.p ? strdup(j->log.p) : NULL;
	free(res->progress);
	res->progress = NULL;
	res->nprogress = 0;
	if (j->nprog && (res->progress = malloc(j->nprog * sizeof(*res->progress)))) {
		memcpy(res->progress, j->prog, j->nprog * sizeof(*res->progress));
		res->nprogress = j->nprog;
		res->progress_total = j->prog_total;
	}
	res->message[0] = '\0';

	if (res->exit_status == 0 && !stat(j->cmd.povout, &st) && S_ISREG(st.st_mode)) {
		if (j->cmd.final && rename(j->cmd.povout, j->cmd.final)) {
			report(res, POV_FAILED, "cannot rename '%s' to '%s': %s", j->cmd.povout,
			       j->cmd.final, strerror(errno));
		} else {
			res->status = POV_OK;
			return 0;
		}
	} else if (j->stop == STOP_CANCEL) {
		int sig = pov_signal_received();

		report(res, POV_CANCELLED, "povray stopped by %s rendering '%s'",
		       sig ? signame(sig) : "an interruption", j->cmd.output);
		salvage(j, res);
	} else if (j->stop == STOP_DEADLINE) {
		report(res, POV_CANCELLED, "povray stopped past the deadline (%g s) rendering '%s'",
		       opts->deadline_s, j->cmd.output);
		salvage(j, res);
	} else if (j->stop == STOP_TIMEOUT) {
		report(res, POV_TIMED_OUT, "povray timed out after %g s rendering '%s'",
		       opts->timeout_s, j->cmd.output);
	} else if (res->term_signal) {
		error_summary(j->log.p, &j->cmd, pov, sizeof(pov));
		report(res, POV_CRASHED, "povray was killed by signal %d (%s) rendering '%s'%s%s",
		       res->term_signal, signame(res->term_signal), j->cmd.output,
		       pov[0] ? ": " : "", pov);
	} else if (res->exit_status != 0) {
		error_summary(j->log.p, &j->cmd, pov, sizeof(pov));
		report(res, POV_FAILED, "povray failed (exit status %d) on '%s': %s",
		       res->exit_status, j->cmd.scene, pov[0] ? pov : "no message");
	} else {
		report(res, POV_FAILED, "povray did not write '%s'", j->cmd.output);
	}
	/* Leave nothing of a failed attempt behind. */
	unlink(j->cmd.povout);
	unlink(j->cmd.state);
	if ((res->status == POV_TIMED_OUT || res->status == POV_CRASHED) && !stopping &&
	    res->attempts <= opts->retries)
		return 1;
	return 0;
}

/* One pool run. */
struct pool {
	const struct pov_pool_opts *opts;
	struct pjob *pj;
	struct pov_result *res;
	size_t n;
	size_t next;		/* no pending job before this index */
	size_t running, done;
	int stopping;		/* STOP_NONE, or why the pool starts nothing and
				 * stops all: STOP_CANCEL (a signal arrived) or
				 * STOP_DEADLINE (opts->deadline_s passed) */
	int devnull;
	double t0;
	int ino;		/* inotify descriptor when opts->ready, or -1 */
	struct pollfd *pfd;	/* scratch for poll(), one per slot and ino */
	size_t *pidx;		/* the job of each pfd */
};

/* The last path component of p. */
static const char *base_name(const char *p)
{
	const char *b = strrchr(p, '/');

	return b ? b + 1 : p;
}

/* Read the inotify events: a running job whose output was closed after
 * writing, and that opts->ready accepts, is marked accepted. */
static void pool_notice(struct pool *p)
{
#ifdef __linux__
	_Alignas(struct inotify_event) char buf[4096];

	for (;;) {
		ssize_t n = read(p->ino, buf, sizeof(buf));

		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0)
			return;
		for (char *q = buf; q < buf + n;) {
			const struct inotify_event *ev = (const struct inotify_event *)q;

			q += sizeof(*ev) + ev->len;
			if (!(ev->mask & IN_CLOSE_WRITE) || !ev->len)
				continue;
			for (size_t i = 0; i < p->n; i++) {
				struct pjob *j = &p->pj[i];

				if (j->state != J_RUNNING || j->accepted || j->stop != STOP_NONE ||
				    j->wd != ev->wd || strcmp(base_name(j->cmd.povout), ev->name))
					continue;
				j->accepted = p->opts->ready(p->opts->arg, i, j->cmd.povout) != 0;
			}
		}
	}
#else
	(void)p;
#endif
}

/* Kill the jobs whose output was accepted and whose console output, if
 * opts->ready_log asks, says they are done. */
static void pool_early(struct pool *p)
{
	for (size_t i = 0; i < p->n; i++) {
		struct pjob *j = &p->pj[i];

		if (j->state != J_RUNNING || !j->accepted || j->early || j->stop != STOP_NONE)
			continue;
		if (!p->opts->ready_log ||
		    p->opts->ready_log(p->opts->arg, i, j->log.p ? j->log.p : "")) {
			j->early = 1;
			kill(-j->pid, SIGKILL);
		}
	}
}

/* Whether running job j's progress lines say it will have rendered its
 * pixels within s seconds of now: those left at its rate over its lines,
 * and the time since its last line added, not taken off (lines that have
 * stopped coming are a render slowing, and a render left past the
 * deadline in error costs the budget). */
static int job_finishing(const struct pjob *j, double now, double s)
{
	if (j->nprog < 2 || j->prog_total <= 0)
		return 0;
	const struct pov_progress *a = &j->prog[0], *b = &j->prog[j->nprog - 1];
	const long left = j->prog_total - b->done;
	if (left <= 0)
		return 1;
	if (b->done <= a->done || !(b->t > a->t))
		return 0;
	const double rate = (double)(b->done - a->done) / (b->t - a->t);
	return (now - j->start - b->t) + (double)left / rate <= s;
}

/* Start nothing more and stop the running jobs (why: STOP_CANCEL or
 * STOP_DEADLINE), SIGKILL after grace seconds; at the deadline, those
 * job_finishing() within half of opts->finish_s (the rest to write their
 * image) are left finish_s first. */
static void pool_stop(struct pool *p, int why, double grace)
{
	const double now = now_s(), fs = p->opts->finish_s;
	p->stopping = why;
	for (size_t i = 0; i < p->n; i++) {
		struct pjob *j = &p->pj[i];

		if (j->state != J_RUNNING)
			continue;
		if (why == STOP_DEADLINE && fs > 0.0 && j->stop == STOP_NONE &&
		    job_finishing(j, now, 0.5 * fs))
			j->finish_by = now + fs;
		else
			stop_job(j, why, now, grace);
	}
}

static void job_final(struct pool *p, size_t i)
{
	p->pj[i].state = J_DONE;
	p->done++;
	if (p->opts->on_done)
		p->opts->on_done(p->opts->arg, i, &p->res[i]);
}

/* Start pending jobs while there are free slots. */
static void pool_fill(struct pool *p)
{
	while (!p->stopping && p->running < (size_t)p->opts->max_jobs) {
		struct pjob *j;

		while (p->next < p->n && p->pj[p->next].state != J_PENDING)
			p->next++;
		if (p->next == p->n)
			return;
		j = &p->pj[p->next];
		if (spawn(j, p->devnull, p->t0, &p->res[p->next])) {
			job_final(p, p->next);
		} else {
			j->deadline = j->start + p->opts->timeout_s;
			p->running++;
		}
		p->next++;
	}
}

/*
 * Gates (pov_prelaunch_start()).  A FIFO blocks its readers' open() until a
 * writer opens it.  POV-Ray opens its include header twice, from two
 * threads, the second just after the first gets through; so the gate is
 * opened by renaming an empty file over the FIFO (later opens read that)
 * and opening the FIFO itself, through the descriptor kept of it, for
 * writing and closing it at once: every open waiting on it returns and
 * reads an empty header.  A reader whose open() found the FIFO just before
 * the rename may start waiting after that: the pool opens the FIFO again at
 * each of its checks (every 10 ms) for GATE_HOLD_S.
 */
#define GATE_HOLD_S 0.5

static void gate_open(struct pjob *j)
{
#ifdef __linux__
	char path[64];

	snprintf(path, sizeof(path), "/proc/self/fd/%d", j->gate);
	int w = open(path, O_WRONLY | O_NONBLOCK | O_CLOEXEC);
	if (w >= 0)
		close(w);	/* ENXIO: no reader waits now */
#else
	(void)j;
#endif
}

/* Replace the FIFO at path by an empty file; -1 if that fails (the gate
 * is then opened only through the FIFO). */
static int gate_replace(const char *path)
{
	char *tmp = xprintf("%s.open", path);
	int rc = -1;

	if (!tmp)
		return -1;
	unlink(tmp);
	int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
	if (fd >= 0) {
		close(fd);
		rc = rename(tmp, path);
		if (rc)
			unlink(tmp);
	}
	free(tmp);
	return rc;
}

/* Wait for output, or until the next deadline or tick, and read it. */
static void pool_wait(struct pool *p)
{
	double now = now_s(), wait_s = POV_TICK_S;
	size_t npfd = 0;
	int eof_seen = 0;

	for (size_t i = 0; i < p->n; i++) {
		struct pjob *j = &p->pj[i];

		if (j->state != J_RUNNING)
			continue;
		if (j->fd >= 0) {
			p->pfd[npfd].fd = j->fd;
			p->pfd[npfd].events = POLLIN;
			p->pfd[npfd].revents = 0;
			p->pidx[npfd++] = i;
		} else {
			eof_seen = 1;
		}
		if (j->stop == STOP_NONE && p->opts->timeout_s > 0 && j->deadline - now < wait_s)
			wait_s = j->deadline - now;
		if (j->kill_at && !j->killed && j->kill_at - now < wait_s)
			wait_s = j->kill_at - now;
		if (j->stop == STOP_NONE && j->finish_by > 0 && j->finish_by - now < wait_s)
			wait_s = j->finish_by - now;
		if (j->gate >= 0) {
			if (now - j->released > GATE_HOLD_S) {
				close(j->gate);
				j->gate = -1;
			} else {
				gate_open(j);
				if (wait_s > 0.01)
					wait_s = 0.01;
			}
		}
	}
	if (p->opts->deadline_s > 0 && !p->stopping && p->t0 + p->opts->deadline_s - now < wait_s)
		wait_s = p->t0 + p->opts->deadline_s - now;
	if (eof_seen && wait_s > 0.005)
		wait_s = 0.005;	/* its output is closed: the exit is imminent */
	if (wait_s < 0)
		wait_s = 0;
	size_t nj = npfd;
	if (p->ino >= 0) {
		p->pfd[npfd].fd = p->ino;
		p->pfd[npfd].events = POLLIN;
		p->pfd[npfd].revents = 0;
		npfd++;
	}
	/* A caught signal interrupts poll() (no SA_RESTART) when it lands in
	 * this thread; otherwise the tick bounds the delay. */
	if (poll(p->pfd, (nfds_t)npfd, (int)ceil(wait_s * 1000.0)) > 0) {
		for (size_t k = 0; k < nj; k++)
			if (p->pfd[k].revents)
				drain(&p->pj[p->pidx[k]]);
		if (npfd > nj && p->pfd[nj].revents)
			pool_notice(p);
	}
	if (p->ino >= 0)
		pool_early(p);
}

/* Reap the children that exited; enforce timeouts and kill deadlines. */
static void pool_check(struct pool *p)
{
	double now = now_s();

	for (size_t i = 0; i < p->n; i++) {
		struct pjob *j = &p->pj[i];
		siginfo_t si;

		if (j->state != J_RUNNING)
			continue;
		memset(&si, 0, sizeof(si));
		/* WNOWAIT: see finish() */
		if (waitid(P_PID, (id_t)j->pid, &si, WEXITED | WNOHANG | WNOWAIT) == 0 &&
		    si.si_pid == j->pid) {
			p->running--;
			if (finish(j, p->opts, p->t0, &p->res[i], p->stopping)) {
				j->state = J_PENDING;	/* retry */
				if (i < p->next)
					p->next = i;
			} else {
				job_final(p, i);
			}
			continue;
		}
		if (j->stop == STOP_NONE && p->opts->timeout_s > 0 && now >= j->deadline)
			stop_job(j, STOP_TIMEOUT, now, p->opts->grace_s);
		if (j->stop == STOP_NONE && j->finish_by > 0 && now >= j->finish_by)
			stop_job(j, STOP_DEADLINE, now, DEADLINE_GRACE_S);
		if (j->kill_at && !j->killed && now >= j->kill_at) {
			kill(-j->pid, SIGKILL);
			j->killed = 1;
		}
	}
}

/* ---- pre-launched renders (povray.h) ---- */

static unsigned gate_serial;	/* gates' names, unique in the process */

struct pov_prelaunch {
	struct pjob *pj;	/* the jobs; pid 0 once taken or stopped */
	size_t n, taken;
	char **gate;		/* the gates' paths (+HI, each command's last
				 * argument) */
	double cpu_s;		/* of the stopped ones */
};

/* Stop and reap pre-launched job k if it still runs. */
static void prelaunch_stop(struct pov_prelaunch *pre, size_t k)
{
	struct pjob *j = &pre->pj[k];
	struct rusage ru;
	int status;

	if (j->gate >= 0) {
		close(j->gate);
		j->gate = -1;
	}
	if (j->fd >= 0) {
		close(j->fd);
		j->fd = -1;
	}
	if (j->pid <= 0)
		return;
	kill(-j->pid, SIGKILL);
	memset(&ru, 0, sizeof(ru));
	while (wait4(j->pid, &status, 0, &ru) < 0 && errno == EINTR)
		;
	pre->cpu_s += rusage_cpu_s(&ru);
	j->pid = 0;
	unlink(j->cmd.povout);
	unlink(j->cmd.state);
}

double pov_prelaunch_end(struct pov_prelaunch *pre)
{
	if (!pre)
		return 0.0;
	for (size_t k = 0; k < pre->n; k++) {
		prelaunch_stop(pre, k);
		if (pre->gate && pre->gate[k]) {
			unlink(pre->gate[k]);
			free(pre->gate[k]);
		}
		cmd_release(&pre->pj[k].cmd);
		free(pre->pj[k].bin);
		free(pre->pj[k].log.p);
		free(pre->pj[k].prog);
	}
	double cpu = pre->cpu_s;
	free(pre->pj);
	free(pre->gate);
	free(pre);
	return cpu;
}

size_t pov_prelaunch_taken(const struct pov_prelaunch *pre)
{
	return pre ? pre->taken : 0;
}

int pov_prelaunch_start(const struct pov_job *jobs, size_t njobs, const char *gatedir,
			struct pov_prelaunch **out, char *err, size_t errlen)
{
	*out = NULL;
#ifndef __linux__
	(void)jobs;
	(void)njobs;
	(void)gatedir;
	errbuf_printf(err, errlen, "pre-launched renders need Linux");
	return -1;
#else
	char bin[PATH_MAX];
	struct pov_result res;
	int devnull = -1;

	if (!pov_path_safe(gatedir)) {
		errbuf_printf(err, errlen, "cannot pre-launch renders: unsafe directory '%s'",
			      gatedir);
		return -1;
	}
	struct pov_prelaunch *pre = calloc(1, sizeof(*pre));
	if (!pre || !(pre->pj = calloc(njobs ? njobs : 1, sizeof(*pre->pj))) ||
	    !(pre->gate = calloc(njobs ? njobs : 1, sizeof(*pre->gate)))) {
		pov_prelaunch_end(pre);	/* n is still 0 */
		errbuf_printf(err, errlen, "out of memory");
		return -1;
	}
	pre->n = njobs;
	for (size_t k = 0; k < njobs; k++) {
		pre->pj[k].fd = -1;
		pre->pj[k].gate = -1;
		pre->pj[k].want_progress = jobs[k].progress;
	}
	devnull = open("/dev/null", O_RDWR | O_CLOEXEC);
	if (devnull >= 0)
		devnull = high_fd(devnull);
	if (devnull < 0) {
		errbuf_printf(err, errlen, "cannot open '/dev/null': %s", strerror(errno));
		goto fail;
	}
	for (size_t k = 0; k < njobs; k++) {
		struct pjob *j = &pre->pj[k];

		if (pov_find_binary(&jobs[k], bin, sizeof(bin), err, errlen) ||
		    cmd_build(&jobs[k], &j->cmd, err, errlen))
			goto fail;
		pre->gate[k] = xprintf("%s/gate-%u.inc", gatedir, ++gate_serial);
		j->bin = strdup(bin);
		if (!pre->gate[k] || !j->bin ||
		    cmd_push(&j->cmd, xprintf("+HI\"%s\"", pre->gate[k]))) {
			errbuf_printf(err, errlen, "out of memory");
			goto fail;
		}
		unlink(pre->gate[k]);
		if (mkfifo(pre->gate[k], 0600)) {
			errbuf_printf(err, errlen, "cannot make the FIFO '%s': %s", pre->gate[k],
				      strerror(errno));
			goto fail;
		}
		j->gate = open(pre->gate[k], O_PATH | O_CLOEXEC);
		if (j->gate < 0) {
			errbuf_printf(err, errlen, "cannot open the FIFO '%s': %s", pre->gate[k],
				      strerror(errno));
			goto fail;
		}
		memset(&res, 0, sizeof(res));
		if (spawn(j, devnull, now_s(), &res)) {
			errbuf_printf(err, errlen, "%s", res.message);
			goto fail;
		}
	}
	close(devnull);
	*out = pre;
	return 0;
fail:
	if (devnull >= 0)
		close(devnull);
	pov_prelaunch_end(pre);
	return -1;
#endif
}

/* Whether pre-launched job k's command, the gate aside, is c. */
static int prelaunch_matches(const struct pov_prelaunch *pre, size_t k, const struct cmd *c)
{
	const struct cmd *q = &pre->pj[k].cmd;

	if (pre->pj[k].pid <= 0 || q->argc - 1 != c->argc)
		return 0;
	for (int i = 0; i < c->argc; i++)
		if (strcmp(q->argv[i], c->argv[i]))
			return 0;
	return 1;
}

/* Take the pre-launched jobs that match pool jobs (their commands built),
 * stop the rest.  The taken ones are released when the run begins. */
static void prelaunch_take(struct pool *p, struct pov_prelaunch *pre)
{
	for (size_t i = 0; i < p->n; i++) {
		for (size_t k = 0; k < pre->n; k++) {
			if (!prelaunch_matches(pre, k, &p->pj[i].cmd))
				continue;
			struct pjob *j = &p->pj[i];
			const struct pov_job *job = j->job;	/* the same render */
			cmd_release(&j->cmd);
			free(j->bin);
			*j = pre->pj[k];
			j->job = job;
			memset(&pre->pj[k], 0, sizeof(pre->pj[k]));
			pre->pj[k].fd = -1;
			pre->pj[k].gate = -1;
			j->state = J_RUNNING;
			gate_replace(pre->gate[k]);
			p->res[i].prelaunched = 1;
			pre->taken++;
			break;
		}
	}
	for (size_t k = 0; k < pre->n; k++)
		prelaunch_stop(pre, k);
}

/* Begin the taken jobs: open their gates. */
static void prelaunch_begin(struct pool *p)
{
	for (size_t i = 0; i < p->n; i++) {
		struct pjob *j = &p->pj[i];

		if (!p->res[i].prelaunched)
			continue;
		j->start = j->released = now_s();
		j->deadline = j->start + p->opts->timeout_s;
		p->res[i].attempts = 1;
		p->res[i].start_s = j->start - p->t0;
		p->running++;
		if (j->gate >= 0)
			gate_open(j);
	}
}

int pov_pool_run(const struct pov_job *jobs, size_t njobs, const struct pov_pool_opts *opts,
		 struct pov_result *results, char *err, size_t errlen)
{
	struct pool p = { .opts = opts, .res = results, .n = njobs, .devnull = -1, .ino = -1 };
	struct sigaction chld_old, chld_dfl;
	char bin[PATH_MAX];
	int chld_changed = 0, rc = -1, caught = 0;
	size_t slots = 1;

	for (size_t i = 0; i < njobs; i++)
		memset(&results[i], 0, sizeof(results[i]));
	if (!opts || opts->max_jobs < 1) {
		errbuf_printf(err, errlen, "a pool needs at least one job slot");
		return -1;
	}
	if (njobs)
		slots = (size_t)opts->max_jobs < njobs ? (size_t)opts->max_jobs : njobs;
	p.pj = calloc(njobs ? njobs : 1, sizeof(*p.pj));
	p.pfd = calloc(slots + 1, sizeof(*p.pfd));
	p.pidx = calloc(slots + 1, sizeof(*p.pidx));
	if (!p.pj || !p.pfd || !p.pidx) {
		errbuf_printf(err, errlen, "out of memory");
		goto out;
	}
	for (size_t i = 0; i < njobs; i++) {
		p.pj[i].fd = -1;
		p.pj[i].gate = -1;
		p.pj[i].want_progress = jobs[i].progress;
		p.pj[i].job = &jobs[i];
	}
	/* Everything that can be checked is checked before anything starts. */
	for (size_t i = 0; i < njobs; i++) {
		if (pov_find_binary(&jobs[i], bin, sizeof(bin), err, errlen) ||
		    cmd_build(&jobs[i], &p.pj[i].cmd, err, errlen))
			goto out;
		p.pj[i].bin = strdup(bin);
		if (!p.pj[i].bin) {
			errbuf_printf(err, errlen, "out of memory");
			goto out;
		}
	}
	if (opts->prelaunched)
		prelaunch_take(&p, opts->prelaunched);
	/* Outputs seen whole before POV-Ray exits (where inotify works). */
#ifdef __linux__
	if (opts->ready && njobs) {
		p.ino = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
		for (size_t i = 0; i < njobs && p.ino >= 0; i++) {
			char *dir = strdup(p.pj[i].cmd.povout);

			if (!dir) {
				errbuf_printf(err, errlen, "out of memory");
				goto out;
			}
			char *slash = strrchr(dir, '/');
			if (slash)
				*(slash == dir ? slash + 1 : slash) = '\0';
			p.pj[i].wd = inotify_add_watch(p.ino, slash ? dir : ".", IN_CLOSE_WRITE);
			free(dir);
			if (p.pj[i].wd < 0) {	/* then none: every job ends at its exit */
				close(p.ino);
				p.ino = -1;
			}
		}
	}
#endif
	p.devnull = open("/dev/null", O_RDWR | O_CLOEXEC);
	if (p.devnull >= 0)
		p.devnull = high_fd(p.devnull);
	if (p.devnull < 0) {
		errbuf_printf(err, errlen, "cannot open '/dev/null': %s", strerror(errno));
		goto out;
	}
	if (pov_signals_catch(err, errlen))
		goto out;
	caught = 1;
	/* Children must stay waitable. */
	if (sigaction(SIGCHLD, NULL, &chld_old) == 0 &&
	    (chld_old.sa_handler == SIG_IGN || (chld_old.sa_flags & SA_NOCLDWAIT))) {
		memset(&chld_dfl, 0, sizeof(chld_dfl));
		chld_dfl.sa_handler = SIG_DFL;
		chld_changed = !sigaction(SIGCHLD, &chld_dfl, NULL);
	}

	p.t0 = now_s();
	prelaunch_begin(&p);
	while (1) {
		if (p.stopping != STOP_CANCEL && pov_signal_received())
			pool_stop(&p, STOP_CANCEL, opts->grace_s);
		if (!p.stopping && opts->deadline_s > 0 && now_s() - p.t0 >= opts->deadline_s) {
			/* outputs closed just before it still count */
			if (p.ino >= 0) {
				pool_notice(&p);
				pool_early(&p);
			}
			pool_stop(&p, STOP_DEADLINE, DEADLINE_GRACE_S);
		}
		pool_fill(&p);
		if (!p.running && (p.stopping || p.done == njobs))
			break;
		pool_wait(&p);
		pool_check(&p);
	}
	/* Only an interruption or the deadline leaves jobs pending.  One that
	 * already ran keeps the result of its last attempt. */
	for (size_t i = 0; i < njobs; i++) {
		if (p.pj[i].state != J_PENDING)
			continue;
		if (results[i].attempts == 0) {
			int sig = pov_signal_received();

			if (p.stopping == STOP_CANCEL)
				report(&results[i], POV_CANCELLED, "not started: interrupted by %s",
				       sig ? signame(sig) : "a signal");
			else
				report(&results[i], POV_CANCELLED,
				       "not started: past the deadline (%g s)", opts->deadline_s);
			results[i].exit_status = -1;
		}
		job_final(&p, i);
	}
	rc = p.stopping == STOP_CANCEL ? POV_INTERRUPTED : 0;
out:
	if (chld_changed)
		sigaction(SIGCHLD, &chld_old, NULL);
	if (caught)
		pov_signals_restore();
	if (p.devnull >= 0)
		close(p.devnull);
	if (p.ino >= 0)
		close(p.ino);
	if (p.pj) {
		for (size_t i = 0; i < njobs; i++) {
			if (p.pj[i].gate >= 0)
				close(p.pj[i].gate);
			if (p.pj[i].pid > 0) {	/* taken, but the run failed before it began */
				kill(-p.pj[i].pid, SIGKILL);
				while (waitpid(p.pj[i].pid, NULL, 0) < 0 && errno == EINTR)
					;
			}
			if (p.pj[i].fd >= 0)
				close(p.pj[i].fd);
			cmd_release(&p.pj[i].cmd);
			free(p.pj[i].bin);
			free(p.pj[i].log.p);
			free(p.pj[i].prog);
		}
	}
	free(p.pj);
	free(p.pfd);
	free(p.pidx);
	return rc;
}
