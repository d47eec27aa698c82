/* csvrow.c — see csvrow.h. */
#include "csvrow.h"

#include <math.h>

void csvrow_num(FILE *f, double v)
{
	if (isfinite(v))
		fprintf(f, ",%.9g", v);
	else
		fputs(",", f);
}

void csvrow_nums(FILE *f, const double *v, size_t n)
{
	for (size_t i = 0; i < n; i++)
		csvrow_num(f, v[i]);
}

void csvrow_str(FILE *f, const char *s)
{
	fputc('"', f);
	for (; s && *s; s++) {
		if (*s == '"')
			fputc('"', f);
		fputc(*s == '\n' || *s == '\r' ? ' ' : *s, f);
	}
	fputc('"', f);
}

void csvrow_collision(FILE *f, const struct csvrow_collision *r)
{
	fprintf(f, "%lld,%.6f,%d,%d,", (long long)r->utime, r->t, r->left, r->right);
	csvrow_str(f, r->left_robot);
	fputc(',', f);
	csvrow_str(f, r->right_robot);
	csvrow_nums(f, (const double[]){ r->pre_left, r->pre_right, r->post_left, r->post_right, r->impulse }, 5);
	fputc(',', f);
	if (r->pair)
		csvrow_str(f, r->pair);
	csvrow_num(f, r->delta);
	fprintf(f, ",%d\n", r->new_contact ? 1 : 0);
}
