/*
 * sdk_p1.c — ROBOTIS's DynamixelSDK (its C library, Protocol 1.0 API) as a
 * client of undulate-sim's simulated AX-12A: every operation the SDK offers
 * for Protocol 1.0, each checked against the AX-12A e-manual; the ones the
 * AX-12A does not have (BULK_READ, REBOOT, SYNC_READ, BULK_WRITE) must fail
 * as they would on the real servo or be refused by the SDK itself.
 *
 *   sdk_p1 PORT ID1 ID2      (neither ID 1: FACTORY_RESET makes ID2 ID 1)
 *
 * The bus runs at 1 Mbps (the AX-12A's factory rate). Output as sdk_p2.c:
 * "ok WHAT", "not ok WHAT: WHY", "# ..." lines for tests/sdk/run.sh.
 */
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "dynamixel_sdk.h"
/* The generic C API has no action(): the protocol's own action1() is used. */
#include "protocol1_packet_handler.h"

#define P1 1
#define SDK_PROTOCOL P1
#define SDK_ERR_NAME "error byte"
#include "sdk_common.h"
/* AX-12A addresses (e-manual). */
#define A_MODEL        0
#define A_ID           3
#define A_RETURN_DELAY 5
#define A_CCW_LIMIT    8
#define A_MIN_VOLTAGE  12
#define A_TORQUE       24
#define A_LED          25
#define A_GOAL_POS     30
#define A_MOVING_SPEED 32
#define A_PRESENT_POS  36
#define A_VOLTAGE      42
#define A_TEMPERATURE  43
#define A_REGISTERED   44
/* Protocol 1.0 status error bits. */
#define E_VOLTAGE      0x01
#define E_ANGLE_LIMIT  0x02
#define E_RANGE        0x08
#define E_INSTRUCTION  0x40

static uint8_t id1, id2;

static void basics(void)
{
	uint16_t m = pingGetModelNum(port, P1, id1);
	result(good() && m == 12, "ping: AX-12A answers with model 12", "model %u; %s", m, said());
	ping(port, P1, 99);
	result(comm() == COMM_RX_TIMEOUT, "ping of an absent ID: no status packet", "%s", said());
	broadcastPing(port, P1);
	result(comm() == COMM_NOT_AVAILABLE, "broadcastPing: the SDK offers it on 2.0 only", "%s", said());
	uint8_t id = read1ByteTxRx(port, P1, id2, A_ID);
	result(good() && id == id2, "read1ByteTxRx: ID", "%u; %s", id, said());
	uint16_t model = read2ByteTxRx(port, P1, id2, A_MODEL);
	result(good() && model == 12, "read2ByteTxRx: model number", "%u; %s", model, said());
	write1ByteTxRx(port, P1, id1, A_LED, 1);
	result(good() && read1ByteTxRx(port, P1, id1, A_LED) == 1, "write1ByteTxRx: LED on, read back", "%s", said());
	write2ByteTxRx(port, P1, id1, A_GOAL_POS, 600);
	result(good() && read2ByteTxRx(port, P1, id1, A_GOAL_POS) == 600, "write2ByteTxRx: goal position, read back",
	       "%s", said());
	/* four bytes on the AX-12A: goal position and moving speed in one write */
	write4ByteTxRx(port, P1, id1, A_GOAL_POS, (200u << 16) | 550u);
	result(good() && read4ByteTxRx(port, P1, id1, A_GOAL_POS) == ((200u << 16) | 550u),
	       "write4ByteTxRx/read4ByteTxRx: goal position + moving speed", "%s", said());
	readTxRx(port, P1, id2, A_PRESENT_POS, 8);
	uint16_t v = (uint16_t)getDataRead(port, P1, 1, A_VOLTAGE - A_PRESENT_POS);
	uint16_t p = (uint16_t)getDataRead(port, P1, 2, 0);
	result(good() && v == 120 && p <= 1023, "readTxRx of 8 bytes from present position: 12.0 V inside it",
	       "voltage %u, position %u; %s", v, p, said());
	write1ByteTxOnly(port, P1, id1, A_LED, 0);
	ms(10);
	result(read1ByteTxRx(port, P1, id1, A_LED) == 0 && good(), "write1ByteTxOnly: LED off", "%s", said());
}

static void reg_write_action(void)
{
	setDataWrite(port, P1, 2, 0, 700);
	regWriteTxRx(port, P1, id2, A_GOAL_POS, 2);
	bool reg = good() && read1ByteTxRx(port, P1, id2, A_REGISTERED) == 1;
	result(reg, "regWriteTxRx: registered", "%s", said());
	action1(port, BROADCAST_ID);
	ms(5);
	uint16_t g = read2ByteTxRx(port, P1, id2, A_GOAL_POS);
	result(good() && g == 700, "action (broadcast): the registered goal is written", "%u; %s", g, said());
	action1(port, id2);
	ms(10);
	read1ByteTxRx(port, P1, id2, A_LED);
	printf("# action (unicast) with nothing registered, then a read: %s\n", said());
	clearPort(port);
}

static void groups(void)
{
	int gw = groupSyncWrite(port, P1, A_GOAL_POS, 2);
	groupSyncWriteAddParam(gw, id1, 400, 2);
	groupSyncWriteAddParam(gw, id2, 450, 2);
	groupSyncWriteTxPacket(gw);
	bool sent = comm() == COMM_SUCCESS;
	ms(5);
	uint16_t a = read2ByteTxRx(port, P1, id1, A_GOAL_POS), b = read2ByteTxRx(port, P1, id2, A_GOAL_POS);
	result(sent && a == 400 && b == 450, "groupSyncWrite: goal positions of both", "%u, %u; %s", a, b, said());
	int gr = groupSyncRead(port, P1, A_PRESENT_POS, 2);
	groupSyncReadAddParam(gr, id1);
	groupSyncReadTxRxPacket(gr);
	result(comm() == COMM_NOT_AVAILABLE, "groupSyncRead: the SDK offers it on 2.0 only", "%s", said());
	int gbw = groupBulkWrite(port, P1);
	groupBulkWriteAddParam(gbw, id1, A_LED, 1, 1, 1);
	groupBulkWriteTxPacket(gbw);
	result(comm() == COMM_NOT_AVAILABLE, "groupBulkWrite: the SDK offers it on 2.0 only", "%s", said());
	/* BULK_READ exists in 1.0 for the MX series; the AX-12A has none: its
	 * e-manual instruction table ends at SYNC_WRITE. No status comes. */
	int gbr = groupBulkRead(port, P1);
	groupBulkReadAddParam(gbr, id1, A_PRESENT_POS, 2);
	groupBulkReadAddParam(gbr, id2, A_PRESENT_POS, 2);
	groupBulkReadTxRxPacket(gbr);
	result(comm() == COMM_RX_TIMEOUT, "groupBulkRead: the AX-12A has no BULK_READ, no status packet",
	       "%s", said());
	reboot(port, P1, id1);
	result(comm() == COMM_NOT_AVAILABLE, "reboot: the SDK offers it on 2.0 only", "%s", said());
	clearMultiTurn(port, P1, id1);
	result(comm() == COMM_NOT_AVAILABLE, "clearMultiTurn: the SDK offers it on 2.0 only", "%s", said());
}

/* The status packet the SDK received: its error byte (rx_packet[4], the
 * SDK's PacketData is public). The SDK's own getLastRxPacketError() is
 * printed beside it: its txRxPacket1 copies the error byte only when the
 * stored one is already non-zero, so on 1.0 it stays 0 (README, "ROBOTIS's
 * DynamixelSDK as a client"). */
static uint8_t rx_error(void)
{
	return comm() == COMM_SUCCESS ? packetData[port].rx_packet[4] : 0xFF;
}

static void error_bit(uint8_t want, const char *what)
{
	uint8_t got = rx_error();
	result(comm() == COMM_SUCCESS && (got & want), what, "error byte 0x%02x; %s", got, said());
	printf("# %s: status error byte 0x%02x, getLastRxPacketError() 0x%02x, getRxPacketError(0x%02x): %s\n", what,
	       got, err(), got, getRxPacketError(P1, got));
}

static void errors_and_reset(void)
{
	write2ByteTxRx(port, P1, id1, A_GOAL_POS, 1024);
	error_bit(E_RANGE, "goal position 1024: the range bit");
	write2ByteTxRx(port, P1, id1, A_CCW_LIMIT, 800);
	write2ByteTxRx(port, P1, id1, A_GOAL_POS, 900);
	error_bit(E_ANGLE_LIMIT, "goal 900 beyond CCW limit 800: the angle-limit bit");
	write2ByteTxRx(port, P1, id1, A_CCW_LIMIT, 1023);
	/* a lasting condition: the supply below Min Voltage Limit */
	write1ByteTxRx(port, P1, id2, A_MIN_VOLTAGE, 130);
	ms(10);
	read1ByteTxRx(port, P1, id2, A_LED);
	error_bit(E_VOLTAGE, "12 V below Min Voltage Limit 13 V: the voltage bit in every status");
	write1ByteTxRx(port, P1, id2, A_MIN_VOLTAGE, 60);
	ms(10);
	read1ByteTxRx(port, P1, id2, A_LED);
	result(comm() == COMM_SUCCESS && rx_error() == 0, "Min Voltage Limit back: no error", "%s", said());
	/* FACTORY_RESET: ID 1, 1 Mbps, return delay back to 250 */
	write1ByteTxRx(port, P1, id2, A_RETURN_DELAY, 0);
	write1ByteTxRx(port, P1, id2, A_ID, 9);
	factoryReset(port, P1, 9, 0);
	result(good(), "factoryReset of ID 9: answered", "%s", said());
	ms(10);
	uint8_t rd = read1ByteTxRx(port, P1, 1, A_RETURN_DELAY);
	result(good() && rd == 250, "factoryReset: the servo is ID 1 with return delay 250", "%u; %s", rd, said());
}

int main(int argc, char **argv)
{
	if (argc != 4) {
		fprintf(stderr, "usage: sdk_p1 PORT ID1 ID2\n");
		return 2;
	}
	id1 = (uint8_t)atoi(argv[2]);
	id2 = (uint8_t)atoi(argv[3]);
	port = portHandler(argv[1]);
	packetHandler();
	if (!openPort(port) || !setBaudRate(port, 1000000)) {
		printf("not ok openPort/setBaudRate(1000000) on %s\n", argv[1]);
		return 1;
	}
	result(true, "openPort and setBaudRate(1000000) on the simulator's pty", "");
	basics();
	reg_write_action();
	groups();
	errors_and_reset();
	closePort(port);
	return 0;
}
