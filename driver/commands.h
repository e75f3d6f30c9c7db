/*
 * commands.h - the povpress subcommands.
 *
 * Each takes the arguments after "povpress" (argv[0] is the command's own
 * name), does its own printing, and returns the process exit code: 0 on
 * success, 1 on a runtime error, 2 on a usage error.
 */
#ifndef POVPRESS_COMMANDS_H
#define POVPRESS_COMMANDS_H

/* povpress analyze IN.exr -o OUT.exr: the regression's analysis of an image. */
int cmd_analyze(int argc, char **argv);

/* povpress compare IMAGE.exr REF.exr: print relMSE, MSE and PSNR. */
int cmd_compare(int argc, char **argv);

/* povpress render SCENE.pov -o OUT.exr: the adaptive re-rendering loop. */
int cmd_render(int argc, char **argv);

/* povpress plan ANALYSIS.exr -o DIR: pixels, regions and POV-Ray jobs. */
int cmd_plan(int argc, char **argv);

/* povpress merge: fold region renders into an accumulation. */
int cmd_merge(int argc, char **argv);

/* povpress scene SCENE.pov: what render reads from the scene file. */
int cmd_scene(int argc, char **argv);

#endif
