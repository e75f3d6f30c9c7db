/*
 * povray_waits - the waits POV-Ray polls with, for tests/render.sh's checks
 * of povwait.so (driver/povwait/povwait.c): N rounds of a 50 ms nanosleep,
 * a 50 ms relative clock_nanosleep, and 50 ms condition-variable timeouts on
 * the realtime and the monotonic clock (as Boost's threads use), then one
 * 300 ms sleep; prints the milliseconds the rounds took and the 300 ms
 * sleep took.  Its name starts with "povray", as povwait.so requires of the
 * programs whose waits it cuts; a copy under another name is not cut.
 *
 * usage: povray_waits [ROUNDS]
 */
#define _GNU_SOURCE
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now_ms(void)
{
	struct timespec t;

	clock_gettime(CLOCK_MONOTONIC, &t);
	return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

static struct timespec after(clockid_t c, long ms)
{
	struct timespec t;

	clock_gettime(c, &t);
	t.tv_nsec += ms * 1000000L;
	t.tv_sec += t.tv_nsec / 1000000000L;
	t.tv_nsec %= 1000000000L;
	return t;
}

/* A timed wait on a condition nobody signals, on clock c. */
static void cond_wait_ms(clockid_t c, long ms)
{
	pthread_condattr_t a;
	pthread_cond_t cv;
	pthread_mutex_t m = PTHREAD_MUTEX_INITIALIZER;
	struct timespec d;

	pthread_condattr_init(&a);
	pthread_condattr_setclock(&a, c);
	pthread_cond_init(&cv, &a);
	pthread_mutex_lock(&m);
	d = after(c, ms);
	while (pthread_cond_timedwait(&cv, &m, &d) == 0)
		;	/* a spurious wake-up: wait again */
	pthread_mutex_unlock(&m);
	pthread_cond_destroy(&cv);
	pthread_condattr_destroy(&a);
}

int main(int argc, char **argv)
{
	const struct timespec ms50 = { 0, 50000000L }, ms300 = { 0, 300000000L };
	int rounds = argc > 1 ? atoi(argv[1]) : 4;
	double t0, t1, t2;

	if (rounds < 1) {
		fprintf(stderr, "usage: povray_waits [ROUNDS]\n");
		return 2;
	}
	t0 = now_ms();
	for (int k = 0; k < rounds; k++) {
		nanosleep(&ms50, NULL);
		clock_nanosleep(CLOCK_MONOTONIC, 0, &ms50, NULL);
		cond_wait_ms(CLOCK_REALTIME, 50);
		cond_wait_ms(CLOCK_MONOTONIC, 50);
	}
	t1 = now_ms();
	nanosleep(&ms300, NULL);
	t2 = now_ms();
	printf("%.1f %.1f\n", t1 - t0, t2 - t1);
	return 0;
}
