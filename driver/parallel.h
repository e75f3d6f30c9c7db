/*
 * parallel.h - one function over an array of tasks, on threads.
 *
 * What the filter (denoise.c) and the pixel errors (plan.c) share: their
 * work is cut into bands beforehand, so that the result does not depend on
 * how many threads ran it.
 */
#ifndef POVPRESS_PARALLEL_H
#define POVPRESS_PARALLEL_H

#include <stddef.h>

/*
 * Call fn on each of the n tasks (task k at (char *)tasks + k * size):
 * tasks 1 to n - 1 on threads of their own, task 0 on the calling thread,
 * and any task whose thread cannot start on the calling thread after it.
 * Returns when every task is done; fn's return value is ignored.
 */
void parallel_run(void *(*fn)(void *), void *tasks, size_t size, int n);

#endif
