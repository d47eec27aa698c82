/*
 * dxl_axview.c — the AX-12A's rows as struct dxl_reg (dxl_table.h): a thin
 * view for the code that walks the AX-12's 8-bit addresses (the simulated
 * servo's memory). The rows are dxl_ax12_rows.h's, the same the AX-12A's
 * model descriptor has; lookup, write checks and formatting are the
 * descriptor's (dxl2_table.c), so the view cannot disagree with it.
 */
#include "dxl_table.h"

#include <stdio.h>

#include "dxl.h"
#include "dxl2_table.h"
#include "dxl_ax12_rows.h"

#define R   DXL_ACCESS_R
#define RW  DXL_ACCESS_RW
#define EE  DXL_AREA_EEPROM
#define RAM DXL_AREA_RAM
#define NODEF (-1)
#define VIEW_ROW(name, addr, size, access, area, min, max, def, unit, desc) \
	{ name, addr, size, access, area, min, max, def, DXL_UNIT_##unit, desc },

const struct dxl_reg dxl_ax12_regs[] = {
	DXL_AX12_ROWS(VIEW_ROW)
};
const size_t dxl_ax12_nregs = sizeof dxl_ax12_regs / sizeof dxl_ax12_regs[0];

static const struct dxl2_model *ax12a(void)
{
	return dxl2_model_find(1, DXL_AX12_MODEL);
}

/* The descriptor's row of a view row. */
static const struct dxl2_reg *row_of(const struct dxl_reg *reg)
{
	return reg != NULL ? dxl2_reg_at(ax12a(), reg->addr) : NULL;
}

const struct dxl_reg *dxl_reg_at(uint8_t addr)
{
	for (size_t i = 0; i < dxl_ax12_nregs; i++)
		if (dxl_ax12_regs[i].addr == addr)
			return &dxl_ax12_regs[i];
	return NULL;
}

const struct dxl_reg *dxl_reg_lookup(const char *name_or_addr)
{
	const struct dxl2_reg *r = dxl2_reg_lookup(ax12a(), name_or_addr);
	return r != NULL ? dxl_reg_at((uint8_t)r->addr) : NULL;
}

int dxl_reg_check_write(const struct dxl_reg *reg, long value)
{
	return dxl2_reg_check_write(ax12a(), row_of(reg), value);
}

int dxl_reg_check_write_mode(const struct dxl_reg *reg, long value, bool wheel)
{
	/* an image of the angle limits: both 0 is wheel mode */
	uint8_t image[DXL_AX_CCW_ANGLE_LIMIT + 2] = { 0 };
	if (!wheel)
		image[DXL_AX_CCW_ANGLE_LIMIT] = 1;
	return dxl2_reg_check_write_live(ax12a(), row_of(reg), value, image, sizeof image);
}

char *dxl_reg_format(const struct dxl_reg *reg, uint16_t raw, char *buf, size_t cap)
{
	if (reg == NULL) {
		if (buf != NULL && cap > 0)
			snprintf(buf, cap, "%u", raw);
		return buf;
	}
	return dxl2_reg_format(row_of(reg), raw, buf, cap);
}
