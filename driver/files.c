/*
 * files.c - text files written whole or not at all, and directories
 * (see files.h).
 */
#include "driver/errbuf.h"
#include "driver/files.h"

#include <errno.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

FILE *file_begin(const char *path, char *tmp, size_t tmplen, char *err, size_t errlen)
{
	if (snprintf(tmp, tmplen, "%s.tmp", path) >= (int)tmplen) {
		errbuf_printf(err, errlen, "cannot write '%s': path too long", path);
		return NULL;
	}
	FILE *f = fopen(tmp, "w");
	if (!f)
		errbuf_printf(err, errlen, "cannot write '%s': %s", path, strerror(errno));
	return f;
}

int file_commit(FILE *f, const char *tmp, const char *path, char *err, size_t errlen)
{
	errno = 0;
	int bad = ferror(f) != 0;
	bad |= fflush(f) != 0 || fsync(fileno(f)) != 0;
	int saved = bad ? errno : 0;
	bad |= fclose(f) != 0;
	if (!bad && rename(tmp, path) == 0)
		return 0;
	if (!saved)
		saved = errno;
	errbuf_printf(err, errlen, "cannot write '%s': %s", path,
		      saved ? strerror(saved) : "write error");
	unlink(tmp);
	return -1;
}

void file_abort(FILE *f, const char *tmp)
{
	fclose(f);
	unlink(tmp);
}

int file_write_text(const char *path, const char *text, char *err, size_t errlen)
{
	char tmp[PATH_MAX + 8];
	FILE *f = file_begin(path, tmp, sizeof tmp, err, errlen);
	if (!f)
		return -1;
	fputs(text, f);
	return file_commit(f, tmp, path, err, errlen);
}

void *file_read(const char *path, size_t *len)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		return NULL;
	/* a regular file's size and 2: its end is seen in one read */
	struct stat st;
	size_t cap = !fstat(fileno(f), &st) && st.st_size > 0 ? (size_t)st.st_size + 2 : 4096;
	size_t n = 0;
	char *s = malloc(cap);
	while (s) {
		size_t k = fread(s + n, 1, cap - n - 1, f);
		n += k;
		if (n + 1 < cap)
			break;
		char *t = realloc(s, cap *= 2);
		if (!t) {
			free(s);
			s = NULL;
		} else {
			s = t;
		}
	}
	if (s && ferror(f)) {
		free(s);
		s = NULL;
		errno = EIO;
	}
	fclose(f);
	if (s) {
		s[n] = '\0';
		if (len)
			*len = n;
	}
	return s;
}

char *file_read_text(const char *path)
{
	return file_read(path, NULL);
}

static int make_one(const char *dir, const char *what, char *err, size_t errlen)
{
	struct stat st;
	if (mkdir(dir, 0777) && errno != EEXIST) {
		errbuf_printf(err, errlen, "cannot create %s '%s': %s", what, dir, strerror(errno));
		return -1;
	}
	errno = 0;
	if (stat(dir, &st) || !S_ISDIR(st.st_mode)) {
		errbuf_printf(err, errlen, "cannot create %s '%s': %s", what, dir,
			      errno ? strerror(errno) : "it exists and is not a directory");
		return -1;
	}
	return 0;
}

int file_mkdirs(const char *dir, const char *what, char *err, size_t errlen)
{
	char buf[PATH_MAX];
	if (snprintf(buf, sizeof buf, "%s", dir) >= (int)sizeof buf) {
		errbuf_printf(err, errlen, "cannot create %s '%s': path too long", what, dir);
		return -1;
	}
	for (char *p = buf + 1; *p; p++) {
		if (*p != '/')
			continue;
		*p = '\0';
		if (make_one(buf, what, err, errlen))
			return -1;
		*p = '/';
	}
	return make_one(buf, what, err, errlen);
}
