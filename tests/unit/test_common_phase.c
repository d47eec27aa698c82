/* test_common_phase.c — the one phase definition and the frequency/amplitude
 * estimator the daemon and the analyser share: the convention on an exact
 * cosine, the wrap's boundaries, unknown as NAN, and the estimator on clean,
 * noisy, quantized, offset, stopped, drifting and collision-disturbed swings
 * (the daemon's osc_estimator tests and the analyser's tracker tests, both
 * with their own tolerances, so either can switch without losing a promise). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "phase.h"

#define PI 3.14159265358979323846
#define AX12_POS_STEP (300.0 / 1023.0 * PI / 180.0)   /* 0.29°, one position unit */

/* ---- definition ---------------------------------------------------------------- */

static void test_wrap(void **state)
{
	(void)state;
	assert_true(fabs(phase_wrap(3.0 * PI) - PI) < 1e-12);
	assert_true(phase_wrap(-PI) == phase_wrap(PI));      /* (−π, π]: −π maps to π */
	assert_true(fabs(phase_wrap(PI) - PI) < 1e-12);
	assert_true(fabs(phase_wrap(2.0 * PI + 0.25) - 0.25) < 1e-12);
	assert_true(fabs(phase_wrap(-2.0 * PI - 0.25) + 0.25) < 1e-12);
	assert_true(fabs(phase_wrap(7.0) - (7.0 - 2.0 * PI)) < 1e-12);
	assert_true(fabs(phase_wrap(1e6) - remainder(1e6, 2.0 * PI)) < 1e-9);
	for (double a = -20; a < 20; a += 0.37) {
		double w = phase_wrap(a);
		assert_true(w > -PI && w <= PI);
		assert_true(fabs(sin(w) - sin(a)) < 1e-9 && fabs(cos(w) - cos(a)) < 1e-9);
	}
	/* the extremes of the double range stay inside */
	double w = phase_wrap(1.7e308);
	assert_true(w > -PI && w <= PI);
	w = phase_wrap(-nextafter(PI, 0.0) - 2.0 * PI);
	assert_true(w > -PI && w <= PI);
	assert_true(isnan(phase_wrap(NAN)));
	assert_true(isnan(phase_wrap(INFINITY)));
	assert_true(isnan(phase_wrap(-INFINITY)));
}

static void test_from_state(void **state)
{
	(void)state;
	/* on x = A cos φ, ẋ = −Aω sin φ the phase is φ (theory.md's convention) */
	const double A = 0.8, w = 2.0 * PI * 0.8;
	for (double phi = -3.1; phi < 3.14; phi += 0.05) {
		double got = phase_from_state(A * cos(phi), -A * w * sin(phi), w);
		assert_true(fabs(phase_wrap(got - phi)) < 1e-12);
		assert_true(got > -PI && got <= PI);
	}
	/* φ grows with time along the motion */
	double before = phase_from_state(A * cos(w * 1.0), -A * w * sin(w * 1.0), w);
	double after = phase_from_state(A * cos(w * 1.01), -A * w * sin(w * 1.01), w);
	assert_true(phase_wrap(after - before) > 0.0);
	/* clockwise in (x, ẋ): moving up through zero is −π/2, the top is 0 */
	assert_true(fabs(phase_from_state(0.0, 1.0, w) + PI / 2) < 1e-12);
	assert_true(fabs(phase_from_state(0.0, -1.0, w) - PI / 2) < 1e-12);
	assert_true(phase_from_state(A, 0.0, w) == 0.0);
	/* the negative turning point is π, also with a negative zero speed */
	assert_true(phase_from_state(-A, 0.0, w) == phase_wrap(PI));
	assert_true(phase_from_state(-A, -0.0, w) == phase_wrap(PI));
	/* unknown is NAN, never a phase that looks measured */
	assert_true(isnan(phase_from_state(0.1, 0.2, 0.0)));
	assert_true(isnan(phase_from_state(0.1, 0.2, -w)));
	assert_true(isnan(phase_from_state(0.1, 0.2, NAN)));
	assert_true(isnan(phase_from_state(0.1, 0.2, INFINITY)));
	assert_true(isnan(phase_from_state(NAN, 0.0, w)));
	assert_true(isnan(phase_from_state(0.1, INFINITY, w)));
}

/* ---- estimator ------------------------------------------------------------------ */

/* deterministic noise in [−1, 1] */
static double noise(uint32_t *s)
{
	*s = *s * 1664525u + 1013904223u;
	return ((*s >> 8) / (double)(1u << 24)) * 2.0 - 1.0;
}

static void test_estimator_clean_sine(void **state)
{
	(void)state;
	struct phase_estimator e;
	phase_estimator_init(&e);
	assert_true(e.frequency == 0.0 && e.amplitude == 0.0 && phase_estimator_omega(&e) == 0.0);
	int crossings_before_frequency = 0;
	double prev_cross = 0.0;
	for (int i = 0; i <= 1000; i++) {
		double t = i * 0.01;
		phase_estimator_update(&e, 0.8 * sin(2.0 * PI * 0.8 * t + 0.3), t);
		if (e.last_cross_t != prev_cross && e.frequency == 0.0)
			crossings_before_frequency++;
		prev_cross = e.last_cross_t;
	}
	print_message("clean: A %.5f f %.5f\n", e.amplitude, e.frequency);
	assert_true(fabs(e.amplitude - 0.8) < 0.005);
	assert_true(fabs(e.frequency - 0.8) < 0.002);
	assert_true(fabs(phase_estimator_omega(&e) - 2.0 * PI * e.frequency) < 1e-12);
	/* the first two crossings are timed against a guessed centre: a frequency
	 * is known from the fourth crossing */
	assert_int_equal(crossings_before_frequency, 3);
	/* a frequency change shows within ten cycles (the median flips after three) */
	for (int i = 1; i <= 834; i++) {
		double t = 10.0 + i * 0.01;
		phase_estimator_update(&e, 0.5 * sin(2.0 * PI * 1.2 * t), t);
	}
	print_message("after change: A %.5f f %.5f\n", e.amplitude, e.frequency);
	assert_true(fabs(e.frequency - 1.2) < 0.005);
	assert_true(fabs(e.amplitude - 0.5) < 0.005);
}

/* The analyser's case: small noise, 20 s, tight tolerances. */
static void test_estimator_noisy(void **state)
{
	(void)state;
	struct phase_estimator e;
	phase_estimator_init(&e);
	uint32_t seed = 7;
	double f = 0.8, A = 0.6;
	for (int i = 0; i < 2000; i++) {
		double t = i * 0.01;
		phase_estimator_update(&e, A * sin(2 * PI * f * t + 0.3) + 0.0025 * noise(&seed), t);
	}
	assert_true(fabs(e.frequency - f) < 0.002);
	assert_true(fabs(e.amplitude - A) < 0.01);
}

static void test_estimator_quantized_noisy_offset_sine(void **state)
{
	(void)state;
	struct phase_estimator e;
	phase_estimator_init(&e);
	uint32_t seed = 12345;
	for (int i = 0; i <= 2000; i++) {
		double t = i * 0.01;
		/* a mean of 0.3 rad: the signal crosses zero only on part of its swing */
		double x = 0.3 + 0.4 * sin(2.0 * PI * 0.8 * t) + 2.0 * AX12_POS_STEP * noise(&seed);
		phase_estimator_update(&e, AX12_POS_STEP * round(x / AX12_POS_STEP), t);
	}
	print_message("quantized noisy: A %.4f f %.4f (true 0.4, 0.8)\n", e.amplitude, e.frequency);
	assert_true(fabs(e.frequency - 0.8) < 0.01);
	/* peaks ride on the noise: up to 2 steps + half a step high */
	assert_true(e.amplitude > 0.39 && e.amplitude < 0.42);

	/* a swing that never reaches zero is still measured about its own centre */
	struct phase_estimator off;
	phase_estimator_init(&off);
	for (int i = 0; i <= 1000; i++) {
		double t = i * 0.01;
		double x = 0.5 + 0.2 * sin(2.0 * PI * 0.8 * t) + AX12_POS_STEP * noise(&seed);
		phase_estimator_update(&off, AX12_POS_STEP * round(x / AX12_POS_STEP), t);
	}
	print_message("mean 0.5: A %.4f f %.4f (true 0.2, 0.8)\n", off.amplitude, off.frequency);
	assert_true(fabs(off.frequency - 0.8) < 0.01);
	assert_true(off.amplitude > 0.19 && off.amplitude < 0.21);

	/* bad samples are counted, not used */
	unsigned long before = e.rejected;
	double f = e.frequency, a = e.amplitude;
	phase_estimator_update(&e, NAN, 20.5);
	phase_estimator_update(&e, 5.0, 20.0);      /* time went backwards */
	phase_estimator_update(&e, 5.0, e.last_t);  /* time stood still */
	phase_estimator_update(&e, 0.1, INFINITY);
	assert_true(e.rejected == before + 4);
	assert_true(e.frequency == f && e.amplitude == a);
}

static void test_estimator_follows_stop_and_new_centre(void **state)
{
	(void)state;
	struct phase_estimator e;
	phase_estimator_init(&e);
	double t = 0.0;
	for (int i = 0; i < 800; i++, t += 0.01)
		phase_estimator_update(&e, 0.8 * sin(2.0 * PI * 0.8 * t), t);
	assert_true(fabs(e.frequency - 0.8) < 0.002);
	/* the joint stops: after three periods the estimate says so */
	for (int i = 0; i < 500; i++, t += 0.01)
		phase_estimator_update(&e, 0.1, t);
	assert_true(e.frequency == 0.0 && e.amplitude == 0.0);
	/* it resumes about a new centre, entirely above the old one; the old
	 * cycles are forgotten, not outvoting the new ones */
	for (int i = 0; i < 1000; i++, t += 0.01)
		phase_estimator_update(&e, 0.9 + 0.3 * sin(2.0 * PI * 0.6 * t), t);
	print_message("resumed: A %.4f f %.4f (true 0.3, 0.6)\n", e.amplitude, e.frequency);
	assert_true(fabs(e.frequency - 0.6) < 0.005);
	assert_true(fabs(e.amplitude - 0.3) < 0.005);
	/* a centre drifting by more than the swing (a third of it per cycle) is
	 * followed: while the lag of the median-of-three centre builds up, a few
	 * periods come out ~2 % long; once it is steady (one cycle behind) the
	 * periods are exact again and outvote them. The daemon's EMA estimator
	 * settled within 1 % after 7 s, this one after 10.5 s: the price of a
	 * centre one bent cycle cannot move (test_estimator_phase_jumps). */
	const double t_drift = t;
	for (int i = 0; i < 2000; i++, t += 0.01) {
		double drift = 0.9 + 0.06 * (t - t_drift);
		phase_estimator_update(&e, drift + 0.3 * sin(2.0 * PI * 0.6 * t), t);
		assert_true(e.frequency > 0.0);   /* never lost */
		if (i > 1100)
			assert_true(fabs(e.frequency - 0.6) < 0.01);
		if (i > 1250)
			assert_true(fabs(e.frequency - 0.6) < 0.005);
	}
}

static void test_estimator_ignores_flicker_at_rest(void **state)
{
	(void)state;
	struct phase_estimator e;
	phase_estimator_init(&e);
	/* a joint at rest flickering one position step about zero is not oscillating */
	for (int i = 0; i < 1000; i++)
		phase_estimator_update(&e, (i % 2) ? AX12_POS_STEP : -AX12_POS_STEP, i * 0.01);
	assert_true(e.frequency == 0.0);
}

/* A collision's phase jump disturbs a period or two; the median outvotes
 * them, in frequency and amplitude. Repeated jumps every few cycles (a pair
 * colliding once a period would be another matter) leave the estimate within
 * 1 %. */
static void test_estimator_phase_jumps(void **state)
{
	(void)state;
	struct phase_estimator e;
	phase_estimator_init(&e);
	double w = 2 * PI * 1.0;
	double jump = 0.0, worst = 0.0;
	for (int i = 0; i < 6000; i++) {
		double t = i * 0.01;
		if (i > 1000 && i % 530 == 0)
			jump += 1.5;   /* about every five cycles, once five are measured */
		phase_estimator_update(&e, 0.8 * cos(w * t + jump), t);
		if (t > 10.0)
			worst = fmax(worst, fabs(phase_estimator_omega(&e) - w) / w);
	}
	print_message("phase jumps: worst frequency error %.4f\n", worst);
	assert_true(worst < 0.01);
	assert_true(fabs(e.amplitude - 0.8) < 0.01);
}

/* The period lower bound: a burst of 30 Hz noise bigger than the hysteresis
 * gives no period of its own. */
static void test_estimator_min_period(void **state)
{
	(void)state;
	struct phase_estimator e;
	phase_estimator_init(&e);
	double t = 0.0;
	for (int i = 0; i < 800; i++, t += 0.005)
		phase_estimator_update(&e, 0.5 * sin(2.0 * PI * 30.0 * t), t);
	assert_true(e.frequency == 0.0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_wrap),
		cmocka_unit_test(test_from_state),
		cmocka_unit_test(test_estimator_clean_sine),
		cmocka_unit_test(test_estimator_noisy),
		cmocka_unit_test(test_estimator_quantized_noisy_offset_sine),
		cmocka_unit_test(test_estimator_follows_stop_and_new_centre),
		cmocka_unit_test(test_estimator_ignores_flicker_at_rest),
		cmocka_unit_test(test_estimator_phase_jumps),
		cmocka_unit_test(test_estimator_min_period),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
