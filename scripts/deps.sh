#!/usr/bin/env bash
# scripts/deps.sh [PACKAGE...] — installs the Debian packages undulate needs
# (or the ones named), when they are missing.
# As root: runs apt-get. Otherwise: prints the exact command and stops.
set -eu
# build + runtime: compiler, LCM (pkg-config lcm needs glib's .pc), serial
# ports, config parsing (inih), command authentication (libsodium), unit tests (cmocka); tests and tools: jq and
# python3 (test peers and JSON checks), iproute2 (`ss`: the sockets a daemon
# holds, safety_commands),
# gnuplot for plots, GNU parallel for the figures' runs (make figures,
# scripts/figures.sh), cyclictest for the jitter benchmark; systemd and man-db
# for checking the units (systemd-analyze verify) and the man pages;
# libwebsockets and Chart.js for undulate-web (its page's plots, served from
# the installed path); Chipmunk2D for the simulator's plane world; GSL for
# undulate-model (the paper's equations: odeiv2, root finding). Chromium (headless: web_dashboard's browser test) is
# installed by `make test` when it can be (`scripts/deps.sh chromium`);
# without it that test says so and skips.
need=(build-essential pkg-config liblcm-dev liblcm-bin libglib2.0-dev libserialport-dev
      libinih-dev libsodium-dev libcmocka-dev libpng-dev gnuplot-nox parallel rt-tests procps iproute2 jq python3 socat systemd man-db curl
      libwebsockets-dev libjs-chart.js libchipmunk-dev libgsl-dev liblzma-dev xz-utils)
[ $# -gt 0 ] && need=("$@")
# one dpkg-query for all (one each cost seconds: it reads the whole status file)
installed=" $(dpkg-query -W -f='${Package} ${Status}\n' "${need[@]}" 2>/dev/null |
	awk '/ install ok installed$/ { printf "%s ", $1 }')"
missing=()
for p in "${need[@]}"; do
	[[ "$installed" == *" $p "* ]] || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
cmd="apt-get install -y --no-install-recommends ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
	echo "undulate needs these Debian packages: ${missing[*]}" >&2
	echo "run:  sudo apt-get update && sudo $cmd" >&2
	exit 1
fi
echo "installing: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
