/*
 * pngdata — how much of a plot is data: counts the coloured pixels of PNG
 * files, so a test can fail on a plot that was drawn without its data.
 *
 *   pngdata FILE...               prints "FILE WIDTHxHEIGHT coloured=N" per file
 *   pngdata --rgb RRGGBB FILE...  counts only pixels of that colour (within
 *                                 PNGDATA_NEAR per channel): one series
 *
 * gnuplot draws frames, tics, grid and text in black and grey, and data in
 * saturated colours; a pixel is "coloured" when its channels differ by more
 * than PNGDATA_CHROMA. An empty plot still has its key samples (tens of
 * pixels per entry), so tests compare N with a threshold well above that.
 * Exit 0, or 1 when a file is not a readable PNG (said on stderr).
 */
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* max(r,g,b) - min(r,g,b) above this is a colour, not a grey. */
#define PNGDATA_CHROMA 60
/* --rgb: a channel within this of the wanted value matches (anti-aliasing
 * blends a line's edges; its core keeps the colour). */
#define PNGDATA_NEAR 24

static int pngdata_want = -1; /* --rgb as 0xRRGGBB; -1: any colour */

static int pngdata_abs(int x) { return x < 0 ? -x : x; }

static int pngdata_match(int r, int g, int b)
{
	if (pngdata_want < 0) {
		int hi = r > g ? (r > b ? r : b) : (g > b ? g : b);
		int lo = r < g ? (r < b ? r : b) : (g < b ? g : b);
		return hi - lo > PNGDATA_CHROMA;
	}
	return pngdata_abs(r - (pngdata_want >> 16)) <= PNGDATA_NEAR &&
	       pngdata_abs(g - ((pngdata_want >> 8) & 0xFF)) <= PNGDATA_NEAR &&
	       pngdata_abs(b - (pngdata_want & 0xFF)) <= PNGDATA_NEAR;
}

static long pngdata_count(const char *path, unsigned *w, unsigned *h)
{
	png_image img;

	memset(&img, 0, sizeof img);
	img.version = PNG_IMAGE_VERSION;
	if (!png_image_begin_read_from_file(&img, path)) {
		fprintf(stderr, "pngdata: %s: %s\n", path, img.message);
		return -1;
	}
	img.format = PNG_FORMAT_RGB;
	size_t size = PNG_IMAGE_SIZE(img);
	unsigned char *buf = malloc(size);
	if (buf == NULL || !png_image_finish_read(&img, NULL, buf, 0, NULL)) {
		fprintf(stderr, "pngdata: %s: %s\n", path, buf ? img.message : "out of memory");
		free(buf);
		png_image_free(&img);
		return -1;
	}
	long n = 0;
	for (size_t i = 0; i + 2 < size; i += 3) {
		if (pngdata_match(buf[i], buf[i + 1], buf[i + 2]))
			n++;
	}
	*w = img.width;
	*h = img.height;
	free(buf);
	return n;
}

int main(int argc, char **argv)
{
	int rc = 0;

	int first = 1;
	if (argc > 2 && strcmp(argv[1], "--rgb") == 0) {
		char *end;
		long v = strtol(argv[2], &end, 16);
		if (*end != '\0' || end - argv[2] != 6 || v < 0) {
			fprintf(stderr, "pngdata: --rgb wants RRGGBB, not '%s'\n", argv[2]);
			return 2;
		}
		pngdata_want = (int)v;
		first = 3;
	}
	if (argc <= first) {
		fprintf(stderr, "usage: pngdata [--rgb RRGGBB] FILE...\n");
		return 2;
	}
	for (int i = first; i < argc; i++) {
		unsigned w = 0, h = 0;
		long n = pngdata_count(argv[i], &w, &h);
		if (n < 0) {
			rc = 1;
			continue;
		}
		printf("%s %ux%u %s=%ld\n", argv[i], w, h, pngdata_want < 0 ? "coloured" : "matching", n);
	}
	return rc;
}
