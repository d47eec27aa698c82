#!/usr/bin/env bash
# run.sh: alone — it measures an experiment in real time: nothing beside it (tests/run.sh)
# e2e_pair_realtime.sh — the real-time half of tests/integration/e2e_pair.sh: the
# same pair runs through the daemons on the simulator's real clock, the same
# regime claims. `make test` runs the lockstep half, whose outcome does not
# depend on the machine's load; these depend on it (tests/lib.sh, E2E_PART).
E2E_PART=realtime exec bash "$(dirname "$0")/../integration/e2e_pair.sh"
