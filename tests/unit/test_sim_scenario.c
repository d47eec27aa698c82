/*
 * test_sim_scenario.c — scenarios (INI, overrides, errors), the simulator's
 * set-up (row layout, walls, seeded initial angles), the command language
 * and physics steps that make two driven bodies collide.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "dxl_table.h"
#include "../../sim-bridge/sim.h"

static const char pair_ini[] =
	"# a pair\n"
	"[sim]\nseed = 5\nrate_hz = 1000\n"
	"[world]\nrestitution = 0.67\nseparation = 0.4\namplitude = 0.8\nlever = 0.2\nwalls = auto\n"
	"[robot left]\nids = 1\n"
	"[robot right]\nids = 1\ncontact = 1\nlatency_ms = 16\n"
	"[events]\n1.0 = fault right 1 no-reply\n0.5 = fault left 1 slow 2\n";

static char path[64];

static int write_file(const char *text)
{
	snprintf(path, sizeof(path), "/tmp/test_sim_scenario.XXXXXX");
	int fd = mkstemp(path);
	if (fd < 0)
		return -1;
	size_t n = strlen(text);
	int ok = write(fd, text, n) == (ssize_t)n;
	close(fd);
	return ok ? 0 : -1;
}

static int load(struct sim_config *c, const char *text, char *err, size_t cap)
{
	sim_config_defaults(c);
	assert_int_equal(write_file(text), 0);
	int r = sim_config_load(c, path, err, cap);
	unlink(path);
	return r;
}

static struct sim_config cfg;
static struct sim sim;

static void test_load_pair(void **state)
{
	(void)state;
	char err[256];
	assert_int_equal(load(&cfg, pair_ini, err, sizeof(err)), 0);
	assert_int_equal(sim_config_set(&cfg, "world.separation=0.25", err, sizeof(err)), 0);
	assert_int_equal(sim_config_set(&cfg, "sim.link_dir=/tmp/x", err, sizeof(err)), 0);
	assert_int_equal(sim_config_finish(&cfg, err, sizeof(err)), 0);
	assert_int_equal(cfg.nrobots, 2);
	assert_string_equal(cfg.robots[0].link, "/tmp/x/left");
	assert_int_equal(cfg.robots[0].contact_id, 1);  /* default: the last ID */
	assert_true(cfg.robots[1].latency_ms == 16);
	assert_int_equal(cfg.seed, 5);
	/* events come out sorted by time */
	assert_int_equal(cfg.nevents, 2);
	assert_true(cfg.events[0].at == 0.5);
	assert_string_equal(cfg.events[1].command, "fault right 1 no-reply");

	assert_int_equal(sim_init(&sim, &cfg, err, sizeof(err)), 0);
	assert_int_equal(sim.world.nbodies, 2);
	/* d = d̃ · 2 · lever · A = 0.25 · 2 · 0.2 · 0.8 = 0.08 m, centred on 0 */
	assert_float_equal(sim.world.bodies[0].neutral, -0.04, 1e-12);
	assert_float_equal(sim.world.bodies[1].neutral, 0.04, 1e-12);
	/* auto walls: half a spacing beyond each end */
	assert_float_equal(sim.world.params.wall_left, -0.08, 1e-12);
	assert_float_equal(sim.world.params.wall_right, 0.08, 1e-12);
	assert_float_equal(sim.world.params.restitution, 0.67, 1e-12);
	/* no body starts inside its neighbour */
	assert_true(sim_world_lateral(&sim.world, 0) <= sim_world_lateral(&sim.world, 1));
	/* the servo starts with goal = present, torque off */
	struct sim_servo *s = &sim.buses[1].joints[0].servo;
	assert_int_equal(sim_servo_peek(s, DXL_AX_GOAL_POSITION), sim_servo_peek(s, DXL_AX_PRESENT_POSITION));
	assert_int_equal(s->mem[DXL_AX_TORQUE_ENABLE], 0);
}

static void test_config_errors(void **state)
{
	(void)state;
	char err[256];
	assert_int_equal(load(&cfg, "[world]\nrestitution = 1.5\n", err, sizeof(err)), -1);
	assert_non_null(strstr(err, ":2:"));
	assert_non_null(strstr(err, "restitution"));
	assert_int_equal(load(&cfg, "[nonsense]\nx = 1\n", err, sizeof(err)), -1);
	assert_non_null(strstr(err, "unknown section"));
	assert_int_equal(load(&cfg, "[robot a]\nids = 1,1\n", err, sizeof(err)), -1);
	assert_int_equal(load(&cfg, "[robot a]\nids = 300\n", err, sizeof(err)), -1);
	assert_int_equal(load(&cfg, "[robot a]\nids = 1,2\ncontact = 3\n", err, sizeof(err)), 0);
	assert_int_equal(sim_config_finish(&cfg, err, sizeof(err)), -1);
	assert_non_null(strstr(err, "contact 3"));
	assert_int_equal(load(&cfg, "[events]\nsoon = help\n", err, sizeof(err)), -1);
	sim_config_defaults(&cfg);
	assert_int_equal(sim_config_finish(&cfg, err, sizeof(err)), -1);  /* no robots */
	assert_int_equal(sim_config_set(&cfg, "nodot=1", err, sizeof(err)), -1);
	assert_int_equal(sim_config_set(&cfg, "sim.rate_hz", err, sizeof(err)), -1);
	assert_int_equal(sim_config_set(&cfg, "sim.rate_hz=abc", err, sizeof(err)), -1);
	assert_int_equal(sim_config_set(&cfg, "world.walls=3,1", err, sizeof(err)), -1);
	assert_int_equal(sim_config_set(&cfg, "world.walls=-1,1", err, sizeof(err)), 0);
	/* an event's key is its time, which may hold a dot: the section is
	 * "events", the key "2.5" (scripts/demo.sh --lockstep --switch-at 2.5) */
	size_t had = cfg.nevents;
	assert_int_equal(sim_config_set(&cfg, "events.2.5=command * mode oscillator", err, sizeof(err)), 0);
	assert_int_equal(cfg.nevents, had + 1);
	assert_true(cfg.events[had].at == 2.5);
	assert_string_equal(cfg.events[had].command, "command * mode oscillator");
	assert_int_equal(sim_config_set(&cfg, "faults.0.25=fault left 1 no-reply", err, sizeof(err)), 0);
	assert_true(cfg.events[had + 1].at == 0.25);
	assert_int_equal(sim_config_set(&cfg, "events.soon.5=stats", err, sizeof(err)), -1);
	assert_non_null(strstr(err, "time in seconds"));
	/* wheel-mode drive: pwm (AX-12A) or current, nothing else */
	assert_false(cfg.motor.current_drive);
	assert_int_equal(sim_config_set(&cfg, "motor.drive=current", err, sizeof(err)), 0);
	assert_true(cfg.motor.current_drive);
	assert_int_equal(sim_config_set(&cfg, "motor.drive=torque", err, sizeof(err)), -1);
	assert_non_null(strstr(err, "pwm or current"));
	assert_true(cfg.motor.current_drive);
	assert_int_equal(sim_config_set(&cfg, "motor.drive=pwm", err, sizeof(err)), 0);
	assert_false(cfg.motor.current_drive);
	assert_int_equal(cfg.walls, SIM_WALLS_FIXED);
	uint8_t ids[8];
	assert_int_equal(sim_parse_ids("1-3,7", ids, 8), 4);
	assert_int_equal(ids[3], 7);
	assert_int_equal(sim_parse_ids("", ids, 8), -1);
	assert_int_equal(sim_parse_ids("1,,2", ids, 8), -1);
}

static void quick(struct sim_config *c, uint64_t seed)
{
	char err[256];
	sim_config_defaults(c);
	c->seed = seed;
	assert_int_equal(sim_config_add_robot(c, "a", "/tmp/none/a", "1,2", err, sizeof(err)), 0);
	assert_int_equal(sim_config_add_robot(c, "b", "/tmp/none/b", "1,2", err, sizeof(err)), 0);
	assert_int_equal(sim_config_finish(c, err, sizeof(err)), 0);
}

/* A line longer than the INI parser reads is an error of its own line; the
 * tail of a long comment is never parsed as a key, and lines before it keep
 * their numbers. */
static void test_long_line(void **state)
{
	(void)state;
	static char text[2048];
	char pad[600];
	memset(pad, 'x', sizeof(pad) - 1);
	pad[sizeof(pad) - 1] = '\0';
	char err[256];
	snprintf(text, sizeof(text), "[sim]\nrate_hz = 1000 ; %s = 5\n[world]\nrestitution = 0.5\n", pad);
	assert_int_equal(load(&cfg, text, err, sizeof(err)), -1);
	assert_non_null(strstr(err, ":2: line too long"));
	snprintf(text, sizeof(text), "[world]\nrestitution = 7\n; %s\n", pad);
	assert_int_equal(load(&cfg, text, err, sizeof(err)), -1);
	assert_non_null(strstr(err, ":2:"));
	assert_non_null(strstr(err, "restitution"));
}

/* Only a regular file of at most 1 MiB is a scenario: a directory, a device,
 * a FIFO, a huge file or NUL bytes get "PATH: why" and load nothing. (A FIFO
 * with no writer would block open() without O_NONBLOCK; it is checked here
 * before opening, and end to end in sim_scenario_file.sh under a timeout.) */
static void test_scenario_files(void **state)
{
	(void)state;
	char err[256];
	sim_config_defaults(&cfg);
	assert_int_equal(sim_config_load(&cfg, "/tmp", err, sizeof(err)), -1);
	assert_string_equal(err, "/tmp: not a regular file (a directory): a scenario is a text file");
	assert_int_equal(sim_config_load(&cfg, "/dev/null", err, sizeof(err)), -1);
	assert_non_null(strstr(err, "/dev/null: not a regular file (a character device)"));
	assert_int_equal(sim_config_load(&cfg, "/dev/zero", err, sizeof(err)), -1);
	assert_non_null(strstr(err, "/dev/zero: not a regular file"));
	char fifo[] = "/tmp/test_sim_scenario.fifo.XXXXXX";
	int tfd = mkstemp(fifo);
	assert_true(tfd >= 0);
	close(tfd);
	unlink(fifo);
	assert_int_equal(mkfifo(fifo, 0600), 0);
	assert_int_equal(sim_config_load(&cfg, fifo, err, sizeof(err)), -1);
	unlink(fifo);
	assert_non_null(strstr(err, "(a FIFO)"));
	assert_int_equal(sim_config_load(&cfg, "/nonexistent/x.scenario", err, sizeof(err)), -1);
	assert_non_null(strstr(err, "/nonexistent/x.scenario: cannot open: No such file"));
	/* one byte over 1 MiB (a sparse file: nothing is written) */
	assert_int_equal(write_file("[robot a]\nids = 1\n"), 0);
	assert_int_equal(truncate(path, SIM_SCENARIO_MAX_BYTES + 1), 0);
	assert_int_equal(sim_config_load(&cfg, path, err, sizeof(err)), -1);
	assert_non_null(strstr(err, "larger than 1 MiB"));
	/* exactly 1 MiB: the NUL padding is refused, with its line */
	assert_int_equal(truncate(path, SIM_SCENARIO_MAX_BYTES), 0);
	assert_int_equal(sim_config_load(&cfg, path, err, sizeof(err)), -1);
	assert_non_null(strstr(err, ":3: a NUL byte"));
	unlink(path);
	assert_int_equal(cfg.nrobots, 0);  /* nothing was loaded by any of these */
	/* the same text from memory, without a terminating NUL */
	static const char text[] = "[robot a]\nids = 1,2\n[sim]\nseed = 9";
	assert_int_equal(sim_config_load_text(&cfg, "mem", text, sizeof(text) - 1, err, sizeof(err)), 0);
	assert_int_equal(cfg.nrobots, 1);
	assert_int_equal(cfg.robots[0].nids, 2);
	assert_int_equal(cfg.seed, 9);
	assert_int_equal(sim_config_load_text(&cfg, "mem", "[world]\nbeta = -1\n", 18, err, sizeof(err)), -1);
	assert_string_equal(err, "mem:2: beta: >= 0");
	/* a robot's own mobility (the paper's fixed ends: beta = 0 for them) */
	static const char own[] = "[world]\nbeta = 0.05\n[robot a]\nids = 1,2\nbeta = 0\n[robot b]\nids = 1,2\n"
	                          "[robot c]\nids = 1,2\nbeta = 0.2\n";
	assert_int_equal(sim_config_load_text(&cfg, "mem", own, sizeof(own) - 1, err, sizeof(err)), 0);
	assert_int_equal(sim_config_finish(&cfg, err, sizeof(err)), 0);
	assert_int_equal(sim_init(&sim, &cfg, err, sizeof(err)), 0);
	assert_true(sim.world.bodies[0].own_beta && sim.world.bodies[0].beta == 0);
	assert_false(sim.world.bodies[1].own_beta);
	assert_true(sim.world.bodies[2].own_beta && sim.world.bodies[2].beta == 0.2);
	sim_free(&sim);
	static const char neg[] = "[robot a]\nids = 1,2\nbeta = -0.1\n";
	assert_int_equal(sim_config_load_text(&cfg, "mem", neg, sizeof(neg) - 1, err, sizeof(err)), -1);
	assert_string_equal(err, "mem:3: beta: >= 0 s (0: this robot's base does not move)");
}

/* Numbers that end up in integers are parsed as integers, in range: a double
 * like 1e98 cast to the seed's uint64 was undefined behaviour (found by UBSan
 * fuzzing), and 1.5 was silently cut to 1. */
static void test_integer_values(void **state)
{
	(void)state;
	char err[256];
	sim_config_defaults(&cfg);
	const char *bad[] = {
		"sim.seed=1e98", "sim.seed=-1", "sim.seed=1.5", "sim.seed=nan", "sim.seed=inf",
		"sim.seed=18446744073709551616", "sim.seed=", "sim.seed=0x", "sim.seed=5x",
		"sim.baud=1e300", "sim.baud=57600.5", "sim.return_delay_us=3.5", "sim.return_delay_us=1e300",
		"sim.duration=1e300", "robot a.contact=1.5", "robot a.contact=1e300", "robot a.baud=1e98",
		"robot a.return_delay_us=-1", "robot a.servo_baud=3.5", "robot a.servo_baud=1e300",
	};
	for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
		err[0] = '\0';
		if (sim_config_set(&cfg, bad[i], err, sizeof(err)) != -1)
			fail_msg("'%s' accepted", bad[i]);
		assert_non_null(strstr(err, bad[i]));  /* the message quotes it */
	}
	assert_int_equal(cfg.seed, 1);  /* unchanged by all of these */
	assert_int_equal(sim_config_set(&cfg, "sim.seed=18446744073709551615", err, sizeof(err)), 0);
	assert_true(cfg.seed == UINT64_MAX);
	assert_int_equal(sim_config_set(&cfg, "sim.seed=0x10", err, sizeof(err)), 0);
	assert_int_equal(cfg.seed, 16);
	assert_int_equal(sim_config_set(&cfg, "sim.seed=9007199254740993", err, sizeof(err)), 0);
	assert_true(cfg.seed == 9007199254740993ull);  /* exact, beyond a double's 2^53 */
	assert_int_equal(sim_config_set(&cfg, "sim.seed= 7 ", err, sizeof(err)), 0);  /* spaces as in a file */
	assert_int_equal(cfg.seed, 7);
	assert_int_equal(sim_config_set(&cfg, "sim.baud=57600", err, sizeof(err)), 0);
	assert_int_equal(cfg.baud, 57600);
	assert_int_equal(sim_config_set(&cfg, "sim.duration=3600.5", err, sizeof(err)), 0);
	assert_int_equal(sim_config_set(&cfg, "robot a.contact=none", err, sizeof(err)), 0);
	assert_int_equal(sim_config_set(&cfg, "robot a.contact=2", err, sizeof(err)), 0);
	assert_int_equal(cfg.robots[0].contact_id, 2);
	/* in a file: the line of the bad value */
	assert_int_equal(load(&cfg, "[sim]\nrate_hz = 1000\nseed = 1e98\n", err, sizeof(err)), -1);
	assert_non_null(strstr(err, ":3: seed"));

	/* command arguments that become integers or times */
	char reply[512];
	quick(&cfg, 1);
	assert_int_equal(sim_init(&sim, &cfg, err, sizeof(err)), 0);
	const char *bads[] = {
		"fault a 1 truncate 1e300", "fault a 1 truncate 2.5", "fault a 1 slow 1e300", "fault a 1 wrong-id 1e300",
		"fault a 1 wrong-id 254", "fault a 1 garbage 1e300", "fault a 1 garbage 65", "fault a 1 no-reply count=1.5",
		"fault a 1 no-reply count=1e300", "fault a 1 temperature 1e300", "fault a 1 voltage 1e300",
		"peek a 257 goal_position", "peek a 1x goal_position", "poke a 257 led 1", "servo a 257", "servo a -255",
		"poke a 1 led 1x", "garbage a 5x", "garbage a 1e1",
	};
	for (size_t i = 0; i < sizeof(bads) / sizeof(bads[0]); i++)
		if (sim_command(&sim, bads[i], 0, reply, sizeof(reply)) != -1)
			fail_msg("'%s' accepted: %s", bads[i], reply);
	for (size_t k = 0; k < SIM_FAULT_KINDS; k++)
		assert_false(sim.buses[0].joints[0].faults.f[k].active);
	/* register values are decimal or 0x, never octal */
	assert_int_equal(sim_command(&sim, "poke a 1 temperature_limit 010", 0, reply, sizeof(reply)), 0);
	assert_int_equal(sim_command(&sim, "peek a 1 temperature_limit", 0, reply, sizeof(reply)), 0);
	assert_string_equal(reply, "ok 10");
	assert_int_equal(sim_command(&sim, "fault a 1 slow 2.5 count=3", 0, reply, sizeof(reply)), 0);
	assert_int_equal(sim_command(&sim, "fault a 1 wrong-id 253", 0, reply, sizeof(reply)), 0);
}

/* A refused --set leaves the configuration exactly as it was (found by
 * fuzz_sim_scenario: a bad ID list half-overwrote the robot's IDs, leaving
 * duplicates; a too-long URL or link was stored cut short; a bad key of a
 * new robot left that robot behind). */
static void test_failed_set_changes_nothing(void **state)
{
	(void)state;
	static struct sim_config before;
	char err[256], longv[SIM_PATH_MAX + 40], assign[SIM_PATH_MAX + 80];
	memset(longv, 'x', sizeof(longv) - 1);
	longv[sizeof(longv) - 1] = '\0';
	sim_config_defaults(&cfg);
	assert_int_equal(sim_config_set(&cfg, "robot a.ids=1-3", err, sizeof(err)), 0);
	assert_int_equal(sim_config_set(&cfg, "sim.lcm_url=udpm://239.255.76.67:7667", err, sizeof(err)), 0);
	memcpy(&before, &cfg, sizeof(cfg));
	const char *bad[] = { "robot a.ids=2,x", "robot a.ids=3,3", "robot zz.bogus=1", "robot zz.ids=", NULL };
	for (size_t i = 0; bad[i]; i++) {
		assert_int_equal(sim_config_set(&cfg, bad[i], err, sizeof(err)), -1);
		if (memcmp(&before, &cfg, sizeof(cfg)) != 0)
			fail_msg("'%s' changed the configuration", bad[i]);
	}
	const char *keys[] = { "sim.lcm_url", "sim.link_dir", "sim.control", "robot a.link", "robot b.link", NULL };
	for (size_t i = 0; keys[i]; i++) {
		snprintf(assign, sizeof(assign), "%s=%s", keys[i], longv);
		assert_int_equal(sim_config_set(&cfg, assign, err, sizeof(err)), -1);
		if (memcmp(&before, &cfg, sizeof(cfg)) != 0)
			fail_msg("'%s=xxx...' changed the configuration", keys[i]);
	}
	assert_int_equal(cfg.robots[0].nids, 3);
	assert_int_equal(cfg.robots[0].ids[0], 1);
}

static void test_seeded_start(void **state)
{
	(void)state;
	static struct sim a, b;
	char err[256];
	quick(&cfg, 11);
	assert_int_equal(sim_init(&a, &cfg, err, sizeof(err)), 0);
	assert_int_equal(sim_init(&b, &cfg, err, sizeof(err)), 0);
	for (size_t i = 0; i < 2; i++)
		for (size_t k = 0; k < 2; k++)
			assert_true(a.buses[i].joints[k].motor.angle == b.buses[i].joints[k].motor.angle);
	quick(&cfg, 12);
	assert_int_equal(sim_init(&b, &cfg, err, sizeof(err)), 0);
	assert_true(a.buses[0].joints[0].motor.angle != b.buses[0].joints[0].motor.angle);
}

static void test_commands(void **state)
{
	(void)state;
	char err[256], reply[512];
	quick(&cfg, 1);
	assert_int_equal(sim_init(&sim, &cfg, err, sizeof(err)), 0);
	assert_int_equal(sim_command(&sim, "fault a 2 slow 3 count=2", 0, reply, sizeof(reply)), 0);
	assert_string_equal(reply, "ok 1 servo(s): slow");
	struct sim_fault *f = &sim.buses[0].joints[1].faults.f[SIM_FAULT_SLOW];
	assert_true(f->active && f->arg == 3 && f->remaining == 2);
	assert_int_equal(sim_command(&sim, "fault * * stuck-error overload", 0, reply, sizeof(reply)), 0);
	assert_string_equal(reply, "ok 4 servo(s): stuck-error");
	const struct sim_fault *stuck = &sim.buses[1].joints[0].faults.f[SIM_FAULT_STUCK_ERROR];
	assert_true(stuck->active && stuck->arg == DXL_ERRBIT_OVERLOAD && stuck->remaining < 0);
	assert_int_equal(sim_command(&sim, "clear * * stuck-error", 0, reply, sizeof(reply)), 0);
	assert_false(stuck->active);
	assert_true(f->active);  /* other kinds stay */
	assert_int_equal(sim_command(&sim, "clear a", 0, reply, sizeof(reply)), 0);
	assert_false(f->active);
	assert_int_equal(sim_command(&sim, "power b 1 off", 0, reply, sizeof(reply)), 0);
	assert_false(sim.buses[1].joints[0].servo.powered);
	assert_int_equal(sim_command(&sim, "power b 1 on", 0, reply, sizeof(reply)), 0);
	assert_true(sim.buses[1].joints[0].servo.powered);
	assert_int_equal(sim_command(&sim, "poke a 1 temperature_limit 40", 0, reply, sizeof(reply)), 0);
	assert_int_equal(sim_command(&sim, "peek a 1 temperature_limit", 0, reply, sizeof(reply)), 0);
	assert_string_equal(reply, "ok 40");
	assert_int_equal(sim_command(&sim, "walls -0.5 0.5", 0, reply, sizeof(reply)), 0);
	assert_float_equal(sim.world.params.wall_right, 0.5, 1e-12);
	assert_int_equal(sim_command(&sim, "garbage a 4", 0, reply, sizeof(reply)), 0);
	assert_int_equal(sim.buses[0].line.n, 4);
	/* bad commands: a clear error each, counted, nothing changed */
	uint64_t bad = sim.bad_commands;
	const char *bads[] = {
		"", "explode", "fault", "fault a 1", "fault a 1 melt", "fault a x no-reply", "fault zz 1 no-reply",
		"fault a 9 no-reply", "clear a 1 melt", "power a 1 maybe", "disconnect zz", "disconnect a",
		"reconnect", "poke a 1 nosuchreg 1", "poke a 1 goal_position 70000", "peek a 7 goal_position",
		"walls 1 -1", "walls x y", "garbage a 1000",
		"fault a 1 slow 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17",
	};
	for (size_t i = 0; i < sizeof(bads) / sizeof(bads[0]); i++) {
		assert_int_equal(sim_command(&sim, bads[i], 0, reply, sizeof(reply)), -1);
		assert_memory_equal(reply, "error: ", 7);
	}
	assert_int_equal(sim.bad_commands - bad, sizeof(bads) / sizeof(bads[0]));
	assert_false(sim.buses[0].joints[0].faults.f[SIM_FAULT_NO_REPLY].active);
}

static void test_events_run_on_time(void **state)
{
	(void)state;
	char err[256];
	assert_int_equal(load(&cfg, pair_ini, err, sizeof(err)), 0);
	assert_int_equal(sim_config_finish(&cfg, err, sizeof(err)), 0);
	assert_int_equal(sim_init(&sim, &cfg, err, sizeof(err)), 0);
	sim_run_events(&sim, 0.4, 0);
	assert_false(sim.buses[0].joints[0].faults.f[SIM_FAULT_SLOW].active);
	sim_run_events(&sim, 0.5, 0);
	assert_true(sim.buses[0].joints[0].faults.f[SIM_FAULT_SLOW].active);
	assert_false(sim.buses[1].joints[0].faults.f[SIM_FAULT_NO_REPLY].active);
	sim_run_events(&sim, 2.0, 0);
	assert_true(sim.buses[1].joints[0].faults.f[SIM_FAULT_NO_REPLY].active);
}

/* Drive the two bodies at each other through their registers: they collide,
 * the collision is reported for the step, and they never pass each other. */
static void test_driven_bodies_collide(void **state)
{
	(void)state;
	char err[256];
	assert_int_equal(load(&cfg, pair_ini, err, sizeof(err)), 0);
	assert_int_equal(sim_config_set(&cfg, "world.walls=none", err, sizeof(err)), 0);
	assert_int_equal(sim_config_set(&cfg, "sim.overload_time=100", err, sizeof(err)), 0);  /* no shutdown */
	assert_int_equal(sim_config_finish(&cfg, err, sizeof(err)), 0);
	assert_int_equal(sim_init(&sim, &cfg, err, sizeof(err)), 0);
	struct sim_servo *l = &sim.buses[0].joints[0].servo, *r = &sim.buses[1].joints[0].servo;
	l->mem[DXL_AX_TORQUE_ENABLE] = r->mem[DXL_AX_TORQUE_ENABLE] = 1;
	dxl_put_u16(&l->mem[DXL_AX_GOAL_POSITION], dxl_rad_to_pos(0.6));
	dxl_put_u16(&r->mem[DXL_AX_GOAL_POSITION], dxl_rad_to_pos(-0.6));
	size_t reported = 0;
	for (int i = 0; i < 1000; i++) {
		sim_step(&sim);
		reported += sim.nstep_collisions;
		assert_true(sim_world_lateral(&sim.world, 0) <= sim_world_lateral(&sim.world, 1) + 1e-9);
	}
	assert_true(sim.world.total_collisions >= 1);
	assert_int_equal(reported, sim.world.total_collisions);
	assert_true(sim.world.total_impulse > 0);
	/* pushing against each other: the servos report load */
	assert_true((sim_servo_peek(l, DXL_AX_PRESENT_LOAD) & 1023) > 100);
	assert_int_equal(sim.steps, 1000);
}

/* Servo models: one for all, one per ID, per robot; a bus speaks one
 * protocol; the X series' factory rate and ID range; motor parameters per
 * model with the [motor] keys given on top. */
static void test_models(void **state)
{
	(void)state;
	char err[300], reply[600];
	static const char x_ini[] =
		"[sim]\nmodel = xl430-w250\n[robot a]\nids = 1,2\n[robot b]\nids = 3\nmodel = XM430-W350\n"
		"[robot c]\nids = 4,5\nmodel = xl430-w250, xm430-w350\n[robot d]\nids = 6\nmodel = ax12a\n";
	sim_config_defaults(&cfg);
	assert_int_equal(sim_config_load_text(&cfg, "x", x_ini, strlen(x_ini), err, sizeof err), 0);
	assert_int_equal(sim_config_finish(&cfg, err, sizeof err), 0);
	assert_int_equal(cfg.robots[0].models[1], SIM_MODEL_XL430_W250);
	assert_int_equal(cfg.robots[1].models[0], SIM_MODEL_XM430_W350);
	assert_int_equal(cfg.robots[2].models[1], SIM_MODEL_XM430_W350);
	assert_int_equal(sim_config_robot_protocol(&cfg.robots[2]), 2);
	assert_int_equal(sim_config_robot_protocol(&cfg.robots[3]), 1);
	assert_int_equal(sim_init(&sim, &cfg, err, sizeof err), 0);
	/* X buses start at 57600 (the factory Baud Rate 1), the AX-12A's at 1 Mbps */
	assert_int_equal(sim.buses[0].proto->number, 2);
	assert_int_equal(sim.buses[0].baud, 57600);
	assert_int_equal(sim.buses[0].joints[0].xservo.mem[DXL2_X_BAUD_RATE], 1);
	assert_int_equal(sim.buses[3].proto->number, 1);
	assert_int_equal(sim.buses[3].baud, 1000000);
	assert_int_equal(sim_joint_id(&sim.buses[2].joints[1]), 5);
	/* each model its own motor line (e-manual, 12 V) */
	assert_float_equal(sim.buses[1].joints[0].params.stall_torque_12v, 4.1, 1e-12);
	assert_float_equal(sim.buses[0].joints[0].params.stall_torque_12v, 1.5, 1e-12);
	assert_float_equal(sim.buses[0].joints[0].params.no_load_speed_12v, 61 * 2 * M_PI / 60, 1e-9);
	assert_true(sim.buses[1].joints[0].params.inertia > sim.buses[0].joints[0].params.inertia);
	/* commands take the X table's names; the servo line says the model */
	assert_int_equal(sim_command(&sim, "peek a 1 model_number", 0, reply, sizeof reply), 0);
	assert_string_equal(reply, "ok 1060");
	assert_int_equal(sim_command(&sim, "poke b 3 goal_position -5", 0, reply, sizeof reply), 0);
	assert_int_equal(sim_command(&sim, "peek b 3 goal", 0, reply, sizeof reply), 0);
	assert_string_equal(reply, "ok -5");
	assert_int_equal(sim_command(&sim, "poke a 1 cw_angle_limit 0", 0, reply, sizeof reply), -1);
	assert_non_null(strstr(reply, "XL430-W250"));
	assert_int_equal(sim_command(&sim, "servo c 5", 0, reply, sizeof reply), 0);
	assert_non_null(strstr(reply, "model=xm430-w350"));
	/* stuck-error takes each protocol's own words, and a refusal changes nothing */
	assert_int_equal(sim_command(&sim, "fault a 1 stuck-error alert|data-limit", 0, reply, sizeof reply), 0);
	assert_true(sim.buses[0].joints[0].faults.f[SIM_FAULT_STUCK_ERROR].err2 == 0x86);
	assert_int_equal(sim_command(&sim, "fault a 1 stuck-error overload", 0, reply, sizeof reply), -1);
	assert_non_null(strstr(reply, "Protocol 2.0"));
	assert_int_equal(sim_command(&sim, "fault d 6 stuck-error alert", 0, reply, sizeof reply), -1);
	assert_int_equal(sim_command(&sim, "clear * * stuck-error", 0, reply, sizeof reply), 0);
	assert_int_equal(sim_command(&sim, "fault * * stuck-error overheating", 0, reply, sizeof reply), -1);
	for (size_t i = 0; i < sim.nbuses; i++)
		for (size_t k = 0; k < sim.buses[i].njoints; k++)
			assert_false(sim.buses[i].joints[k].faults.f[SIM_FAULT_STUCK_ERROR].active);
	/* power loss resets an X servo's RAM */
	assert_int_equal(sim_command(&sim, "poke a 2 led 1", 0, reply, sizeof reply), 0);
	assert_int_equal(sim_command(&sim, "power a 2 off", 0, reply, sizeof reply), 0);
	assert_int_equal(sim_command(&sim, "power a 2 on", 0, reply, sizeof reply), 0);
	assert_int_equal(sim_command(&sim, "peek a 2 led", 0, reply, sizeof reply), 0);
	assert_string_equal(reply, "ok 0");

	/* refusals, each with a clear message */
	static const struct { const char *text, *why; } bad[] = {
		{ "[robot a]\nids = 1,2\nmodel = ax12a,xl430-w250\n", "cannot share a bus" },
		{ "[robot a]\nids = 1,2,3\nmodel = xl430-w250,xm430-w350\n", "2 models for 3 servos" },
		{ "[robot a]\nids = 253\nmodel = xl430-w250\n", "Protocol 2.0 IDs are 0..252" },
		{ "[robot a]\nids = 1\nmodel = xl430-w250\nservo_baud = 9\n", "0..7" },
		{ "[robot a]\nids = 1\nmodel = xl430-w250\nbaud = 500000\n", "no X-series rate" },
		{ "[robot a]\nids = 1\nmodel = mx28\n", "not a servo model" },
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		sim_config_defaults(&cfg);
		err[0] = '\0';
		int r = sim_config_load_text(&cfg, "bad", bad[i].text, strlen(bad[i].text), err, sizeof err);
		if (r == 0)
			r = sim_config_finish(&cfg, err, sizeof err);
		if (r == 0)
			r = sim_init(&sim, &cfg, err, sizeof err);
		if (r == 0 || !strstr(err, bad[i].why))
			fail_msg("'%s': %d '%s', want '%s'", bad[i].text, r, err, bad[i].why);
	}
	/* [motor] keys given apply to every model; the rest stay each model's */
	sim_config_defaults(&cfg);
	assert_int_equal(sim_config_set(&cfg, "motor.viscous=0.01", err, sizeof err), 0);
	assert_int_equal(sim_config_set(&cfg, "sim.voltage=11.1", err, sizeof err), 0);
	struct sim_motor_params p;
	sim_config_motor_params(&cfg, SIM_MODEL_XM430_W350, &p);
	assert_float_equal(p.viscous, 0.01, 1e-12);
	assert_float_equal(p.supply_voltage, 11.1, 1e-12);
	assert_float_equal(p.stall_torque_12v, 4.1, 1e-12);
	sim_config_motor_params(&cfg, SIM_MODEL_AX12A, &p);
	assert_float_equal(p.stall_torque_12v, 1.5, 1e-12);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_models),
		cmocka_unit_test(test_load_pair),
		cmocka_unit_test(test_config_errors),
		cmocka_unit_test(test_long_line),
		cmocka_unit_test(test_scenario_files),
		cmocka_unit_test(test_integer_values),
		cmocka_unit_test(test_failed_set_changes_nothing),
		cmocka_unit_test(test_seeded_start),
		cmocka_unit_test(test_commands),
		cmocka_unit_test(test_events_run_on_time),
		cmocka_unit_test(test_driven_bodies_collide),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
