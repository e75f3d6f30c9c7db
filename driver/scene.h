/*
 * scene.h - what povpress reads from a scene file itself (not from the
 * files it includes, and not from POV-Ray): the keys that steer
 * `povpress render` before POV-Ray has run, and `povpress scene`, which
 * prints them so that scripts read a scene as render does.
 */
#ifndef POVPRESS_SCENE_H
#define POVPRESS_SCENE_H

/* What the scene file says outside comments and strings, but radiosity. */
struct scene_keys {
	int aperture;		/* "aperture", but for "aperture 0" */
	int blur_samples;	/* "blur_samples" */
	double gamma;		/* the last assumed_gamma given as a number, or 1 */
	int radiosity;		/* the text holds "radiosity" anywhere, comments
				 * and names such as use_radiosity too: render's
				 * cue to start its radiosity pass early (whether
				 * the scene has radiosity, POV-Ray's statistics
				 * tell) */
};

/* *k as for a file that says nothing: no focal blur, gamma 1. */
void scene_keys_init(struct scene_keys *k);

/* Scan the NUL-terminated scene text t into *k, which starts as
 * scene_keys_init() leaves it (radiosity is scene_read()'s). */
void scene_scan(const char *t, struct scene_keys *k);

/* Read and scan the scene file at path.  Returns 0, or -1 with errno set
 * when it cannot be read: EISDIR for a directory, EINVAL for another file
 * that is not a regular one (*k then as scene_keys_init() leaves it). */
int scene_read(const char *path, struct scene_keys *k);

/* What scene_read()'s errno says, for a message: "not a regular file" for
 * EINVAL, else strerror()'s text. */
const char *scene_strerror(int e);

/* Whether the file names both of focal blur's camera keywords, aperture
 * (but for "aperture 0") and blur_samples: render's --sampler auto then
 * scales frames up to 8 Mpixels before it turns to grid renders. */
int scene_focal_blur(const struct scene_keys *k);

/* The assumed_gamma the file gives as a number other than 1 (more than
 * 0.01 from it; the last one given), else 0: where it gives none, gives 1,
 * or gives an expression.  render's --sampler auto then scales every
 * refinement, since POV-Ray's antialiasing averages in that gamma's
 * encoding. */
double scene_assumed_gamma(const struct scene_keys *k);

#endif
