#include "regression/kernel.h"

#include <math.h>

double kernel_tricube(double u)
{
	double a = fabs(u);
	if (a >= 1.0)
		return 0.0;
	double b = 1.0 - a * a * a;
	return b * b * b;
}

void kernel_weights(int r, double *t)
{
	for (int i = -r; i <= r; i++)
		t[i + r] = kernel_tricube((double)i / (r + 1));
}
