/*
 * files.h - text files written whole or not at all, and directories.
 */
#ifndef POVPRESS_FILES_H
#define POVPRESS_FILES_H

#include <stdio.h>

/*
 * Start writing path: open "<path>.tmp" (its name goes to tmp, tmplen
 * bytes) for writing.  NULL with a message naming path on failure.
 */
FILE *file_begin(const char *path, char *tmp, size_t tmplen, char *err, size_t errlen);

/*
 * Finish: flush, sync and close f, then rename tmp to path.  On any
 * failure tmp is removed, path is left as it was, and -1 comes back with
 * a message naming path.
 */
int file_commit(FILE *f, const char *tmp, const char *path, char *err, size_t errlen);

/* Give up: close f and remove tmp; path is left as it was. */
void file_abort(FILE *f, const char *tmp);

/* Write text to path through file_begin() and file_commit(). */
int file_write_text(const char *path, const char *text, char *err, size_t errlen);

/* The whole of a file, its length in *len (len may be NULL) and a NUL after
 * it (you free() it), or NULL when it cannot be read (errno says why). */
void *file_read(const char *path, size_t *len);

/* The whole of a text file, NUL-terminated (you free() it), or NULL when it
 * cannot be read. */
char *file_read_text(const char *path);

/*
 * Make directory dir and any missing parents (mkdir -p); fails when one of
 * them cannot be made or dir exists but is not a directory, with a message
 * calling it what ("work directory", "directory").
 */
int file_mkdirs(const char *dir, const char *what, char *err, size_t errlen);

#endif
