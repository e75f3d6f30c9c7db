/*
 * test_image.c - unit tests for driver/image.c (EXR input and output).
 *
 * Files go in a fresh mkdtemp() directory that is removed at the end.
 * Some tests make their input with oiiotool or povray, so both must be
 * installed; a missing tool fails the test rather than skipping it.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "driver/image.h"
#include "tests/testutil.h"


static int setup_dir(void **state)
{
	(void)state;
	snprintf(scratch_dir, sizeof(scratch_dir), "/tmp/povpress-test-image.XXXXXX");
	if (!mkdtemp(scratch_dir))
		return -1;
	return 0;
}

static int teardown_dir(void **state)
{
	(void)state;
	return run("rm -rf '%s'", scratch_dir) == 0 ? 0 : -1;
}

static uint32_t float_bits(float f)
{
	uint32_t u;

	memcpy(&u, &f, sizeof(u));
	return u;
}

static float bits_float(uint32_t u)
{
	float f;

	memcpy(&f, &u, sizeof(f));
	return f;
}

/*
 * A w x h image with the given channels, holding smooth values with a few
 * awkward ones (NaN with a payload, infinities, -0, a denormal, FLT_MAX)
 * sprinkled in when specials is set.
 */
static void make_image(struct image *img, int w, int h, int nch, const char *const *names,
		       int specials)
{
	char err[256];

	assert_int_equal(image_init(img, w, h, nch, names, err, sizeof(err)), 0);
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++)
			for (int c = 0; c < nch; c++)
				img->px[((size_t)y * w + x) * nch + c] =
					(float)(0.5 + 0.4 * sin(0.37 * x + 1.3 * c) *
						cos(0.23 * y) + 0.01 * c);
	if (specials) {
		static const uint32_t odd[] = {
			0x7fc00001u,	/* quiet NaN, payload 1 */
			0xffc12345u,	/* negative NaN with payload */
			0x7f800000u,	/* +inf */
			0xff800000u,	/* -inf */
			0x80000000u,	/* -0 */
			0x00000001u,	/* smallest denormal */
			0x7f7fffffu,	/* FLT_MAX */
		};
		size_t n = (size_t)w * h * nch;

		for (size_t k = 0; k < sizeof(odd) / sizeof(odd[0]); k++)
			img->px[(k * 97 + 5) % n] = bits_float(odd[k]);
	}
}

/* Every channel of want is in got, with the same bits at every pixel. */
static void assert_same_pixels(const struct image *got, const struct image *want)
{
	assert_int_equal(got->w, want->w);
	assert_int_equal(got->h, want->h);
	assert_int_equal(got->nch, want->nch);
	for (int c = 0; c < want->nch; c++) {
		int gc = image_channel(got, want->names[c]);

		assert_true(gc >= 0);
		for (size_t i = 0; i < (size_t)want->w * want->h; i++) {
			uint32_t g = float_bits(got->px[i * got->nch + gc]);
			uint32_t e = float_bits(want->px[i * want->nch + c]);

			if (g != e)
				fail_msg("channel %s pixel %zu: got 0x%08x, want 0x%08x",
					 want->names[c], i, (unsigned)g, (unsigned)e);
		}
	}
}

static void assert_names(const struct image *img, const char *const *names, int n)
{
	assert_int_equal(img->nch, n);
	for (int c = 0; c < n; c++)
		assert_string_equal(img->names[c], names[c]);
}

static void assert_err_names(const char *err, const char *path)
{
	if (!strstr(err, path))
		fail_msg("message \"%s\" does not name '%s'", err, path);
}

static const char *const rgb_names[] = { "R", "G", "B" };
static const char *const bgr_names[] = { "B", "G", "R" };

/* ------------------------------------------------------------------ */

static void test_init_release_channel(void **state)
{
	static const char *const names[] = { "R", "G", "B", "depth.Z" };
	struct image img;
	char err[256];
	char name[8] = "R";
	const char *mutable_names[] = { name };

	(void)state;
	err[0] = '\0';
	assert_int_equal(image_init(&img, 0, 4, 3, names, err, sizeof(err)), -1);
	assert_true(err[0] != '\0');
	assert_zeroed(&img);
	assert_int_equal(image_init(&img, 4, -1, 3, names, err, sizeof(err)), -1);
	assert_int_equal(image_init(&img, 4, 4, 0, names, err, sizeof(err)), -1);
	assert_int_equal(image_init(&img, INT_MAX, INT_MAX, INT_MAX, names, err, sizeof(err)), -1);
	assert_zeroed(&img);

	assert_int_equal(image_init(&img, 5, 3, 4, names, err, sizeof(err)), 0);
	assert_int_equal(img.w, 5);
	assert_int_equal(img.h, 3);
	assert_int_equal(img.nch, 4);
	for (int i = 0; i < 5 * 3 * 4; i++)
		assert_true(img.px[i] == 0.0f);
	assert_names(&img, names, 4);
	assert_ptr_not_equal(img.names[0], names[0]);
	assert_int_equal(image_channel(&img, "R"), 0);
	assert_int_equal(image_channel(&img, "depth.Z"), 3);
	assert_int_equal(image_channel(&img, "A"), -1);
	assert_int_equal(image_channel(&img, "r"), -1);
	image_release(&img);
	assert_zeroed(&img);
	image_release(&img);	/* a released image can be released again */
	image_release(NULL);

	/* names are copied, not borrowed */
	assert_int_equal(image_init(&img, 1, 1, 1, mutable_names, err, sizeof(err)), 0);
	name[0] = 'X';
	assert_string_equal(img.names[0], "R");
	image_release(&img);
}

static void test_float_round_trip(void **state)
{
	struct image img, got;
	char path[256], err[512];

	(void)state;
	/* 37 x 23: neither a multiple of PIZ's 32-line chunks nor square */
	make_image(&img, 37, 23, 3, rgb_names, 1);
	scratch(path, sizeof(path), "float.exr");
	assert_int_equal(image_write_exr(path, &img, err, sizeof(err)), 0);
	assert_int_equal(count_entries(scratch_dir, ".tmp."), 0);

	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	/* OpenEXR stores channels sorted by name */
	assert_names(&got, bgr_names, 3);
	assert_same_pixels(&got, &img);
	image_release(&got);

	/* written as float, ZIP (narrow), scanline: ask an independent reader */
	assert_int_equal(run("iinfo -v '%s' | grep -q '37 x   23, 3 channel, float openexr'",
			     path), 0);
	assert_int_equal(run("iinfo -v '%s' | grep -q 'compression: \"zip\"'", path), 0);
	assert_int_equal(run("iinfo -v '%s' | grep -q 'tile size'", path), 1);
	image_release(&img);

	/* 1024 wide and more: PIZ, and the same floats back */
	make_image(&img, 1024, 3, 3, rgb_names, 1);
	assert_int_equal(image_write_exr(path, &img, err, sizeof(err)), 0);
	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	assert_same_pixels(&got, &img);
	image_release(&got);
	assert_int_equal(run("iinfo -v '%s' | grep -q 'compression: \"piz\"'", path), 0);
	image_release(&img);
}

/* More channels than OpenEXRCore's five-entry quick store, in unsorted order. */
static void test_many_channels_round_trip(void **state)
{
	static const char *const names[] = { "Z", "R", "albedo.G", "A", "G", "B", "N.x" };
	static const char *const sorted[] = { "A", "B", "G", "N.x", "R", "Z", "albedo.G" };
	struct image img, got;
	char path[256], err[512];

	(void)state;
	make_image(&img, 19, 40, 7, names, 1);
	scratch(path, sizeof(path), "many.exr");
	assert_int_equal(image_write_exr(path, &img, err, sizeof(err)), 0);
	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	assert_names(&got, sorted, 7);
	assert_same_pixels(&got, &img);
	image_release(&got);
	image_release(&img);
}

static void test_overwrite_replaces_file(void **state)
{
	struct image a, b, got;
	char path[256], err[512];
	struct stat st;
	mode_t old = umask(022);

	(void)state;
	make_image(&a, 8, 8, 3, rgb_names, 0);
	make_image(&b, 12, 5, 3, rgb_names, 1);
	scratch(path, sizeof(path), "over.exr");
	assert_int_equal(image_write_exr(path, &a, err, sizeof(err)), 0);
	assert_int_equal(image_write_exr(path, &b, err, sizeof(err)), 0);
	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	assert_same_pixels(&got, &b);
	assert_int_equal(count_entries(scratch_dir, ".tmp."), 0);
	/* an ordinary file, not mkstemp's 0600 */
	assert_int_equal(stat(path, &st), 0);
	assert_int_equal(st.st_mode & 0777, 0644);
	umask(old);
	image_release(&got);
	image_release(&a);
	image_release(&b);
}

static void test_half_read(void **state)
{
	struct image img, got;
	char path[256], err[512];
	int changed = 0;

	(void)state;
	make_image(&img, 33, 17, 3, rgb_names, 0);
	scratch(path, sizeof(path), "half.exr");
	assert_int_equal(image_write_exr_half(path, &img, err, sizeof(err)), 0);
	assert_int_equal(run("iinfo '%s' | grep -q 'half openexr'", path), 0);

	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	assert_int_equal(got.w, 33);
	assert_int_equal(got.h, 17);
	assert_names(&got, bgr_names, 3);
	for (int c = 0; c < 3; c++) {
		int gc = image_channel(&got, rgb_names[c]);

		for (size_t i = 0; i < (size_t)33 * 17; i++) {
			float want = img.px[i * 3 + c], have = got.px[i * 3 + gc];

			/* half keeps 11 significant bits: rounding error <= 2^-11 relative */
			if (fabsf(have - want) > ldexpf(fabsf(want), -11))
				fail_msg("channel %s pixel %zu: got %.9g, want %.9g",
					 rgb_names[c], i, have, want);
			changed += have != want;
		}
	}
	assert_true(changed > 0);	/* really stored as half */
	image_release(&got);
	image_release(&img);
}

static void test_tiled_read(void **state)
{
	struct image img, got;
	char src[256], path[256], err[512];

	(void)state;
	/* 70 x 45: partial tiles on the right and at the bottom */
	make_image(&img, 70, 45, 3, rgb_names, 1);
	scratch(src, sizeof(src), "tsrc.exr");
	scratch(path, sizeof(path), "tiled.exr");
	assert_int_equal(image_write_exr(src, &img, err, sizeof(err)), 0);
	assert_int_equal(run("oiiotool '%s' --tile 32 32 -o '%s'", src, path), 0);
	assert_int_equal(run("iinfo -v '%s' | grep -q 'tile size: 32 x 32'", path), 0);

	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	assert_same_pixels(&got, &img);
	image_release(&got);
	image_release(&img);
}

static void test_tiled_half_piz_read(void **state)
{
	struct image img, half, got;
	char src[256], hpath[256], path[256], err[512];

	(void)state;
	make_image(&img, 50, 30, 3, rgb_names, 0);
	scratch(src, sizeof(src), "thsrc.exr");
	scratch(hpath, sizeof(hpath), "thref.exr");
	scratch(path, sizeof(path), "tiledhalf.exr");
	assert_int_equal(image_write_exr_half(src, &img, err, sizeof(err)), 0);
	assert_int_equal(image_read_exr(src, &half, err, sizeof(err)), 0);
	assert_int_equal(run("oiiotool '%s' --tile 16 16 --compression piz -o '%s'",
			     src, path), 0);
	assert_int_equal(run("iinfo -v '%s' | grep -q 'tile size: 16 x 16'", path), 0);
	assert_int_equal(run("iinfo '%s' | grep -q 'half openexr'", path), 0);

	/* same halves, different layout and compression: identical floats */
	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	assert_same_pixels(&got, &half);
	image_release(&got);
	image_release(&half);
	image_release(&img);
}

static void test_mipmap_read_level0(void **state)
{
	struct image img, got;
	char src[256], path[256], err[512];

	(void)state;
	make_image(&img, 70, 45, 3, rgb_names, 0);
	scratch(src, sizeof(src), "msrc.exr");
	scratch(path, sizeof(path), "mip.exr");
	assert_int_equal(image_write_exr(src, &img, err, sizeof(err)), 0);
	assert_int_equal(run("oiiotool '%s' -otex '%s'", src, path), 0);
	assert_int_equal(run("iinfo -v '%s' | grep -q 'MIP-map levels: 70x45 35x22'", path), 0);

	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	assert_same_pixels(&got, &img);
	image_release(&got);
	image_release(&img);
}

static void test_multipart_reads_part0(void **state)
{
	static const char *const other[] = { "R", "G", "B", "A" };
	struct image a, b, got;
	char pa[256], pb[256], path[256], err[512];

	(void)state;
	make_image(&a, 24, 20, 3, rgb_names, 1);
	make_image(&b, 24, 20, 4, other, 0);
	for (size_t i = 0; i < (size_t)24 * 20 * 4; i++)
		b.px[i] += 3.0f;
	scratch(pa, sizeof(pa), "parta.exr");
	scratch(pb, sizeof(pb), "partb.exr");
	scratch(path, sizeof(path), "multi.exr");
	assert_int_equal(image_write_exr(pa, &a, err, sizeof(err)), 0);
	assert_int_equal(image_write_exr(pb, &b, err, sizeof(err)), 0);
	assert_int_equal(run("oiiotool '%s' '%s' --siappend -o '%s'", pa, pb, path), 0);
	assert_int_equal(run("iinfo -v '%s' | grep -q '2 subimages'", path), 0);

	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	assert_same_pixels(&got, &a);
	image_release(&got);
	image_release(&a);
	image_release(&b);
}

static void test_data_window_offset(void **state)
{
	struct image img, got;
	char src[256], path[256], err[512];

	(void)state;
	make_image(&img, 40, 21, 3, rgb_names, 0);
	scratch(src, sizeof(src), "osrc.exr");
	scratch(path, sizeof(path), "origin.exr");
	assert_int_equal(image_write_exr(src, &img, err, sizeof(err)), 0);
	assert_int_equal(run("oiiotool '%s' --origin +10+5 -o '%s'", src, path), 0);
	assert_int_equal(run("iinfo -v '%s' | grep -q 'pixel data origin: x=10, y=5'", path), 0);

	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	assert_same_pixels(&got, &img);
	/* the size alone, from the header: the data window's */
	int w = 0, h = 0;
	assert_int_equal(image_exr_size(path, &w, &h, err, sizeof(err)), 0);
	assert_int_equal(w, 40);
	assert_int_equal(h, 21);
	image_release(&got);
	image_release(&img);
}

static void test_other_compressions(void **state)
{
	static const char *const lossless[] = { "none", "rle", "zips", "piz", "b44", "b44a" };
	struct image img, got;
	char src[256], path[256], err[512];

	(void)state;
	make_image(&img, 45, 37, 3, rgb_names, 1);
	scratch(src, sizeof(src), "csrc.exr");
	assert_int_equal(image_write_exr(src, &img, err, sizeof(err)), 0);
	/*
	 * b44 only compresses half channels, so these float chunks are stored
	 * raw (OpenEXRCore 3.1 used to mangle them; see image.c)
	 */
	for (size_t k = 0; k < sizeof(lossless) / sizeof(lossless[0]); k++) {
		char name[64];

		snprintf(name, sizeof(name), "c_%s.exr", lossless[k]);
		scratch(path, sizeof(path), name);
		assert_int_equal(run("oiiotool '%s' --compression %s -o '%s'",
				     src, lossless[k], path), 0);
		assert_int_equal(run("iinfo -v '%s' | grep -q 'compression: \"%s\"'",
				     path, lossless[k]), 0);
		assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
		assert_same_pixels(&got, &img);
		image_release(&got);
	}
	image_release(&img);

	/* pxr24 rounds floats to 24 bits */
	make_image(&img, 45, 37, 3, rgb_names, 0);
	assert_int_equal(image_write_exr(src, &img, err, sizeof(err)), 0);
	scratch(path, sizeof(path), "c_pxr24.exr");
	assert_int_equal(run("oiiotool '%s' --compression pxr24 -o '%s'", src, path), 0);
	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	for (int c = 0; c < 3; c++) {
		int gc = image_channel(&got, rgb_names[c]);

		assert_true(gc >= 0);
		for (size_t i = 0; i < (size_t)45 * 37; i++)
			assert_true(fabsf(got.px[i * 3 + gc] - img.px[i * 3 + c]) <=
				    ldexpf(fabsf(img.px[i * 3 + c]), -15));
	}
	image_release(&got);
	image_release(&img);
}

/*
 * Lossy and mixed-type files: OpenImageIO's own decoder (the C++ OpenEXR
 * library) converts each to a float ZIP file, which must hold exactly the
 * floats we decode ourselves.
 */
static void test_decoding_matches_oiio(void **state)
{
	static const char *const variants[] = {
		"-d half --compression b44",
		"-d half --compression b44a --tile 16 8",
		"-d half --compression pxr24",
		"-d float --compression pxr24 --tile 16 16",
		"-d float -d G=half --compression piz",
		"-d float -d G=half --compression b44",
		"-d float -d G=half --compression rle --tile 8 8",
	};
	struct image img, got, want;
	char src[256], path[256], ref[256], err[512];

	(void)state;
	make_image(&img, 37, 29, 3, rgb_names, 0);
	scratch(src, sizeof(src), "lsrc.exr");
	scratch(path, sizeof(path), "lossy.exr");
	scratch(ref, sizeof(ref), "lossy_ref.exr");
	assert_int_equal(image_write_exr(src, &img, err, sizeof(err)), 0);
	for (size_t k = 0; k < sizeof(variants) / sizeof(variants[0]); k++) {
		assert_int_equal(run("oiiotool '%s' %s -o '%s'", src, variants[k], path), 0);
		assert_int_equal(run("oiiotool '%s' -d float --compression zip -o '%s'",
				     path, ref), 0);
		assert_int_equal(image_read_exr(ref, &want, err, sizeof(err)), 0);
		if (image_read_exr(path, &got, err, sizeof(err)))
			fail_msg("%s: %s", variants[k], err);
		assert_same_pixels(&got, &want);
		image_release(&got);
		image_release(&want);
	}
	image_release(&img);
}

static void test_uint_read(void **state)
{
	struct image img, got;
	char src[256], path[256], err[512];

	(void)state;
	make_image(&img, 20, 18, 3, rgb_names, 0);
	scratch(src, sizeof(src), "usrc.exr");
	scratch(path, sizeof(path), "uint.exr");
	assert_int_equal(image_write_exr(src, &img, err, sizeof(err)), 0);
	/* oiiotool scales [0, 1] to the full uint32 range */
	assert_int_equal(run("oiiotool '%s' -d uint32 -o '%s'", src, path), 0);
	assert_int_equal(run("iinfo '%s' | grep -q 'uint openexr'", path), 0);

	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	for (int c = 0; c < 3; c++) {
		int gc = image_channel(&got, rgb_names[c]);

		assert_true(gc >= 0);
		for (size_t i = 0; i < (size_t)20 * 18; i++) {
			double want = img.px[i * 3 + c] * 4294967295.0;

			assert_true(fabs(got.px[i * 3 + gc] - want) <= want * 1e-6 + 1.0);
		}
	}
	image_release(&got);
	image_release(&img);
}

static void test_povray_render(void **state)
{
	static const char scene[] =
		"camera { location <0, 1, -3> look_at <0, 0, 0> }\n"
		"light_source { <2, 4, -3> color rgb 1 }\n"
		"sphere { <0, 0, 0>, 1 pigment { color rgb <1, 0.5, 0.2> } }\n"
		"plane { y, -1 pigment { checker color rgb 1 color rgb 0.2 } }\n";
	struct image got;
	char pov[256], path[256], log[256], err[512];
	double sum[3] = { 0, 0, 0 };
	FILE *f;

	(void)state;
	scratch(pov, sizeof(pov), "scene.pov");
	scratch(path, sizeof(path), "render.exr");
	scratch(log, sizeof(log), "povray.log");
	f = fopen(pov, "w");
	assert_non_null(f);
	assert_true(fputs(scene, f) >= 0);
	assert_int_equal(fclose(f), 0);
	if (run("povray -D -GA +W16 +H12 +FE '+O%s' '+I%s' >'%s' 2>&1", path, pov, log))
		fail_msg("povray failed; see %s", log);

	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	assert_int_equal(got.w, 16);
	assert_int_equal(got.h, 12);
	assert_names(&got, bgr_names, 3);
	for (size_t i = 0; i < (size_t)16 * 12; i++) {
		for (int c = 0; c < 3; c++) {
			float v = got.px[i * 3 + image_channel(&got, rgb_names[c])];

			assert_true(isfinite(v) && v >= 0.0f);
			sum[c] += v;
		}
	}
	/* an orange sphere on a grey floor: lit, and redder than blue */
	assert_true(sum[0] > 1.0);
	assert_true(sum[0] > sum[2]);
	image_release(&got);
}

static void test_missing_file(void **state)
{
	struct image got;
	char path[256], err[512];

	(void)state;
	scratch(path, sizeof(path), "no-such-file.exr");
	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), -1);
	assert_err_names(err, path);
	assert_non_null(strstr(err, "cannot open"));
	assert_non_null(strstr(err, strerror(ENOENT)));
	assert_zeroed(&got);
	int w, h;
	err[0] = '\0';
	assert_int_equal(image_exr_size(path, &w, &h, err, sizeof(err)), -1);
	assert_non_null(strstr(err, "cannot open"));
}

static void test_not_exr(void **state)
{
	struct image got;
	char path[256], err[512];
	FILE *f;

	(void)state;
	scratch(path, sizeof(path), "text.exr");
	f = fopen(path, "w");
	assert_non_null(f);
	fputs("P3\n1 1\n255\n0 0 0\n", f);
	assert_int_equal(fclose(f), 0);
	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), -1);
	assert_err_names(err, path);
	assert_non_null(strstr(err, "not an EXR file"));
	assert_zeroed(&got);

	/* empty */
	f = fopen(path, "w");
	assert_non_null(f);
	assert_int_equal(fclose(f), 0);
	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), -1);
	assert_err_names(err, path);
	assert_zeroed(&got);

	/* a directory */
	assert_int_equal(image_read_exr(scratch_dir, &got, err, sizeof(err)), -1);
	assert_err_names(err, scratch_dir);
	assert_zeroed(&got);
}

/*
 * Write a file, cut it to `keep` bytes (half when keep is 0, all but -keep
 * bytes when keep is negative), expect failure.
 */
static void check_truncated(const char *name, const char *tool_args, off_t keep)
{
	struct image img, got;
	char src[256], path[256], err[512];
	struct stat st;

	make_image(&img, 64, 64, 3, rgb_names, 0);
	scratch(src, sizeof(src), "trsrc.exr");
	scratch(path, sizeof(path), name);
	assert_int_equal(image_write_exr(src, &img, err, sizeof(err)), 0);
	if (tool_args)
		assert_int_equal(run("oiiotool '%s' %s -o '%s'", src, tool_args, path), 0);
	else
		assert_int_equal(rename(src, path), 0);
	/* the intact file reads */
	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	image_release(&got);

	assert_int_equal(stat(path, &st), 0);
	assert_int_equal(truncate(path, keep > 0 ? keep : keep < 0 ? st.st_size + keep :
				  st.st_size / 2), 0);
	err[0] = '\0';
	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), -1);
	assert_err_names(err, path);
	assert_zeroed(&got);
	image_release(&img);
}

static void test_truncated_scanline(void **state)
{
	(void)state;
	check_truncated("trunc_zip.exr", NULL, 0);
}

static void test_truncated_uncompressed(void **state)
{
	(void)state;
	/* uncompressed chunks are read with short reads allowed */
	check_truncated("trunc_none.exr", "--compression none", 0);
	/* only the end of the last chunk missing: must not come back zero-filled */
	check_truncated("trunc_none_tail.exr", "--compression none", -10);
}

static void test_truncated_tiled(void **state)
{
	(void)state;
	check_truncated("trunc_tiled.exr", "--tile 16 16", 0);
}

static void test_truncated_header(void **state)
{
	(void)state;
	check_truncated("trunc_header.exr", NULL, 100);
}

/* OpenEXRCore's default error handler prints to stderr; ours must not. */
static void test_failures_print_nothing(void **state)
{
	struct image img, got;
	char path[256], bad[256], log[256], err[512];
	struct stat st;
	int saved, fd;

	(void)state;
	make_image(&img, 40, 40, 3, rgb_names, 0);
	scratch(path, sizeof(path), "quiet.exr");
	scratch(bad, sizeof(bad), "no-dir/quiet.exr");
	scratch(log, sizeof(log), "stderr.log");
	assert_int_equal(image_write_exr(path, &img, err, sizeof(err)), 0);
	assert_int_equal(stat(path, &st), 0);
	assert_int_equal(truncate(path, st.st_size * 2 / 3), 0);

	fflush(stderr);
	saved = dup(2);
	assert_true(saved >= 0);
	fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0600);
	assert_true(fd >= 0);
	assert_int_equal(dup2(fd, 2), 2);
	close(fd);

	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), -1);
	assert_int_equal(truncate(path, 300), 0);
	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), -1);
	assert_int_equal(image_write_exr(bad, &img, err, sizeof(err)), -1);

	fflush(stderr);
	assert_int_equal(dup2(saved, 2), 2);
	close(saved);
	assert_int_equal(stat(log, &st), 0);
	assert_int_equal(st.st_size, 0);
	image_release(&img);
}

static void test_write_to_missing_dir(void **state)
{
	struct image img;
	char dir[256], path[256], err[512];
	struct stat st;

	(void)state;
	make_image(&img, 10, 10, 3, rgb_names, 0);
	scratch(dir, sizeof(dir), "missing");
	scratch(path, sizeof(path), "missing/out.exr");
	err[0] = '\0';
	assert_int_equal(image_write_exr(path, &img, err, sizeof(err)), -1);
	assert_err_names(err, path);
	assert_non_null(strstr(err, strerror(ENOENT)));
	assert_int_equal(stat(path, &st), -1);
	assert_int_equal(stat(dir, &st), -1);
	image_release(&img);
}

/* A failure after the temporary file exists must remove it. */
static void test_failed_write_leaves_no_temp(void **state)
{
	static const char *const dup_names[] = { "R", "G", "R" };
	struct image img;
	char path[256], err[512];
	struct stat st;

	(void)state;
	/* the target is a directory: everything works until rename() */
	scratch(path, sizeof(path), "target-dir.exr");
	assert_int_equal(mkdir(path, 0755), 0);
	make_image(&img, 10, 10, 3, rgb_names, 0);
	err[0] = '\0';
	assert_int_equal(image_write_exr(path, &img, err, sizeof(err)), -1);
	assert_err_names(err, path);
	assert_int_equal(count_entries(scratch_dir, ".tmp."), 0);
	assert_int_equal(stat(path, &st), 0);
	assert_true(S_ISDIR(st.st_mode));
	image_release(&img);

	/* repeated channel names fail inside the encoder setup */
	make_image(&img, 10, 10, 3, dup_names, 0);
	scratch(path, sizeof(path), "dup.exr");
	assert_int_equal(image_write_exr(path, &img, err, sizeof(err)), -1);
	assert_err_names(err, path);
	assert_int_equal(stat(path, &st), -1);
	assert_int_equal(count_entries(scratch_dir, ".tmp."), 0);
	image_release(&img);
}

static void test_rgb(void **state)
{
	static const char *const rgba[] = { "R", "G", "B", "A" };
	static const char *const z[] = { "Z" };
	static const char *const y[] = { "Y", "A" };
	struct image src, rgb, got;
	char path[256], err[512];

	(void)state;
	/* RGBA from a file (stored A, B, G, R) comes out as R, G, B */
	make_image(&src, 9, 7, 4, rgba, 0);
	scratch(path, sizeof(path), "rgba.exr");
	assert_int_equal(image_write_exr(path, &src, err, sizeof(err)), 0);
	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	assert_int_equal(image_rgb(&got, path, &rgb, err, sizeof(err)), 0);
	assert_names(&rgb, rgb_names, 3);
	assert_int_equal(rgb.w, 9);
	assert_int_equal(rgb.h, 7);
	for (size_t i = 0; i < (size_t)9 * 7; i++)
		for (int c = 0; c < 3; c++)
			assert_true(float_bits(rgb.px[i * 3 + c]) ==
				    float_bits(src.px[i * 4 + c]));
	image_release(&rgb);
	image_release(&got);
	image_release(&src);

	/* a lone Y goes to all three */
	make_image(&src, 4, 3, 2, y, 0);
	assert_int_equal(image_rgb(&src, "lum.exr", &rgb, err, sizeof(err)), 0);
	for (size_t i = 0; i < (size_t)4 * 3; i++)
		for (int c = 0; c < 3; c++)
			assert_true(rgb.px[i * 3 + c] == src.px[i * 2]);
	image_release(&rgb);
	image_release(&src);

	/* no colour channels: the message names the file */
	make_image(&src, 6, 6, 1, z, 0);
	scratch(path, sizeof(path), "nocolour.exr");
	assert_int_equal(image_write_exr(path, &src, err, sizeof(err)), 0);
	image_release(&src);
	assert_int_equal(image_read_exr(path, &got, err, sizeof(err)), 0);
	err[0] = '\0';
	assert_int_equal(image_rgb(&got, path, &rgb, err, sizeof(err)), -1);
	assert_err_names(err, path);
	assert_zeroed(&rgb);
	image_release(&got);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_init_release_channel),
		cmocka_unit_test(test_float_round_trip),
		cmocka_unit_test(test_many_channels_round_trip),
		cmocka_unit_test(test_overwrite_replaces_file),
		cmocka_unit_test(test_half_read),
		cmocka_unit_test(test_tiled_read),
		cmocka_unit_test(test_tiled_half_piz_read),
		cmocka_unit_test(test_mipmap_read_level0),
		cmocka_unit_test(test_multipart_reads_part0),
		cmocka_unit_test(test_data_window_offset),
		cmocka_unit_test(test_other_compressions),
		cmocka_unit_test(test_decoding_matches_oiio),
		cmocka_unit_test(test_uint_read),
		cmocka_unit_test(test_povray_render),
		cmocka_unit_test(test_missing_file),
		cmocka_unit_test(test_not_exr),
		cmocka_unit_test(test_truncated_scanline),
		cmocka_unit_test(test_truncated_uncompressed),
		cmocka_unit_test(test_truncated_tiled),
		cmocka_unit_test(test_truncated_header),
		cmocka_unit_test(test_failures_print_nothing),
		cmocka_unit_test(test_write_to_missing_dir),
		cmocka_unit_test(test_failed_write_leaves_no_temp),
		cmocka_unit_test(test_rgb),
	};

	return cmocka_run_group_tests(tests, setup_dir, teardown_dir);
}
