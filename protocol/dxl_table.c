/*
 * dxl_table.c — the AX-12(A)'s unit conversions. Its control table is
 * dxl_ax12_rows.h's, its model descriptor dxl2_table.c's; dxl_axview.c
 * is the struct dxl_reg view of them.
 */
#include "dxl_table.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dxl.h"

/* ---- unit conversions ------------------------------------------------------ */

double dxl_pos_to_rad(uint16_t raw)
{
	return ((int)raw - DXL_POS_CENTER) * DXL_POS_RAD_PER_UNIT;
}

uint16_t dxl_rad_to_pos(double rad)
{
	if (!isfinite(rad))
		return DXL_POS_CENTER;
	double units = rad / DXL_POS_RAD_PER_UNIT + DXL_POS_CENTER;
	if (units <= 0.0)
		return 0;
	if (units >= DXL_POS_MAX)
		return DXL_POS_MAX;
	return (uint16_t)lround(units);
}

int dxl_speed_to_units(uint16_t raw)
{
	int mag = (int)(raw & 0x3FFu);
	return (raw & DXL_DIRECTION_BIT) ? -mag : mag;
}

uint16_t dxl_units_to_speed(int units)
{
	/* clamp before negating: -INT_MIN overflows */
	int mag = units < -1023 ? 1023 : units > 1023 ? 1023 : (units < 0 ? -units : units);
	return (uint16_t)(mag | (units < 0 ? DXL_DIRECTION_BIT : 0));
}

double dxl_speed_to_rad_s(uint16_t raw)
{
	return dxl_speed_to_units(raw) * DXL_SPEED_RAD_S_PER_UNIT;
}

uint16_t dxl_rad_s_to_speed(double rad_s)
{
	if (!isfinite(rad_s))
		return 0;
	double units = rad_s / DXL_SPEED_RAD_S_PER_UNIT;
	if (units > 1023.0)
		units = 1023.0;
	if (units < -1023.0)
		units = -1023.0;
	return dxl_units_to_speed((int)lround(units));
}

uint16_t dxl_duty_to_wheel(double duty)
{
	if (!isfinite(duty))
		return 0;
	return dxl_units_to_speed((int)lround(fmax(-1.0, fmin(1.0, duty)) * 1023.0));
}

uint16_t dxl_rad_s_to_moving_speed(double rad_s)
{
	/* 0 would mean "as fast as possible" — never produce it by rounding a slow
	 * request; NaN also gets the slowest speed, the safe side */
	if (isnan(rad_s))
		return 1;
	double units = fabs(rad_s) / DXL_SPEED_RAD_S_PER_UNIT;
	if (units >= 1023.0)
		return 1023;
	long v = lround(units);
	return (uint16_t)(v < 1 ? 1 : v);
}

double dxl_load_to_fraction(uint16_t raw)
{
	return dxl_speed_to_units(raw) * 0.001;
}

uint16_t dxl_fraction_to_load(double fraction)
{
	if (!isfinite(fraction))
		return 0;
	double units = fraction * 1000.0;
	if (units > 1023.0)
		units = 1023.0;
	if (units < -1023.0)
		units = -1023.0;
	return dxl_units_to_speed((int)lround(units));
}

double dxl_voltage_to_volts(uint8_t raw)
{
	return raw * 0.1;
}

/* The servo's clock divides 2 MHz by (v + 1); rounded to the nearest bps. */
#define DXL_BAUD_CLOCK 2000000L
/* Tolerance of a UART to a rate mismatch (the e-Manual's figure for 8N1). */
#define DXL_BAUD_TOLERANCE 0.03

long dxl_baud_from_reg(uint8_t v)
{
	long div = (long)v + 1;
	return (DXL_BAUD_CLOCK + div / 2) / div;
}

int dxl_baud_to_reg(long bps, uint8_t *v)
{
	if (bps <= 0 || v == NULL)
		return DXL_E_ARG;
	long guess = lround((double)DXL_BAUD_CLOCK / (double)bps) - 1;
	long best = -1;
	double best_err = 1e9;
	for (long c = guess - 1; c <= guess + 1; c++) {
		if (c < 0 || c > 254)
			continue;
		double err = fabs((double)dxl_baud_from_reg((uint8_t)c) - (double)bps) / (double)bps;
		if (err < best_err) {
			best_err = err;
			best = c;
		}
	}
	if (best < 0 || best_err > DXL_BAUD_TOLERANCE)
		return DXL_E_ARG;
	*v = (uint8_t)best;
	return DXL_OK;
}

unsigned dxl_return_delay_us(uint8_t v)
{
	return 2u * v;
}

bool dxl_is_wheel_mode(uint16_t cw_limit, uint16_t ccw_limit)
{
	return cw_limit == 0 && ccw_limit == 0;
}
