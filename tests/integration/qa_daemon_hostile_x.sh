#!/usr/bin/env bash
# qa_daemon_hostile.sh on two simulated XM430-W350 (Protocol 2.0, 1 Mbps): the
# same attack from the network (hostile and half-signed LCM commands, limits
# narrowed to +-0.5 rad) and from the bus (garbage, bad CRCs, replies cut
# short, wrong IDs, random bytes), the same assertions: the loop keeps 100 Hz,
# every bad command counted and none accepted, no goal outside the limits.
QA_MODEL=xm430-w350 QA_PORT=7956
. "$(dirname "$0")/qa_daemon_hostile.sh"
