/*
 * scenario.c — INI scenarios, quick form and overrides (see scenario.h).
 */
#include "scenario.h"

#include "num.h"
#include "textfile.h"

#include <ini.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

void sim_config_defaults(struct sim_config *c)
{
	memset(c, 0, sizeof(*c));
	c->rate_hz = 1000;
	c->truth_hz = 100;
	c->seed = 1;
	snprintf(c->link_dir, sizeof(c->link_dir), "/tmp/undulate-sim");
	c->baud = 0;
	c->nmodels = 1;
	c->models[0] = SIM_MODEL_AX12A;
	c->baud_follows_tty = true;
	c->return_delay_us = -1;
	c->ambient_c = 25.0;
	c->initial_spread = 0.5;
	c->eeprom_needs_torque_off = true;
	c->overload_time_s = 0.5;
	c->world.restitution = 0.67;
	c->world.beta = 0;
	c->world.wall_left = c->world.wall_right = 0;
	c->world.wall_restitution = 0.67;
	c->separation = 0.5;
	c->amplitude = 0.8;
	c->lever = 0.1865;
	c->half_width = 0;
	c->effective_mass = 0;
	c->walls = SIM_WALLS_NONE;
	c->world_kind = SIM_WORLD_ROW;
	/* the paper's links; the AX-12A's 32 mm width; 0.12 kg as the row's
	 * link inertia assumes; drag and friction chosen (PHYSICS.md §6) */
	c->plane = (struct plane_params){ .link_length = 0.1865, .link_width = 0.032, .link_mass = 0.12,
					  .friction = 0.2, .drag_tangent = 1.0, .drag_normal = 2.0, .substeps = 2 };
	c->wall_force_max = 20.0;
	sim_motor_default_params(&c->motor);
}

/* ---- value parsers -------------------------------------------------------------- */

/* Values as inih hands them over may carry spaces (a --set value too);
 * common/num.h parses only the bare number. */
static const char *trim(const char *s, char *buf, size_t cap)
{
	while (*s == ' ' || *s == '\t')
		s++;
	size_t n = strlen(s);
	while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t'))
		n--;
	if (n >= cap)
		return "";   /* longer than any number: refused as empty */
	memcpy(buf, s, n);
	buf[n] = '\0';
	return buf;
}

/* A finite double (no inf, nan, hex floats). */
static bool parse_num(const char *s, double *out)
{
	char buf[64];
	return num_parse_double(trim(s, buf, sizeof(buf)), out) == NUM_OK;
}

/* A whole number in [lo, hi]: values stored in integers are parsed as
 * integers, never as a double cast afterwards (1e98 into a uint64 is
 * undefined behaviour, and 1.5 would silently become 1). */
static bool parse_long(const char *s, long lo, long hi, long *out)
{
	char buf[64];
	return num_parse_long(trim(s, buf, sizeof(buf)), lo, hi, out) == NUM_OK;
}

static bool parse_bool(const char *s, bool *out)
{
	if (!strcasecmp(s, "1") || !strcasecmp(s, "true") || !strcasecmp(s, "yes") || !strcasecmp(s, "on"))
		*out = true;
	else if (!strcasecmp(s, "0") || !strcasecmp(s, "false") || !strcasecmp(s, "no") || !strcasecmp(s, "off"))
		*out = false;
	else
		return false;
	return true;
}

int sim_parse_ids(const char *text, uint8_t *ids, size_t cap)
{
	size_t n = 0;
	const char *p = text;
	while (*p) {
		char *end;
		long a = strtol(p, &end, 10), b;
		if (end == p || a < 0 || a > DXL_MAX_ID)
			return -1;
		b = a;
		p = end;
		if (*p == '-') {
			b = strtol(p + 1, &end, 10);
			if (end == p + 1 || b < a || b > DXL_MAX_ID)
				return -1;
			p = end;
		}
		for (long id = a; id <= b; id++) {
			if (n >= cap)
				return -1;
			for (size_t k = 0; k < n; k++)
				if (ids[k] == id)
					return -1;  /* a duplicate ID is a wiring fault, not a config */
			ids[n++] = (uint8_t)id;
		}
		if (*p == ',')
			p++;
		else if (*p)
			return -1;
	}
	return n > 0 ? (int)n : -1;
}

/* "xl430-w250" or "xl430-w250,xm430-w350": one model, or one per ID. */
static int parse_models(const char *v, enum sim_model *models, size_t cap)
{
	char buf[SIM_CMD_MAX];
	size_t n = 0;
	if (strlen(v) >= sizeof(buf))
		return -1;
	strcpy(buf, v);
	for (char *save = NULL, *w = strtok_r(buf, ", \t", &save); w; w = strtok_r(NULL, ", \t", &save)) {
		if (n >= cap || sim_model_parse(w, &models[n]) != 0)
			return -1;
		n++;
	}
	return n > 0 ? (int)n : -1;
}

/* ---- sections ------------------------------------------------------------------- */

#define ERR(...) (snprintf(err, errcap, __VA_ARGS__), -1)

/* Copy a text value whole or not at all: a refused value must leave the
 * setting as it was, not cut short. */
static bool set_text(char *dst, size_t cap, const char *v)
{
	size_t n = strlen(v);
	if (n >= cap)
		return false;
	memcpy(dst, v, n + 1);
	return true;
}

static int set_sim(struct sim_config *c, const char *k, const char *v, char *err, size_t errcap)
{
	double d;
	if (!strcmp(k, "lcm_url"))
		return set_text(c->lcm_url, sizeof(c->lcm_url), v) ? 0 : ERR("lcm_url: too long");
	if (!strcmp(k, "link_dir"))
		return set_text(c->link_dir, sizeof(c->link_dir), v) ? 0 : ERR("link_dir: too long");
	if (!strcmp(k, "control"))
		return set_text(c->control, sizeof(c->control), v) ? 0 : ERR("control: too long");
	if (!strcmp(k, "echo"))
		return parse_bool(v, &c->echo) ? 0 : ERR("echo: want true/false");
	if (!strcmp(k, "indirect")) {
		bool on;
		return parse_bool(v, &on) ? (c->no_indirect = !on, 0) : ERR("indirect: want true/false");
	}
	if (!strcmp(k, "baud_follows_tty"))
		return parse_bool(v, &c->baud_follows_tty) ? 0 : ERR("%s: want true/false", k);
	if (!strcmp(k, "eeprom_needs_torque_off"))
		return parse_bool(v, &c->eeprom_needs_torque_off) ? 0 : ERR("%s: want true/false", k);
	if (!strcmp(k, "model")) {
		enum sim_model m[SIM_BUS_MAX_SERVOS];
		int n = parse_models(v, m, SIM_BUS_MAX_SERVOS);
		if (n < 0)
			return ERR("model: '%s' is not a servo model or a list of them (%s)", v, sim_model_names());
		memcpy(c->models, m, sizeof(m[0]) * (size_t)n);
		c->nmodels = (size_t)n;
		return 0;
	}
	if (!strcmp(k, "seed")) {
		char buf[64];
		uint64_t seed;
		if (num_parse_u64(trim(v, buf, sizeof(buf)), 0, UINT64_MAX, &seed) != NUM_OK)
			return ERR("seed: '%s' is not a whole number 0..18446744073709551615", v);
		c->seed = seed;
		return 0;
	}
	long n;
	if (!strcmp(k, "baud"))
		return parse_long(v, 1200, 4500000, &n) ? (c->baud = n, 0) : ERR("baud: '%s' is not a whole number 1200..4500000", v);
	if (!strcmp(k, "return_delay_us"))
		return parse_long(v, 0, 508, &n) ? (c->return_delay_us = (int)n, 0)
		                                 : ERR("return_delay_us: '%s' is not a whole number 0..508", v);
	if (!strcmp(k, "firmware"))
		return parse_long(v, 1, 255, &n) ? (c->firmware = (int)n, 0)
		                                 : ERR("firmware: '%s' is not a version 1..255", v);
	if (!parse_num(v, &d))
		return ERR("%s: '%s' is not a number", k, v);
	if (!strcmp(k, "rate_hz"))
		return d >= 100 && d <= 20000 ? (c->rate_hz = d, 0) : ERR("rate_hz: 100..20000");
	if (!strcmp(k, "truth_hz"))
		return d >= 1 && d <= 1000 ? (c->truth_hz = d, 0) : ERR("truth_hz: 1..1000");
	/* main.c turns it into int64 nanoseconds: bounded well inside */
	if (!strcmp(k, "duration"))
		return d >= 0 && d <= SIM_MAX_DURATION_S ? (c->duration_s = d, 0) : ERR("duration: 0..%.0f s", SIM_MAX_DURATION_S);
	if (!strcmp(k, "latency_ms"))
		return d >= 0 && d <= 1000 ? (c->latency_ms = d, 0) : ERR("latency_ms: 0..1000");
	if (!strcmp(k, "temperature") || !strcmp(k, "ambient_c"))
		return d > -40 && d < 150 ? (c->ambient_c = d, c->motor.ambient_c = d, 0) : ERR("%s: -40..150", k);
	if (!strcmp(k, "voltage"))
		return d >= 0 && d <= 25 ? (c->motor.supply_voltage = d, 0) : ERR("voltage: 0..25 V");
	if (!strcmp(k, "initial_spread"))
		return d >= 0 && d <= 2.5 ? (c->initial_spread = d, 0) : ERR("initial_spread: 0..2.5 rad");
	if (!strcmp(k, "overload_time"))
		return d >= 0 ? (c->overload_time_s = d, 0) : ERR("overload_time: >= 0 s");
	return ERR("unknown key sim.%s", k);
}

/* LO,HI: two finite numbers, LO < HI (sscanf's %lf used to take "-inf"). */
static bool parse_range(const char *v, double *lo, double *hi)
{
	char first[64];
	const char *comma = strchr(v, ',');
	size_t n = comma ? (size_t)(comma - v) : sizeof(first);
	if (n >= sizeof(first))
		return false;
	memcpy(first, v, n);
	first[n] = '\0';
	return parse_num(first, lo) && parse_num(comma + 1, hi) && *lo < *hi;
}

static int set_walls(struct sim_config *c, const char *v, char *err, size_t errcap)
{
	if (!strcasecmp(v, "none")) {
		c->walls = SIM_WALLS_NONE;
		return 0;
	}
	if (!strcasecmp(v, "auto")) {
		c->walls = SIM_WALLS_AUTO;
		return 0;
	}
	double l, r;
	if (!parse_range(v, &l, &r))
		return ERR("walls: none, auto or LEFT,RIGHT (m, LEFT < RIGHT)");
	c->walls = SIM_WALLS_FIXED;
	c->world.wall_left = l;
	c->world.wall_right = r;
	return 0;
}

/* world.ends = none | BACK,FRONT: walls across the plane robots' length */
static int set_ends(struct sim_config *c, const char *v, char *err, size_t errcap)
{
	if (!strcasecmp(v, "none")) {
		c->ends_set = false;
		return 0;
	}
	double b, f;
	if (!parse_range(v, &b, &f))
		return ERR("ends: none or BACK,FRONT (m along y, BACK < FRONT)");
	c->ends_set = true;
	c->ends_back = b;
	c->ends_front = f;
	return 0;
}

/* The plane world's keys (world.kind = plane); 1 when k is not one. */
static int set_plane(struct sim_config *c, const char *k, double d, char *err, size_t errcap)
{
	struct plane_params *p = &c->plane;
	if (!strcmp(k, "link_length"))
		return d > 0 && d <= 2 ? (p->link_length = d, 0) : ERR("link_length: 0..2 m");
	if (!strcmp(k, "link_width"))
		return d > 0 && d <= 0.5 ? (p->link_width = d, 0) : ERR("link_width: 0..0.5 m");
	if (!strcmp(k, "link_mass"))
		return d > 0 && d <= 50 ? (p->link_mass = d, 0) : ERR("link_mass: 0..50 kg");
	if (!strcmp(k, "friction"))
		return d >= 0 && d <= 5 ? (p->friction = d, 0) : ERR("friction: 0..5");
	if (!strcmp(k, "drag_tangent"))
		return d >= 0 && d <= 1000 ? (p->drag_tangent = d, 0) : ERR("drag_tangent: 0..1000 N s/m per m");
	if (!strcmp(k, "drag_normal"))
		return d >= 0 && d <= 1000 ? (p->drag_normal = d, 0) : ERR("drag_normal: 0..1000 N s/m per m");
	if (!strcmp(k, "wall_force_max"))
		return d >= 0 && d <= 1e4 ? (c->wall_force_max = d, 0) : ERR("wall_force_max: 0..10000 N (0: walls never hold)");
	if (!strcmp(k, "substeps"))
		return d >= 1 && d <= 64 && d == floor(d) ? (p->substeps = (int)d, 0) : ERR("substeps: a whole number 1..64");
	return 1;
}

static int set_world(struct sim_config *c, const char *k, const char *v, char *err, size_t errcap)
{
	double d;
	if (!strcmp(k, "walls"))
		return set_walls(c, v, err, errcap);
	if (!strcmp(k, "ends"))
		return set_ends(c, v, err, errcap);
	if (!strcmp(k, "kind")) {
		if (!strcasecmp(v, "row") || !strcasecmp(v, "plane"))
			return c->world_kind = strcasecmp(v, "row") ? SIM_WORLD_PLANE : SIM_WORLD_ROW, 0;
		return ERR("kind: '%s' is not row (the theory's line) or plane (links in a plane)", v);
	}
	if (!parse_num(v, &d))
		return ERR("%s: '%s' is not a number", k, v);
	if (!strcmp(k, "restitution"))
		return d >= 0 && d <= 1 ? (c->world.restitution = d, 0) : ERR("restitution: 0..1");
	if (!strcmp(k, "wall_restitution"))
		return d >= 0 && d <= 1 ? (c->world.wall_restitution = d, 0) : ERR("wall_restitution: 0..1");
	if (!strcmp(k, "beta"))
		return d >= 0 ? (c->world.beta = d, 0) : ERR("beta: >= 0");
	if (!strcmp(k, "separation"))
		return d >= 0 && d <= 100 ? (c->separation = d, 0) : ERR("separation: 0..100");
	if (!strcmp(k, "amplitude"))
		return d > 0 && d <= 2.6 ? (c->amplitude = d, 0) : ERR("amplitude: 0..2.6 rad");
	if (!strcmp(k, "spacing"))
		return d >= 0 ? (c->spacing = d, 0) : ERR("spacing: >= 0 m");
	if (!strcmp(k, "lever"))
		return d > 0 && d <= 2 ? (c->lever = d, 0) : ERR("lever: 0..2 m/rad");
	if (!strcmp(k, "half_width"))
		return d >= 0 ? (c->half_width = d, 0) : ERR("half_width: >= 0 m");
	if (!strcmp(k, "effective_mass"))
		return d >= 0 ? (c->effective_mass = d, 0) : ERR("effective_mass: >= 0 kg");
	int r = set_plane(c, k, d, err, errcap);
	return r <= 0 ? r : ERR("unknown key world.%s", k);
}

static int set_motor(struct sim_config *c, const char *k, const char *v, char *err, size_t errcap)
{
	double d;
	struct sim_motor_params *m = &c->motor;
	if (!strcmp(k, "drive")) {
		if (!strcmp(v, "pwm") || !strcmp(v, "current")) {
			m->current_drive = !strcmp(v, "current");
			c->motor_set |= SIM_MOTOR_SET_DRIVE;
			return 0;
		}
		return ERR("motor.drive: '%s' is not pwm or current", v);
	}
	if (!parse_num(v, &d) || d < 0)
		return ERR("motor.%s: '%s' is not a number >= 0", k, v);
	unsigned set;
	if (!strcmp(k, "inertia") && d > 0) m->inertia = d, set = SIM_MOTOR_SET_INERTIA;
	else if (!strcmp(k, "viscous")) m->viscous = d, set = SIM_MOTOR_SET_VISCOUS;
	else if (!strcmp(k, "coulomb")) m->coulomb = d, set = SIM_MOTOR_SET_COULOMB;
	else if (!strcmp(k, "stall_torque") && d > 0) m->stall_torque_12v = d, set = SIM_MOTOR_SET_STALL_TORQUE;
	else if (!strcmp(k, "no_load_speed") && d > 0) m->no_load_speed_12v = d, set = SIM_MOTOR_SET_NO_LOAD_SPEED;
	else if (!strcmp(k, "thermal_tau") && d > 0) m->thermal_tau_s = d, set = SIM_MOTOR_SET_THERMAL_TAU;
	else if (!strcmp(k, "heat_gain")) m->heat_gain = d, set = SIM_MOTOR_SET_HEAT_GAIN;
	else return ERR("unknown or invalid key motor.%s", k);
	c->motor_set |= set;
	return 0;
}

static struct sim_robot_config *robot_named(struct sim_config *c, const char *name, bool create)
{
	for (size_t i = 0; i < c->nrobots; i++)
		if (!strcmp(c->robots[i].name, name))
			return &c->robots[i];
	if (!create || c->nrobots >= SIM_MAX_BUSES || !*name || strlen(name) >= SIM_NAME_MAX)
		return NULL;
	struct sim_robot_config *r = &c->robots[c->nrobots++];
	memset(r, 0, sizeof(*r));
	snprintf(r->name, sizeof(r->name), "%s", name);
	r->contact_id = -2;
	r->latency_ms = -1;
	r->echo = -1;
	r->return_delay_us = -1;
	r->servo_baud_reg = -1;
	return r;
}

static int robot_key(struct sim_robot_config *r, const char *name, const char *k, const char *v, char *err,
                     size_t errcap)
{
	double d;
	bool b;
	if (!strcmp(k, "link"))
		return set_text(r->link, sizeof(r->link), v) ? 0 : ERR("link: too long");
	if (!strcmp(k, "ids")) {
		uint8_t ids[SIM_BUS_MAX_SERVOS];   /* the old list stays if the new one is bad */
		int n = sim_parse_ids(v, ids, SIM_BUS_MAX_SERVOS);
		if (n <= 0)
			return ERR("ids: want e.g. 1,2 (0..253, no duplicates, max %d)", SIM_BUS_MAX_SERVOS);
		memcpy(r->ids, ids, (size_t)n);
		r->nids = (size_t)n;
		return 0;
	}
	long n;
	if (!strcmp(k, "contact")) {
		if (!strcasecmp(v, "none"))
			return r->contact_id = -1, 0;
		return parse_long(v, 0, DXL_MAX_ID, &n) ? (r->contact_id = (int)n, 0) : ERR("contact: '%s' is not an ID 0..253 or none", v);
	}
	if (!strcmp(k, "echo"))
		return parse_bool(v, &b) ? (r->echo = b, 0) : ERR("echo: true/false");
	if (!strcmp(k, "mirror"))
		return parse_bool(v, &r->mirror) ? 0 : ERR("mirror: true/false");
	if (!strcmp(k, "model")) {
		enum sim_model m[SIM_BUS_MAX_SERVOS];
		int nm = parse_models(v, m, SIM_BUS_MAX_SERVOS);
		if (nm < 0)
			return ERR("model: '%s' is not a servo model or a list of them (%s)", v, sim_model_names());
		memcpy(r->models, m, sizeof(m[0]) * (size_t)nm);
		r->nmodels = (size_t)nm;
		return 0;
	}
	if (!strcmp(k, "baud"))
		return parse_long(v, 1200, 4500000, &n) ? (r->baud = n, 0) : ERR("baud: '%s' is not a whole number 1200..4500000", v);
	if (!strcmp(k, "return_delay_us"))
		return parse_long(v, 0, 508, &n) ? (r->return_delay_us = (int)n, 0)
		                                 : ERR("return_delay_us: '%s' is not a whole number 0..508", v);
	if (!strcmp(k, "firmware"))
		return parse_long(v, 1, 255, &n) ? (r->firmware = (int)n, 0)
		                                 : ERR("firmware: '%s' is not a version 1..255", v);
	if (!strcmp(k, "position")) {
		double x, y;
		char first[64];
		const char *comma = strchr(v, ',');
		size_t len = comma ? (size_t)(comma - v) : sizeof(first);
		if (len < sizeof(first)) {
			memcpy(first, v, len);
			first[len] = '\0';
		}
		if (len >= sizeof(first) || !parse_num(first, &x) || !parse_num(comma + 1, &y) || fabs(x) > 1e3 ||
		    fabs(y) > 1e3)
			return ERR("position: X,Y in metres (the plane world), each within +-1000");
		r->position_set = true;
		r->x = x;
		r->y = y;
		return 0;
	}
	if (!strcmp(k, "servo_baud"))
		return parse_long(v, 0, 254, &n) ? (r->servo_baud_reg = (int)n, 0)
		                                 : ERR("servo_baud: '%s' is not a register value 0..254 (X series: 0..7)", v);
	if (!parse_num(v, &d))
		return ERR("robot.%s: '%s' is not a number", k, v);
	if (!strcmp(k, "neutral"))
		return r->neutral_set = true, r->neutral = d, 0;
	if (!strcmp(k, "heading"))
		return fabs(d) <= 360 ? (r->heading_set = true, r->heading = d * M_PI / 180.0, 0)
		                      : ERR("heading: -360..360 degrees");
	if (!strcmp(k, "latency_ms"))
		return d >= 0 && d <= 1000 ? (r->latency_ms = d, 0) : ERR("latency_ms: 0..1000");
	if (!strcmp(k, "beta"))
		return d >= 0 ? (r->beta_set = true, r->beta = d, 0) : ERR("beta: >= 0 s (0: this robot's base does not move)");
	return ERR("unknown key %s.%s", name, k);
}

static int set_robot(struct sim_config *c, const char *name, const char *k, const char *v, char *err, size_t errcap)
{
	size_t had = c->nrobots;
	struct sim_robot_config *r = robot_named(c, name, true);
	if (!r)
		return ERR("robot '%s': too many robots (max %d) or bad name", name, SIM_MAX_BUSES);
	if (robot_key(r, name, k, v, err, errcap) == 0)
		return 0;
	/* a robot the bad assignment would have created is not kept */
	if (c->nrobots > had) {
		memset(r, 0, sizeof(*r));
		c->nrobots = had;
	}
	return -1;
}

static int set_event(struct sim_config *c, const char *k, const char *v, char *err, size_t errcap)
{
	double at;
	if (!parse_num(k, &at) || at < 0)
		return ERR("event key '%s': want a time in seconds", k);
	if (c->nevents >= SIM_MAX_EVENTS)
		return ERR("too many events (max %d)", SIM_MAX_EVENTS);
	struct sim_event *e = &c->events[c->nevents];
	if (snprintf(e->command, sizeof(e->command), "%s", v) >= (int)sizeof(e->command))
		return ERR("event command too long");
	e->at = at;
	c->nevents++;
	return 0;
}

static int config_set(struct sim_config *c, const char *section, const char *k, const char *v, char *err,
                      size_t errcap)
{
	if (!strcmp(section, "sim"))
		return set_sim(c, k, v, err, errcap);
	if (!strcmp(section, "world"))
		return set_world(c, k, v, err, errcap);
	if (!strcmp(section, "motor"))
		return set_motor(c, k, v, err, errcap);
	if (!strcmp(section, "events") || !strcmp(section, "faults"))
		return set_event(c, k, v, err, errcap);
	if (!strncmp(section, "robot ", 6))
		return set_robot(c, section + 6, k, v, err, errcap);
	return ERR("unknown section [%s]", section);
}

struct load_ctx {
	struct sim_config *c;
	char *err;
	size_t errcap;
	int failed;
};

static int ini_cb(void *user, const char *section, const char *name, const char *value)
{
	struct load_ctx *x = user;
	if (x->failed)
		return 0;
	if (config_set(x->c, section, name, value, x->err, x->errcap) != 0) {
		x->failed = 1;
		return 0;
	}
	return 1;
}

/* Hands inih one line at a time from the scenario text in memory, and drops
 * the rest of a line longer than inih's buffer: inih would parse that rest as
 * lines of its own (the tail of a long comment becomes a key) and number
 * every line after it wrong. */
struct line_reader {
	const char *p, *end;
	int line;
	int long_line;   /* first line too long, 0 if none */
	int cap;         /* the longest line inih reads */
};

static char *read_line(char *str, int num, void *stream)
{
	struct line_reader *r = stream;
	if (r->p >= r->end || num < 2)
		return NULL;
	const char *nl = memchr(r->p, '\n', (size_t)(r->end - r->p));
	const char *eol = nl ? nl + 1 : r->end;   /* the line with its newline */
	size_t len = (size_t)(eol - r->p);
	r->line++;
	if (len > (size_t)num - 1) {
		len = (size_t)num - 1;
		if (r->long_line == 0) {
			r->long_line = r->line;
			r->cap = num - 1;
		}
	}
	memcpy(str, r->p, len);
	str[len] = '\0';
	r->p = eol;
	return str;
}

int sim_config_load_text(struct sim_config *c, const char *name, const char *text, size_t len, char *err,
                         size_t errcap)
{
	struct load_ctx x = { c, err, errcap, 0 };
	char why[200] = "";
	x.err = why;
	x.errcap = sizeof(why);
	/* inih sees C strings: a NUL would silently end a line early. */
	const char *nul = memchr(text, '\0', len);
	if (nul) {
		int line = 1;
		for (const char *q = text; q < nul; q++)
			line += *q == '\n';
		return ERR("%s:%d: a NUL byte: a scenario is a text file", name, line);
	}
	struct line_reader rd = { .p = text, .end = text + len };
	int r = ini_parse_stream(read_line, &rd, ini_cb, &x);
	/* the first problem wins: a long line, or an error before it */
	if (rd.long_line > 0 && (r <= 0 || r >= rd.long_line))
		return ERR("%s:%d: line too long (at most %d characters)", name, rd.long_line, rd.cap);
	if (r > 0)
		return ERR("%s:%d: %s", name, r, why[0] ? why : "syntax error");
	if (r < 0)
		return ERR("%s: cannot parse (out of memory)", name);
	return 0;
}

/* A scenario is a regular file of bounded size, read whole (common/textfile.h). */
int sim_config_load(struct sim_config *c, const char *path, char *err, size_t errcap)
{
	size_t len;
	char *text = textfile_read(path, "a scenario", &len, err, errcap);
	if (text == NULL)
		return -1;
	int r = sim_config_load_text(c, path, text, len, err, errcap);
	free(text);
	return r;
}

int sim_config_set(struct sim_config *c, const char *assignment, char *err, size_t errcap)
{
	char buf[SIM_CMD_MAX + SIM_PATH_MAX];
	if (strlen(assignment) >= sizeof(buf))
		return ERR("--set: too long");
	strcpy(buf, assignment);
	char *eq = strchr(buf, '=');
	if (!eq)
		return ERR("--set '%s': want section.key=value", assignment);
	*eq = '\0';
	/* section.key, split at the last dot (a robot's name may hold dots),
	 * except in [events] and [faults], whose keys are times: 2.5 s */
	bool timed = !strncmp(buf, "events.", 7) || !strncmp(buf, "faults.", 7);
	char *dot = timed ? buf + 6 : strrchr(buf, '.');
	if (!dot || dot == buf || !dot[1])
		return ERR("--set '%s': want section.key=value", assignment);
	*dot = '\0';
	char why[200] = "";
	if (config_set(c, buf, dot + 1, eq + 1, why, sizeof(why)) != 0)
		return ERR("--set %s: %s", assignment, why);
	return 0;
}

int sim_config_add_robot(struct sim_config *c, const char *name, const char *link, const char *ids, char *err,
                         size_t errcap)
{
	if (robot_named(c, name, false))
		return ERR("robot '%s' twice", name);
	if (set_robot(c, name, "ids", ids, err, errcap) != 0)
		return -1;
	return set_robot(c, name, "link", link, err, errcap);
}

/* One model per ID, all speaking one protocol: a bus speaks one. */
static int finish_models(const struct sim_config *c, struct sim_robot_config *r, char *err, size_t errcap)
{
	const enum sim_model *m = r->nmodels ? r->models : c->models;
	size_t n = r->nmodels ? r->nmodels : c->nmodels;
	if (n != 1 && n != r->nids)
		return ERR("robot %s: %zu models for %zu servos (give one model, or one per ID)", r->name, n, r->nids);
	enum sim_model all[SIM_BUS_MAX_SERVOS];
	for (size_t k = 0; k < r->nids; k++)
		all[k] = m[n == 1 ? 0 : k];
	for (size_t k = 1; k < r->nids; k++) {
		const struct sim_model_info *a = sim_model_info(all[0]), *b = sim_model_info(all[k]);
		if (a->protocol != b->protocol)
			return ERR("robot %s: servo %u (%s, Protocol %d.0) and servo %u (%s, Protocol %d.0) cannot share "
			           "a bus: a bus speaks one protocol (give the robot one protocol's models, or two robots)",
			           r->name, r->ids[0], a->label, a->protocol, r->ids[k], b->label, b->protocol);
	}
	memcpy(r->models, all, sizeof(all[0]) * r->nids);
	r->nmodels = r->nids;
	/* the parser took IDs 0..253 and registers 0..254: a family's own limits */
	const struct sim_joint_ops *ops = sim_joint_ops_of(all[0]);
	for (size_t k = 0; k < r->nids; k++)
		if (r->ids[k] > ops->max_id)
			return ERR("robot %s: ID %u: Protocol %s IDs are 0..%d", r->name, r->ids[k], ops->proto->name,
			           ops->max_id);
	if (r->servo_baud_reg > ops->max_baud_reg)
		return ERR("robot %s: servo_baud %d: the %s' Baud Rate register is 0..%d", r->name, r->servo_baud_reg,
		           ops->family, ops->max_baud_reg);
	return 0;
}

int sim_config_robot_protocol(const struct sim_robot_config *r)
{
	return r->nmodels ? sim_model_info(r->models[0])->protocol : 1;
}

void sim_config_motor_params(const struct sim_config *c, enum sim_model m, struct sim_motor_params *p)
{
	const struct sim_motor_params *g = &c->motor;
	if (sim_joint_ops_of(m)->motor_from_config) {
		*p = *g;
		return;
	}
	sim_model_motor_params(m, p);
	unsigned set = c->motor_set;
	if (set & SIM_MOTOR_SET_INERTIA) p->inertia = g->inertia;
	if (set & SIM_MOTOR_SET_VISCOUS) p->viscous = g->viscous;
	if (set & SIM_MOTOR_SET_COULOMB) p->coulomb = g->coulomb;
	if (set & SIM_MOTOR_SET_STALL_TORQUE) p->stall_torque_12v = g->stall_torque_12v;
	if (set & SIM_MOTOR_SET_NO_LOAD_SPEED) p->no_load_speed_12v = g->no_load_speed_12v;
	if (set & SIM_MOTOR_SET_THERMAL_TAU) p->thermal_tau_s = g->thermal_tau_s;
	if (set & SIM_MOTOR_SET_HEAT_GAIN) p->heat_gain = g->heat_gain;
	if (set & SIM_MOTOR_SET_DRIVE) p->current_drive = g->current_drive;
	p->supply_voltage = g->supply_voltage;
	p->ambient_c = g->ambient_c;
}

static int finish_robot(struct sim_config *c, struct sim_robot_config *r, char *err, size_t errcap)
{
	if (r->nids == 0)
		return ERR("robot %s: no ids", r->name);
	if (finish_models(c, r, err, errcap) != 0)
		return -1;
	if (!r->link[0] && snprintf(r->link, sizeof(r->link), "%s/%s", c->link_dir, r->name) >= (int)sizeof(r->link))
		return ERR("robot %s: link path too long", r->name);
	if (r->contact_id == -2)
		r->contact_id = r->ids[r->nids - 1];
	if (r->contact_id >= 0) {
		bool found = false;
		for (size_t k = 0; k < r->nids; k++)
			found |= r->ids[k] == r->contact_id;
		if (!found)
			return ERR("robot %s: contact %d is not one of its ids", r->name, r->contact_id);
	}
	for (size_t i = 0; i < c->nrobots; i++)
		if (&c->robots[i] != r && !strcmp(c->robots[i].link, r->link))
			return ERR("robots %s and %s share the link %s", c->robots[i].name, r->name, r->link);
	return 0;
}

int sim_config_finish(struct sim_config *c, char *err, size_t errcap)
{
	if (c->nrobots == 0)
		return ERR("no robots: give --link PATH --ids 1,2 or a scenario with [robot NAME] sections");
	size_t bodies = 0;
	for (size_t i = 0; i < c->nrobots; i++) {
		if (finish_robot(c, &c->robots[i], err, errcap) != 0)
			return -1;
		bodies += c->robots[i].contact_id >= 0;
	}
	if (bodies > SIM_MAX_BODIES)
		return ERR("too many contact bodies (max %d)", SIM_MAX_BODIES);
	for (size_t i = 1; i < c->nevents; i++)  /* stable order by time */
		for (size_t j = i; j > 0 && c->events[j - 1].at > c->events[j].at; j--) {
			struct sim_event t = c->events[j];
			c->events[j] = c->events[j - 1];
			c->events[j - 1] = t;
		}
	return 0;
}
