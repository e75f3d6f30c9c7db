/*
 * povray.h - run POV-Ray 3.7: command lines, statistics, and a bounded pool
 * of concurrent renders with timeouts, retries and clean interruption.
 *
 * The contract, once:
 *
 * - POV-Ray is always run from an argument vector (fork + execv, never a
 *   shell) as
 *
 *       povray -D +FE -GR -V +W<w> +H<h> [+SC +EC +SR +ER] [+WT<n>]
 *              +L"<scene dir>" +I"<scene>" +O"<output>"
 *              [Declare=NAME=VALUE ...] [extra options ...]
 *
 *   and, with job->radiosity, +RFO or +RFI and +RF"<file>" after +O.
 *
 *   -D: no display window.  +FE: OpenEXR output.  -GR and -V silence the
 *   option summaries and the progress counter; the statistics stream (on
 *   stderr, which is where POV-Ray writes everything) and the warning and
 *   fatal streams stay on, because the statistics and the error messages
 *   are what we read.  (-GA would silence the statistics too.)  The extra
 *   options come last and are passed verbatim, so they may override ours;
 *   an extra -GS or -GA leaves the statistics empty.
 *
 * - Paths.  POV-Ray's own option parser splits an option at spaces even
 *   when it arrives as one argv element, so the values of +I, +O and +L are
 *   always wrapped in double quotes.  A path that contains a double quote,
 *   a control character or any byte outside ASCII cannot be passed even so
 *   (POV-Ray 3.7 mangles non-ASCII bytes).  For such a path a symbolic link
 *   with a safe name is made in the job's work directory (job->workdir,
 *   which must then be given and be itself safe): a link to the scene file,
 *   a link to the scene's directory for +L, and a link to the output's
 *   directory or the radiosity file's (whose own name must be safe).  POV-Ray replaces an existing output file by unlinking it, so
 *   the output itself is never linked: when its file name is unsafe or does
 *   not end in ".exr" (POV-Ray would append ".exr"), POV-Ray writes to a
 *   stand-in name in the output's directory that is renamed to the output
 *   when the render succeeds.  Links are named after a hash of their target
 *   (povpress-<hash>.pov, povpress-<hash>.d), are reused by later jobs, and
 *   are left in the work directory, which the caller owns and removes.
 *   Messages name the original paths, not the links.
 *
 * - Files.  Before each attempt the output file is removed, so a missing
 *   output means the attempt wrote none.  A render POV-Ray does not finish
 *   leaves a "<output stem>.pov-state" file beside the output; the runner
 *   removes it, and removes the output of any attempt that did not succeed.
 *
 * - The binary is job->povray, else $POVPRESS_POVRAY, else "povray" looked
 *   up in PATH.
 *
 * - Children.  Each child runs in its own process group, with stdin from
 *   /dev/null and stdout and stderr captured.  A timeout, an interruption
 *   or the end of a pool run sends SIGTERM to the whole group and SIGKILL
 *   after a grace period; every child is reaped before the pool returns.
 *   On Linux each child also asks for SIGKILL when the thread that started
 *   it dies (PR_SET_PDEATHSIG), so even a povpress killed with SIGKILL
 *   leaves no povray behind.  Consequence: run pools from a thread that
 *   outlives them (the pool returns only when its children are gone, so any
 *   thread that calls pov_pool_run() qualifies).
 *
 * - Signals.  While a pool runs, SIGINT, SIGTERM and SIGHUP only set a
 *   flag; the pool then stops its children and returns POV_INTERRUPTED.
 *   See pov_signals_catch() to extend that window over a whole command.
 *   Other code in the process must not reap the pool's children (no
 *   wait(-1) in another thread); SIGCHLD is set to SIG_DFL during a run.
 *
 * Functions return 0 on success and -1 on failure with a message in the
 * caller's buffer (lowercase, the subject quoted), except where stated.
 * Nothing here prints or exits.
 */
#ifndef POVPRESS_POVRAY_H
#define POVPRESS_POVRAY_H

#include <stddef.h>

#include "driver/image.h"

/* A pixel rectangle, 0-based and inclusive: columns x0..x1, rows y0..y1. */
struct pov_region {
	int x0, y0, x1, y1;
};

/* Declare=NAME=VALUE: NAME an identifier, VALUE a number (POV-Ray 3.7
 * accepts nothing else on the command line). */
struct pov_define {
	const char *name;
	const char *value;
};

/* One render.  The job only borrows its strings and arrays. */
struct pov_job {
	const char *scene;		/* the .pov file (required) */
	const char *output;		/* the EXR to write (required) */
	int width, height;		/* +W +H, the full image size (required) */
	const struct pov_region *region; /* NULL: the whole image; else
					 * +SC +EC +SR +ER, the output is still
					 * full size, black outside */
	int threads;			/* +WT; 0: POV-Ray's default (one per core) */
	const struct pov_define *defines; /* ndefines Declare= options */
	size_t ndefines;
	const char *const *extra;	/* nextra options passed verbatim, last */
	size_t nextra;
	const char *workdir;		/* where links for unsafe paths go; may be
					 * NULL when no path needs one */
	const char *povray;		/* the binary; NULL: $POVPRESS_POVRAY or
					 * "povray" */
	const char *radiosity;		/* radiosity data file (+RF), or NULL */
	enum pov_radiosity {
		POV_RAD_SAVE = 1,	/* +RFO: write the samples computed */
		POV_RAD_LOAD,		/* +RFI: start from the file's samples */
	} radiosity_mode;		/* with radiosity; POV-Ray ignores both
					 * options when the scene has none */
	int progress;			/* +V rather than -V: POV-Ray prints a
					 * "Rendered N of M pixels" line as each
					 * block ends, which the pool keeps
					 * (struct pov_result's progress) */
	int salvage;			/* stopped at the pool's deadline or by
					 * an interruption, the blocks it
					 * finished are read from its render
					 * state file (povstate.h) into struct
					 * pov_result's partial */
};

/* What POV-Ray's statistics report about one run. */
struct pov_phase {
	double wall_s;			/* "(0.026 seconds)" */
	double cpu_s;			/* "with 0.048 CPU-seconds total" */
	int threads;			/* "using 2 thread(s)" */
};

enum {
	POV_HAVE_PARSE = 1 << 0,	/* "Parse Time:" */
	POV_HAVE_BOUNDING = 1 << 1,	/* "Bounding Time:" */
	POV_HAVE_PHOTON = 1 << 2,	/* "Photon Time:" with a time (not "No photons") */
	POV_HAVE_RADIOSITY = 1 << 3,	/* "Radiosity Time:" with a time */
	POV_HAVE_TRACE = 1 << 4,	/* "Trace Time:" */
	POV_HAVE_PIXELS = 1 << 5,	/* the "Pixels: Samples: Smpls/Pxl:" line */
	POV_HAVE_RAYS = 1 << 6,		/* the "Rays: Saved:" line */
	POV_HAVE_RAD_RAYS = 1 << 7,	/* "Radiosity (final) rays shot:" */
};

struct pov_stats {
	unsigned have;			/* POV_HAVE_* bits: which fields were found */
	struct pov_phase parse, bounding, photon, radiosity, trace;
	long long pixels;		/* pixels traced; with antialiasing this
					 * includes the extra ones AA needs */
	long long samples;		/* antialiasing samples beyond the first
					 * per pixel (0 without AA) */
	double samples_per_pixel;	/* samples / pixels; 0 when POV-Ray prints "-" */
	long long rays;			/* camera rays: pixels + samples */
	long long rays_saved;		/* "Saved:" */
	long long rad_final_rays;	/* radiosity sample rays shot during the
					 * render proper, after the pretrace */
};

/*
 * Fill *st from POV-Ray's console output text (NUL-terminated; the last
 * occurrence of each field wins).  Returns 0 when the render statistics
 * (the Pixels line and the Trace Time) were found, -1 when not (st->have
 * still says what was); no message.
 */
int pov_stats_parse(const char *text, struct pov_stats *st);

/*
 * Whether POV-Ray's console output text has come as far as its render
 * time, through the trace time's CPU line, for a render without
 * radiosity: POV-Ray prints it just after writing the image, and with
 * radiosity it writes its radiosity file after that.  For
 * pov_pool_opts.ready_log.
 */
int pov_render_time_printed(const char *text);

/*
 * Build the argument vector for job: argv[0] is the binary as named (not
 * looked up), the vector is NULL-terminated and *argc_out (may be NULL)
 * counts its elements.  May create links in job->workdir (see above).  When
 * the output needs a stand-in name, the vector writes the stand-in and the
 * rename is left to the caller; pov_pool_run() and pov_shell_line() do it.
 * Fails on a bad job (a missing scene, a size or region out of range, a bad
 * Declare, an output directory that does not exist, an unsafe path without
 * a work directory) with a message naming the culprit.  You own *argv_out;
 * free it with pov_argv_free().
 */
int pov_argv_build(const struct pov_job *job, char ***argv_out, int *argc_out, char *err,
		   size_t errlen);

/* Free a vector from pov_argv_build(); NULL is a no-op. */
void pov_argv_free(char **argv);

/*
 * The same command as one line for sh, xargs -P or GNU parallel: every
 * word that needs it in single quotes (a ' becomes '\''), no trailing
 * newline; when the output needs a stand-in, "&& mv -f -- STANDIN OUTPUT"
 * follows.  Relative paths stay relative to the current directory.  You own
 * *line_out; free() it.
 */
int pov_shell_line(const struct pov_job *job, char **line_out, char *err, size_t errlen);

/*
 * Find the binary job would run (job->povray, else $POVPRESS_POVRAY, else
 * "povray"; a name without '/' is looked up in PATH) and write the path to
 * execute into path.  Fails when it is missing or not executable, with a
 * message naming it: "cannot run 'povray': No such file or directory
 * (looked in PATH; set POVPRESS_POVRAY to the binary)".
 */
int pov_find_binary(const struct pov_job *job, char *path, size_t pathlen, char *err,
		    size_t errlen);

/* Whether POV-Ray can be given path in double quotes (printable ASCII,
 * no double quote). */
int pov_path_safe(const char *path);

/*
 * A path POV-Ray can be given for directory dir: dir itself when it is
 * safe, else a symbolic link to it in $TMPDIR (or /tmp) named after a
 * hash of its real path, made or reused.  For work directories whose own
 * path has a double quote or a non-ASCII byte.
 */
int pov_safe_dir(const char *dir, char *out, size_t outlen, char *err, size_t errlen);

/* ---- the pool ------------------------------------------------------- */

enum pov_status {
	POV_OK = 0,		/* exit status 0 and the output exists */
	POV_FAILED,		/* a non-zero exit status, or no output: message has
				 * POV-Ray's own error (file and line for a parse
				 * error) */
	POV_CRASHED,		/* killed by a signal the pool did not send */
	POV_TIMED_OUT,		/* ran past the timeout and was killed */
	POV_NOT_RUN,		/* could not be started (fork or exec failed) */
	POV_CANCELLED,		/* stopped, or never started, by an interruption */
};

/* Short lowercase name of a status ("ok", "timed out", ...); static. */
const char *pov_status_name(enum pov_status st);

struct pov_result {
	enum pov_status status;
	int attempts;			/* runs made: 0 up to 1 + retries */
	int exit_status;		/* of the last attempt; -1 if it did not exit */
	int term_signal;		/* signal that ended the last attempt, or 0 */
	double wall_s;			/* wall seconds, summed over attempts */
	double cpu_s;			/* user + system CPU seconds of the child,
					 * summed over attempts (wait4) */
	double start_s, end_s;		/* first start and last end, seconds after
					 * the pool run began; 0 if never started */
	struct pov_stats stats;		/* of the last attempt */
	char message[1024];		/* empty for POV_OK; else what happened */
	char *log;			/* POV-Ray's console output of the last
					 * attempt (its last 1 MiB), or NULL; owned */
	int prelaunched;		/* its first attempt was taken from
					 * opts->prelaunched: wall_s and start_s
					 * count from its release */
	/* For a job with progress: POV-Ray's "Rendered N of M pixels" lines of
	 * the last attempt as they were read, each when (seconds after the
	 * attempt started) and N, the last rising run of them (a count that
	 * falls starts again); owned, NULL when none */
	struct pov_progress *progress;
	size_t nprogress;
	long progress_total;		/* their M */
	/* For a job with salvage stopped at the deadline or by an interruption
	 * (POV_CANCELLED): the pixels of its frame's rows (its region's, or
	 * all) that it finished, NaN where it did not, the image's first row
	 * partial_oy, and how many (pov_state_read()); a zeroed image when
	 * none; owned */
	struct image partial;
	int partial_oy;
	long partial_pixels;
};

/* One "Rendered N of M pixels" line of a render: when it was read, and N. */
struct pov_progress {
	double t;
	long done;
};

/* Free what res owns and zero it; a zeroed result is a no-op. */
void pov_result_release(struct pov_result *res);

/*
 * What the n one-thread renders of a pool run (res, as pov_pool_run() left
 * them) waited on besides their CPU on cores cores: the least, over those
 * that ran once and succeeded, of their wall time less the wall time their
 * CPU took with the cores shared.  A render's share of the cores is theirs
 * over the renders running alongside it on average (itself included), at
 * most 1.  lat[0] is from a fresh start, lat[1] for renders taken from
 * prelaunched ones (from their release); INFINITY where no render counts.
 */
void pov_results_latency(const struct pov_result *res, size_t n, int cores, double lat[2]);

struct pov_prelaunch;

struct pov_pool_opts {
	int max_jobs;			/* at most this many children at once (>= 1) */
	double timeout_s;		/* per attempt; 0: none */
	double grace_s;			/* SIGTERM to SIGKILL delay */
	int retries;			/* extra attempts for a job that crashed or
					 * timed out */
	/* Called, if set, in the pool's thread as each job reaches its final
	 * result (index into jobs, and that result). */
	void (*on_done)(void *arg, size_t index, const struct pov_result *res);
	void *arg;
	/* Called, if set, when a running job's output file has been written
	 * and closed (seen through inotify), with its path: when it returns
	 * nonzero (the file is whole), the job is done without waiting for
	 * POV-Ray to exit, which it does about 0.3 s after writing its image
	 * (its frontend polls the backend at 50 ms intervals); the pool kills
	 * it.  Where inotify is not available, jobs end at their exit. */
	int (*ready)(void *arg, size_t index, const char *path);
	/* Called, if set, after ready() accepted a job's output, with its
	 * console output so far, until it returns nonzero: only then is the
	 * job done and POV-Ray killed (for a render whose statistics, printed
	 * just after the image, or other files are wanted too). */
	int (*ready_log)(void *arg, size_t index, const char *log);
	/* If > 0: seconds after the run began when the pool stops: jobs still
	 * running (but those whose output ready() has accepted) are killed and
	 * reported POV_CANCELLED ("past the deadline"), unless they exit with
	 * their output first (POV_OK); jobs not started are reported
	 * POV_CANCELLED, or, if they had an attempt, keep its result; no
	 * retries; pov_pool_run() returns 0. */
	double deadline_s;
	/* If set: jobs whose command line is one of these pre-launched
	 * renders' are taken from it instead of started (see
	 * pov_prelaunch_start()); the rest of the set is stopped before any
	 * job starts.  The set is spent: end it with pov_prelaunch_end(). */
	struct pov_prelaunch *prelaunched;
	/* If > 0: at deadline_s, a running job with progress whose progress
	 * lines say it will have rendered its pixels within half of finish_s
	 * (those left at its rate so far; the last line's count its whole:
	 * done rendering, writing its image) is left finish_s to end before
	 * it is stopped, rather than lost with its work all but done. */
	double finish_s;
};

/* Defaults: max_jobs from pov_pool_size() for one job per core, no
 * timeout, grace 2 s, 1 retry, no callback. */
void pov_pool_opts_init(struct pov_pool_opts *opts);

/* CPUs this process may run on (its affinity mask), at least 1. */
int pov_cpu_count(void);

/* The library every POV-Ray process is started with preloaded (povwait.so
 * next to the povpress executable, or $POVPRESS_POVWAIT; "0" or empty for
 * none), or NULL when there is none.  It cuts POV-Ray's polling waits. */
const char *pov_wait_library(void);

/*
 * Choose the number of concurrent jobs (*jobs_out) and POV-Ray threads per
 * job (*threads_out, for +WT) for njobs jobs on cores CPUs: jobs =
 * min(requested, njobs) when requested > 0 (the user's --jobs), else
 * min(cores, njobs); threads = cores / jobs, at least 1.  So jobs * threads
 * never exceeds cores unless the user asked for more jobs than cores.
 */
void pov_pool_size(int cores, size_t njobs, int requested, int *jobs_out, int *threads_out);

enum {
	POV_INTERRUPTED = 1	/* pov_pool_run(): a signal stopped the run */
};

/*
 * Run njobs jobs, at most opts->max_jobs at once, and fill results[i] for
 * jobs[i].  Every job's command is built first: a bad job or a missing
 * binary fails the whole run (-1, nothing started, results zeroed).
 * Otherwise returns 0 when every job ran to a final result (each result
 * says how it went: POV_FAILED is not an error of the pool), or
 * POV_INTERRUPTED when SIGINT, SIGTERM or SIGHUP arrived (see
 * pov_signal_received()): running children were stopped (POV_CANCELLED),
 * jobs not yet started are POV_CANCELLED with 0 attempts, finished jobs
 * keep their results.  Either way no child is left when it returns.  You
 * own the results' contents; release each with pov_result_release().
 */
int pov_pool_run(const struct pov_job *jobs, size_t njobs, const struct pov_pool_opts *opts,
		 struct pov_result *results, char *err, size_t errlen);

/*
 * Pre-launched renders.  POV-Ray spends about 0.3 s of wall time starting
 * (its frontend polls its backend at 50 ms intervals) before it opens the
 * scene, on about 0.01 s of CPU.  pov_prelaunch_start() starts each job
 * with a FIFO in gatedir as its include header (+HI): POV-Ray starts up,
 * then sleeps in the FIFO's open until a pov_pool_run() takes the job
 * (opts->prelaunched) and opens the gate (the FIFO is replaced by an empty
 * file, and its waiting readers see an empty header).  The render then
 * begins at once: from the gate to the image takes about 0.09 s on a
 * 160x120 scene where a fresh start takes 0.36 to 0.42 s.  A job is taken
 * when its command line, without the +HI option, equals the pool job's.
 * gatedir must be a path POV-Ray takes as it is (pov_path_safe()).
 * Linux only (elsewhere -1 with a message).  Returns 0 and *out, or -1
 * with nothing left running.
 */
struct pov_prelaunch;
int pov_prelaunch_start(const struct pov_job *jobs, size_t njobs, const char *gatedir,
			struct pov_prelaunch **out, char *err, size_t errlen);

/* How many of the set's jobs a pool run took. */
size_t pov_prelaunch_taken(const struct pov_prelaunch *pre);

/* Stop and reap the jobs not taken, remove the gates and free the set;
 * returns the CPU seconds the stopped ones used (their start-up).  NULL:
 * 0. */
double pov_prelaunch_end(struct pov_prelaunch *pre);

/* ---- signals ---------------------------------------------------------- */

/*
 * Catch SIGINT, SIGTERM and SIGHUP: their handler only records the signal.
 * pov_pool_run() calls this itself for its duration; a command calls it
 * too to cover the time between pool runs (and then checks
 * pov_signal_received() between steps).  Calls nest; the outermost clears
 * the record.  Returns -1 with a message if sigaction fails.
 */
int pov_signals_catch(char *err, size_t errlen);

/* Undo one pov_signals_catch(); the outermost restores the previous
 * handlers.  The record stays readable. */
void pov_signals_restore(void);

/* The last caught signal since the outermost pov_signals_catch(), or 0. */
int pov_signal_received(void);

#endif
