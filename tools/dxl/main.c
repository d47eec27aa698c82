/*
 * dxl — the Dynamixel bus tool. Everything lives in libdxl (dxlt.h) so the
 * tests run the same code in-process.
 */
#include <stdio.h>

#include "dxlt.h"

int main(int argc, char **argv)
{
	return dxlt_main(argc, argv, stdout, stderr);
}
