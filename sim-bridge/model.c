/*
 * model.c — the simulated servo models and their datasheet facts (model.h).
 * Numbers: the ROBOTIS e-manual's specification tables, at 12 V: the X
 * series' are protocol/dxl2_table.c's descriptors (the daemon and dxl read
 * the same ones), the AX-12A's dxl_table.h; PHYSICS.md §5 says how each is
 * used.
 */
#include "model.h"

#include <ctype.h>
#include <stdio.h>
#include <string.h>

#include "dxl_table.h"

#define RPM_TO_RAD_S (2.0 * 3.14159265358979323846 / 60.0)

static const struct sim_model_info ax12a = {
	.name = "ax12a", .label = "AX-12A", .protocol = 1, .default_baud = 1000000, .firmware = 24,
	.stall_torque_nm = DXL_AX12_STALL_TORQUE_NM, .no_load_speed_rpm = DXL_AX12_NO_LOAD_SPEED_RPM,
	.stall_current_a = 1.5, .gear_ratio = 254.0, .rotor_inertia = 4.6e-8,
	.model_number = DXL_AX12_MODEL,
};

/* The X models: model m is protocol/dxl2_table.c's descriptor m - 1, its
 * facts taken from there (a new model there is one here). */
#define SIM_MAX_X 32
static struct sim_model_info xinfo[SIM_MAX_X];
static char xname[SIM_MAX_X][24];
static bool xmade[SIM_MAX_X];

int sim_model_count(void)
{
	size_t n = dxl2_model_count();
	return 1 + (int)(n < SIM_MAX_X ? n : SIM_MAX_X);
}

const struct sim_model_info *sim_model_info(enum sim_model m)
{
	if ((int)m <= 0 || (int)m >= sim_model_count())
		return &ax12a;
	size_t i = (size_t)m - 1;
	if (!xmade[i]) {
		const struct dxl2_model *d = dxl2_model_at(i);
		size_t k = 0;
		for (; d->name[k] != '\0' && k + 1 < sizeof xname[i]; k++)
			xname[i][k] = (char)tolower((unsigned char)d->name[k]);
		xname[i][k] = '\0';
		xinfo[i] = (struct sim_model_info){
			.name = xname[i], .label = d->name, .protocol = 2, .default_baud = d->factory_baud,
			.firmware = d->firmware, .stall_torque_nm = d->sheet.stall_torque_nm,
			.no_load_speed_rpm = d->sheet.no_load_speed_rpm, .stall_current_a = d->sheet.stall_current_a,
			.gear_ratio = d->sheet.gear_ratio, .rotor_inertia = d->sheet.rotor_inertia, .model_number = d->number,
		};
		xmade[i] = true;
	}
	return &xinfo[i];
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
	static char names[SIM_MAX_X * 26];
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
	return i->protocol == 2 ? dxl2_model_by_number(i->model_number) : NULL;
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
