/*
 * povstate.c - the pixels of a stopped POV-Ray render, from its render
 * state file (povstate.h has the format).
 */
#include "driver/povstate.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "driver/errbuf.h"
#include "driver/files.h"

static const char state_magic[] = "POV-Ray Render State File";
static const unsigned char msg_magic[8] = { 'P', 'O', 'V', 'R', 'A', 'Y', 'M', 'S' };

int pov_state_path(const char *output, char *buf, size_t len)
{
	const char *slash = strrchr(output, '/'), *dot = strrchr(output, '.');
	size_t stem = dot && (!slash || dot > slash) ? (size_t)(dot - output) : strlen(output);
	int n = snprintf(buf, len, "%.*s.pov-state", (int)stem, output);
	return n < 0 || (size_t)n >= len ? -1 : 0;
}

static uint32_t be32(const unsigned char *p)
{
	return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static float befloat(const unsigned char *p)
{
	uint32_t u = be32(p);
	float f;
	memcpy(&f, &u, sizeof f);
	return f;
}

/* The first place at or after from where the 8 bytes of key follow, before
 * end; NULL if none. */
static const unsigned char *find8(const unsigned char *from, const unsigned char *end,
				  const unsigned char key[8])
{
	while (from + 8 <= end) {
		const unsigned char *p = memchr(from, key[0], (size_t)(end - from) - 7);
		if (!p)
			return NULL;
		if (!memcmp(p, key, 8))
			return p;
		from = p + 1;
	}
	return NULL;
}

/* The INT4 attribute name (four characters) of the message from msg to
 * end, after its pixels (from), into *v; -1 if missing. */
static int int_attr(const unsigned char *from, const unsigned char *end, const char *name,
		    long *v)
{
	unsigned char key[8];
	memcpy(key, name, 4);
	memcpy(key + 4, "INT4", 4);
	const unsigned char *p = find8(from, end, key);
	if (!p || p + 16 > end || be32(p + 8) != 4)
		return -1;
	*v = (long)(int32_t)be32(p + 12);
	return 0;
}

/* Block pixels v (five floats each, from row top, columns l..r) of rows
 * ya..yb into out (whose first row is y0); the pixels it had not had. */
static long put_block(struct image *out, int y0, const unsigned char *v, long l, long ya,
		      long r, long yb, long top)
{
	long fresh = 0;
	for (long y = ya; y <= yb; y++)
		for (long x = l; x <= r; x++) {
			const unsigned char *q =
				v + (((size_t)(y - top) * (size_t)(r - l + 1) + (size_t)(x - l)) * 5) * 4;
			float *o = out->px + ((size_t)(y - y0) * out->w + (size_t)x) * 3;
			fresh += isnan(o[0]) != 0;
			for (int c = 0; c < 3; c++)
				o[c] = befloat(q + 4 * c);
		}
	return fresh;
}

int pov_state_parse(const unsigned char *data, size_t len, const char *name, int w, int h,
		    int y0, int y1, struct image *out, int *oy, long *pixels, char *err,
		    size_t errlen)
{
	static const char *const rgb[3] = { "R", "G", "B" };
	static const unsigned char pblo[8] = { 'P', 'B', 'l', 'o', 'V', 'F', 'L', '4' };

	memset(out, 0, sizeof(*out));
	*pixels = 0;
	*oy = y0;
	if (len < sizeof state_magic - 1 || memcmp(data, state_magic, sizeof state_magic - 1)) {
		errbuf_printf(err, errlen, "'%s' is not a POV-Ray render state file", name);
		return -1;
	}
	if (w < 1 || h < 1 || y0 < 0 || y1 >= h || y0 > y1) {
		errbuf_printf(err, errlen, "rows %d..%d of a %dx%d frame: no such rows", y0, y1, w,
			      h);
		return -1;
	}
	if (image_init(out, w, y1 - y0 + 1, 3, rgb, err, errlen))
		return -1;
	const size_t n = (size_t)w * out->h * 3;
	for (size_t i = 0; i < n; i++)
		out->px[i] = NAN;

	/* each block's pixels, then the message's other attributes up to the
	 * next message (or the file's end) */
	const unsigned char *end = data + len;
	const unsigned char *m = find8(data, end, msg_magic);
	while (m) {
		const unsigned char *pb = find8(m + 8, end, pblo);
		if (!pb || pb + 12 > end)
			break;
		const uint32_t nf = be32(pb + 8);
		const unsigned char *v = pb + 12;
		if ((size_t)nf > (size_t)(end - v) / 4)
			break;	/* cut short */
		const unsigned char *after = v + (size_t)nf * 4;
		const unsigned char *next = find8(after, end, msg_magic);
		const unsigned char *mend = next ? next : end;
		long l, t, r, b;
		/* a whole block of this frame, its rows wanted put in (a message
		 * not a block's, cut short or not of this frame is left out) */
		if (!int_attr(after, mend, "Left", &l) && !int_attr(after, mend, "Top ", &t) &&
		    !int_attr(after, mend, "Righ", &r) && !int_attr(after, mend, "Bott", &b) &&
		    l >= 0 && t >= 0 && r < w && b < h && l <= r && t <= b &&
		    (uint64_t)nf == (uint64_t)(r - l + 1) * (uint64_t)(b - t + 1) * 5)
			*pixels += put_block(out, y0, v, l, t > y0 ? t : y0, r, b < y1 ? b : y1,
					     t);
		m = next;
	}
	return 0;
}

int pov_state_read(const char *path, int w, int h, int y0, int y1, struct image *out, int *oy,
		   long *pixels, char *err, size_t errlen)
{
	memset(out, 0, sizeof(*out));
	*pixels = 0;
	size_t len;
	unsigned char *data = file_read(path, &len);
	if (!data) {
		errbuf_printf(err, errlen, "cannot read '%s': %s", path, strerror(errno));
		return -1;
	}
	int rc = pov_state_parse(data, len, path, w, h, y0, y1, out, oy, pixels, err, errlen);
	free(data);
	return rc;
}
