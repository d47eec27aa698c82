/*
 * test_daemon_tune.c — the tuner (daemon/tune.c) against model plants whose
 * answer to k and μ is a power law unlike the one it starts from: it
 * converges, confirms, and writes a configuration that loads; a plant that
 * runs at its speed limit makes it stop and say what can be reached; a loop
 * that dies gets more lead (position actuation) or a failure (torque); the
 * targets are checked against the configuration's limits first.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "../../daemon/config.h"
#include "../../daemon/control.h"
#include "../../daemon/tune.h"

#define PI 3.14159265358979323846
#define DT 0.01

/* A plant's gait as a function of the parameters: f = f0·(k/k0)^ef·(μ0/μ)^0.1
 * (μ slows it a little, as through the servo), A_j = a0_j·(μ0_j/μ_j)^ea, the
 * product 2π f A capped at vmax (a speed-limited servo), or dead (x = 0). */
struct plant {
	double f0, a0[2], ef, ea, vmax;
	double lead_exp;   /* > 0: joint 2's amplitude grows with the lead, not with its μ */
	double harmonic;   /* joint 1 moves as sin φ + h·sin 2φ (a double hump: extra crossings) */
	bool dead;
	double phase[2];
};

static struct cfg *base_cfg(size_t njoints)
{
	static struct cfg c;
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_true(cfg_override(&c, "robot.port=/dev/null", &e));
	assert_true(cfg_override(&c, njoints == 1 ? "robot.ids=1" : "robot.ids=1,2", &e));
	assert_true(cfg_finish(&c, &e));
	return &c;
}

struct run {
	struct tune t;
	struct cfg *cfg;
	struct ctl ctl;            /* what runs: the tuner's steps go through ctl_set_param */
	double k0, mu0[2], lead0;
	double time;
	int applied;
};

static void gait(const struct run *r, const struct plant *p, double *f, double *a)
{
	double kr = r->ctl.p.osc[0].k / r->k0;
	*f = p->f0 * pow(kr, p->ef) * pow(r->mu0[0] / r->ctl.p.osc[0].mu, 0.1);
	for (size_t j = 0; j < r->t.n; j++) {
		a[j] = p->a0[j] * pow(r->mu0[j] / r->ctl.p.osc[j].mu, p->ea);
		/* the energy the loop gets caps what μ can give */
		if (j == 1 && p->lead_exp > 0)
			a[j] = fmin(p->a0[j] * pow(r->ctl.p.servo_lead_s / r->lead0, p->lead_exp), 1.1 * a[j]);
		double v = 2 * PI * *f * a[j];
		if (p->vmax > 0 && v > p->vmax)
			a[j] *= p->vmax / v;
	}
}

/* Feed the plant until the tuner is done or failed, or `seconds` pass.
 * The first 2 s are the daemon's starter. */
static void drive(struct run *r, struct plant *p, double seconds)
{
	double end = r->time + seconds;
	while (r->time < end && r->t.state != TUNE_DONE && r->t.state != TUNE_FAILED) {
		double f, a[2];
		gait(r, p, &f, a);
		double x[2], v[2];
		for (size_t j = 0; j < r->t.n; j++) {
			/* phase advances by the present frequency: a change is continuous */
			p->phase[j] += 2 * PI * f * DT;
			double ph = p->phase[j] - (double)j * PI / 2;
			double h = j == 0 ? p->harmonic : 0.0;
			x[j] = p->dead ? 0.0 : a[j] * (sin(ph) + h * sin(2 * ph));
			v[j] = p->dead ? 0.0 : a[j] * 2 * PI * f * (cos(ph) + 2 * h * cos(2 * ph));
		}
		bool starter = r->time < 2.0;
		bool ch = tune_sample(&r->t, r->time, x, v, starter);
		if (getenv("TUNE_TRACE") && r->t.progress[0])
			print_message("%6.1f %s\n", r->time, r->t.progress);
		if (ch) {
			assert_true(tune_apply(&r->t, &r->ctl));
			r->applied++;
		}
		r->time += DT;
	}
}

static void start(struct run *r, size_t njoints, double f, double a, bool torque)
{
	memset(r, 0, sizeof *r);
	r->cfg = base_cfg(njoints);
	if (torque) {
		struct cfg_errors e = { 0 };
		assert_true(cfg_override(r->cfg, "robot.actuation=torque", &e));
		assert_true(cfg_finish(r->cfg, &e));
	}
	r->k0 = r->cfg->joint[0].osc.k;
	r->lead0 = r->cfg->servo_lead_s;
	for (size_t j = 0; j < njoints; j++)
		r->mu0[j] = r->cfg->joint[j].osc.mu;
	ctl_init(&r->ctl, r->cfg);
	struct tune_opts o = { .target_freq = f, .target_amp = a, .max_s = 90 };
	char why[TUNE_TEXT];
	assert_true(tune_init(&r->t, &o, r->cfg, &r->ctl.p, why, sizeof why));
}

/* The usual run: two joints on position actuation, targets 0.8 Hz and
 * 0.8 rad, the plant fed for 90 s (the tuner's own limit); the servos
 * report SUPPLY_V volts first when it is above 0. */
static void tune_on(struct run *r, struct plant *p, double supply_v)
{
	start(r, 2, 0.8, 0.8, false);
	if (supply_v > 0)
		tune_supply(&r->t, supply_v);
	drive(r, p, 90);
}

/* The plant the audit found: the defaults give 1.07 Hz and 1.25 rad, and its
 * exponents are not the simulator's. */
static void test_converges_on_a_fast_plant(void **state)
{
	(void)state;
	struct run r;
	struct plant p = { .f0 = 1.07, .a0 = { 1.23, 1.30 }, .ef = 0.45, .ea = 0.28 };
	tune_on(&r, &p, 0);
	assert_int_equal(r.t.state, TUNE_DONE);
	assert_true(fabs(r.t.result.freq / 0.8 - 1) <= TUNE_TOLERANCE);
	for (int j = 0; j < 2; j++)
		assert_true(fabs(r.t.result.amp[j] / 0.8 - 1) <= TUNE_TOLERANCE);
	/* what it started from is kept for the report */
	assert_true(fabs(r.t.first.freq - 1.07) < 0.02);
	assert_true(r.t.iterations <= 10);
	assert_true(r.time < 60);
	/* the Jacobian moved towards the plant's exponents (0.45 and -0.28) */
	assert_true(r.t.jac[0][0] < 0.66 && r.t.jac[1][1] > -0.40);
	/* the parameters the controller runs are the result's; the configuration keeps the start */
	for (size_t j = 0; j < 2; j++) {
		assert_true(fabs(r.ctl.p.osc[j].k / r.k0 - r.t.result.k) < 1e-9);
		assert_true(fabs(r.ctl.p.osc[j].mu - r.t.result.mu[j]) < 1e-12);
	}
	assert_true(fabs(r.ctl.p.servo_lead_s - r.t.result.lead) < 1e-12);
	assert_true(r.cfg->joint[0].osc.k == r.k0 && r.cfg->joint[1].osc.mu == r.mu0[1]);
	assert_true(fabs(r.t.result.lag_deg - 90) < 3);
}

/* Joint 1 in a double hump crosses its centre twice a cycle: the window
 * still reads the fundamental, and the whole excursion as its amplitude. */
static void test_double_hump_reads_the_fundamental(void **state)
{
	(void)state;
	struct run r;
	struct plant p = { .f0 = 1.0, .a0 = { 0.6, 1.2 }, .ef = 0.6, .ea = 0.4, .harmonic = 0.8 };
	tune_on(&r, &p, 0);
	assert_true(r.t.have_first);
	assert_true(fabs(r.t.first.freq / 1.0 - 1) < 0.03);
	double hi = -1e9, lo = 1e9;
	for (int i = 0; i < 10000; i++) {
		double ph = 2 * PI * i / 10000.0, x = 0.6 * (sin(ph) + 0.8 * sin(2 * ph));
		hi = fmax(hi, x);
		lo = fmin(lo, x);
	}
	assert_true(fabs(r.t.first.amp[0] / (0.5 * (hi - lo)) - 1) < 0.03);
	assert_true(fabs(r.t.first.amp[1] / 1.2 - 1) < 0.03);
}

/* A plant already on target: one window, one to confirm, nothing changed. */
static void test_on_target_confirms_without_change(void **state)
{
	(void)state;
	struct run r;
	struct plant p = { .f0 = 0.805, .a0 = { 0.81, 0.79 }, .ef = 0.66, .ea = 0.4 };
	tune_on(&r, &p, 0);
	assert_int_equal(r.t.state, TUNE_DONE);
	assert_int_equal(r.applied, 0);
	assert_int_equal(r.t.iterations, 2);
	assert_true(fabs(r.t.result.k - 1.0) < 1e-12);
}

/* One joint, other targets, a slow plant. */
static void test_one_joint_other_targets(void **state)
{
	(void)state;
	struct run r;
	start(&r, 1, 1.1, 0.5, false);
	struct plant p = { .f0 = 0.62, .a0 = { 0.95 }, .ef = 0.8, .ea = 0.5 };
	drive(&r, &p, 90);
	assert_int_equal(r.t.state, TUNE_DONE);
	assert_true(fabs(r.t.result.freq / 1.1 - 1) <= TUNE_TOLERANCE);
	assert_true(fabs(r.t.result.amp[0] / 0.5 - 1) <= TUNE_TOLERANCE);
	assert_true(isnan(r.t.result.lag_deg));
}

/* The servo cannot go faster than 3.2 rad/s: 0.8 Hz at 0.8 rad (4.0 rad/s)
 * is out of reach, and it says what is in reach. */
static void test_speed_limit_says_what_is_reachable(void **state)
{
	(void)state;
	struct run r;
	struct plant p = { .f0 = 0.7, .a0 = { 0.7, 0.7 }, .ef = 0.6, .ea = 0.4, .vmax = 3.2 };
	tune_on(&r, &p, 12.0);
	assert_int_equal(r.t.state, TUNE_FAILED);
	assert_non_null(strstr(r.t.why, "out of reach"));
	assert_non_null(strstr(r.t.why, "Reachable"));
	assert_true(r.time < 60);
}

/* Joint 2 lags behind in amplitude whatever its μ (a weak supply: the loop
 * loses its energy to the servo's lag); the lead feeds it. */
static void test_amplitude_short_with_mu_at_floor_raises_the_lead(void **state)
{
	(void)state;
	struct run r;
	struct plant p = { .f0 = 0.8, .a0 = { 0.8, 0.55 }, .ef = 0.6, .ea = 0.4, .lead_exp = 1.5 };
	tune_on(&r, &p, 12.0);
	if (r.t.state != TUNE_DONE)
		print_message("%s\n", r.t.why);
	assert_int_equal(r.t.state, TUNE_DONE);
	assert_true(r.t.result.lead > r.lead0 * 1.2);
	assert_true(fabs(r.t.result.amp[1] / 0.8 - 1) <= TUNE_TOLERANCE);
}

/* The servos report 7 V: 4.0 rad/s is beyond them, said once the starter is done. */
static void test_low_supply_is_out_of_reach(void **state)
{
	(void)state;
	struct run r;
	struct plant p = { .f0 = 0.8, .a0 = { 0.5, 0.4 }, .ef = 0.6, .ea = 0.4 };
	tune_on(&r, &p, 7.0);
	assert_int_equal(r.t.state, TUNE_FAILED);
	assert_int_equal(r.t.iterations, 0);
	assert_true(r.time < 2.5);
	assert_non_null(strstr(r.t.why, "7.0 V"));
	assert_non_null(strstr(r.t.why, "Reachable"));
}

/* A loop that dies: position actuation raises the lead, each death once. */
static void test_dead_loop_raises_the_lead(void **state)
{
	(void)state;
	struct run r;
	start(&r, 2, 0.8, 0.8, false);
	double lead0 = r.t.lead;
	struct plant p = { .f0 = 0.8, .a0 = { 0.8, 0.8 }, .ef = 0.6, .ea = 0.4, .dead = true };
	drive(&r, &p, 2.0 + TUNE_DEAD_S + 0.5);
	assert_true(r.t.lead > lead0 * 1.3 && r.t.lead < lead0 * 1.4);
	assert_true(r.applied == 1);
	assert_true(fabs(r.ctl.p.servo_lead_s - r.t.lead) < 1e-12);
	/* it keeps dying: the lead grows to its largest, then it gives up */
	drive(&r, &p, 80);
	assert_int_equal(r.t.state, TUNE_FAILED);
	assert_non_null(strstr(r.t.why, "stopped oscillating"));
	assert_true(fabs(r.t.lead - TUNE_MAX_LEAD_S) < 1e-9);
}

static void test_dead_loop_torque_fails(void **state)
{
	(void)state;
	struct run r;
	start(&r, 1, 0.8, 0.8, true);
	struct plant p = { .dead = true };
	drive(&r, &p, 20);
	assert_int_equal(r.t.state, TUNE_FAILED);
	assert_non_null(strstr(r.t.why, "stopped oscillating"));
}

/* The daemon's starter running again after the tuner began measuring is a
 * stall: more lead. */
static void test_starter_again_is_a_stall(void **state)
{
	(void)state;
	struct run r;
	start(&r, 1, 0.8, 0.8, false);
	double x = 0.3, v = 0;
	tune_sample(&r.t, 0.0, &x, &v, true);
	tune_sample(&r.t, 0.01, &x, &v, false);
	assert_int_equal(r.t.state, TUNE_MEASURING);
	assert_true(tune_sample(&r.t, 0.02, &x, &v, true));
	assert_int_equal(r.t.state, TUNE_STARTING);
	assert_non_null(strstr(r.t.progress, "servo_lead_s"));
}

static void test_targets_checked_against_the_configuration(void **state)
{
	(void)state;
	struct cfg *c = base_cfg(2);
	struct cfg_errors e = { 0 };
	assert_true(cfg_override(c, "joint.2.limit_max=0.7", &e));
	assert_true(cfg_finish(c, &e));
	struct tune t;
	char why[TUNE_TEXT];
	struct tune_opts o = { .target_freq = 0.8, .target_amp = 0.8 };
	assert_false(tune_init(&t, &o, c, NULL, why, sizeof why));
	assert_non_null(strstr(why, "joint 2's limits"));
	/* faster than the servo can move at that amplitude */
	c = base_cfg(2);
	o = (struct tune_opts){ .target_freq = 2.0, .target_amp = 0.8 };
	assert_false(tune_init(&t, &o, c, NULL, why, sizeof why));
	assert_non_null(strstr(why, "no-load speed"));
	assert_non_null(strstr(why, "reaches"));
	/* a goal step larger than max_step allows */
	assert_true(cfg_override(c, "joint.1.max_step=0.02", &e));
	assert_true(cfg_finish(c, &e));
	o = (struct tune_opts){ .target_freq = 0.8, .target_amp = 0.8 };
	assert_false(tune_init(&t, &o, c, NULL, why, sizeof why));
	assert_non_null(strstr(why, "max_step"));
	/* implausible targets */
	c = base_cfg(2);
	o = (struct tune_opts){ .target_freq = 0.0, .target_amp = 0.8 };
	assert_false(tune_init(&t, &o, c, NULL, why, sizeof why));
	o = (struct tune_opts){ .target_freq = 0.8, .target_amp = NAN };
	assert_false(tune_init(&t, &o, c, NULL, why, sizeof why));
}

/* The tuner sets parameters as a command would: never past the ranges the
 * configuration accepts (k <= 10, the natural frequency <= 5 Hz). A plant
 * that would need k beyond them gets "out of reach", and nothing the daemon
 * ran with was refusable. */
static void test_search_stays_inside_the_configuration_ranges(void **state)
{
	(void)state;
	struct run r;
	memset(&r, 0, sizeof r);
	r.cfg = base_cfg(2);
	struct cfg_errors e = { 0 };
	assert_true(cfg_override(r.cfg, "joint.1.k=6", &e) && cfg_override(r.cfg, "joint.2.k=6", &e));
	assert_true(cfg_override(r.cfg, "joint.1.inertia=0.02", &e) && cfg_override(r.cfg, "joint.2.inertia=0.02", &e));
	assert_true(cfg_finish(r.cfg, &e));
	r.k0 = 6;
	r.mu0[0] = r.cfg->joint[0].osc.mu;
	r.mu0[1] = r.cfg->joint[1].osc.mu;
	r.lead0 = r.cfg->servo_lead_s;
	ctl_init(&r.ctl, r.cfg);
	struct tune_opts o = { .target_freq = 0.8, .target_amp = 0.8, .max_s = 90 };
	char why[TUNE_TEXT];
	assert_true(tune_init(&r.t, &o, r.cfg, &r.ctl.p, why, sizeof why));
	struct plant p = { .f0 = 0.35, .a0 = { 0.8, 0.8 }, .ef = 0.66, .ea = 0.4 };
	double kmax = 0;
	while (r.t.state != TUNE_DONE && r.t.state != TUNE_FAILED && r.time < 95) {
		drive(&r, &p, 0.5);
		for (int j = 0; j < 2; j++) {
			kmax = fmax(kmax, r.ctl.p.osc[j].k);
			struct cfg_joint jt = r.cfg->joint[j];
			jt.osc = r.ctl.p.osc[j];
			char jwhy[128];
			assert_true(cfg_joint_check(&jt, jwhy, sizeof jwhy));
			struct param_range kr;
			assert_true(cfg_param_range("k", &kr) && r.ctl.p.osc[j].k <= kr.max);
		}
	}
	assert_int_equal(r.t.state, TUNE_FAILED);
	assert_non_null(strstr(r.t.why, "out of reach"));
	assert_true(kmax > 9.0);   /* it went to the edge, not past it */
}

/* The tuner's steps go through the controller's one door: a step it
 * refuses (here k beyond its range, forced by hand: the search box stays
 * inside) fails the tuning with the controller's reason and leaves the
 * controller running what it ran, whole — no joint half-changed. */
static void test_refused_step_fails_and_changes_nothing(void **state)
{
	(void)state;
	struct run r;
	start(&r, 2, 0.8, 0.8, false);
	struct plant p = { .f0 = 1.07, .a0 = { 1.23, 1.30 }, .ef = 0.45, .ea = 0.28 };
	drive(&r, &p, 12);
	assert_true(r.applied >= 1);
	struct cfg_params before = r.ctl.p;
	r.t.mu[0] *= 1.01;                  /* joint 0 alone would pass ... */
	r.t.k = 20.0 / r.t.k0[1];           /* ... joint 1's k does not */
	r.t.changed = true;
	assert_false(tune_apply(&r.t, &r.ctl));
	assert_false(r.t.changed);
	assert_int_equal(r.t.state, TUNE_FAILED);
	assert_non_null(strstr(r.t.why, "the controller refused the tuner's step: parameter k: "));
	assert_memory_equal(&r.ctl.p, &before, sizeof before);
	assert_memory_equal(&r.t.ran, &before, sizeof before);
}

/* Bad samples (NaN angles, time going backwards) neither crash nor count. */
static void test_bad_samples(void **state)
{
	(void)state;
	struct run r;
	start(&r, 2, 0.8, 0.8, false);
	double x[2] = { NAN, NAN }, v[2] = { NAN, 0 };
	for (int i = 0; i < 1000; i++)
		tune_sample(&r.t, 3.0 + i * DT, x, v, false);
	assert_int_equal(r.t.iterations, 0);
	assert_false(tune_sample(&r.t, NAN, x, v, false));
}

/* The configuration written loads as it is, runs OSCILLATOR, and its
 * baseline is the gait measured. */
static void test_written_configuration_loads(void **state)
{
	(void)state;
	struct run r;
	struct plant p = { .f0 = 1.07, .a0 = { 1.23, 1.30 }, .ef = 0.45, .ea = 0.28 };
	tune_on(&r, &p, 0);
	assert_int_equal(r.t.state, TUNE_DONE);
	char *buf = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&buf, &len);
	assert_non_null(f);
	tune_write_config(&r.t, r.cfg, "2026-11-25 12:00 UTC", 33.0, f);
	fclose(f);
	assert_non_null(strstr(buf, "written by undulated --tune"));
	static struct cfg back;
	struct cfg_errors e = { 0 };
	cfg_defaults(&back);
	assert_true(cfg_load_string(&back, "tuned.conf", buf, &e));
	assert_true(cfg_finish(&back, &e));
	assert_int_equal(back.mode, CFG_MODE_OSCILLATOR);
	assert_true(fabs(back.frequency - r.t.result.freq) < 1e-4);
	double mean = 0.5 * (r.t.result.amp[0] + r.t.result.amp[1]);
	assert_true(fabs(back.amplitude - mean) < 1e-4);
	for (int j = 0; j < 2; j++) {
		assert_true(fabs(back.joint[j].osc.mu / r.t.result.mu[j] - 1) < 1e-5);
		assert_true(fabs(back.joint[j].osc.k / (r.k0 * r.t.result.k) - 1) < 1e-5);
		assert_true(fabs(back.joint[j].limit_max - r.cfg->joint[j].limit_max) < 1e-9);
	}
	assert_string_equal(back.port, "/dev/null");
	free(buf);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_converges_on_a_fast_plant),
		cmocka_unit_test(test_double_hump_reads_the_fundamental),
		cmocka_unit_test(test_on_target_confirms_without_change),
		cmocka_unit_test(test_one_joint_other_targets),
		cmocka_unit_test(test_speed_limit_says_what_is_reachable),
		cmocka_unit_test(test_amplitude_short_with_mu_at_floor_raises_the_lead),
		cmocka_unit_test(test_low_supply_is_out_of_reach),
		cmocka_unit_test(test_dead_loop_raises_the_lead),
		cmocka_unit_test(test_dead_loop_torque_fails),
		cmocka_unit_test(test_starter_again_is_a_stall),
		cmocka_unit_test(test_targets_checked_against_the_configuration),
		cmocka_unit_test(test_search_stays_inside_the_configuration_ranges),
		cmocka_unit_test(test_refused_step_fails_and_changes_nothing),
		cmocka_unit_test(test_bad_samples),
		cmocka_unit_test(test_written_configuration_loads),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
