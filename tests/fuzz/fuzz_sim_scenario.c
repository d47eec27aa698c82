/*
 * fuzz_sim_scenario.c — libFuzzer target for undulate-sim's scenario parser:
 * arbitrary text as a scenario file (sim_config_load_text, the same path as
 * --scenario after the file checks), then --set overrides, then the checks
 * of sim_config_finish() and the simulator's set-up from the result.
 *
 * Input: the scenario text, optionally followed by a line "%%" and one
 * --set assignment per line ("world.separation=0.4", "robot a.ids=1,2").
 *
 * Invariants (abort() on violation):
 *  - every error message is one NUL-terminated line, non-empty, naming where
 *    ("fuzz:LINE: ..." / "fuzz: ..." for the file, "--set ..." for overrides);
 *  - a refused --set leaves the configuration byte for byte as it was;
 *  - a configuration that finish() accepts has every value in its
 *    documented range (sim-bridge/README.md), robot names, links and IDs
 *    unique, contacts among the IDs, events sorted by time;
 *  - finish() is idempotent;
 *  - the simulator builds from it, and its joint angles and body positions
 *    are finite at the start and after a few physics steps;
 *  - its [events] run through the command language: each gets one "ok ..."
 *    or "error: ..." line (no pty is ever opened).
 *
 *   make fuzz-build && build/fuzz/fuzz_sim_scenario tests/fuzz/seeds/fuzz_sim_scenario
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "dxl.h"
#include "dxl2.h"
#include "../../sim-bridge/sim.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(cond) do { if (!(cond)) abort(); } while (0)

/* Overrides after the scenario: at most this many, as main.c's option table. */
#define FUZZ_MAX_SETS 16

static bool in(double v, double lo, double hi) { return isfinite(v) && v >= lo && v <= hi; }

static bool terminated(const char *s, size_t cap) { return memchr(s, '\0', cap) != NULL; }

/* One line, NUL-terminated inside the buffer, not empty. */
static void check_message(const char *err, size_t cap, const char *prefix)
{
	CHECK(terminated(err, cap));
	CHECK(err[0] != '\0');
	CHECK(strncmp(err, prefix, strlen(prefix)) == 0);
}

static void check_config(const struct sim_config *c)
{
	CHECK(in(c->rate_hz, 100, 20000));
	CHECK(in(c->truth_hz, 1, 1000));
	CHECK(in(c->duration_s, 0, SIM_MAX_DURATION_S));
	CHECK(c->baud == 0 || (c->baud >= 1200 && c->baud <= 4500000));   /* 0: the models' factory rate */
	CHECK(c->nmodels >= 1 && c->nmodels <= SIM_BUS_MAX_SERVOS);
	for (size_t k = 0; k < c->nmodels; k++)
		CHECK((unsigned)c->models[k] < sim_model_count());
	CHECK(in(c->latency_ms, 0, 1000));
	CHECK(c->return_delay_us == -1 || (c->return_delay_us >= 0 && c->return_delay_us <= 508));
	CHECK(in(c->ambient_c, -40, 150) && c->ambient_c > -40 && c->ambient_c < 150);
	CHECK(in(c->initial_spread, 0, 2.5));
	CHECK(in(c->overload_time_s, 0, INFINITY));
	CHECK(terminated(c->lcm_url, sizeof(c->lcm_url)) && terminated(c->link_dir, sizeof(c->link_dir)) &&
	      terminated(c->control, sizeof(c->control)));
	/* [world] */
	CHECK(in(c->world.restitution, 0, 1) && in(c->world.wall_restitution, 0, 1));
	CHECK(in(c->world.beta, 0, INFINITY));
	CHECK(in(c->separation, 0, 100));
	CHECK(in(c->amplitude, 0, 2.6) && c->amplitude > 0);
	CHECK(in(c->spacing, 0, INFINITY));
	CHECK(in(c->lever, 0, 2) && c->lever > 0);
	CHECK(in(c->half_width, 0, INFINITY) && in(c->effective_mass, 0, INFINITY));
	CHECK(c->walls == SIM_WALLS_NONE || c->walls == SIM_WALLS_AUTO || c->walls == SIM_WALLS_FIXED);
	if (c->walls == SIM_WALLS_FIXED)
		CHECK(isfinite(c->world.wall_left) && isfinite(c->world.wall_right) &&
		      c->world.wall_left < c->world.wall_right);
	/* [motor] */
	const struct sim_motor_params *m = &c->motor;
	CHECK(in(m->inertia, 0, INFINITY) && m->inertia > 0);
	CHECK(in(m->viscous, 0, INFINITY) && in(m->coulomb, 0, INFINITY) && in(m->heat_gain, 0, INFINITY));
	CHECK(in(m->stall_torque_12v, 0, INFINITY) && m->stall_torque_12v > 0);
	CHECK(in(m->no_load_speed_12v, 0, INFINITY) && m->no_load_speed_12v > 0);
	CHECK(in(m->thermal_tau_s, 0, INFINITY) && m->thermal_tau_s > 0);
	CHECK(in(m->supply_voltage, 0, 25) && in(m->ambient_c, -40, 150));
	/* robots */
	CHECK(c->nrobots >= 1 && c->nrobots <= SIM_MAX_BUSES);
	size_t bodies = 0;
	for (size_t i = 0; i < c->nrobots; i++) {
		const struct sim_robot_config *r = &c->robots[i];
		CHECK(terminated(r->name, sizeof(r->name)) && r->name[0]);
		CHECK(terminated(r->link, sizeof(r->link)) && r->link[0]);
		CHECK(r->nids >= 1 && r->nids <= SIM_BUS_MAX_SERVOS);
		bool contact_found = r->contact_id == -1;
		for (size_t k = 0; k < r->nids; k++) {
			CHECK(r->ids[k] <= DXL_MAX_ID);
			for (size_t q = 0; q < k; q++)
				CHECK(r->ids[q] != r->ids[k]);
			contact_found |= r->ids[k] == r->contact_id;
		}
		CHECK(contact_found);
		bodies += r->contact_id >= 0;
		CHECK(r->baud == 0 || (r->baud >= 1200 && r->baud <= 4500000));
		CHECK(r->latency_ms == -1 || in(r->latency_ms, 0, 1000));
		CHECK(r->echo >= -1 && r->echo <= 1);
		CHECK(r->return_delay_us == -1 || (r->return_delay_us >= 0 && r->return_delay_us <= 508));
		CHECK(r->servo_baud_reg >= -1 && r->servo_baud_reg <= 254);
		/* one model per ID, one protocol per bus, 2.0's IDs and baud register */
		CHECK(r->nmodels == r->nids);
		int proto = sim_config_robot_protocol(r);
		for (size_t k = 0; k < r->nids; k++) {
			CHECK((unsigned)r->models[k] < sim_model_count() && sim_model_info(r->models[k])->protocol == proto);
			CHECK(proto == 1 || r->ids[k] <= DXL2_MAX_ID);
		}
		CHECK(proto == 1 || r->servo_baud_reg <= 7);
		CHECK(!r->neutral_set || isfinite(r->neutral));
		for (size_t q = 0; q < i; q++) {
			CHECK(strcmp(c->robots[q].name, r->name) != 0);
			CHECK(strcmp(c->robots[q].link, r->link) != 0);
		}
	}
	CHECK(bodies <= SIM_MAX_BODIES);
	/* events */
	CHECK(c->nevents <= SIM_MAX_EVENTS);
	for (size_t i = 0; i < c->nevents; i++) {
		CHECK(in(c->events[i].at, 0, INFINITY));
		CHECK(terminated(c->events[i].command, sizeof(c->events[i].command)));
		if (i > 0)
			CHECK(c->events[i - 1].at <= c->events[i].at);
	}
}

/* The set-up and a few steps: every angle and position stays a number. */
static void check_sim(const struct sim_config *c)
{
	static struct sim s;   /* 3 MB: static */
	char err[256];
	if (sim_init(&s, c, err, sizeof(err)) != 0) {
		/* the only refusal left: a bus rate with no servo rate and no servo_baud */
		check_message(err, sizeof(err), "robot ");
		return;
	}
	for (int step = 0; step < 4; step++) {
		for (size_t i = 0; i < s.nbuses; i++)
			for (size_t k = 0; k < s.buses[i].njoints; k++)
				CHECK(isfinite(s.buses[i].joints[k].motor.angle) && isfinite(s.buses[i].joints[k].motor.speed));
		for (size_t b = 0; b < s.world.nbodies; b++)
			CHECK(isfinite(sim_world_lateral(&s.world, b)));
		sim_step(&s);
	}
	/* The scenario's events through the command language (sim_run_events()
	 * does this, and prints each). Not "reconnect": it would create a pty
	 * and a symlink at a path taken from the input. */
	char reply[512];
	for (size_t i = 0; i < s.cfg.nevents; i++) {
		const char *cmd = s.cfg.events[i].command;
		if (strncmp(cmd + strspn(cmd, " \t"), "reconnect", 9) == 0)
			continue;
		memset(reply, 0x55, sizeof(reply));
		int r = sim_command(&s, cmd, 0, reply, sizeof(reply));
		CHECK(terminated(reply, sizeof(reply)));
		CHECK(strncmp(reply, r == 0 ? "ok" : "error: ", r == 0 ? 2 : 7) == 0);
	}
	for (size_t i = 0; i < s.nbuses; i++)
		CHECK(!sim_bus_connected(&s.buses[i]));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static struct sim_config c, again;
	static char line[SIM_CMD_MAX + SIM_PATH_MAX + 8];
	char err[400];
	const char *text = (const char *)data;
	/* the scenario ends at the first "\n%%\n"; the rest are --set lines */
	size_t ini_len = size;
	for (size_t i = 0; i + 4 <= size; i++)
		if (memcmp(text + i, "\n%%\n", 4) == 0) {
			ini_len = i + 1;
			break;
		}
	sim_config_defaults(&c);
	memset(err, 0x55, sizeof(err));
	bool ok = sim_config_load_text(&c, "fuzz", text, ini_len, err, sizeof(err)) == 0;
	if (!ok)
		check_message(err, sizeof(err), "fuzz:");
	size_t off = ini_len < size ? ini_len + 3 : size;
	for (int n = 0; off < size && n < FUZZ_MAX_SETS; n++) {
		const char *nl = memchr(text + off, '\n', size - off);
		size_t len = (nl ? (size_t)(nl - (text + off)) : size - off);
		size_t keep = len < sizeof(line) - 1 ? len : sizeof(line) - 1;
		memcpy(line, text + off, keep);
		line[keep] = '\0';   /* a C string, as argv: an embedded NUL ends it */
		memset(err, 0x55, sizeof(err));
		memcpy(&again, &c, sizeof(c));
		if (sim_config_set(&c, line, err, sizeof(err)) != 0) {
			check_message(err, sizeof(err), "--set");
			CHECK(memcmp(&again, &c, sizeof(c)) == 0);   /* a refused value changes nothing */
			ok = false;
		}
		off += len + 1;
	}
	/* main.c stops at the first error; going on explores more states */
	(void)ok;
	memset(err, 0x55, sizeof(err));
	if (sim_config_finish(&c, err, sizeof(err)) != 0) {
		CHECK(terminated(err, sizeof(err)) && err[0]);
		return 0;
	}
	check_config(&c);
	memcpy(&again, &c, sizeof(c));
	CHECK(sim_config_finish(&again, err, sizeof(err)) == 0);
	CHECK(memcmp(&again, &c, sizeof(c)) == 0);
	check_sim(&c);
	return 0;
}
