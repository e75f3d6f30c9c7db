/*
 * scene.c - what povpress reads from a scene file itself (scene.h), and
 * `povpress scene`, which prints it.
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "driver/commands.h"
#include "driver/files.h"
#include "driver/scene.h"

void scene_keys_init(struct scene_keys *k)
{
	k->aperture = 0;
	k->blur_samples = 0;
	k->gamma = 1.0;
	k->radiosity = 0;
}

/* Whether word w starts at t[i] as a word of the scene language. */
static int word_at(const char *t, size_t i, const char *w)
{
	size_t n = strlen(w);
	if (strncmp(t + i, w, n))
		return 0;
	int before = i > 0 && (isalnum((unsigned char)t[i - 1]) || t[i - 1] == '_');
	int after = isalnum((unsigned char)t[i + n]) || t[i + n] == '_';
	return !before && !after;
}

/* The number after the keyword at t[i] (sizeof key - 1 long), or NAN. */
static double number_after(const char *t, size_t i, size_t keylen)
{
	const char *v = t + i + keylen;
	char *end;
	double x = strtod(v, &end);
	return end == v ? NAN : x;
}

void scene_scan(const char *t, struct scene_keys *k)
{
	for (size_t i = 0; t[i]; i++) {
		if (t[i] == '/' && t[i + 1] == '/') {
			while (t[i + 1] && t[i + 1] != '\n')
				i++;
		} else if (t[i] == '/' && t[i + 1] == '*') {
			i += 2;
			while (t[i] && !(t[i] == '*' && t[i + 1] == '/'))
				i++;
			if (!t[i])
				break;
			i++;
		} else if (t[i] == '"') {
			while (t[i + 1] && t[i + 1] != '"' && t[i + 1] != '\n')
				i++;
			if (t[i + 1])
				i++;
		} else if (word_at(t, i, "aperture")) {
			/* "aperture 0" is a camera without focal blur */
			k->aperture |= !(number_after(t, i, sizeof "aperture" - 1) == 0.0);
		} else if (word_at(t, i, "blur_samples")) {
			k->blur_samples = 1;
		} else if (word_at(t, i, "assumed_gamma")) {
			double x = number_after(t, i, sizeof "assumed_gamma" - 1);
			if (isfinite(x))
				k->gamma = x;
		}
	}
}

int scene_read(const char *path, struct scene_keys *k)
{
	scene_keys_init(k);
	struct stat st;
	if (stat(path, &st))
		return -1;
	if (!S_ISREG(st.st_mode)) {	/* a directory, a device, a pipe */
		errno = S_ISDIR(st.st_mode) ? EISDIR : EINVAL;
		return -1;
	}
	errno = 0;
	char *t = file_read_text(path);
	if (!t) {
		if (!errno)
			errno = ENOMEM;
		return -1;
	}
	scene_scan(t, k);
	k->radiosity = strstr(t, "radiosity") != NULL;	/* a NUL ends the search */
	free(t);
	return 0;
}

const char *scene_strerror(int e)
{
	return e == EINVAL ? "not a regular file" : strerror(e);
}

/*
 * Whether the scene file (not what it includes) names both of focal blur's
 * camera keywords, aperture (but for "aperture 0") and blur_samples,
 * outside comments and strings.  There
 * POV-Ray's antialiasing converges far more slowly than resolution scaling:
 * each antialiasing sub-sample traces its own blur samples, whose sub-pixel
 * offsets come from a table indexed by the position (tracepixel.cpp), so
 * the sub-samples of a pixel share much of their pattern.  focal_blur at
 * 160x120, the whole frame against the sweep's reference: +AM1 +A0.0 +R8
 * +J0.75 at twice the size (256 samples a pixel) 7.8e-5, resolution
 * scaling at 8 (64) 7.8e-5 and at 16 (256) 2.3e-5; on the other bundled
 * scenes the grid renders did as well as scaling or better (README).
 */
int scene_focal_blur(const struct scene_keys *k)
{
	return k->aperture && k->blur_samples;
}

/*
 * The value the scene file (not what it includes) gives assumed_gamma,
 * outside comments and strings, when it is a number other than 1 (the
 * last such); 0 where it gives none, gives 1, or gives an expression.
 * There POV-Ray's antialiasing averages its samples in that gamma's
 * encoding, not linearly as resolution scaling's box average does: grid
 * renders and antialiased renders are biased against the linear
 * reference.  Debian's advanced/biscuit (assumed_gamma 1.3) at 160x120,
 * the whole frame against resolution scaling at 15: +AM1 +A0.0 +R4 +J0
 * (scale 4's positions and the centre) 3.8e-3, scaling at 4 1.33e-3, the
 * grid render at scale 4 (+AM1 +A0.0 +R2 +J0.75 at twice the size)
 * 2.36e-3.  povpress render there, --sampler auto against scale: --target
 * 1e-3 7.2e-4 in 8.8 CPU s against 1.7e-4 in 9.2 s; advanced/pawns (1.8)
 * 1.33e-3 in 7.5 s against 4.5e-4 in 8.5 s; lights/spotlite (2.2) at
 * --budget 3 5.3e-4 against 5.7e-5.
 */
double scene_assumed_gamma(const struct scene_keys *k)
{
	const double g = k->gamma;
	return fabs(g - 1.0) > 0.01 && g > 0.0 ? g : 0.0;
}

static const char scene_usage[] =
	"usage: povpress scene SCENE.pov\n"
	"\n"
	"Print what 'povpress render' reads from the scene file itself (not from\n"
	"the files it includes) before POV-Ray has run, one line each:\n"
	"\n"
	"  assumed_gamma: G     the assumed_gamma the file gives as a number outside\n"
	"                       comments and strings (the last one given); 1 where\n"
	"                       it gives none, an expression, 1 (to 0.01), or 0\n"
	"                       or less.\n"
	"                       Other than 1, --sampler auto refines by resolution\n"
	"                       scaling alone: POV-Ray's antialiasing averages its\n"
	"                       samples in that gamma's encoding\n"
	"  focal_blur: yes|no   whether it names both of focal blur's camera\n"
	"                       keywords, aperture (but for \"aperture 0\") and\n"
	"                       blur_samples, outside comments and strings; under\n"
	"                       --sampler auto frames are then scaled up to\n"
	"                       8 Mpixels before region renders turn to grids\n"
	"  radiosity: yes|no    whether its text holds \"radiosity\" anywhere\n"
	"                       (comments and names such as use_radiosity too):\n"
	"                       render then may start its radiosity pass with the\n"
	"                       base pass (--prelaunch); whether the scene has\n"
	"                       radiosity at all, POV-Ray's statistics tell\n"
	"\n"
	"Exit status: 0 done, 1 the file cannot be read (or is not a regular file)\n"
	"or the output cannot be written, 2 bad usage.\n";

int cmd_scene(int argc, char **argv)
{
	const char *path = NULL;
	int opts = 1;	/* options end at "--" */
	for (int i = 1; i < argc; i++) {
		const char *a = argv[i];
		if (opts && (!strcmp(a, "-h") || !strcmp(a, "--help"))) {
			fputs(scene_usage, stdout);
			return 0;
		}
		if (opts && !strcmp(a, "--")) {
			opts = 0;
			continue;
		}
		if (opts && a[0] == '-' && a[1]) {
			fprintf(stderr, "povpress scene: unknown option '%s'\n\n%s", a, scene_usage);
			return 2;
		}
		if (path) {
			fprintf(stderr, "povpress scene: one scene file, not '%s' and '%s'\n\n%s",
				path, a, scene_usage);
			return 2;
		}
		path = a;
	}
	if (!path) {
		fprintf(stderr, "povpress scene: no scene file given\n\n%s", scene_usage);
		return 2;
	}
	struct scene_keys k;
	if (scene_read(path, &k)) {
		fprintf(stderr, "povpress scene: cannot read scene '%s': %s\n", path,
			scene_strerror(errno));
		return 1;
	}
	const double g = scene_assumed_gamma(&k);
	printf("assumed_gamma: %g\nfocal_blur: %s\nradiosity: %s\n", g > 0.0 ? g : 1.0,
	       scene_focal_blur(&k) ? "yes" : "no", k.radiosity ? "yes" : "no");
	if (fflush(stdout) || ferror(stdout)) {
		fprintf(stderr, "povpress scene: cannot write the output: %s\n", strerror(errno));
		return 1;
	}
	return 0;
}
