/*
 * model.c — the simulated servo models and their datasheet facts (model.h).
 * Numbers: the ROBOTIS e-manual's specification tables (ROBOTIS-GIT/emanual,
 * _data/dxl_x_info.yml for the X series; the AX-12A page for the AX-12A), at
 * 12 V; PHYSICS.md §5 says how each is used.
 */
#include "model.h"

#include <ctype.h>
#include <string.h>

#include "dxl_table.h"

#define RPM_TO_RAD_S (2.0 * 3.14159265358979323846 / 60.0)

static const struct sim_model_info models[SIM_MODELS] = {
	[SIM_MODEL_AX12A] = {
		.name = "ax12a", .label = "AX-12A", .protocol = 1, .default_baud = 1000000, .firmware = 24,
		.stall_torque_nm = DXL_AX12_STALL_TORQUE_NM, .no_load_speed_rpm = DXL_AX12_NO_LOAD_SPEED_RPM,
		.stall_current_a = 1.5, .gear_ratio = 254.0, .rotor_inertia = 4.6e-8,
		.model_number = DXL_AX12_MODEL,
	},
	/* 1.5 N·m at 12 V (1.4 A), 61 rpm at 12 V, 258.5:1, a cored motor: its
	 * rotor taken as the AX-12A's (the same class of motor). */
	[SIM_MODEL_XL430_W250] = {
		.name = "xl430-w250", .label = "XL430-W250", .protocol = 2, .default_baud = 57600, .firmware = 46,
		.stall_torque_nm = DXL2_XL430_STALL_TORQUE_NM, .no_load_speed_rpm = DXL2_XL430_NO_LOAD_SPEED_RPM,
		.stall_current_a = DXL2_XL430_STALL_CURRENT_A, .gear_ratio = 258.5,
		.rotor_inertia = 4.6e-8, .model_number = DXL2_MODEL_XL430_W250,
	},
	/* 4.1 N·m at 12 V (2.3 A), 46 rpm at 12 V, 353.5:1, a coreless (Maxon)
	 * motor: 0.5 g·cm² taken for its rotor (not published; PHYSICS.md). */
	[SIM_MODEL_XM430_W350] = {
		.name = "xm430-w350", .label = "XM430-W350", .protocol = 2, .default_baud = 57600, .firmware = 46,
		.stall_torque_nm = DXL2_XM430_STALL_TORQUE_NM, .no_load_speed_rpm = DXL2_XM430_NO_LOAD_SPEED_RPM,
		.stall_current_a = DXL2_XM430_STALL_CURRENT_A, .gear_ratio = 353.5,
		.rotor_inertia = 5.0e-8, .model_number = DXL2_MODEL_XM430_W350,
	},
};

const struct sim_model_info *sim_model_info(enum sim_model m)
{
	return (unsigned)m < SIM_MODELS ? &models[m] : &models[SIM_MODEL_AX12A];
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
	for (int i = 0; i < SIM_MODELS; i++)
		if (model_name_eq(name, models[i].name)) {
			*m = (enum sim_model)i;
			return 0;
		}
	return -1;
}

const char *sim_model_names(void)
{
	return "ax12a, xl430-w250, xm430-w350";
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
