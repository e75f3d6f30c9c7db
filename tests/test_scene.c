/*
 * test_scene.c - unit tests for driver/scene.c: what povpress reads from a
 * scene file's text (assumed_gamma, focal blur's keywords, radiosity)
 * outside comments and strings, and the file's errors.
 */
#define _XOPEN_SOURCE 700	/* mkstemp */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "driver/scene.h"

static struct scene_keys scan(const char *text)
{
	struct scene_keys k;
	scene_keys_init(&k);
	scene_scan(text, &k);
	return k;
}

static double gamma_of(const char *text)
{
	struct scene_keys k = scan(text);
	return scene_assumed_gamma(&k);
}

static int focal_of(const char *text)
{
	struct scene_keys k = scan(text);
	return scene_focal_blur(&k);
}

static void test_gamma(void **state)
{
	(void)state;
	assert_true(gamma_of("global_settings { assumed_gamma 1.8 }") == 1.8);
	/* none, 1, within 0.01 of 1, an expression, zero or less: 0 */
	assert_true(gamma_of("global_settings { max_trace_level 5 }") == 0.0);
	assert_true(gamma_of("global_settings { assumed_gamma 1.0 }") == 0.0);
	assert_true(gamma_of("global_settings { assumed_gamma 1.005 }") == 0.0);
	assert_true(gamma_of("global_settings { assumed_gamma G }") == 0.0);
	assert_true(gamma_of("global_settings { assumed_gamma -2.2 }") == 0.0);
	/* the last given as a number counts; an expression after it does not
	 * undo it; a number on the next line is the keyword's */
	assert_true(gamma_of("assumed_gamma 1.8\nassumed_gamma 2.2") == 2.2);
	assert_true(gamma_of("assumed_gamma 2.2\nassumed_gamma G") == 2.2);
	assert_true(gamma_of("assumed_gamma\n  2.0 }") == 2.0);
	assert_true(gamma_of("assumed_gamma 2.2 assumed_gamma 1") == 0.0);
	/* at the text's very end, with no number */
	assert_true(gamma_of("assumed_gamma") == 0.0);
}

static void test_comments_and_strings(void **state)
{
	(void)state;
	/* a line comment, a block comment over lines, a string */
	assert_true(gamma_of("// assumed_gamma 2.2\nx") == 0.0);
	assert_true(gamma_of("/* a\n assumed_gamma 2.2\n */ x") == 0.0);
	assert_true(gamma_of("#declare S = \"assumed_gamma 2.2\";") == 0.0);
	/* a comment's end lets the text count again, and a "//" in a string is
	 * no comment */
	assert_true(gamma_of("/* c */ assumed_gamma 1.3") == 1.3);
	assert_true(gamma_of("#declare S = \"a // b\"; assumed_gamma 1.3") == 1.3);
	/* a string ends at its line (POV-Ray's do not span lines) */
	assert_true(gamma_of("#declare S = \"open\nassumed_gamma 1.3") == 1.3);
	/* an unclosed block comment hides the rest, and ends the scan */
	assert_true(gamma_of("assumed_gamma 1.4 /* assumed_gamma 2.2") == 1.4);
	/* a lone slash or star is text */
	assert_true(gamma_of("#declare A = 1 / 2 * 3; assumed_gamma 1.6") == 1.6);
}

static void test_words(void **state)
{
	(void)state;
	/* a longer name holding the keyword is not the keyword */
	assert_true(gamma_of("#declare my_assumed_gamma = 2.4;") == 0.0);
	assert_true(gamma_of("#declare assumed_gamma2 = 2.4;") == 0.0);
	assert_false(focal_of("#declare aperture_size = 1; #declare my_blur_samples = 4;"));
	/* a word character before the keyword too, with a number after it */
	assert_true(gamma_of("#declare My_assumed_gamma 2.4") == 0.0);
	assert_false(focal_of("#declare my_aperture = 1; camera { blur_samples 4 }"));
	assert_false(focal_of("#declare Cam_aperture 0.4; camera { blur_samples 4 }"));
}

static void test_focal_blur(void **state)
{
	(void)state;
	assert_true(focal_of("camera { aperture 0.4 blur_samples 4, 16 focal_point 0 }"));
	/* both keywords are needed; "aperture 0" is a camera without blur */
	assert_false(focal_of("camera { aperture 0.4 }"));
	assert_false(focal_of("camera { blur_samples 4 }"));
	assert_false(focal_of("camera { aperture 0 blur_samples 4 }"));
	assert_false(focal_of("camera { aperture 0.0 blur_samples 4 }"));
	/* an aperture given by a name is taken as one */
	assert_true(focal_of("camera { aperture Aperture blur_samples 4 }"));
	/* in a comment it does not count */
	assert_false(focal_of("// aperture 0.4 blur_samples 4\ncamera { }"));
}

static void test_read(void **state)
{
	(void)state;
	char path[] = "/tmp/povpress-test-scene-XXXXXX";
	int fd = mkstemp(path);
	assert_true(fd >= 0);
	FILE *f = fdopen(fd, "w");
	assert_non_null(f);
	fputs("// radiosity off here\nglobal_settings { assumed_gamma 2.2 }\n", f);
	assert_int_equal(fclose(f), 0);
	struct scene_keys k;
	assert_int_equal(scene_read(path, &k), 0);
	assert_true(scene_assumed_gamma(&k) == 2.2);
	/* radiosity is named anywhere, comments too */
	assert_int_equal(k.radiosity, 1);
	assert_int_equal(scene_focal_blur(&k), 0);
	assert_int_equal(unlink(path), 0);
	/* a missing file and a directory are errors, with errno */
	assert_int_equal(scene_read(path, &k), -1);
	assert_int_equal(errno, ENOENT);
	assert_int_equal(scene_read("/tmp", &k), -1);
	assert_int_equal(errno, EISDIR);
	assert_int_equal(scene_read("/dev/null", &k), -1);
	assert_int_equal(errno, EINVAL);
	assert_true(k.gamma == 1.0 && !k.radiosity && !k.aperture);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_gamma),
		cmocka_unit_test(test_comments_and_strings),
		cmocka_unit_test(test_words),
		cmocka_unit_test(test_focal_blur),
		cmocka_unit_test(test_read),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
