/*
 * fault.c — fault descriptions and their effect on a status packet.
 */
#include "fault.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dxl.h"
#include "dxl2.h"
#include "num.h"

static const char *const fault_names[SIM_FAULT_KINDS] = {
	[SIM_FAULT_NO_REPLY] = "no-reply",
	[SIM_FAULT_BAD_CHECKSUM] = "bad-checksum",
	[SIM_FAULT_TRUNCATE] = "truncate",
	[SIM_FAULT_GARBAGE] = "garbage",
	[SIM_FAULT_WRONG_ID] = "wrong-id",
	[SIM_FAULT_STUCK_ERROR] = "stuck-error",
	[SIM_FAULT_SLOW] = "slow",
	[SIM_FAULT_TEMPERATURE] = "temperature",
	[SIM_FAULT_VOLTAGE] = "voltage",
};

const char *sim_fault_name(enum sim_fault_kind k)
{
	return (unsigned)k < SIM_FAULT_KINDS ? fault_names[k] : "?";
}

uint64_t sim_rand_next(uint64_t *state)
{
	uint64_t x = *state ? *state : 0x9E3779B97F4A7C15ull;
	x ^= x >> 12;
	x ^= x << 25;
	x ^= x >> 27;
	*state = x;
	return x * 0x2545F4914F6CDD1Dull;
}

double sim_rand_uniform(uint64_t *state)
{
	return (double)(sim_rand_next(state) >> 11) * (1.0 / 9007199254740992.0);
}

static bool parse_double(const char *s, double *out)
{
	return num_parse_double(s, out) == NUM_OK;
}

/* One word per status error bit, 0..6 (no spaces: they go on a command line). */
static const char *const errbit_words[7] = {
	"voltage", "angle-limit", "overheating", "range", "checksum", "overload", "instruction",
};

int sim_fault_parse_bits(const char *text)
{
	char buf[128];
	char *end;
	long v = strtol(text, &end, 0);
	if (end != text && *end == '\0')
		return (v >= 0 && v <= (long)DXL_ERRBIT_MASK) ? (int)v : -1;
	if (strlen(text) >= sizeof(buf))
		return -1;
	strcpy(buf, text);
	int bits = 0;
	for (char *save = NULL, *tok = strtok_r(buf, "|,+", &save); tok; tok = strtok_r(NULL, "|,+", &save)) {
		int found = 0;
		for (int b = 0; b < 7; b++) {
			if (strcmp(errbit_words[b], tok) == 0) {
				bits |= 1 << b;
				found = 1;
			}
		}
		if (!found)
			return -1;
	}
	return bits;
}

/* Protocol 2.0's error numbers 1..7 by name (dxl2.h), for stuck-error. */
static const char *const err2_words[8] = {
	NULL, "result-fail", "instruction", "crc", "data-range", "data-length", "data-limit", "access",
};

int sim_fault_parse_err2(const char *text)
{
	char buf[128];
	char *end;
	long v = strtol(text, &end, 0);
	if (end != text && *end == '\0')
		return (v >= 0 && v <= 0xFF) ? (int)v : -1;
	if (strlen(text) >= sizeof(buf))
		return -1;
	strcpy(buf, text);
	int err = 0;
	for (char *save = NULL, *tok = strtok_r(buf, "|,+", &save); tok; tok = strtok_r(NULL, "|,+", &save)) {
		int found = -1;
		if (strcmp(tok, "alert") == 0)
			found = DXL2_ERR_ALERT;
		for (int n = 1; n < 8 && found < 0; n++)
			if (strcmp(err2_words[n], tok) == 0)
				found = n;
		/* the alert bit and one error number: a second number cannot share the field */
		if (found < 0 || (found != DXL2_ERR_ALERT && (err & DXL2_ERR_NUMBER_MASK)))
			return -1;
		err |= found;
	}
	return err;
}

static int fault_kind_of(const char *name)
{
	for (int k = 0; k < SIM_FAULT_KINDS; k++)
		if (strcmp(name, fault_names[k]) == 0)
			return k;
	return -1;
}

/* What ARG may be for each kind: sim_faults_apply() turns the byte counts,
 * the ID and the delay into integers, so each is bounded here (a cast of
 * 1e300 to size_t or uint8_t is undefined behaviour). */
static const struct {
	bool whole;        /* a whole number */
	double lo, hi;
} fault_arg_range[SIM_FAULT_KINDS] = {
	[SIM_FAULT_TRUNCATE] = { true, 0, DXL_MAX_PACKET },        /* bytes cut */
	[SIM_FAULT_GARBAGE] = { true, 0, SIM_FAULT_MAX_GARBAGE },   /* bytes added */
	[SIM_FAULT_WRONG_ID] = { true, 0, DXL_MAX_ID },
	[SIM_FAULT_SLOW] = { false, 0, SIM_FAULT_MAX_SLOW_MS },
	[SIM_FAULT_TEMPERATURE] = { false, -40, 255 },             /* °C; the register holds 0..255 */
	[SIM_FAULT_VOLTAGE] = { false, 0, 25.5 },                  /* V; the register holds 0..25.5 */
};

/* The ARG of a fault: a number, or error-bit names for stuck-error. */
static int fault_parse_arg(enum sim_fault_kind kind, const char *word, struct sim_fault *out)
{
	if (kind == SIM_FAULT_STUCK_ERROR) {
		/* 1.0 error bits, 2.0 ERR field, or a number meaning either */
		int bits = sim_fault_parse_bits(word), err2 = sim_fault_parse_err2(word);
		if (bits < 0 && err2 < 0)
			return -1;
		out->arg = bits;
		out->err2 = err2;
		return 0;
	}
	if (kind == SIM_FAULT_NO_REPLY || kind == SIM_FAULT_BAD_CHECKSUM)
		return -1;   /* no ARG */
	double v;
	if (fault_arg_range[kind].whole) {
		long n;
		if (num_parse_long(word, (long)fault_arg_range[kind].lo, (long)fault_arg_range[kind].hi, &n) != NUM_OK)
			return -1;
		v = (double)n;
	} else if (num_parse_double_in(word, fault_arg_range[kind].lo, fault_arg_range[kind].hi, &v) != NUM_OK) {
		return -1;
	}
	out->arg = v;
	return 0;
}

int sim_fault_parse(int argc, char **argv, enum sim_fault_kind *kind, struct sim_fault *out,
                    char *err, size_t errcap)
{
	if (argc < 1) {
		snprintf(err, errcap, "missing fault kind");
		return -1;
	}
	int k = fault_kind_of(argv[0]);
	if (k < 0) {
		snprintf(err, errcap, "unknown fault '%s' (no-reply, bad-checksum, truncate, garbage, wrong-id, "
		                      "stuck-error, slow, temperature, voltage)", argv[0]);
		return -1;
	}
	memset(out, 0, sizeof(*out));
	out->active = true;
	out->remaining = -1;
	out->prob = 1.0;
	for (int i = 1; i < argc; i++) {
		double v;
		long n;
		if (strncmp(argv[i], "count=", 6) == 0 && num_parse_long(argv[i] + 6, 1, SIM_FAULT_MAX_COUNT, &n) == NUM_OK) {
			out->remaining = n;
		} else if (strncmp(argv[i], "prob=", 5) == 0 && parse_double(argv[i] + 5, &v) && v >= 0 && v <= 1) {
			out->prob = v;
		} else if (!out->has_arg && fault_parse_arg((enum sim_fault_kind)k, argv[i], out) == 0) {
			out->has_arg = true;
		} else {
			snprintf(err, errcap, "bad argument '%s' for fault %s", argv[i], argv[0]);
			return -1;
		}
	}
	if ((k == SIM_FAULT_TEMPERATURE || k == SIM_FAULT_VOLTAGE) && !out->has_arg) {
		snprintf(err, errcap, "fault %s needs a value", argv[0]);
		return -1;
	}
	if (k == SIM_FAULT_STUCK_ERROR && !out->has_arg) {
		out->arg = DXL_ERRBIT_OVERLOAD;
		out->err2 = DXL2_ERR_ALERT;
		out->has_arg = true;
	}
	*kind = (enum sim_fault_kind)k;
	return 0;
}

void sim_faults_clear(struct sim_faults *fs)
{
	memset(fs->f, 0, sizeof(fs->f));
}

/* Whether a reply fault fires for this reply (count and probability). */
static bool fault_fires(struct sim_fault *f, uint64_t *rng)
{
	if (!f->active)
		return false;
	if (f->prob < 1.0 && sim_rand_uniform(rng) >= f->prob)
		return false;
	if (f->remaining > 0 && --f->remaining == 0)
		f->active = false;
	return true;
}

/* Where a status packet of one protocol keeps what the faults edit. */
struct fault_layout {
	size_t min_len;                 /* a whole status packet is at least this long */
	size_t cap;                     /* room in pkt (a re-stuffed packet may grow) */
	void (*stuck)(uint8_t *pkt, size_t *len, size_t cap, const struct sim_fault *f);
	void (*wrong_id)(uint8_t *pkt, size_t len, const struct sim_fault *f);
	void (*bad_checksum)(uint8_t *pkt, size_t len);
};

static void fault_fix_checksum(uint8_t *pkt, size_t len)
{
	pkt[len - 1] = dxl_checksum(&pkt[2], len - 3);
}

static void stuck1(uint8_t *pkt, size_t *len, size_t cap, const struct sim_fault *f)
{
	(void)cap;
	double bits = f->arg;
	pkt[4] |= bits > 0 && bits <= DXL_ERRBIT_MASK ? (uint8_t)bits : 0;
	fault_fix_checksum(pkt, *len);
}

static uint8_t wrong_id_of(const struct sim_fault *f, uint8_t own)
{
	double id = f->arg;
	return f->has_arg && id >= 0 && id <= DXL_MAX_ID ? (uint8_t)id : (uint8_t)(own + 1);
}

static void wrong_id1(uint8_t *pkt, size_t len, const struct sim_fault *f)
{
	pkt[2] = wrong_id_of(f, pkt[2]);
	fault_fix_checksum(pkt, len);
}

static void bad_checksum1(uint8_t *pkt, size_t len)
{
	pkt[len - 1] ^= 0xFF;
}

/* Protocol 2.0: the CRC covers everything before it. */
static void fix_crc2(uint8_t *pkt, size_t len)
{
	uint16_t crc = dxl2_crc_update(0, pkt, len - DXL2_CRC_BYTES);
	pkt[len - 2] = (uint8_t)crc;
	pkt[len - 1] = (uint8_t)(crc >> 8);
}

/* The ERR field changed: the packet is decoded and encoded again, so its
 * stuffing stays right whatever the new byte is. */
static void stuck2(uint8_t *pkt, size_t *len, size_t cap, const struct sim_fault *f)
{
	struct dxl2_parser p;
	struct dxl2_packet st;
	size_t used = 0;
	if (f->err2 <= 0)
		return;
	dxl2_parser_init(&p, DXL2_PARSE_STATUS);
	if (dxl2_parser_feed(&p, pkt, *len, &used, &st) != DXL_FRAME || used != *len)
		return;
	uint8_t e = (uint8_t)f->err2, err = (uint8_t)(st.err | (e & DXL2_ERR_ALERT));
	if (e & DXL2_ERR_NUMBER_MASK)
		err = (uint8_t)((err & DXL2_ERR_ALERT) | (e & DXL2_ERR_NUMBER_MASK));
	uint8_t out[DXL2_MAX_PACKET];
	int n = dxl2_encode_status(out, cap < sizeof out ? cap : sizeof out, st.id, err, st.params, st.nparams);
	if (n > 0) {
		memcpy(pkt, out, (size_t)n);
		*len = (size_t)n;
	}
}

static void wrong_id2(uint8_t *pkt, size_t len, const struct sim_fault *f)
{
	pkt[4] = wrong_id_of(f, pkt[4]);
	fix_crc2(pkt, len);
}

static void bad_checksum2(uint8_t *pkt, size_t len)
{
	pkt[len - 2] ^= 0xFF;
	pkt[len - 1] ^= 0xFF;
}

static bool faults_apply(struct sim_faults *fs, uint64_t *rng, const struct fault_layout *ly, uint8_t *pkt,
                         size_t *len, uint8_t *garbage, size_t *ngarbage, int64_t *extra_delay_ns)
{
	struct sim_fault *f = fs->f;
	bool changed = false;
	*ngarbage = 0;
	*extra_delay_ns = 0;
	/* First what the servo says (its error byte), then what the line does
	 * to it: a bad-checksum fault inverts the checksum of the packet with
	 * the stuck bits in. */
	if (*len >= ly->min_len && fault_fires(&f[SIM_FAULT_STUCK_ERROR], rng)) {
		ly->stuck(pkt, len, ly->cap, &f[SIM_FAULT_STUCK_ERROR]);
		changed = true;
	}
	if (fault_fires(&f[SIM_FAULT_SLOW], rng)) {
		double ms = f[SIM_FAULT_SLOW].has_arg ? f[SIM_FAULT_SLOW].arg : 5.0;
		/* parsed within range; a caller's own struct is clamped (no cast of a huge double) */
		if (!(ms > 0))
			ms = 0;
		else if (ms > SIM_FAULT_MAX_SLOW_MS)
			ms = SIM_FAULT_MAX_SLOW_MS;
		*extra_delay_ns = (int64_t)(ms * 1e6);
		changed = true;
	}
	if (fault_fires(&f[SIM_FAULT_GARBAGE], rng)) {
		double n = f[SIM_FAULT_GARBAGE].has_arg ? f[SIM_FAULT_GARBAGE].arg : 8;
		*ngarbage = n > SIM_FAULT_MAX_GARBAGE ? SIM_FAULT_MAX_GARBAGE : (n > 0 ? (size_t)n : 0);
		for (size_t i = 0; i < *ngarbage; i++)
			garbage[i] = (uint8_t)sim_rand_next(rng);
		changed = true;
	}
	if (fault_fires(&f[SIM_FAULT_NO_REPLY], rng)) {
		*len = 0;
		fs->applied++;
		return true;
	}
	if (*len >= ly->min_len && fault_fires(&f[SIM_FAULT_WRONG_ID], rng)) {
		ly->wrong_id(pkt, *len, &f[SIM_FAULT_WRONG_ID]);
		changed = true;
	}
	if (*len >= ly->min_len && fault_fires(&f[SIM_FAULT_BAD_CHECKSUM], rng)) {
		ly->bad_checksum(pkt, *len);
		changed = true;
	}
	if (*len > 0 && fault_fires(&f[SIM_FAULT_TRUNCATE], rng)) {
		double a = f[SIM_FAULT_TRUNCATE].arg;
		size_t cut = !f[SIM_FAULT_TRUNCATE].has_arg ? *len / 2 : (a >= (double)*len ? *len : (a > 0 ? (size_t)a : 0));
		*len = cut >= *len ? 1 : *len - cut;
		changed = true;
	}
	if (changed)
		fs->applied++;
	return changed;
}

bool sim_faults_apply(struct sim_faults *fs, uint64_t *rng, uint8_t *pkt, size_t *len,
                      uint8_t *garbage, size_t *ngarbage, int64_t *extra_delay_ns)
{
	static const struct fault_layout p1 = { 6, 0, stuck1, wrong_id1, bad_checksum1 };
	return faults_apply(fs, rng, &p1, pkt, len, garbage, ngarbage, extra_delay_ns);
}

bool sim_faults_apply2(struct sim_faults *fs, uint64_t *rng, uint8_t *pkt, size_t *len, size_t cap,
                       uint8_t *garbage, size_t *ngarbage, int64_t *extra_delay_ns)
{
	struct fault_layout p2 = { DXL2_HEADER_BYTES + 2 + DXL2_CRC_BYTES, cap, stuck2, wrong_id2, bad_checksum2 };
	return faults_apply(fs, rng, &p2, pkt, len, garbage, ngarbage, extra_delay_ns);
}
