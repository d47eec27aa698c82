/*
 * lcmdec.c — the frame around lcm-gen's decoders (lcmdec.h says why).
 *
 * lcm-gen's code allocates through lcm_malloc(), which compat/lcm/
 * lcm_coretypes.h sends here. Inside lcmdec_decode() each allocation is
 * counted against the message's budget and remembered; an allocation past the
 * budget abandons the decode with longjmp() back to lcmdec_decode() — the
 * generated code would otherwise call malloc(sizeof(T) * n) for the lying n
 * and decode into whatever came back (NULL included). Jumping out of it is
 * safe: it holds nothing but the allocations we remembered, which are freed.
 * Outside a decode (lcm-gen's _copy) this is calloc().
 */
#include "lcmdec.h"

#include <limits.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void *lcmdec_alloc(size_t size);

struct lcmdec_frame {
	jmp_buf abandon;
	size_t budget;               /* bytes this decode may still allocate */
	void *allocs[LCMDEC_MAX_ALLOCS];
	size_t nallocs;
};

/* The decode running on this thread, NULL outside one. Thread-local storage,
 * not lcmdec_decode()'s stack: what longjmp() comes back to must not live in
 * the locals of the function that called setjmp(). */
static _Thread_local struct lcmdec_frame lcmdec_frame;
static _Thread_local bool lcmdec_active;

void *lcmdec_alloc(size_t size)
{
	if (!lcmdec_active)
		return calloc(1, size);
	struct lcmdec_frame *f = &lcmdec_frame;
	if (size > f->budget || f->nallocs == LCMDEC_MAX_ALLOCS)
		longjmp(f->abandon, 1);
	void *p = calloc(1, size);
	if (p == NULL)
		longjmp(f->abandon, 1);
	f->budget -= size;
	f->allocs[f->nallocs++] = p;
	return p;
}

static void lcmdec_forget(bool free_them)
{
	struct lcmdec_frame *f = &lcmdec_frame;
	if (free_them)
		for (size_t i = 0; i < f->nallocs; i++)
			free(f->allocs[i]);
	f->nallocs = 0;
	lcmdec_active = false;
}

enum lcmdec_status lcmdec_decode(const struct lcmdec_type *t, const void *buf, size_t len, void *out)
{
	memset(out, 0, t->size);
	if (len > t->max_len || len > INT_MAX)
		return LCMDEC_TOO_LONG;
	struct lcmdec_frame *f = &lcmdec_frame;
	f->budget = LCMDEC_BUDGET(len);
	f->nallocs = 0;
	lcmdec_active = true;
	if (setjmp(f->abandon) != 0) {
		lcmdec_forget(true);
		memset(out, 0, t->size);
		return LCMDEC_OVER_BUDGET;
	}
	int used = t->decode(buf, (int)len, out);
	if (used < 0 || (size_t)used != len) {
		lcmdec_forget(true);
		memset(out, 0, t->size);
		return used < 0 ? LCMDEC_MALFORMED : LCMDEC_TRAILING;
	}
	lcmdec_forget(false);
	return LCMDEC_OK;
}

void lcmdec_free(const struct lcmdec_type *t, void *msg)
{
	t->cleanup(msg);
	memset(msg, 0, t->size);
}

const char *lcmdec_describe(char *out, size_t cap, const struct lcmdec_type *t, size_t len, enum lcmdec_status s)
{
	static const char *const why[] = {
		[LCMDEC_OK] = "decodes",
		[LCMDEC_TOO_LONG] = "longer than any such message",
		[LCMDEC_MALFORMED] = "wrong type, or a length past the end of the message",
		[LCMDEC_TRAILING] = "bytes left over after the message",
		[LCMDEC_OVER_BUDGET] = "an array count larger than the message could hold",
	};
	snprintf(out, cap, "%s: %zu bytes do not decode (%s)", t->name, len,
	         (unsigned)s < sizeof why / sizeof why[0] ? why[s] : "?");
	return out;
}

/* lcm-gen's functions take the message's own pointer type: one thunk each */
#define LCMDEC_TYPE(T, max)                                                                      \
	static int lcmdec_decode_##T(const void *buf, int len, void *out)                          \
	{                                                                                        \
		return undulate_##T##_decode(buf, 0, len, (undulate_##T *)out);                     \
	}                                                                                        \
	static int lcmdec_cleanup_##T(void *msg) { return undulate_##T##_decode_cleanup((undulate_##T *)msg); } \
	const struct lcmdec_type lcmdec_##T = { #T, sizeof(undulate_##T), (max), lcmdec_decode_##T,    \
						lcmdec_cleanup_##T }

LCMDEC_TYPE(robot_state_t, LCMDEC_MAX_ROBOT);
LCMDEC_TYPE(bus_stats_t, LCMDEC_MAX_ROBOT);
LCMDEC_TYPE(osc_params_t, LCMDEC_MAX_ROBOT);
LCMDEC_TYPE(event_t, LCMDEC_MAX_ROBOT);
LCMDEC_TYPE(command_t, LCMDEC_MAX_SMALL);
LCMDEC_TYPE(sim_truth_t, LCMDEC_MAX_SIM);
LCMDEC_TYPE(sim_collision_t, LCMDEC_MAX_SMALL);
LCMDEC_TYPE(sim_world_t, LCMDEC_MAX_SMALL);
LCMDEC_TYPE(sim_command_t, LCMDEC_MAX_SMALL);
LCMDEC_TYPE(sim_reply_t, LCMDEC_MAX_SMALL);
