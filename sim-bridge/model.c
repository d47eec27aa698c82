/*
 * model.c — the simulated servo models and their datasheet facts (model.h).
 * Numbers: the ROBOTIS e-manual's specification tables, at 12 V, as
 * protocol/dxl2_table.c's model descriptors have them (the daemon and dxl
 * read the same ones); PHYSICS.md §5 says how each is used.
 */
#include "model.h"

#include <ctype.h>
#include <stdio.h>
#include <string.h>

#include "dxl_table.h"

#define RPM_TO_RAD_S (2.0 * 3.14159265358979323846 / 60.0)

/* Model m is protocol/dxl2_table.c's descriptor m (the AX-12A first), its
 * facts taken from there (a new model there is one here). */
#define SIM_MAX_MODELS 32
static struct sim_model_info info[SIM_MAX_MODELS];
static char lname[SIM_MAX_MODELS][24];
static bool made[SIM_MAX_MODELS];

int sim_model_count(void)
{
	size_t n = dxl2_model_count();
	return (int)(n < SIM_MAX_MODELS ? n : SIM_MAX_MODELS);
}

/* The option's name: the label in lower case, or the name scenarios have
 * used since before the model list held the X series. */
static const struct {
	uint16_t number;
	const char *name;
} model_old_names[] = {
	{ DXL_AX12_MODEL, "ax12a" },
};

static void model_option_name(const struct dxl2_model *d, char *out, size_t cap)
{
	size_t k = 0;
	for (size_t i = 0; i < sizeof model_old_names / sizeof model_old_names[0]; i++)
		if (model_old_names[i].number == d->number) {
			snprintf(out, cap, "%s", model_old_names[i].name);
			return;
		}
	for (const char *c = d->name; *c != '\0' && k + 1 < cap; c++)
		out[k++] = (char)tolower((unsigned char)*c);
	out[k] = '\0';
}

const struct sim_model_info *sim_model_info(enum sim_model m)
{
	size_t i = ((int)m <= 0 || (int)m >= sim_model_count()) ? 0 : (size_t)m;
	if (!made[i]) {
		const struct dxl2_model *d = dxl2_model_at(i);
		model_option_name(d, lname[i], sizeof lname[i]);
		info[i] = (struct sim_model_info){
			.name = lname[i], .label = d->name, .protocol = d->protocol, .default_baud = d->factory_baud,
			.firmware = d->firmware, .stall_torque_nm = d->sheet.stall_torque_nm,
			.no_load_speed_rpm = d->sheet.no_load_speed_rpm, .stall_current_a = d->sheet.stall_current_a,
			.gear_ratio = d->sheet.gear_ratio, .rotor_inertia = d->sheet.rotor_inertia, .model_number = d->number,
		};
		made[i] = true;
	}
	return &info[i];
}

/* Case-insensitive, '-' and '_' ignored: "AX-12A", "ax12a", "XL430_W250". */
static bool model_name_eq(const char *a, const char *b)
{
	for (;;) {
		while (*a == '-' || *a == '_')
			a++;
		while (*b == '-' || *b == '_')
			b++;
		if (tolower((unsigned char)*a) != tolower((unsigned char)*b))
			return false;
		if (*a == '\0')
			return true;
		a++;
		b++;
	}
}

int sim_model_parse(const char *name, enum sim_model *m)
{
	if (name == NULL)
		return -1;
	for (int i = 0; i < sim_model_count(); i++)
		if (model_name_eq(name, sim_model_info((enum sim_model)i)->name)) {
			*m = (enum sim_model)i;
			return 0;
		}
	return -1;
}

const char *sim_model_names(void)
{
	static char names[SIM_MAX_MODELS * 26];
	size_t off = 0;
	names[0] = '\0';
	for (int i = 0; i < sim_model_count(); i++) {
		int w = snprintf(names + off, sizeof names - off, "%s%s", i ? ", " : "",
		                 sim_model_info((enum sim_model)i)->name);
		if (w < 0 || (size_t)w >= sizeof names - off)
			break;
		off += (size_t)w;
	}
	return names;
}

const struct dxl2_model *sim_model_table(enum sim_model m)
{
	const struct sim_model_info *i = sim_model_info(m);
	return i->protocol == 2 ? dxl2_model_find(2, i->model_number) : NULL;
}

void sim_model_motor_params(enum sim_model m, struct sim_motor_params *p)
{
	sim_motor_default_params(p);
	if (m == SIM_MODEL_AX12A)
		return;
	const struct sim_model_info *i = sim_model_info(m);
	p->stall_torque_12v = i->stall_torque_nm;
	p->no_load_speed_12v = i->no_load_speed_rpm * RPM_TO_RAD_S;
	p->inertia = sim_motor_link_inertia() + i->rotor_inertia * i->gear_ratio * i->gear_ratio;
}

double sim_model_torque_constant(enum sim_model m)
{
	const struct sim_model_info *i = sim_model_info(m);
	return i->stall_torque_nm / i->stall_current_a;
}
