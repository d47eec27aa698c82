#!/usr/bin/env bash
echo "make demo: not yet — the daemon and the simulator are being built." >&2
exit 1
