/*
 * povstate.h - the pixels of a POV-Ray 3.7 render that was stopped, read
 * from the render state file it leaves beside its output.
 *
 * POV-Ray renders a frame in blocks (32 x 32 pixels unless +BS says
 * otherwise) and, while it renders to a file, appends each finished block
 * to "<output without its extension>.pov-state" so that +C can continue
 * the render.  A render that ends normally removes the file; one that is
 * cancelled (SIGTERM, SIGINT) writes no image but leaves the file, which
 * then holds every block it finished.
 *
 * The file is a header ("POV-Ray Render State File", then POV-Ray's
 * options) followed by one POVMS message a block: "POVRAYMS", then
 * attributes, each a four-character key, a four-character type, a
 * big-endian 32-bit count and the values, big-endian.  A block's message
 * has its pixels under "PBlo" (type "VFL4": five floats a pixel, red,
 * green, blue, filter and transmit, in rows from its top left) and its
 * place under "Left", "Top ", "Righ" and "Bott" (type "INT4": 0-based
 * pixels of the frame, inclusive).  The colours are the render's, linear,
 * as POV-Ray writes them to an OpenEXR file (which holds them as halves).
 * Only those attributes are read; a message cut short at the file's end (a
 * render killed while it wrote) is left out, as is any block whose size
 * does not match its pixels or that lies outside the frame.
 */
#ifndef POVPRESS_POVSTATE_H
#define POVPRESS_POVSTATE_H

#include <stddef.h>

#include "driver/image.h"

/*
 * The state file of a render to `output` (its name with the extension cut
 * and ".pov-state" put on, as POV-Ray names it), into buf (len bytes);
 * -1 when it does not fit.
 */
int pov_state_path(const char *output, char *buf, size_t len);

/*
 * Read the blocks of the state file at path, of a render of a w x h frame,
 * whose rows y0 to y1 (inclusive) are wanted, into *out: an image w wide of
 * rows y0 to y1 with R, G and B channels, *oy = y0, where every pixel no
 * block gave is NaN.  *pixels counts those the blocks gave (each once).
 * Returns 0; -1 when the file cannot be read or is not a render state file
 * (the message in err), *out then zeroed.  A file with no whole block is
 * not an error: every pixel is NaN and *pixels is 0.
 */
int pov_state_read(const char *path, int w, int h, int y0, int y1, struct image *out, int *oy,
		   long *pixels, char *err, size_t errlen);

/*
 * The same from the len bytes at data (name, for messages, says whence).
 */
int pov_state_parse(const unsigned char *data, size_t len, const char *name, int w, int h,
		    int y0, int y1, struct image *out, int *oy, long *pixels, char *err,
		    size_t errlen);

#endif
