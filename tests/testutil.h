/*
 * testutil.h - helpers shared by the cmocka tests: a scratch directory,
 * shell commands, and checks on files and images.  Include after <cmocka.h>; each
 * test program gets its own copy (everything here is static).
 */
#ifndef POVPRESS_TESTUTIL_H
#define POVPRESS_TESTUTIL_H

#include <dirent.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "driver/image.h"

#if defined(__GNUC__)
#define TESTUTIL_UNUSED __attribute__((unused))
#else
#define TESTUTIL_UNUSED
#endif

/* The test program's scratch directory, made by its group setup. */
static char scratch_dir[128] TESTUTIL_UNUSED;

/* scratch_dir/name in buf */
TESTUTIL_UNUSED static const char *scratch(char *buf, size_t len, const char *name)
{
	int n = snprintf(buf, len, "%s/%s", scratch_dir, name);

	assert_true(n > 0 && (size_t)n < len);
	return buf;
}

/* Run a shell command; its exit status, or -1 if it did not exit. */
TESTUTIL_UNUSED static int run(const char *fmt, ...)
{
	char cmd[4096];
	va_list ap;
	int n, st;

	va_start(ap, fmt);
	n = vsnprintf(cmd, sizeof(cmd), fmt, ap);
	va_end(ap);
	assert_true(n > 0 && (size_t)n < sizeof(cmd));
	st = system(cmd);
	if (st == -1 || !WIFEXITED(st))
		return -1;
	return WEXITSTATUS(st);
}

/* Entries of dir whose name contains part. */
TESTUTIL_UNUSED static int count_entries(const char *dir, const char *part)
{
	DIR *d = opendir(dir);
	struct dirent *e;
	int n = 0;

	assert_non_null(d);
	while ((e = readdir(d)))
		n += strstr(e->d_name, part) != NULL;
	closedir(d);
	return n;
}

/* A failed call leaves its output image zeroed. */
TESTUTIL_UNUSED static void assert_zeroed(const struct image *img)
{
	assert_null(img->px);
	assert_null(img->names);
	assert_int_equal(img->w, 0);
	assert_int_equal(img->h, 0);
	assert_int_equal(img->nch, 0);
}

#endif
