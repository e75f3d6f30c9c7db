/*
 * povwait.so - shortens POV-Ray 3.7's polling waits.
 *
 * POV-Ray's front end and back end talk through message queues that each
 * side polls: the threads sleep 10 to 100 ms at a time (nanosleep) or wait
 * on a condition variable with a 50 ms timeout, and a render waits on these
 * polls from its start, through parsing, to its exit.  An 8x8 render takes
 * 0.68 s of wall time for 0.01 s of CPU.  povpress preloads this library
 * into the POV-Ray processes it starts (LD_PRELOAD): every such wait of at
 * most POLL_MAX_NS is cut to CUT_NS, after which the caller polls again and
 * finds its message.  The same 8x8 render then takes 0.03 s; the image is
 * the same.  Longer waits are left as they are, as are all waits in any
 * other program (the library is inherited by POV-Ray's children, and a test
 * may stand a script in for POV-Ray).
 *
 * A timed wait that returns early is within its contract for a condition
 * variable (the caller re-checks its predicate); for a sleep it is what a
 * poll loop does anyway.  The library uses nothing of povpress.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <pthread.h>
#include <string.h>
#include <time.h>

#define CUT_NS 1000000LL	/* what a poll waits instead */
#define POLL_MAX_NS 250000000LL	/* the longest wait taken for a poll */
#define NS 1000000000LL

typedef int (*clock_nanosleep_fn)(clockid_t, int, const struct timespec *, struct timespec *);
typedef int (*timedwait_fn)(pthread_cond_t *, pthread_mutex_t *, const struct timespec *);
typedef int (*clockwait_fn)(pthread_cond_t *, pthread_mutex_t *, clockid_t,
			    const struct timespec *);

static clock_nanosleep_fn real_sleep;
static timedwait_fn real_timedwait;
static clockwait_fn real_clockwait;
static int active;	/* this process is POV-Ray */

static long long ns_of(const struct timespec *t)
{
	return (long long)t->tv_sec * NS + t->tv_nsec;
}

static struct timespec ts_of(long long ns)
{
	struct timespec t;

	t.tv_sec = (time_t)(ns / NS);
	t.tv_nsec = (long)(ns % NS);
	return t;
}

static long long now_ns(clockid_t c)
{
	struct timespec t;

	return clock_gettime(c, &t) ? 0 : ns_of(&t);
}

/* ISO C has no conversion from dlsym's object pointer to a function
 * pointer; POSIX guarantees the representation. */
static void set_fn(void *fn, size_t size, void *sym)
{
	memcpy(fn, &sym, size);
}

/* The real functions, looked up once; before our constructor has run (a
 * wait in another library's constructor) on first use. */
static void resolve(void)
{
	void *ver = dlvsym(RTLD_NEXT, "pthread_cond_timedwait", "GLIBC_2.3.2");

	set_fn(&real_sleep, sizeof(real_sleep), dlsym(RTLD_NEXT, "clock_nanosleep"));
	set_fn(&real_timedwait, sizeof(real_timedwait),
	       ver ? ver : dlsym(RTLD_NEXT, "pthread_cond_timedwait"));
	set_fn(&real_clockwait, sizeof(real_clockwait), dlsym(RTLD_NEXT, "pthread_cond_clockwait"));
}

__attribute__((constructor)) static void povwait_init(void)
{
	const char *name = program_invocation_short_name;

	resolve();
	/* povray, povray3.7, povray.bin, ... */
	active = name && strncmp(name, "povray", 6) == 0;
}

/* Whether t is a valid timespec (the real function reports one that is
 * not). */
static int valid(const struct timespec *t)
{
	return t->tv_nsec >= 0 && t->tv_nsec < NS;
}

/* A relative wait of ns: how long to wait instead. */
static long long cut(long long ns)
{
	return active && ns > CUT_NS && ns <= POLL_MAX_NS ? CUT_NS : ns;
}

/* An absolute deadline on clock c: the deadline to wait for instead. */
static struct timespec cut_abs(clockid_t c, const struct timespec *abst)
{
	long long now = now_ns(c), left = ns_of(abst) - now;

	return left == cut(left) ? *abst : ts_of(now + CUT_NS);
}

int clock_nanosleep(clockid_t c, int flags, const struct timespec *req, struct timespec *rem)
{
	struct timespec r;

	if (!real_sleep && (resolve(), !real_sleep))
		return ENOSYS;
	if (!req || !valid(req))
		return real_sleep(c, flags, req, rem);
	r = (flags & TIMER_ABSTIME) ? cut_abs(c, req) : ts_of(cut(ns_of(req)));
	return real_sleep(c, flags, &r, rem);
}

int nanosleep(const struct timespec *req, struct timespec *rem)
{
	int e = clock_nanosleep(CLOCK_REALTIME, 0, req, rem);

	if (e) {
		errno = e;
		return -1;
	}
	return 0;
}

int pthread_cond_timedwait(pthread_cond_t *cv, pthread_mutex_t *m, const struct timespec *abst)
{
	struct timespec d;
	long long left;

	if (!real_timedwait && (resolve(), !real_timedwait))
		return ENOSYS;
	if (!active || !valid(abst))
		return real_timedwait(cv, m, abst);
	/* The condition variable's clock is not to be read from it: a poll's
	 * deadline is near one of the two clocks (decades apart) */
	left = ns_of(abst) - now_ns(CLOCK_REALTIME);
	d = cut_abs(left == cut(left) ? CLOCK_MONOTONIC : CLOCK_REALTIME, abst);
	return real_timedwait(cv, m, &d);
}

int pthread_cond_clockwait(pthread_cond_t *cv, pthread_mutex_t *m, clockid_t c,
			   const struct timespec *abst)
{
	struct timespec d;

	if (!real_clockwait && (resolve(), !real_clockwait))
		return ENOSYS;
	if (!active || !valid(abst))
		return real_clockwait(cv, m, c, abst);
	d = cut_abs(c, abst);
	return real_clockwait(cv, m, c, &d);
}
