/*
 * sdk_p2.c — ROBOTIS's DynamixelSDK (its C library, Protocol 2.0 API) as a
 * client of undulate-sim's simulated XL430-W250 and XM430-W350: every
 * operation the SDK offers for these models, on one bus, each checked
 * against what the e-manual says the servo answers. Code we did not write on
 * the other end of the wire: what it expects and we do not do (or the other
 * way round) shows here.
 *
 *   sdk_p2 PORT XL_ID XM_ID
 *   sdk_p2 PORT --xc430 ID ID   (two XC430-W150: the model added as data
 *                                only; its own values, a sync loop)
 *
 * The bus starts at the servos' factory 57600 bps. Output: one line per
 * check, "ok WHAT" or "not ok WHAT: WHY", and "# ..." comments; tests/sdk/
 * run.sh turns them into TAP. Exit status 0 unless the port cannot be opened.
 */
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "dynamixel_sdk.h"
/* The generic C API has no action(): the protocol's own action2() is used. */
#include "protocol2_packet_handler.h"

#define P2 2
#define SDK_PROTOCOL P2
#define SDK_ERR_NAME "ERR"
#include "sdk_common.h"
/* X-series addresses (e-manual; the same on both models). */
#define A_MODEL        0
#define A_ID           7
#define A_BAUD         8
#define A_RETURN_DELAY 9
#define A_MODE         11
#define A_TEMP_LIMIT   31
#define A_MAX_VOLTAGE  32
#define A_MIN_VOLTAGE  34
#define A_SHUTDOWN     63
#define A_TORQUE       64
#define A_LED          65
#define A_REGISTERED   69
#define A_HWERR        70
#define A_VEL_P        78
#define A_POS_P        84
#define A_GOAL_PWM     100
#define A_GOAL_POS     116
#define A_MOVING       122
#define A_PRESENT_POS  132
#define A_VOLTAGE      144
#define A_TEMPERATURE  146
#define A_IND_ADDR_1   168
#define A_IND_DATA_1   224

static uint8_t xl, xm;

static void ping_and_models(void)
{
	uint16_t m = pingGetModelNum(port, P2, xl);
	result(good() && m == 1060, "ping: XL430-W250 answers with model 1060", "model %u; %s", m, said());
	m = pingGetModelNum(port, P2, xm);
	result(good() && m == 1020, "ping: XM430-W350 answers with model 1020", "model %u; %s", m, said());
	ping(port, P2, 99);
	result(comm() == COMM_RX_TIMEOUT, "ping of an absent ID: no status packet", "%s", said());
	broadcastPing(port, P2);
	bool both = getBroadcastPingResult(port, P2, xl) && getBroadcastPingResult(port, P2, xm);
	int others = 0;
	for (int id = 0; id < 253; id++)
		others += id != xl && id != xm && getBroadcastPingResult(port, P2, id);
	result(comm() == COMM_SUCCESS && both && others == 0, "broadcastPing finds both servos and nothing else",
	       "found xl=%d xm=%d, %d others; %s", getBroadcastPingResult(port, P2, xl),
	       getBroadcastPingResult(port, P2, xm), others, said());
}

static void reads_and_writes(void)
{
	uint8_t id = read1ByteTxRx(port, P2, xl, A_ID);
	result(good() && id == xl, "read1ByteTxRx: ID", "read %u; %s", id, said());
	uint16_t model = read2ByteTxRx(port, P2, xm, A_MODEL);
	result(good() && model == 1020, "read2ByteTxRx: model number", "read %u; %s", model, said());
	uint32_t pos = read4ByteTxRx(port, P2, xl, A_PRESENT_POS);
	result(good() && pos < 4096, "read4ByteTxRx: present position within a turn", "read %u; %s", pos, said());
	write1ByteTxRx(port, P2, xl, A_LED, 1);
	result(good() && read1ByteTxRx(port, P2, xl, A_LED) == 1, "write1ByteTxRx: LED on, read back", "%s", said());
	write2ByteTxRx(port, P2, xm, A_VEL_P, 150);
	result(good() && read2ByteTxRx(port, P2, xm, A_VEL_P) == 150, "write2ByteTxRx: velocity P gain, read back",
	       "%s", said());
	write4ByteTxRx(port, P2, xl, A_GOAL_POS, 2500);
	result(good() && read4ByteTxRx(port, P2, xl, A_GOAL_POS) == 2500, "write4ByteTxRx: goal position, read back",
	       "%s", said());
	write1ByteTxOnly(port, P2, xl, A_LED, 0);
	ms(20);   /* its status packet arrives unread; the next txPacket flushes it */
	result(read1ByteTxRx(port, P2, xl, A_LED) == 0 && good(), "write1ByteTxOnly: LED off", "%s", said());
	/* a block: Moving .. Present Position (122..135), 14 bytes at once */
	readTxRx(port, P2, xm, A_MOVING, 14);
	uint32_t p2 = getDataRead(port, P2, 4, A_PRESENT_POS - A_MOVING);
	result(good() && p2 < 4096 && p2 == read4ByteTxRx(port, P2, xm, A_PRESENT_POS),
	       "readTxRx of 14 bytes from Moving: Present Position inside it", "%u; %s", p2, said());
	readTx(port, P2, xl, A_VOLTAGE, 3);
	readRx(port, P2, 3);
	uint16_t volts = (uint16_t)getDataRead(port, P2, 2, 0);
	uint8_t temp = (uint8_t)getDataRead(port, P2, 1, 2);
	result(good() && volts == 120 && temp == 25, "readTx + readRx: 12.0 V, 25 C", "%u, %u; %s", volts, temp, said());
}

static void reg_write_action(void)
{
	setDataWrite(port, P2, 4, 0, 2300);
	regWriteTxRx(port, P2, xl, A_GOAL_POS, 4);
	bool reg = good() && read1ByteTxRx(port, P2, xl, A_REGISTERED) == 1;
	uint32_t before = read4ByteTxRx(port, P2, xl, A_GOAL_POS);
	result(reg && before == 2500, "regWriteTxRx: registered, goal unchanged", "registered %d, goal %u; %s",
	       reg, before, said());
	action2(port, BROADCAST_ID);
	ms(5);
	uint32_t after = read4ByteTxRx(port, P2, xl, A_GOAL_POS);
	result(good() && after == 2300 && read1ByteTxRx(port, P2, xl, A_REGISTERED) == 0,
	       "action (broadcast): the registered goal is written", "goal %u; %s", after, said());
	/* the TxOnly forms: REG_WRITE and a 4-byte WRITE whose status is not read */
	setDataWrite(port, P2, 4, 0, 2350);
	regWriteTxOnly(port, P2, xl, A_GOAL_POS, 4);
	ms(20);
	action2(port, BROADCAST_ID);
	ms(5);
	after = read4ByteTxRx(port, P2, xl, A_GOAL_POS);
	result(good() && after == 2350, "regWriteTxOnly + action (broadcast)", "goal %u; %s", after, said());
	write4ByteTxOnly(port, P2, xl, A_GOAL_POS, 2450);
	ms(20);
	after = read4ByteTxRx(port, P2, xl, A_GOAL_POS);
	result(good() && after == 2450, "write4ByteTxOnly: goal position", "goal %u; %s", after, said());
	write2ByteTxOnly(port, P2, xm, A_VEL_P, 120);
	ms(20);
	result(read2ByteTxRx(port, P2, xm, A_VEL_P) == 120 && good(), "write2ByteTxOnly: velocity P gain", "%s", said());
	/* unicast ACTION: the e-manual's Action example has a status packet;
	 * the SDK's txRxPacket2 does not wait for one (INST_ACTION) */
	setDataWrite(port, P2, 4, 0, 2400);
	regWriteTxRx(port, P2, xl, A_GOAL_POS, 4);
	action2(port, xl);
	ms(20);
	after = read4ByteTxRx(port, P2, xl, A_GOAL_POS);
	result(good() && after == 2400, "action (unicast), then a read 20 ms later", "goal %u; %s", after, said());
	/* ... without the pause the ACTION's status packet is taken for the
	 * next read's reply: said in a comment, not judged (the SDK's choice) */
	setDataWrite(port, P2, 4, 0, 2500);
	regWriteTxRx(port, P2, xl, A_GOAL_POS, 4);
	action2(port, xl);
	uint32_t next = read4ByteTxRx(port, P2, xl, A_GOAL_POS);
	printf("# unicast action then an immediate read4ByteTxRx (goal 2500): %s, value %u%s\n", said(), next,
	       next == 2500 ? "" : ": the ACTION's own status packet was taken for the READ's reply");
	ms(50);
	clearPort(port);
}

static void group_sync(void)
{
	int gw = groupSyncWrite(port, P2, A_GOAL_POS, 4);
	groupSyncWriteAddParam(gw, xl, 2000, 4);
	groupSyncWriteAddParam(gw, xm, 2100, 4);
	groupSyncWriteTxPacket(gw);
	bool sent = comm() == COMM_SUCCESS;
	ms(10);
	uint32_t a = read4ByteTxRx(port, P2, xl, A_GOAL_POS), b = read4ByteTxRx(port, P2, xm, A_GOAL_POS);
	result(sent && a == 2000 && b == 2100, "groupSyncWrite: goal positions of both", "%u, %u; %s", a, b, said());
	int gr = groupSyncRead(port, P2, A_PRESENT_POS, 4);
	groupSyncReadAddParam(gr, xl);
	groupSyncReadAddParam(gr, xm);
	groupSyncReadTxRxPacket(gr);
	bool ok = comm() == COMM_SUCCESS && groupSyncReadIsAvailable(gr, xl, A_PRESENT_POS, 4) &&
	          groupSyncReadIsAvailable(gr, xm, A_PRESENT_POS, 4);
	uint32_t pa = groupSyncReadGetData(gr, xl, A_PRESENT_POS, 4), pb = groupSyncReadGetData(gr, xm, A_PRESENT_POS, 4);
	result(ok && pa < 4096 && pb < 4096, "groupSyncRead: present position of both", "%u, %u; %s", pa, pb, said());
	/* one servo in the list absent: the SDK reports the call failed */
	groupSyncReadAddParam(gr, 99);
	groupSyncReadTxRxPacket(gr);
	printf("# groupSyncRead with ID 99 absent: %s; xl available %d, xm available %d\n", said(),
	       groupSyncReadIsAvailable(gr, xl, A_PRESENT_POS, 4), groupSyncReadIsAvailable(gr, xm, A_PRESENT_POS, 4));
	result(comm() != COMM_SUCCESS, "groupSyncRead with an absent servo is not a success", "%s", said());
	ms(50);
	clearPort(port);
}

static void group_bulk(void)
{
	int gr = groupBulkRead(port, P2);
	groupBulkReadAddParam(gr, xl, A_VOLTAGE, 2);
	groupBulkReadAddParam(gr, xm, A_TEMPERATURE, 1);
	groupBulkReadTxRxPacket(gr);
	bool ok = comm() == COMM_SUCCESS && groupBulkReadIsAvailable(gr, xl, A_VOLTAGE, 2) &&
	          groupBulkReadIsAvailable(gr, xm, A_TEMPERATURE, 1);
	uint32_t v = groupBulkReadGetData(gr, xl, A_VOLTAGE, 2), t = groupBulkReadGetData(gr, xm, A_TEMPERATURE, 1);
	result(ok && v == 120 && t == 25, "groupBulkRead: voltage of one, temperature of the other", "%u, %u; %s",
	       v, t, said());
	int gw = groupBulkWrite(port, P2);
	groupBulkWriteAddParam(gw, xl, A_LED, 1, 1, 1);
	groupBulkWriteAddParam(gw, xm, A_POS_P, 2, 700, 2);
	groupBulkWriteTxPacket(gw);
	bool sent = comm() == COMM_SUCCESS;
	ms(10);
	result(sent && read1ByteTxRx(port, P2, xl, A_LED) == 1 && read2ByteTxRx(port, P2, xm, A_POS_P) == 700,
	       "groupBulkWrite: LED of one, position P gain of the other", "%s", said());
}

/* The indirect areas as ROBOTIS's own indirect_address example uses them:
 * torque off, Indirect Address 1..4 = Present Position's four bytes (one
 * write2ByteTxRx each), then a groupSyncRead of Indirect Data 1..4 (224) of
 * both servos: their present positions; with torque on the registers are
 * refused (the example: "Indirect address would not accessible when the
 * torque is already enabled"). What undulated's cycle does, read by code we
 * did not write. */
static void indirect(void)
{
	uint16_t first = read2ByteTxRx(port, P2, xl, A_IND_ADDR_1);
	result(good() && first == A_IND_DATA_1, "read2ByteTxRx: Indirect Address 1 holds 224 at the factory",
	       "read %u; %s", first, said());
	bool mapped = true;
	for (uint8_t id = xl; ; id = xm) {
		write1ByteTxRx(port, P2, id, A_TORQUE, 0);
		for (uint16_t k = 0; k < 4; k++) {
			write2ByteTxRx(port, P2, id, (uint16_t)(A_IND_ADDR_1 + 2 * k), (uint16_t)(A_PRESENT_POS + k));
			mapped = mapped && good();
		}
		if (id == xm)
			break;
	}
	result(mapped, "write2ByteTxRx: Indirect Address 1..4 = 132..135 on both, torque off", "%s", said());
	int gr = groupSyncRead(port, P2, A_IND_DATA_1, 4);
	groupSyncReadAddParam(gr, xl);
	groupSyncReadAddParam(gr, xm);
	groupSyncReadTxRxPacket(gr);
	bool ok = comm() == COMM_SUCCESS && groupSyncReadIsAvailable(gr, xl, A_IND_DATA_1, 4) &&
	          groupSyncReadIsAvailable(gr, xm, A_IND_DATA_1, 4);
	uint32_t ia = groupSyncReadGetData(gr, xl, A_IND_DATA_1, 4), ib = groupSyncReadGetData(gr, xm, A_IND_DATA_1, 4);
	uint32_t pa = read4ByteTxRx(port, P2, xl, A_PRESENT_POS), pb = read4ByteTxRx(port, P2, xm, A_PRESENT_POS);
	result(ok && ia == pa && ib == pb, "groupSyncRead of Indirect Data 1..4: both present positions",
	       "indirect %u, %u; direct %u, %u; %s", ia, ib, pa, pb, said());
	write1ByteTxRx(port, P2, xl, A_TORQUE, 1);
	write2ByteTxRx(port, P2, xl, A_IND_ADDR_1, A_LED);
	result(comm() == COMM_SUCCESS && err() == 7, "Indirect Address with torque on: access error (7)", "%s", said());
	write1ByteTxRx(port, P2, xl, A_TORQUE, 0);
	ms(50);
	clearPort(port);
}

/* The servo's ERR field through the SDK's getRxPacketError. */
static void errors(void)
{
	write4ByteTxRx(port, P2, xl, A_GOAL_POS, 5000);
	result(comm() == COMM_SUCCESS && err() == 6, "goal position 5000 in position mode: data limit error (6)",
	       "%s", said());
	printf("# getRxPacketError: %s\n", getRxPacketError(P2, err()));
	write1ByteTxRx(port, P2, xl, A_TEMP_LIMIT, 101);
	result(comm() == COMM_SUCCESS && err() == 4, "temperature limit 101: data range error (4)", "%s", said());
	write2ByteTxRx(port, P2, xl, A_MODEL, 12);
	result(comm() == COMM_SUCCESS && err() == 7, "write of the model number: access error (7)", "%s", said());
	write1ByteTxRx(port, P2, xm, A_MODE, 0);
	result(good(), "XM430: current control mode exists", "%s", said());
	write1ByteTxRx(port, P2, xl, A_MODE, 0);
	result(comm() == COMM_SUCCESS && err() == 4, "XL430: current control mode does not (data range)", "%s", said());
	write1ByteTxRx(port, P2, xm, A_MODE, 3);
	write1ByteTxRx(port, P2, xl, A_TORQUE, 1);
	write1ByteTxRx(port, P2, xl, A_RETURN_DELAY, 0);
	result(comm() == COMM_SUCCESS && err() == 7, "EEPROM write with torque on: access error (7)", "%s", said());
	write1ByteTxRx(port, P2, xl, A_TORQUE, 0);
	/* an alert: the input voltage above Max Voltage Limit (not a shutdown) */
	write2ByteTxRx(port, P2, xm, A_MAX_VOLTAGE, 110);
	ms(20);
	uint8_t led = read1ByteTxRx(port, P2, xm, A_LED);
	(void)led;
	result(comm() == COMM_SUCCESS && (err() & 0x80), "12 V above Max Voltage Limit 11.0 V: the alert bit",
	       "%s", said());
	printf("# getRxPacketError: %s\n", getRxPacketError(P2, err()));
	uint8_t hw = read1ByteTxRx(port, P2, xm, A_HWERR);
	result(hw == 1, "Hardware Error Status: input voltage (1)", "read %u; %s", hw, said());
	write2ByteTxRx(port, P2, xm, A_MAX_VOLTAGE, 160);
	ms(20);
	read1ByteTxRx(port, P2, xm, A_LED);
	result(good(), "Max Voltage Limit back: no alert", "%s", said());
}

static void reboot_clear_reset(void)
{
	write1ByteTxRx(port, P2, xm, A_TORQUE, 1);
	reboot(port, P2, xm);
	result(good(), "reboot: answered", "%s", said());
	ms(10);
	uint8_t t = read1ByteTxRx(port, P2, xm, A_TORQUE);
	result(good() && t == 0, "reboot: torque off after the boot", "torque %u; %s", t, said());
	/* CLEAR: only while still (Result Fail while moving), then within a turn */
	write1ByteTxRx(port, P2, xm, A_MODE, 4);
	write1ByteTxRx(port, P2, xm, A_TORQUE, 1);
	uint32_t p = read4ByteTxRx(port, P2, xm, A_PRESENT_POS);
	write4ByteTxRx(port, P2, xm, A_GOAL_POS, p + 5000);
	ms(300);
	clearMultiTurn(port, P2, xm);
	result(comm() == COMM_SUCCESS && err() == 1, "clearMultiTurn while moving: result fail (1)", "%s", said());
	for (int i = 0; i < 400 && read1ByteTxRx(port, P2, xm, A_MOVING); i++)
		ms(10);
	int32_t far = (int32_t)read4ByteTxRx(port, P2, xm, A_PRESENT_POS);
	clearMultiTurn(port, P2, xm);
	bool ok = good();
	int32_t near = (int32_t)read4ByteTxRx(port, P2, xm, A_PRESENT_POS);
	/* the joint still creeps a few pulses as it settles */
	int32_t off = (far - near) % 4096;
	result(ok && far > 4096 && near >= 0 && near < 4096 && (off < 30 || off > 4096 - 30),
	       "clearMultiTurn when still: present position back within one turn", "%d -> %d; %s", far, near, said());
	write1ByteTxRx(port, P2, xm, A_TORQUE, 0);
	/* factory reset: 0x02 keeps ID and baud, 0x01 keeps the ID */
	write1ByteTxRx(port, P2, xm, A_RETURN_DELAY, 0);
	factoryReset(port, P2, xm, 0x02);
	result(good(), "factoryReset 0x02: answered", "%s", said());
	ms(10);
	uint8_t rd = read1ByteTxRx(port, P2, xm, A_RETURN_DELAY);
	result(good() && rd == 250, "factoryReset 0x02: return delay back to 250, ID kept", "%u; %s", rd, said());
	write1ByteTxRx(port, P2, xl, A_ID, 9);
	factoryReset(port, P2, 9, 0xFF);
	result(good(), "factoryReset 0xFF of ID 9: answered", "%s", said());
	ms(10);
	uint16_t m = pingGetModelNum(port, P2, 1);
	result(good() && m == 1060, "factoryReset 0xFF: the XL430 is ID 1 again", "model %u; %s", m, said());
	write1ByteTxRx(port, P2, 1, A_ID, xl);
}

/* Baud Rate: the servo answers the write at the old rate, then hears only
 * the new one; the SDK follows with setBaudRate. */
static void baud_change(void)
{
	write1ByteTxRx(port, P2, xl, A_BAUD, 3);
	write1ByteTxRx(port, P2, xm, A_BAUD, 3);
	result(good(), "baud rate 1 Mbps: answered at 57600", "%s", said());
	setBaudRate(port, 1000000);
	uint16_t a = pingGetModelNum(port, P2, xl), b = pingGetModelNum(port, P2, xm);
	result(good() && a == 1060 && b == 1020, "both answer at 1 Mbps", "%u, %u; %s", a, b, said());
	int gr = groupSyncRead(port, P2, A_PRESENT_POS, 4);
	groupSyncReadAddParam(gr, xl);
	groupSyncReadAddParam(gr, xm);
	groupSyncReadTxRxPacket(gr);
	result(comm() == COMM_SUCCESS, "groupSyncRead at 1 Mbps", "%s", said());
	/* 4.5 Mbps is no termios B-constant: the SDK sets it with TCSETS2
	 * (BOTHER) on the pty, as on a USB adapter */
	write1ByteTxRx(port, P2, xl, A_BAUD, 7);
	write1ByteTxRx(port, P2, xm, A_BAUD, 7);
	bool set = setBaudRate(port, 4500000);
	a = pingGetModelNum(port, P2, xl);
	b = pingGetModelNum(port, P2, xm);
	result(set && good() && a == 1060 && b == 1020, "setBaudRate(4500000), a custom rate: both answer",
	       "setBaudRate %d, %u, %u; %s", set, a, b, said());
}

/* Two XC430-W150 (model 1070): its page's own factory values, and the
 * loop undulated runs (sync write of goals, sync read of positions). */
#define A_VEL_LIMIT 44
#define A_PRESENT_LOAD 126
static void xc430(uint8_t a, uint8_t b)
{
	uint16_t ma = pingGetModelNum(port, P2, a);
	bool oka = good();
	uint16_t mb = pingGetModelNum(port, P2, b);
	result(oka && good() && ma == 1070 && mb == 1070, "ping: both XC430-W150 answer with model 1070", "%u, %u; %s",
	       ma, mb, said());
	uint32_t vl = read4ByteTxRx(port, P2, a, A_VEL_LIMIT);
	result(good() && vl == 460, "read4ByteTxRx: velocity limit 460 (the XC430-W150 page's, the XL430's is 265)",
	       "read %u; %s", vl, said());
	uint16_t mv = read2ByteTxRx(port, P2, b, A_MAX_VOLTAGE);
	result(good() && mv == 160, "read2ByteTxRx: max voltage limit 160 (16.0 V)", "read %u; %s", mv, said());
	uint16_t pp = read2ByteTxRx(port, P2, a, A_POS_P);
	result(good() && pp == 460, "read2ByteTxRx: position P gain 460", "read %u; %s", pp, said());
	(void)read2ByteTxRx(port, P2, a, A_PRESENT_LOAD);
	result(good(), "read2ByteTxRx: present load (126)", "%s", said());
	write1ByteTxRx(port, P2, a, A_TORQUE, 1);
	write1ByteTxRx(port, P2, b, A_TORQUE, 1);
	int gw = groupSyncWrite(port, P2, A_GOAL_POS, 4);
	groupSyncWriteAddParam(gw, a, 2300, 4);
	groupSyncWriteAddParam(gw, b, 1800, 4);
	groupSyncWriteTxPacket(gw);
	bool sent = comm() == COMM_SUCCESS;
	int gr = groupSyncRead(port, P2, A_PRESENT_POS, 4);
	groupSyncReadAddParam(gr, a);
	groupSyncReadAddParam(gr, b);
	uint32_t pa = 0, pb = 0;
	bool there = false;
	for (int i = 0; i < 40 && !there; i++) {   /* up to 2 s: 0.1 rad at its speed takes ~0.1 s */
		ms(50);
		groupSyncReadTxRxPacket(gr);
		if (comm() != COMM_SUCCESS || !groupSyncReadIsAvailable(gr, a, A_PRESENT_POS, 4) ||
		    !groupSyncReadIsAvailable(gr, b, A_PRESENT_POS, 4))
			continue;
		pa = groupSyncReadGetData(gr, a, A_PRESENT_POS, 4);
		pb = groupSyncReadGetData(gr, b, A_PRESENT_POS, 4);
		there = pa > 2270 && pa < 2330 && pb > 1770 && pb < 1830;
	}
	result(sent && there, "groupSyncWrite goals 2300/1800, groupSyncRead: both joints get there",
	       "sent %d, present %u, %u; %s", sent, pa, pb, said());
	write1ByteTxRx(port, P2, a, A_TORQUE, 0);
	write1ByteTxRx(port, P2, b, A_TORQUE, 0);
	result(good(), "torque off again", "%s", said());
}

int main(int argc, char **argv)
{
	bool xc = argc == 5 && strcmp(argv[2], "--xc430") == 0;
	if (argc != 4 && !xc) {
		fprintf(stderr, "usage: sdk_p2 PORT XL_ID XM_ID | sdk_p2 PORT --xc430 ID ID\n");
		return 2;
	}
	port = portHandler(argv[1]);
	packetHandler();
	if (!openPort(port) || !setBaudRate(port, 57600)) {
		printf("not ok openPort/setBaudRate(57600) on %s\n", argv[1]);
		return 1;
	}
	result(true, "openPort and setBaudRate(57600) on the simulator's pty", "");
	if (xc) {
		xc430((uint8_t)atoi(argv[3]), (uint8_t)atoi(argv[4]));
		closePort(port);
		return 0;
	}
	xl = (uint8_t)atoi(argv[2]);
	xm = (uint8_t)atoi(argv[3]);
	ping_and_models();
	reads_and_writes();
	reg_write_action();
	group_sync();
	group_bulk();
	indirect();
	errors();
	reboot_clear_reset();
	baud_change();
	closePort(port);
	return 0;
}
