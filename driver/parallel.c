/*
 * parallel.c - one function over an array of tasks, on threads
 * (parallel.h).
 */
#include "driver/parallel.h"

#include <pthread.h>
#include <stdlib.h>

void parallel_run(void *(*fn)(void *), void *tasks, size_t size, int n)
{
	char *t = tasks;
	pthread_t *tid = n > 1 ? malloc(sizeof(*tid) * (size_t)n) : NULL;
	int started = 0;	/* tasks 1 to started run on threads */
	for (int k = 1; tid && k < n; k++) {
		if (pthread_create(&tid[k], NULL, fn, t + (size_t)k * size))
			break;
		started = k;
	}
	fn(t);
	for (int k = started + 1; k < n; k++)
		fn(t + (size_t)k * size);
	for (int k = 1; k <= started; k++)
		pthread_join(tid[k], NULL);
	free(tid);
}
