/*
 * args.h - parsing the numbers of command-line options.
 */
#ifndef POVPRESS_ARGS_H
#define POVPRESS_ARGS_H

/* The whole of s as a decimal integer in lo..hi into *out: 0, else -1 and
 * *out untouched. */
int args_int(const char *s, int lo, int hi, int *out);

/* The whole of s as a finite number in lo..hi into *out: 0, else -1. */
int args_double(const char *s, double lo, double hi, double *out);

#endif
