/*
 * image.c - float images and their EXR input/output through OpenEXRCore.
 *
 * Reading decodes each chunk (scanline block or tile) of part 0 straight
 * into the interleaved float buffer: every channel of the decode pipeline
 * points at its own column of the image, with a pixel stride of nch floats
 * and a line stride of w * nch floats, and OpenEXRCore converts half and
 * uint samples to float on the way.  Writing does the reverse with an
 * encode pipeline, into a temporary file that is renamed into place.
 *
 * File I/O goes through our own read/write callbacks on a descriptor we
 * opened, so that "cannot open" errors carry errno, the library always
 * knows the file size (which lets it reject chunks that run past the end
 * of a truncated file instead of reading garbage), and nothing is printed.
 */
#include "driver/errbuf.h"
#include "driver/image.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <openexr.h>

/* The first four bytes of every OpenEXR file, 20000630 little-endian. */
static const unsigned char exr_magic[4] = { 0x76, 0x2f, 0x31, 0x01 };

/*
 * The first message OpenEXRCore reported since exr_msg_reset().  It is per
 * thread because the library calls the handler with no way back to our
 * data that is safe everywhere: exr_get_user_data() takes the context lock
 * in write mode, and the handler can be called with that lock held.  The
 * first message is kept because later ones ("unable to read pixel data
 * block") only restate that something below failed.
 */
static _Thread_local char exr_msg[256];

static void exr_msg_reset(void)
{
	exr_msg[0] = '\0';
}

static void exr_msg_handler(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
	(void)ctxt;
	if (exr_msg[0])
		return;
	if (!msg || !*msg)
		msg = exr_get_default_error_message(code);
	snprintf(exr_msg, sizeof(exr_msg), "%s", msg);
}

/*
 * Describe failure rv of an OpenEXRCore call: the library's own message if
 * it gave one, otherwise the generic text for the code.  The library
 * capitalises its sentences; our messages are lowercase, so the first
 * letter is lowered unless it starts an acronym ("EXR", "DWA").
 */
static void exr_describe(exr_result_t rv, char *buf, size_t len)
{
	const char *msg = exr_msg[0] ? exr_msg : exr_get_default_error_message(rv);

	snprintf(buf, len, "%s", msg);
	if (buf[0] >= 'A' && buf[0] <= 'Z' && !(buf[1] >= 'A' && buf[1] <= 'Z'))
		buf[0] = (char)(buf[0] - 'A' + 'a');
}

static void set_exr_err(char *err, size_t errlen, const char *verb, const char *path,
			exr_result_t rv)
{
	char why[sizeof(exr_msg)];

	exr_describe(rv, why, sizeof(why));
	errbuf_printf(err, errlen, "cannot %s '%s': %s", verb, path, why);
}

/*
 * A failure while locating or decoding pixel data: once the header has
 * parsed, that almost always means a truncated or damaged file, which the
 * library's messages ("found corrupt leader: packed size ...") do not say
 * in so many words.
 */
static void set_pixel_err(char *err, size_t errlen, const char *path, exr_result_t rv)
{
	char why[sizeof(exr_msg)];

	exr_describe(rv, why, sizeof(why));
	errbuf_printf(err, errlen, "cannot read '%s': truncated or corrupt pixel data (%s)",
		path, why);
}

int image_init(struct image *img, int w, int h, int nch, const char *const *names,
	       char *err, size_t errlen)
{
	size_t n;

	memset(img, 0, sizeof(*img));
	if (w <= 0 || h <= 0 || nch <= 0) {
		errbuf_printf(err, errlen, "invalid image size %dx%d with %d channels", w, h, nch);
		return -1;
	}
	if ((size_t)w > SIZE_MAX / sizeof(float) / (size_t)h / (size_t)nch) {
		errbuf_printf(err, errlen, "image size %dx%d with %d channels is too large",
			w, h, nch);
		return -1;
	}
	n = (size_t)w * (size_t)h * (size_t)nch;
	img->px = calloc(n, sizeof(float));
	img->names = calloc((size_t)nch, sizeof(char *));
	if (!img->px || !img->names)
		goto oom;
	img->nch = nch;
	for (int c = 0; c < nch; c++) {
		const char *name = names && names[c] ? names[c] : "";

		img->names[c] = strdup(name);
		if (!img->names[c])
			goto oom;
	}
	img->w = w;
	img->h = h;
	return 0;

oom:
	image_release(img);
	errbuf_printf(err, errlen, "out of memory for a %dx%d image with %d channels", w, h, nch);
	return -1;
}

void image_release(struct image *img)
{
	if (!img)
		return;
	if (img->names)
		for (int c = 0; c < img->nch; c++)
			free(img->names[c]);
	free(img->names);
	free(img->px);
	memset(img, 0, sizeof(*img));
}

int image_channel(const struct image *img, const char *name)
{
	if (!img->names || !name)
		return -1;
	for (int c = 0; c < img->nch; c++)
		if (img->names[c] && !strcmp(img->names[c], name))
			return c;
	return -1;
}

/*
 * OpenEXRCore takes the line stride in bytes as an int32_t, which bounds
 * the width times the channel count of an image we can read or write.
 */
static int stride_fits(int64_t w, int64_t nch)
{
	return w * nch <= INT32_MAX / (int64_t)sizeof(float);
}

/* ------------------------------------------------------------------ */
/* reading */

struct exr_src {
	int fd;
	int64_t size;
};

static int64_t src_read(exr_const_context_t ctxt, void *userdata, void *buffer,
			uint64_t sz, uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
	const struct exr_src *src = userdata;
	unsigned char *p = buffer;
	uint64_t done = 0;

	if (offset > (uint64_t)INT64_MAX - sz) {
		error_cb(ctxt, EXR_ERR_READ_IO, "read past the largest file offset");
		return -1;
	}
	while (done < sz) {
		size_t want = sz - done > (uint64_t)SSIZE_MAX ?
			(size_t)SSIZE_MAX : (size_t)(sz - done);
		ssize_t n = pread(src->fd, p + done, want, (off_t)(offset + done));

		if (n < 0) {
			if (errno == EINTR)
				continue;
			error_cb(ctxt, EXR_ERR_READ_IO, "%s", strerror(errno));
			return -1;
		}
		if (n == 0)
			break;	/* end of file: the library reports the short read */
		done += (uint64_t)n;
	}
	return (int64_t)done;
}

static int64_t src_size(exr_const_context_t ctxt, void *userdata)
{
	(void)ctxt;
	return ((const struct exr_src *)userdata)->size;
}

/*
 * Point every channel of the decode pipeline at its column of img, for a
 * chunk whose top-left pixel is (x0, y0) in image coordinates.
 */
static int aim_decoder(exr_decode_pipeline_t *dec, struct image *img, int x0, int y0)
{
	for (int c = 0; c < dec->channel_count; c++) {
		exr_coding_channel_info_t *ch = &dec->channels[c];
		int idx = image_channel(img, ch->channel_name);

		if (idx < 0)
			return -1;
		ch->decode_to_ptr = (uint8_t *)(img->px +
			((size_t)y0 * (size_t)img->w + (size_t)x0) * (size_t)img->nch +
			(size_t)idx);
		ch->user_pixel_stride = img->nch * (int32_t)sizeof(float);
		ch->user_line_stride = img->w * img->nch * (int32_t)sizeof(float);
		ch->user_bytes_per_element = (int16_t)sizeof(float);
		ch->user_data_type = EXR_PIXEL_FLOAT;
	}
	return 0;
}

struct reader {
	exr_context_t ctx;
	exr_decode_pipeline_t dec;
	int started;		/* dec has been initialised */
	exr_compression_t comp;
	exr_result_t (*b44_decompress)(exr_decode_pipeline_t *);
	struct image *img;
	const char *path;
	char *err;
	size_t errlen;
	int band;		/* read only rows band_y0..band_y1 (scanline files) */
	int header;		/* read only the size: img->w, img->h, no pixels */
	int band_y0, band_y1;	/* in: wanted rows; out: rows read, image-relative */
};

/*
 * OpenEXR writers store a chunk uncompressed whenever compressing it would
 * not make it smaller, and readers must then take the bytes as they are.
 * OpenEXRCore 3.1 forgets that for B44 and B44A and runs the B44 decoder
 * over such raw chunks, scrambling them; every chunk of a B44 file with
 * only float channels is stored raw, for example.
 */
static exr_result_t b44_decompress_fixed(exr_decode_pipeline_t *dec)
{
	const struct reader *rd = dec->decoding_user_data;

	if (dec->chunk.packed_size == dec->chunk.unpacked_size) {
		if (dec->unpacked_buffer != dec->packed_buffer)
			memcpy(dec->unpacked_buffer, dec->packed_buffer,
			       (size_t)dec->chunk.packed_size);
		return EXR_ERR_SUCCESS;
	}
	return rd->b44_decompress(dec);
}

/* Decode the chunk described by ci into the image at (x0, y0). */
static int read_chunk(struct reader *rd, const exr_chunk_info_t *ci, int x0, int y0)
{
	struct image *img = rd->img;
	exr_result_t rv;

	exr_msg_reset();
	/* a corrupt file must not make us write outside the image */
	if (x0 < 0 || y0 < 0 || ci->width <= 0 || ci->height <= 0 ||
	    ci->width > img->w - x0 || ci->height > img->h - y0) {
		errbuf_printf(rd->err, rd->errlen,
			"cannot read '%s': corrupt chunk %d (%dx%d pixels at %d,%d)",
			rd->path, ci->idx, ci->width, ci->height, x0, y0);
		return -1;
	}
	if (!rd->started) {
		rv = exr_decoding_initialize(rd->ctx, 0, ci, &rd->dec);
		if (rv != EXR_ERR_SUCCESS)
			goto fail;
		rd->started = 1;
		if (aim_decoder(&rd->dec, img, x0, y0))
			goto bad_channel;
		rv = exr_decoding_choose_default_routines(rd->ctx, 0, &rd->dec);
		if (rv == EXR_ERR_SUCCESS && rd->dec.decompress_fn &&
		    (rd->comp == EXR_COMPRESSION_B44 || rd->comp == EXR_COMPRESSION_B44A)) {
			rd->b44_decompress = rd->dec.decompress_fn;
			rd->dec.decompress_fn = b44_decompress_fixed;
			rd->dec.decoding_user_data = rd;
		}
	} else {
		rv = exr_decoding_update(rd->ctx, 0, ci, &rd->dec);
		if (rv == EXR_ERR_SUCCESS && aim_decoder(&rd->dec, img, x0, y0))
			goto bad_channel;
	}
	if (rv == EXR_ERR_SUCCESS)
		rv = exr_decoding_run(rd->ctx, 0, &rd->dec);
	if (rv == EXR_ERR_SUCCESS)
		return 0;
fail:
	set_pixel_err(rd->err, rd->errlen, rd->path, rv);
	return -1;
bad_channel:
	errbuf_printf(rd->err, rd->errlen, "cannot read '%s': chunk %d has unexpected channels",
		rd->path, ci->idx);
	return -1;
}

static int read_scanlines(struct reader *rd, const exr_attr_box2i_t *dw)
{
	exr_chunk_info_t ci;
	int32_t lpc = 0;
	exr_result_t rv;

	rv = exr_get_scanlines_per_chunk(rd->ctx, 0, &lpc);
	if (rv == EXR_ERR_SUCCESS && lpc <= 0)
		rv = EXR_ERR_INVALID_ATTR;
	if (rv != EXR_ERR_SUCCESS) {
		set_exr_err(rd->err, rd->errlen, "read", rd->path, rv);
		return -1;
	}
	int64_t ylo = dw->min.y, yhi = dw->max.y;
	if (rd->band) {
		/* whole chunks: from the chunk holding the first wanted row */
		ylo = dw->min.y + (int64_t)rd->band_y0 / lpc * lpc;
		yhi = dw->min.y + (int64_t)rd->band_y1;
	}
	/* int64_t: a data window ending at INT_MAX must not overflow y */
	for (int64_t y = ylo; y <= yhi; y += lpc) {
		exr_msg_reset();
		rv = exr_read_scanline_chunk_info(rd->ctx, 0, (int)y, &ci);
		if (rv != EXR_ERR_SUCCESS) {
			set_pixel_err(rd->err, rd->errlen, rd->path, rv);
			return -1;
		}
		if (read_chunk(rd, &ci, ci.start_x - dw->min.x,
			       ci.start_y - (int)(rd->band ? ylo : dw->min.y)))
			return -1;
	}
	return 0;
}

/* Read level 0 of a tiled part; that is the whole image for every level mode. */
static int read_tiles(struct reader *rd)
{
	exr_chunk_info_t ci;
	int32_t tw = 0, th = 0, lw = 0, lh = 0;
	exr_result_t rv;

	rv = exr_get_tile_sizes(rd->ctx, 0, 0, 0, &tw, &th);
	if (rv == EXR_ERR_SUCCESS)
		rv = exr_get_level_sizes(rd->ctx, 0, 0, 0, &lw, &lh);
	if (rv == EXR_ERR_SUCCESS && (tw <= 0 || th <= 0 ||
				      lw != rd->img->w || lh != rd->img->h))
		rv = EXR_ERR_INVALID_ATTR;
	if (rv != EXR_ERR_SUCCESS) {
		set_exr_err(rd->err, rd->errlen, "read", rd->path, rv);
		return -1;
	}
	for (int ty = 0; ty <= (lh - 1) / th; ty++) {
		for (int tx = 0; tx <= (lw - 1) / tw; tx++) {
			exr_msg_reset();
			rv = exr_read_tile_chunk_info(rd->ctx, 0, tx, ty, 0, 0, &ci);
			if (rv != EXR_ERR_SUCCESS) {
				set_pixel_err(rd->err, rd->errlen, rd->path, rv);
				return -1;
			}
			/* ci.start_x/y hold tile indices, not pixels */
			if (read_chunk(rd, &ci, tx * tw, ty * th))
				return -1;
		}
	}
	return 0;
}

/* OpenEXRCore decodes DWAA and DWAB only from version 3.2 on. */
static int dwa_unsupported(exr_compression_t comp)
{
	int maj = 0, min = 0, patch = 0;
	const char *extra = NULL;

	if (comp != EXR_COMPRESSION_DWAA && comp != EXR_COMPRESSION_DWAB)
		return 0;
	exr_get_library_version(&maj, &min, &patch, &extra);
	return maj < 3 || (maj == 3 && min < 2);
}

/* Fill rd->img from part 0 of the open context. */
static int read_part0(struct reader *rd)
{
	const exr_attr_chlist_t *chl = NULL;
	const char **names = NULL;
	exr_attr_box2i_t dw;
	exr_storage_t storage;
	exr_compression_t comp;
	int64_t w, h;
	exr_result_t rv;
	int ret = -1;

	rv = exr_get_storage(rd->ctx, 0, &storage);
	if (rv == EXR_ERR_SUCCESS)
		rv = exr_get_compression(rd->ctx, 0, &comp);
	if (rv == EXR_ERR_SUCCESS)
		rv = exr_get_data_window(rd->ctx, 0, &dw);
	if (rv == EXR_ERR_SUCCESS)
		rv = exr_get_channels(rd->ctx, 0, &chl);
	if (rv != EXR_ERR_SUCCESS) {
		set_exr_err(rd->err, rd->errlen, "read", rd->path, rv);
		return -1;
	}
	if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED) {
		errbuf_printf(rd->err, rd->errlen, "cannot read '%s': deep images are not supported",
			rd->path);
		return -1;
	}
	rd->comp = comp;
	if (dwa_unsupported(comp)) {
		errbuf_printf(rd->err, rd->errlen, "cannot read '%s': %s compression needs OpenEXR "
			"3.2 or later (convert with 'oiiotool --compression zip')", rd->path,
			comp == EXR_COMPRESSION_DWAA ? "DWAA" : "DWAB");
		return -1;
	}
	w = (int64_t)dw.max.x - dw.min.x + 1;
	h = (int64_t)dw.max.y - dw.min.y + 1;
	if (w <= 0 || h <= 0 || w > INT_MAX || h > INT_MAX || !chl || chl->num_channels <= 0) {
		errbuf_printf(rd->err, rd->errlen, "cannot read '%s': empty data window or no channels",
			rd->path);
		return -1;
	}
	if (!stride_fits(w, chl->num_channels)) {
		errbuf_printf(rd->err, rd->errlen, "cannot read '%s': %lld pixels x %d channels "
			"per line is too many", rd->path, (long long)w, chl->num_channels);
		return -1;
	}
	if (rd->header) {
		rd->img->w = (int)w;
		rd->img->h = (int)h;
		return 0;
	}
	names = calloc((size_t)chl->num_channels, sizeof(*names));
	if (!names) {
		errbuf_printf(rd->err, rd->errlen, "cannot read '%s': out of memory", rd->path);
		return -1;
	}
	for (int c = 0; c < chl->num_channels; c++) {
		const exr_attr_chlist_entry_t *e = &chl->entries[c];

		if (e->x_sampling != 1 || e->y_sampling != 1) {
			errbuf_printf(rd->err, rd->errlen,
				"cannot read '%s': channel '%s' is subsampled, which is not supported",
				rd->path, e->name.str);
			goto out;
		}
		names[c] = e->name.str;
		/* channels are matched by name, so a damaged list must not repeat one */
		for (int k = 0; k < c; k++) {
			if (!strcmp(names[k], names[c])) {
				errbuf_printf(rd->err, rd->errlen,
					"cannot read '%s': channel '%s' appears twice",
					rd->path, names[c]);
				goto out;
			}
		}
	}
	if (rd->band && storage == EXR_STORAGE_SCANLINE) {
		int32_t lpc = 0;

		rv = exr_get_scanlines_per_chunk(rd->ctx, 0, &lpc);
		if (rv == EXR_ERR_SUCCESS && lpc <= 0)
			rv = EXR_ERR_INVALID_ATTR;
		if (rv != EXR_ERR_SUCCESS) {
			set_exr_err(rd->err, rd->errlen, "read", rd->path, rv);
			goto out;
		}
		int64_t y0 = rd->band_y0 < 0 ? 0 : rd->band_y0;
		int64_t y1 = rd->band_y1 >= h ? h - 1 : rd->band_y1;
		if (y0 > y1) {
			errbuf_printf(rd->err, rd->errlen, "cannot read rows %d..%d of '%s': it has "
				"%lld rows", rd->band_y0, rd->band_y1, rd->path, (long long)h);
			goto out;
		}
		y0 = y0 / lpc * lpc;
		y1 = (y1 / lpc + 1) * lpc - 1;
		if (y1 >= h)
			y1 = h - 1;
		rd->band_y0 = (int)y0;
		rd->band_y1 = (int)y1;
		h = y1 - y0 + 1;
	} else {
		rd->band = 0;
		rd->band_y0 = 0;
		rd->band_y1 = (int)h - 1;
	}
	if (image_init(rd->img, (int)w, (int)h, chl->num_channels, names, rd->err, rd->errlen)) {
		char why[200];

		snprintf(why, sizeof(why), "%s", rd->err ? rd->err : "");
		errbuf_printf(rd->err, rd->errlen, "cannot read '%s': %s", rd->path, why);
		goto out;
	}
	if (storage == EXR_STORAGE_SCANLINE)
		ret = read_scanlines(rd, &dw);
	else
		ret = read_tiles(rd);
out:
	free(names);
	return ret;
}

/* What read_exr() reads: the whole image, rows of it, or its size. */
enum { READ_ALL, READ_ROWS, READ_SIZE };

static int read_exr(const char *path, int what, int y0, int y1, struct image *out,
		    int *oy, char *err, size_t errlen);

int image_read_exr(const char *path, struct image *out, char *err, size_t errlen)
{
	return read_exr(path, READ_ALL, 0, 0, out, NULL, err, errlen);
}

int image_read_exr_rows(const char *path, int y0, int y1, struct image *out, int *oy,
			char *err, size_t errlen)
{
	return read_exr(path, READ_ROWS, y0, y1, out, oy, err, errlen);
}

int image_exr_size(const char *path, int *w, int *h, char *err, size_t errlen)
{
	struct image img;
	if (read_exr(path, READ_SIZE, 0, 0, &img, NULL, err, errlen))
		return -1;
	*w = img.w;
	*h = img.h;
	return 0;
}

static int read_exr(const char *path, int what, int y0, int y1, struct image *out,
		    int *oy, char *err, size_t errlen)
{
	exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
	struct exr_src src = { -1, 0 };
	struct reader rd;
	unsigned char magic[4];
	struct stat st;
	exr_result_t rv;
	ssize_t n;
	int ret = -1;

	memset(out, 0, sizeof(*out));
	memset(&rd, 0, sizeof(rd));
	rd.img = out;
	rd.path = path;
	rd.err = err;
	rd.errlen = errlen;
	rd.band = what == READ_ROWS;
	rd.header = what == READ_SIZE;
	rd.band_y0 = y0;
	rd.band_y1 = y1;

	src.fd = open(path, O_RDONLY | O_CLOEXEC);
	if (src.fd < 0) {
		errbuf_printf(err, errlen, "cannot open '%s': %s", path, strerror(errno));
		return -1;
	}
	if (fstat(src.fd, &st)) {
		errbuf_printf(err, errlen, "cannot read '%s': %s", path, strerror(errno));
		goto out;
	}
	if (S_ISDIR(st.st_mode)) {
		errbuf_printf(err, errlen, "cannot read '%s': %s", path, strerror(EISDIR));
		goto out;
	}
	/* -1 tells the library the size is unknown (a pipe); it then skips checks */
	src.size = S_ISREG(st.st_mode) ? (int64_t)st.st_size : -1;

	do
		n = pread(src.fd, magic, sizeof(magic), 0);
	while (n < 0 && errno == EINTR);
	if (n < 0) {
		errbuf_printf(err, errlen, "cannot read '%s': %s", path, strerror(errno));
		goto out;
	}
	if (n != (ssize_t)sizeof(magic) || memcmp(magic, exr_magic, sizeof(magic))) {
		errbuf_printf(err, errlen, "cannot read '%s': not an EXR file", path);
		goto out;
	}

	init.error_handler_fn = exr_msg_handler;
	init.user_data = &src;
	init.read_fn = src_read;
	init.size_fn = src_size;
	exr_msg_reset();
	rv = exr_start_read(&rd.ctx, path, &init);
	if (rv != EXR_ERR_SUCCESS) {
		rd.ctx = NULL;
		set_exr_err(err, errlen, "read", path, rv);
		goto out;
	}
	ret = read_part0(&rd);
	if (!ret && oy)
		*oy = rd.band_y0;
out:
	if (rd.started)
		exr_decoding_destroy(rd.ctx, &rd.dec);
	if (rd.ctx)
		exr_finish(&rd.ctx);
	close(src.fd);
	if (ret)
		image_release(out);
	return ret;
}

/* ------------------------------------------------------------------ */
/* writing */

struct exr_dst {
	int fd;
};

static int64_t dst_write(exr_const_context_t ctxt, void *userdata, const void *buffer,
			 uint64_t sz, uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
	const struct exr_dst *dst = userdata;
	const unsigned char *p = buffer;
	uint64_t done = 0;

	if (offset > (uint64_t)INT64_MAX - sz) {
		error_cb(ctxt, EXR_ERR_WRITE_IO, "write past the largest file offset");
		return -1;
	}
	while (done < sz) {
		size_t want = sz - done > (uint64_t)SSIZE_MAX ?
			(size_t)SSIZE_MAX : (size_t)(sz - done);
		ssize_t n = pwrite(dst->fd, p + done, want, (off_t)(offset + done));

		if (n < 0) {
			if (errno == EINTR)
				continue;
			error_cb(ctxt, EXR_ERR_WRITE_IO, "%s", strerror(errno));
			return -1;
		}
		if (n == 0) {
			error_cb(ctxt, EXR_ERR_WRITE_IO, "%s", strerror(EIO));
			return -1;
		}
		done += (uint64_t)n;
	}
	return (int64_t)done;
}

static int aim_encoder(exr_encode_pipeline_t *enc, const struct image *img, int y0)
{
	for (int c = 0; c < enc->channel_count; c++) {
		exr_coding_channel_info_t *ch = &enc->channels[c];
		int idx = image_channel(img, ch->channel_name);

		if (idx < 0)
			return -1;
		ch->encode_from_ptr = (const uint8_t *)(img->px +
			(size_t)y0 * (size_t)img->w * (size_t)img->nch + (size_t)idx);
		ch->user_pixel_stride = img->nch * (int32_t)sizeof(float);
		ch->user_line_stride = img->w * img->nch * (int32_t)sizeof(float);
		ch->user_bytes_per_element = (int16_t)sizeof(float);
		ch->user_data_type = EXR_PIXEL_FLOAT;
	}
	return 0;
}

/*
 * Chunks are compressed by several threads at once, each with its own
 * encode pipeline, and kept in memory; the file is then written in chunk
 * order by the calling thread.  OpenEXRCore leaves the scheduling of
 * multi-threaded writes to the caller (yield_until_ready_fn, write_fn): a
 * pipeline here never writes, it hands its compressed bytes to stash_chunk.
 */
struct chunk_data {
	void *data;
	size_t size;
};

struct encoder {
	exr_context_t ctx;
	const struct image *img;
	int lpc, nchunks, next;
	struct chunk_data *chunks;
	exr_result_t rv;
	pthread_mutex_t lock;
};

static exr_result_t ready_now(exr_encode_pipeline_t *enc)
{
	(void)enc;
	return EXR_ERR_SUCCESS;
}

static exr_result_t stash_chunk(exr_encode_pipeline_t *enc)
{
	struct chunk_data *cd = enc->encoding_user_data;
	cd->data = malloc(enc->compressed_bytes ? enc->compressed_bytes : 1);
	if (!cd->data)
		return EXR_ERR_OUT_OF_MEMORY;
	memcpy(cd->data, enc->compressed_buffer, enc->compressed_bytes);
	cd->size = enc->compressed_bytes;
	return EXR_ERR_SUCCESS;
}

static void *encode_chunks(void *arg)
{
	struct encoder *e = arg;
	exr_encode_pipeline_t enc;
	int started = 0;
	exr_result_t rv = EXR_ERR_SUCCESS;

	memset(&enc, 0, sizeof(enc));
	for (;;) {
		pthread_mutex_lock(&e->lock);
		int i = e->rv == EXR_ERR_SUCCESS ? e->next++ : e->nchunks;
		pthread_mutex_unlock(&e->lock);
		if (i >= e->nchunks)
			break;
		int y = i * e->lpc;
		exr_chunk_info_t ci;
		rv = exr_write_scanline_chunk_info(e->ctx, 0, y, &ci);
		if (rv == EXR_ERR_SUCCESS && !started) {
			rv = exr_encoding_initialize(e->ctx, 0, &ci, &enc);
			started = rv == EXR_ERR_SUCCESS;
			if (started && aim_encoder(&enc, e->img, y))
				rv = EXR_ERR_INVALID_ARGUMENT;
			else if (started)
				rv = exr_encoding_choose_default_routines(e->ctx, 0, &enc);
		} else if (rv == EXR_ERR_SUCCESS) {
			rv = exr_encoding_update(e->ctx, 0, &ci, &enc);
			if (rv == EXR_ERR_SUCCESS && aim_encoder(&enc, e->img, y))
				rv = EXR_ERR_INVALID_ARGUMENT;
		}
		if (rv == EXR_ERR_SUCCESS) {
			enc.yield_until_ready_fn = ready_now;
			enc.write_fn = stash_chunk;
			enc.encoding_user_data = &e->chunks[i];
			rv = exr_encoding_run(e->ctx, 0, &enc);
		}
		if (rv != EXR_ERR_SUCCESS) {
			pthread_mutex_lock(&e->lock);
			if (e->rv == EXR_ERR_SUCCESS)
				e->rv = rv;
			pthread_mutex_unlock(&e->lock);
			break;
		}
	}
	if (started)
		exr_encoding_destroy(e->ctx, &enc);
	return NULL;
}

/* Encode all of img into the context, whose header is complete but unwritten. */
static exr_result_t encode_image(exr_context_t ctx, const struct image *img)
{
	struct encoder e = { .ctx = ctx, .img = img };
	exr_result_t rv = exr_write_header(ctx);
	if (rv == EXR_ERR_SUCCESS)
		rv = exr_get_scanlines_per_chunk(ctx, 0, &e.lpc);
	if (rv == EXR_ERR_SUCCESS && e.lpc <= 0)
		rv = EXR_ERR_INVALID_ATTR;
	if (rv != EXR_ERR_SUCCESS)
		return rv;
	e.nchunks = (img->h + e.lpc - 1) / e.lpc;
	e.chunks = calloc((size_t)e.nchunks, sizeof *e.chunks);
	if (!e.chunks)
		return EXR_ERR_OUT_OF_MEMORY;
	pthread_mutex_init(&e.lock, NULL);

	long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
	int nth = ncpu < 1 ? 1 : ncpu > 16 ? 16 : (int)ncpu;
	if (nth > e.nchunks)
		nth = e.nchunks;
	pthread_t tid[16];
	int started = 0;
	for (; started < nth - 1; started++)
		if (pthread_create(&tid[started], NULL, encode_chunks, &e))
			break;
	encode_chunks(&e);   /* the calling thread works too */
	for (int i = 0; i < started; i++)
		pthread_join(tid[i], NULL);
	rv = e.rv;

	for (int i = 0; i < e.nchunks; i++) {
		if (rv == EXR_ERR_SUCCESS)
			rv = e.chunks[i].data ?
				exr_write_scanline_chunk(ctx, 0, i * e.lpc, e.chunks[i].data,
							 e.chunks[i].size) :
				EXR_ERR_INVALID_ARGUMENT;
		free(e.chunks[i].data);
	}
	free(e.chunks);
	pthread_mutex_destroy(&e.lock);
	return rv;
}

static int write_fd(int fd, const char *path, const struct image *img, exr_pixel_type_t type,
		    exr_compression_t comp, char *err, size_t errlen)
{
	exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
	struct exr_dst dst = { fd };
	exr_context_t ctx = NULL;
	int part = 0, longnames = 0;
	exr_result_t rv, frv;

	for (int c = 0; c < img->nch; c++) {
		if (!img->names[c][0] || image_channel(img, img->names[c]) != c) {
			errbuf_printf(err, errlen, "cannot write '%s': channel %d has an empty "
				"or repeated name '%s'", path, c, img->names[c]);
			return -1;
		}
		if (strlen(img->names[c]) > 31)
			longnames = 1;
	}

	init.error_handler_fn = exr_msg_handler;
	init.user_data = &dst;
	init.write_fn = dst_write;
	exr_msg_reset();
	rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
	if (rv != EXR_ERR_SUCCESS) {
		set_exr_err(err, errlen, "write", path, rv);
		return -1;
	}
	rv = exr_add_part(ctx, NULL, EXR_STORAGE_SCANLINE, &part);
	if (rv == EXR_ERR_SUCCESS && longnames)
		rv = exr_set_longname_support(ctx, 1);
	if (rv == EXR_ERR_SUCCESS)
		rv = exr_initialize_required_attr_simple(ctx, part, img->w, img->h, comp);
	/* zlib's fastest level: the default (4) took 15 to 37% longer for files
	 * about 1% smaller (160x120 and 320x240 images and error maps) */
	if (rv == EXR_ERR_SUCCESS && comp == EXR_COMPRESSION_ZIP)
		rv = exr_set_zip_compression_level(ctx, part, 1);
	/*
	 * The library keeps channels sorted by name, so the encoder's channel
	 * order need not be img's; aim_encoder() matches them by name.  The
	 * perceptual flag only steers lossy codecs; "logarithmic" is what
	 * OpenEXR's C++ library writes by default.
	 */
	for (int c = 0; rv == EXR_ERR_SUCCESS && c < img->nch; c++)
		rv = exr_add_channel(ctx, part, img->names[c], type,
				     EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
	if (rv == EXR_ERR_SUCCESS)
		rv = encode_image(ctx, img);
	/* exr_finish writes the chunk offset table, so it can fail too */
	frv = exr_finish(&ctx);
	if (rv == EXR_ERR_SUCCESS)
		rv = frv;
	if (rv != EXR_ERR_SUCCESS) {
		set_exr_err(err, errlen, "write", path, rv);
		return -1;
	}
	return 0;
}

/* The process umask, for giving the temporary file ordinary permissions. */
static mode_t current_umask(void)
{
	/*
	 * POSIX can only read the umask by setting it.  A file that another
	 * thread creates between these two calls gets umask 022 instead of
	 * the real one; povpress creates files from its main thread only.
	 */
	mode_t mask = umask(022);

	umask(mask);
	return mask;
}

static int write_exr(const char *path, const struct image *img, exr_pixel_type_t type,
		     exr_compression_t comp, char *err, size_t errlen)
{
	static const char suffix[] = ".tmp.XXXXXX";
	char *tmp;
	size_t len;
	int fd;

	if (!img || !img->px || !img->names || img->w <= 0 || img->h <= 0 || img->nch <= 0) {
		errbuf_printf(err, errlen, "cannot write '%s': empty image", path);
		return -1;
	}
	if (!stride_fits(img->w, img->nch)) {
		errbuf_printf(err, errlen, "cannot write '%s': %d pixels x %d channels per line "
			"is too many", path, img->w, img->nch);
		return -1;
	}
	len = strlen(path);
	tmp = malloc(len + sizeof(suffix));
	if (!tmp) {
		errbuf_printf(err, errlen, "cannot write '%s': out of memory", path);
		return -1;
	}
	memcpy(tmp, path, len);
	memcpy(tmp + len, suffix, sizeof(suffix));

	fd = mkstemp(tmp);
	if (fd < 0) {
		errbuf_printf(err, errlen, "cannot write '%s': %s", path, strerror(errno));
		free(tmp);
		return -1;
	}
	/* mkstemp makes the file 0600; an output image gets the usual 0666 & ~umask */
	if (fchmod(fd, 0666 & ~current_umask())) {
		errbuf_printf(err, errlen, "cannot write '%s': %s", path, strerror(errno));
		goto fail;
	}
	if (write_fd(fd, path, img, type, comp, err, errlen))
		goto fail;
	if (fsync(fd)) {
		errbuf_printf(err, errlen, "cannot write '%s': %s", path, strerror(errno));
		goto fail;
	}
	if (close(fd)) {
		fd = -1;
		errbuf_printf(err, errlen, "cannot write '%s': %s", path, strerror(errno));
		goto fail;
	}
	fd = -1;
	if (rename(tmp, path)) {
		errbuf_printf(err, errlen, "cannot rename '%s' to '%s': %s", tmp, path,
			strerror(errno));
		goto fail;
	}
	free(tmp);
	return 0;

fail:
	if (fd >= 0)
		close(fd);
	unlink(tmp);
	free(tmp);
	return -1;
}

/*
 * PIZ for wide images, ZIP at zlib's level 1 for narrow ones.  PIZ builds
 * its wavelet and Huffman tables per 32-row chunk, which a narrow chunk
 * does not repay.  CPU seconds a write (2026-11-23, float, 20 writes each):
 * 1920x1080 noise, 13 channels: PIZ 1.12 (91 MB), ZIP-1 2.64 (106 MB);
 * 1920x1440 RGB image: PIZ 0.63, ZIP-1 0.76; 640x480 RGB: PIZ 0.124,
 * ZIP-1 0.090 (3.0 MB against 2.8); a 640x480 error map (8 channels): PIZ
 * 0.183 (5.5 MB), ZIP-1 0.107 (4.2 MB); 160x120 RGB: PIZ 0.0105, ZIP-1
 * 0.0060; its error map: PIZ 0.0127, ZIP-1 0.0071.
 */
#define PIZ_MIN_WIDTH 1024
int image_write_exr(const char *path, const struct image *img, char *err, size_t errlen)
{
	return write_exr(path, img, EXR_PIXEL_FLOAT,
			 img->w >= PIZ_MIN_WIDTH ? EXR_COMPRESSION_PIZ : EXR_COMPRESSION_ZIP, err,
			 errlen);
}

int image_write_exr_raw(const char *path, const struct image *img, char *err, size_t errlen)
{
	return write_exr(path, img, EXR_PIXEL_FLOAT, EXR_COMPRESSION_NONE, err, errlen);
}

int image_write_exr_half(const char *path, const struct image *img, char *err, size_t errlen)
{
	return write_exr(path, img, EXR_PIXEL_HALF, EXR_COMPRESSION_PIZ, err, errlen);
}

/* ------------------------------------------------------------------ */

int image_rgb(const struct image *src, const char *what, struct image *out,
	      char *err, size_t errlen)
{
	static const char *const rgb[3] = { "R", "G", "B" };
	int idx[3];

	memset(out, 0, sizeof(*out));
	for (int k = 0; k < 3; k++)
		idx[k] = image_channel(src, rgb[k]);
	if (idx[0] < 0 || idx[1] < 0 || idx[2] < 0) {
		int y = image_channel(src, "Y");

		if (y < 0) {
			errbuf_printf(err, errlen, "'%s' has no colour channels (needs R, G and B, or Y)", what);
			return -1;
		}
		idx[0] = idx[1] = idx[2] = y;
	}
	if (image_init(out, src->w, src->h, 3, rgb, err, errlen))
		return -1;
	for (size_t i = 0, n = (size_t)src->w * (size_t)src->h; i < n; i++) {
		const float *s = src->px + i * (size_t)src->nch;
		float *d = out->px + i * 3;

		d[0] = s[idx[0]];
		d[1] = s[idx[1]];
		d[2] = s[idx[2]];
	}
	return 0;
}
