/*
 * main.c - the povpress command line: dispatch to the subcommands.
 */
#include "driver/commands.h"

#include <stdio.h>
#include <string.h>

static const char usage[] =
	"usage: povpress COMMAND [ARGS...]\n"
	"\n"
	"Adaptive sampling for POV-Ray by local polynomial regression and PRESS.\n"
	"\n"
	"commands:\n"
	"  render SCENE.pov -o OUT.exr render adaptively through POV-Ray: base pass, then\n"
	"                              region re-renders where the error estimate is high\n"
	"  plan ANALYSIS.exr -o DIR    the pixels that need samples, packed regions and a\n"
	"                              POV-Ray job list (one command line per region)\n"
	"  merge ACCUM.exr REGIONS     fold finished region renders into an accumulation\n"
	"  analyze IN.exr -o OUT.exr   reconstruction, error estimate, order, bandwidth,\n"
	"                              gradients of an image\n"
	"  compare IMAGE.exr REF.exr   relMSE, MSE and PSNR of an image against a reference\n"
	"  scene SCENE.pov             what render reads from a scene file itself\n"
	"                              (assumed_gamma, focal blur, radiosity)\n"
	"\n"
	"Run 'povpress COMMAND --help' for a command's options.\n";

int main(int argc, char **argv)
{
	if (argc < 2) {
		fputs(usage, stderr);
		return 2;
	}
	const char *cmd = argv[1];
	if (!strcmp(cmd, "-h") || !strcmp(cmd, "--help") || !strcmp(cmd, "help")) {
		fputs(usage, stdout);
		return 0;
	}
	if (!strcmp(cmd, "analyze"))
		return cmd_analyze(argc - 1, argv + 1);
	if (!strcmp(cmd, "render"))
		return cmd_render(argc - 1, argv + 1);
	if (!strcmp(cmd, "plan"))
		return cmd_plan(argc - 1, argv + 1);
	if (!strcmp(cmd, "merge"))
		return cmd_merge(argc - 1, argv + 1);
	if (!strcmp(cmd, "compare"))
		return cmd_compare(argc - 1, argv + 1);
	if (!strcmp(cmd, "scene"))
		return cmd_scene(argc - 1, argv + 1);
	fprintf(stderr, "povpress: unknown command '%s'\n\n%s", cmd, usage);
	return 2;
}
