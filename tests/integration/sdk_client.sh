#!/usr/bin/env bash
# sdk_client.sh — ROBOTIS's DynamixelSDK as a client of undulate-sim
# (tests/sdk/run.sh), when $DXL_SDK names a checkout of it; this machine's CI
# cannot download it, so without one the test skips and says how to run it.
. "$(dirname "$0")/../lib.sh"
[ -n "${DXL_SDK:-}" ] || tap_skip_all "ROBOTIS DynamixelSDK not given: make test-sdk DXL_SDK=DIR (a checkout of https://github.com/ROBOTIS-GIT/DynamixelSDK; its C library is built outside this tree)"
trap - EXIT
rm -rf "$T"
exec bash "$(dirname "$0")/../sdk/run.sh" "$DXL_SDK"
