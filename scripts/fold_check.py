#!/usr/bin/python3
"""fold_check.py - how well the fold difference of a stratified region render
estimates the error of the merged means, on whole frames.

For each scene: the base pass (one sample a pixel; with --onto 5 that and
scale 2's four) and one region render over the whole frame, folded as
driver/accum.c folds them (the fold difference d2,
the quadrants' twist averaged over 3 x 3, the independent and the lowered
figures of strat_end()), and each figure's image mean over the true relMSE of
the merged means against make sweep's cached reference (scale 15, jittered):

  min     the per-pixel smaller of the two (the rule before 20c41ad)
  ind     the independent samples' figure alone (the rule onto 5 samples
          before 2026-12-03 evening)
  low     the lowered (stratified) figure alone
  5x5     strat_end()'s rule: chosen on the two's 5 x 5 means, the smaller
          one's value where one is more than APART times the other, else the
          mean of the two (APART 2, and 1.5 and 3 beside it)

usage: scripts/fold_check.py [--scale 4|2] [--onto 1|5] [--scaling] [--size WxH]
                             SCENE.pov ...
  --scale 4: a grid render (+AM1 +A0.0 +R2 +J0.75 at twice the size, 20
             samples a pixel; the default); --scale 2: resolution scaling
             (twice the size without antialiasing, 4 samples a pixel)
  --onto 5:  (scale 4) fold onto the base pass and scale 2's four samples (a
             render at twice the size without antialiasing), as after a
             scale-2 pass: the grid render's centres, which repeat scale 2's,
             taken out, 16 new samples onto 5 (default --onto 1: onto the
             base pass's one)
  --scaling: (scale 4) the render by resolution scaling (four times the size
             without antialiasing, 16 samples a pixel) instead of a grid
             render, as `--sampler auto` renders scale 4 at 160x120

Needs Debian's python3-numpy and python3-openimageio, and POV-Ray.  The renders
go to a temporary directory; POV-Ray runs from an argument vector.
"""
import glob
import os
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio

EPS = 0.01  # METRICS_RELMSE_EPS


def die(msg):
    sys.stderr.write("fold_check: %s\n" % msg)
    sys.exit(1)


def read_rgb(path):
    buf = oiio.ImageBuf(path)
    if buf.has_error:
        die("cannot read '%s': %s" % (path, buf.geterror()))
    return buf.get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)


def povray(scene, w, h, extra, out):
    argv = ["povray", "+I" + scene, "+W%d" % w, "+H%d" % h, "+FE", "+O" + out, "-D", "-GA",
            "+WT2"] + extra
    if subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode:
        die("povray failed on '%s' (%s)" % (scene, " ".join(argv[2:])))


def mean_around(a, r):
    h, w = a.shape
    p = np.pad(a, r, mode="edge")
    return sum(p[r + dy:r + dy + h, r + dx:r + dx + w]
               for dy in range(-r, r + 1) for dx in range(-r, r + 1)) / (2 * r + 1) ** 2


def rel(e2, m):
    """Mean over R, G, B of e2 / (m^2 + 0.01)."""
    return (e2 / (m * m + EPS)).mean(axis=2)


def quadrants(a, h, w):
    q = a.reshape(h, 2, w, 2, 3)
    return q[:, 0, :, 0], q[:, 0, :, 1], q[:, 1, :, 0], q[:, 1, :, 1]


def check(scene, w, h, scale, onto, scaling, tmp):
    name = os.path.splitext(os.path.basename(scene))[0]
    cache = os.environ.get("POVPRESS_CACHE", os.path.expanduser("~/.cache/povpress"))
    refs = sorted(glob.glob("%s/ref/%s-%dx%d-j15-*.exr" % (cache, name, w, h)))
    if not refs:
        die("no reference for %s at %dx%d (make sweep makes them)" % (name, w, h))
    ref = read_rgb(refs[0])
    base, reg, two = (os.path.join(tmp, f) for f in ("b.exr", "r.exr", "s2.exr"))
    povray(scene, w, h, ["-A"], base)
    b = read_rgb(base)
    if scale == 4 and scaling:
        povray(scene, 4 * w, 4 * h, ["-A"], reg)
        g = read_rgb(reg).reshape(2 * h, 2, 2 * w, 2, 3).mean(axis=(1, 3))
        nb = 16.0
    elif scale == 4:
        povray(scene, 2 * w, 2 * h, ["+AM1", "+A0.0", "+R2", "+J0.75"], reg)
        g = read_rgb(reg)
        nb = 20.0
    else:
        povray(scene, 2 * w, 2 * h, ["-A"], reg)
        g = read_rgb(reg)
        nb = 4.0
    na = 1.0
    if onto == 5:
        povray(scene, 2 * w, 2 * h, ["-A"], two)
        c = read_rgb(two)
        b = (b + sum(quadrants(c, h, w))) / 5.0
        na = 5.0
        if not scaling:	# a render pixel's centre repeats scale 2's sample:
            # taken out as the merge does (grid_pixel()), by the old mean
            g, nb = (5.0 * g - np.repeat(np.repeat(b, 2, axis=0), 2, axis=1)) / 4.0, 16.0
    q0, q1, q2, q3 = quadrants(g, h, w)
    m = (q0 + q1 + q2 + q3) / 4.0
    nt = na + nb
    merged = (na * b + nb * m) / nt
    true = rel((merged - ref) ** 2, ref).mean()
    d2 = rel((b - m) ** 2, merged)
    vb = mean_around(rel(((q0 - q1 - q2 + q3) / 4.0) ** 2, m), 1)
    ind = d2 * na * nb / nt ** 2
    low = (na * na * np.maximum(d2 - vb, 0.0) + nb * nb * vb) / nt ** 2
    ai, al = mean_around(ind, 2), mean_around(low, 2)
    row = [np.minimum(ind, low).mean(), ind.mean(), low.mean()]
    for apart in (2.0, 1.5, 3.0):
        small = np.where(al < ai, low, ind)
        chosen = np.where(np.maximum(ai, al) > apart * np.minimum(ai, al), small,
                          0.5 * (ind + low))
        row.append(chosen.mean())
    print("%-28s %10.3g " % (name, true) + " ".join("%7.2f" % (x / true) for x in row))


def main(argv):
    scale, onto, scaling, w, h, scenes = 4, 1, False, 160, 120, []
    it = iter(argv)
    for a in it:
        if a == "--scale":
            try:
                scale = int(next(it, "0"))
            except ValueError:
                die("--scale takes 4 or 2")
        elif a == "--onto":
            try:
                onto = int(next(it, "0"))
            except ValueError:
                die("--onto takes 1 or 5")
        elif a == "--scaling":
            scaling = True
        elif a == "--size":
            try:
                w, h = (int(x) for x in next(it, "").split("x"))
            except ValueError:
                die("--size takes WxH")
        elif a in ("-h", "--help"):
            print(__doc__)
            return 0
        elif a.startswith("-"):
            die("unknown option '%s'" % a)
        else:
            scenes.append(a)
    if scale not in (2, 4) or onto not in (1, 5) or not scenes:
        die("usage: scripts/fold_check.py [--scale 4|2] [--onto 1|5] [--scaling] "
            "[--size WxH] SCENE.pov ...")
    if scale == 2 and (onto == 5 or scaling):
        die("--onto 5 and --scaling are for scale 4")
    for s in scenes:
        if not os.path.isfile(s):
            die("no scene '%s'" % s)
    print("%-28s %10s %7s %7s %7s %7s %7s %7s" %
          ("scene (scale %d%s, onto %d)" % (scale, " scaling" if scaling else "", onto),
           "true", "min", "ind", "low", "5x5", "5x5/1.5", "5x5/3"))
    with tempfile.TemporaryDirectory(prefix="fold_check.") as tmp:
        for s in scenes:
            check(s, w, h, scale, onto, scaling, tmp)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
