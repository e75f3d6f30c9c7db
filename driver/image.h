/*
 * image.h - float images and their EXR input/output (OpenEXRCore).
 *
 * A struct image holds W x H pixels of nch float channels, interleaved:
 * channel c of pixel (x, y) is px[((size_t)y * w + x) * nch + c].  Channel
 * names travel with the pixels so that files round-trip.
 *
 * Functions return 0 on success and -1 on failure, leaving a message that
 * names the file at fault in the caller's error buffer.  Nothing here prints
 * or exits.
 */
#ifndef POVPRESS_IMAGE_H
#define POVPRESS_IMAGE_H

#include <stddef.h>

struct image {
	int w, h, nch;
	float *px;      /* w * h * nch floats, interleaved; owned */
	char **names;   /* nch channel names; owned */
};

/* Allocate a zero-filled w x h image with the given channel names (copied).
 * Returns 0, or -1 on bad size or out of memory. */
int image_init(struct image *img, int w, int h, int nch, const char *const *names,
	       char *err, size_t errlen);

/* Free what img owns and zero it; image_release on a zeroed struct is a no-op. */
void image_release(struct image *img);

/* Index of the channel called name, or -1. */
int image_channel(const struct image *img, const char *name);

/*
 * Read every channel of the first part of an EXR file (scanline or tiled,
 * half, float or uint) as float.  The data window becomes the image; channels
 * keep the file's names in the file's (alphabetical) order.  Of a mipmapped
 * or ripmapped file, the full-resolution level is read.  Deep images,
 * subsampled channels and, with OpenEXR before 3.2, DWAA/DWAB compression
 * are refused.  On failure returns -1 with a message such as
 * "cannot read 'a.exr': not an EXR file" and leaves *out zeroed.  You own
 * *out; free it with image_release().
 */
int image_read_exr(const char *path, struct image *out, char *err, size_t errlen);

/*
 * Read only rows y0..y1 (0-based, of the data window) of an EXR, for a
 * region of a large image: whole scanline chunks are decoded, so the image
 * may hold a few rows more; *oy receives the file row of its first row.
 * Tiled files are read whole (*oy = 0).  Errors as image_read_exr().
 */
int image_read_exr_rows(const char *path, int y0, int y1, struct image *out, int *oy,
			char *err, size_t errlen);

/* The size of an EXR's data window, from its header alone.  Errors as
 * image_read_exr(). */
int image_exr_size(const char *path, int *w, int *h, char *err, size_t errlen);

/*
 * Write img as a single-part scanline EXR, 32-bit float, PIZ compression
 * (ZIP at zlib's level 1 below 1024 pixels wide, where it is faster), one
 * channel per img channel with img's names (OpenEXR stores channels
 * sorted by name, so image_read_exr() returns them in that order).  Names
 * must be distinct and non-empty.  The data is written to a temporary file
 * PATH.tmp.XXXXXX in the same directory and renamed over path only when
 * complete, so a failure never leaves a partial file at path.
 */
int image_write_exr(const char *path, const struct image *img, char *err, size_t errlen);

/*
 * Like image_write_exr() but uncompressed: for the work directory's state,
 * rewritten whole every pass (hdr_highlights at 160x120, three passes:
 * povpress's own process took about 0.03 CPU s less than with PIZ, 0.22
 * against 0.25 s, perf's samples of four runs each; with every file it
 * writes uncompressed, 0.16 s).
 */
int image_write_exr_raw(const char *path, const struct image *img, char *err, size_t errlen);

/*
 * Like image_write_exr() but stores 16-bit half channels, rounding each
 * float to the nearest half.  Used to make test files; povpress's own
 * outputs are float.
 */
int image_write_exr_half(const char *path, const struct image *img, char *err,
			 size_t errlen);

/*
 * Make a W x H x 3 image holding the R, G, B channels of src, matched by
 * name (a lone Y channel is copied to all three).  Returns -1 with a
 * message naming `what` (normally the file name) when src has no colour
 * channels.  You own *out.
 */
int image_rgb(const struct image *src, const char *what, struct image *out,
	      char *err, size_t errlen);

#endif
