/*
 * errbuf.h - the caller's error buffer.
 *
 * Library code in driver/ reports a failure by returning -1 and leaving a
 * message in a buffer its caller owns; only the command layer prints.
 */
#ifndef POVPRESS_ERRBUF_H
#define POVPRESS_ERRBUF_H

#include <stddef.h>

/* printf into err (of errlen bytes, truncating); nothing when err is NULL
 * or errlen is 0. */
#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
void errbuf_printf(char *err, size_t errlen, const char *fmt, ...);

#endif
