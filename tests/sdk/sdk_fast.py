"""sdk_fast.py — ROBOTIS's Python DynamixelSDK (its python/src, which has Fast
Sync Read and Fast Bulk Read; its C port has not) against undulate-sim's X
servos: the fast reads beside the plain SYNC_READ, of the present registers and
of the indirect block mapped to them, and on firmware below 45 no answer. Code we did not write parses the one status packet the simulated
servos build together. Prints "ok"/"not ok" lines (tests/sdk/run.sh).
usage: sdk_fast.py SDK_PYTHON_SRC PORT BAUD fast|none ID..."""
import sys
sys.path.insert(0, sys.argv[1])
from dynamixel_sdk import PortHandler, PacketHandler, GroupSyncRead, GroupBulkRead, COMM_SUCCESS  # noqa: E402

port_path, baud, expect = sys.argv[2], int(sys.argv[3]), sys.argv[4]
ids = [int(x) for x in sys.argv[5:]]
port, ph = PortHandler(port_path), PacketHandler(2.0)
n = 0
def result(ok, name, why=""):
    global n
    n += 1
    print(("ok %d - %s" if ok else "not ok %d - %s") % (n, name))
    if not ok and why:
        print("# " + why)
if not (port.openPort() and port.setBaudRate(baud)):
    result(False, "open " + port_path)
    sys.exit(0)
plain = GroupSyncRead(port, ph, 132, 4)
for i in ids:
    plain.addParam(i)
rc = plain.txRxPacket()
pos = {i: plain.getData(i, 132, 4) for i in ids} if rc == COMM_SUCCESS else {}
result(rc == COMM_SUCCESS, "plain SYNC_READ of present position: %s" % pos, ph.getTxRxResult(rc))
fast = GroupSyncRead(port, ph, 132, 4)
for i in ids:
    fast.addParam(i)
rc = fast.fastSyncRead()
if expect == "fast":
    got = {i: fast.getData(i, 132, 4) for i in ids if fast.isAvailable(i, 132, 4)}
    near = all(abs(int(got.get(i, -99999)) - int(pos.get(i, 0))) < 50 for i in ids)
    result(rc == COMM_SUCCESS and len(got) == len(ids) and near,
           "fastSyncRead (0x8A): every servo's present position, as the plain read's: %s" % got, ph.getTxRxResult(rc))
    bulk = GroupBulkRead(port, ph)
    bulk.addParam(ids[0], 132, 4)
    for i in ids[1:]:
        bulk.addParam(i, 146, 1)
    rc = bulk.fastBulkRead()
    ok = rc == COMM_SUCCESS and bulk.isAvailable(ids[0], 132, 4) and all(bulk.isAvailable(i, 146, 1) for i in ids[1:])
    temps = [bulk.getData(i, 146, 1) for i in ids[1:]] if ok else []
    result(ok and all(10 <= t <= 80 for t in temps),
           "fastBulkRead (0x9A): position of %d, temperature of the others %s" % (ids[0], temps), ph.getTxRxResult(rc))
    # undulated's read: Indirect Address 1..4 (168..) = Present Position's
    # bytes (132..135), torque off, then one fastSyncRead of Indirect Data 1..4
    mapped = True
    for i in ids:
        ph.write1ByteTxRx(port, i, 64, 0)
        for k in range(4):
            rc, err = ph.write2ByteTxRx(port, i, 168 + 2 * k, 132 + k)
            mapped = mapped and rc == COMM_SUCCESS and err == 0
    ind = GroupSyncRead(port, ph, 224, 4)
    for i in ids:
        ind.addParam(i)
    rc = ind.fastSyncRead()
    got = {i: ind.getData(i, 224, 4) for i in ids if ind.isAvailable(i, 224, 4)}
    near = all(abs(int(got.get(i, -99999)) - int(pos.get(i, 0))) < 50 for i in ids)
    result(mapped and rc == COMM_SUCCESS and len(got) == len(ids) and near,
           "fastSyncRead of Indirect Data 1..4 (224) mapped to 132..135: the present positions %s" % got,
           ph.getTxRxResult(rc))
else:
    result(rc != COMM_SUCCESS, "firmware below 45: fastSyncRead gets no answer (%s)" % ph.getTxRxResult(rc))
print("1..%d" % n)
port.closePort()
