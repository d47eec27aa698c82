#!/usr/bin/env bash
# `make install` / `make uninstall` (scripts/install.sh) into a DESTDIR, and
# `systemd-analyze verify` on the installed units.
#
# The programs come from $BUILD/bin when all of them are built; otherwise
# small stand-ins are installed (this test is about the install, not the
# programs, and must not depend on every component compiling).
. "$(dirname "$0")/../lib.sh"

programs=(undulated undulate-sim dxl undulate-top undulate-analyze)
units=(undulated@.service undulate-sim.service undulate-web.service)

src_build="$BUILD"
for p in "${programs[@]}"; do
	[ -x "$BUILD/bin/$p" ] && continue
	src_build="$T/build"
	break
done
if [ "$src_build" != "$BUILD" ]; then
	mkdir -p "$src_build/bin"
	for p in "${programs[@]}"; do
		if [ -x "$BUILD/bin/$p" ]; then cp "$BUILD/bin/$p" "$src_build/bin/$p"
		else printf '#!/bin/sh\necho "%s stand-in"\n' "$p" >"$src_build/bin/$p"; chmod +x "$src_build/bin/$p"
		fi
	done
	echo "# not every program is built in $BUILD: stand-ins installed for the missing ones"
fi

# run_install ROOT PREFIX install|uninstall [extra env...]
run_install() {
	local root=$1 prefix=$2 what=$3; shift 3
	env "$@" PREFIX="$prefix" DESTDIR="$root" BUILD="$src_build" "$top/scripts/install.sh" "$what" \
		>"$T/install.out" 2>&1
}
tree() { (cd "$1" && find . -mindepth 1 | sort); }

# ---- install with the default prefix ---------------------------------------------
R="$T/root"
P=/usr/local
if run_install "$R" "$P" install; then tap_ok "install into a DESTDIR"
else tap_fail "install into a DESTDIR" "$(cat "$T/install.out")"; fi

missing=()
for p in "${programs[@]}"; do
	[ -x "$R$P/bin/$p" ] && cmp -s "$src_build/bin/$p" "$R$P/bin/$p" || missing+=("bin/$p")
done
for u in "${units[@]}"; do [ -f "$R$P/lib/systemd/system/$u" ] || missing+=("unit $u"); done
cmp -s "$top/systemd/99-undulate.rules" "$R$P/lib/udev/rules.d/99-undulate.rules" || missing+=("udev rules")
[ -f "$R$P/lib/sysusers.d/undulate.conf" ] || missing+=("sysusers.d entry")
for p in undulate-sim dxl undulate-top undulate-analyze; do
	cmp -s "$top/man/$p.1" "$R$P/share/man/man1/$p.1" || missing+=("man1/$p.1")
done
cmp -s "$top/man/undulated.8" "$R$P/share/man/man8/undulated.8" || missing+=("man8/undulated.8")
for s in "$top"/sim-bridge/scenarios/*.scenario; do
	[ -f "$s" ] || continue
	cmp -s "$s" "$R$P/share/undulate/scenarios/$(basename "$s")" || missing+=("scenario $(basename "$s")")
done
# the documents installed files point at (the example config: the daemon's README)
for d in README.md daemon/README.md daemon/CONTROL.md sim-bridge/README.md docs/EXPERIMENTS.md; do
	cmp -s "$top/$d" "$R$P/share/doc/undulate/$d" || missing+=("doc $d")
done
grep -q "share/doc/undulate/daemon/README.md" "$R/etc/undulate/undulated.conf.example" 2>/dev/null ||
	missing+=("the example config's pointer to the installed daemon README")
if [ ${#missing[@]} -eq 0 ]; then
	tap_ok "installed tree: programs, units, udev rules, sysusers, man pages, scenarios, documentation"
else
	tap_fail "installed tree complete" "missing or different: ${missing[*]}"
fi
if [ ! -f "$top/systemd/undulated.conf.example" ]; then
	tap_fail "example config installed" "systemd/undulated.conf.example does not exist in the tree"
elif cmp -s "$top/systemd/undulated.conf.example" "$R/etc/undulate/undulated.conf.example"; then
	tap_ok "example config installed in /etc/undulate"
	# What the README tells the operator to start from must be a valid config.
	if [ -x "$BUILD/bin/undulated" ]; then
		if out=$("$BUILD/bin/undulated" --config "$R/etc/undulate/undulated.conf.example" --check-config 2>&1)
		then tap_ok "the installed example passes undulated --check-config"
		else tap_fail "the installed example passes undulated --check-config" "$out"; fi
	fi
else
	tap_fail "example config installed" "$(tree "$R" | grep etc)"
fi

# The sysusers.d entry makes the service user, as the unit needs it, when
# systemd-sysusers applies it (install.sh does, as root; so does every boot).
if command -v systemd-sysusers >/dev/null; then
	U="$T/users"
	mkdir -p "$U/etc"
	echo 'root:x:0:0:root:/root:/bin/sh' >"$U/etc/passwd"
	echo 'root:x:0:' >"$U/etc/group"
	echo 'dialout:x:20:' >>"$U/etc/group"
	out=$(systemd-sysusers --root="$U" "$R$P/lib/sysusers.d/undulate.conf" 2>&1)
	pw=$(grep '^undulate:' "$U/etc/passwd")
	if [[ "$pw" == undulate:x:*:*:*:/nonexistent:/usr/sbin/nologin ]] &&
		grep -qE '^dialout:x:20:(.*,)?undulate(,|$)' "$U/etc/group" && grep -q '^undulate:' "$U/etc/group"; then
		tap_ok "sysusers.d: system user undulate (no login, own group, in dialout)"
	else
		tap_fail "sysusers.d creates the service user" "$out"$'\n'"$(cat "$U/etc/passwd" "$U/etc/group")"
	fi
fi

# Units run the installed programs with the robot's config.
ok=1
exec_d=$(grep '^ExecStart=' "$R$P/lib/systemd/system/undulated@.service")
exec_s=$(grep '^ExecStart=' "$R$P/lib/systemd/system/undulate-sim.service")
[ "$exec_d" = "ExecStart=$P/bin/undulated --config /etc/undulate/%i.conf" ] || ok=0
[ "$exec_s" = "ExecStart=$P/bin/undulate-sim --scenario /etc/undulate/sim.scenario --link-dir /run/undulate --control /run/undulate/sim.control" ] || ok=0
if [ $ok -eq 1 ]; then tap_ok "ExecStart runs the installed binaries ($P/bin)"
else tap_fail "ExecStart runs the installed binaries" "$exec_d"$'\n'"$exec_s"; fi

# The manifest lists exactly what is in the tree (and nothing more).
manifest="$R$P/share/undulate/install-manifest"
listed=$( { cut -f2 "$manifest"; echo "$P/share/undulate/install-manifest"; } | sed 's#^#.#' | sort)
if [ -f "$manifest" ] && [ "$listed" = "$(tree "$R")" ]; then
	tap_ok "install manifest lists every installed file and directory"
else
	tap_fail "install manifest matches the tree" "$(diff <(echo "$listed") <(tree "$R"))"
fi

# ---- systemd-analyze verify: no output at all ---------------------------------------
# verify exits 0 on some errors, so any output is a failure. The installed units
# name $P/bin/... (not there outside the DESTDIR): check copies pointed into it;
# their man pages are found through MANPATH, so Documentation= is checked too.
# Without man(1) installed, verify could only complain that it is missing.
man_check=--man=yes
command -v man >/dev/null || { man_check=--man=no; echo "# man not installed: Documentation= not checked"; }
verify_units() { # DIR UNIT... -> output of systemd-analyze verify
	(cd "$1" && shift && MANPATH="$R$P/share/man" SYSTEMD_LOG_COLOR=0 \
		systemd-analyze verify --generators=no "$man_check" "${@/#/./}" 2>&1)
}
if ! command -v systemd-analyze >/dev/null; then
	tap_skip "systemd-analyze verify" "systemd-analyze not installed"
else
	mkdir -p "$T/units"
	for u in "${units[@]}"; do
		sed "s#^ExecStart=$P/bin/#ExecStart=$R$P/bin/#" "$R$P/lib/systemd/system/$u" >"$T/units/$u"
	done
	out=$(verify_units "$T/units" "${units[@]}")
	if [ -z "$out" ]; then tap_ok "systemd-analyze verify prints nothing for every unit"
	else tap_fail "systemd-analyze verify prints nothing" "$out"; fi

	# ... and it does speak up about a broken unit, so the silence means something.
	mkdir -p "$T/bad"
	sed -e 's/^WatchdogSec=/WatchdogSecs=/' "$T/units/undulated@.service" >"$T/bad/undulated@.service"
	sed -e "s#^ExecStart=$R$P/bin/#ExecStart=$T/nowhere/#" "$T/units/undulate-sim.service" \
		>"$T/bad/undulate-sim.service"
	# The hardening as systemd scores it (offline, 0 = locked down .. 10 = none):
	# fail if a change lets it slide past 2.0.
	sec_ok=1 sec_out=
	for u in "${units[@]}"; do
		line=$(cd "$T/units" && systemd-analyze security --offline=yes --man=no --threshold=20 "./$u" 2>&1) \
			|| sec_ok=0
		sec_out+=$(echo "$line" | grep 'Overall exposure')$'\n'
	done
	if [ $sec_ok -eq 1 ]; then tap_ok "systemd-analyze security: exposure <= 2.0 for every unit ($(echo $sec_out | grep -o '[0-9.]* OK' | tr '\n' ' '))"
	else tap_fail "systemd-analyze security exposure <= 2.0" "$sec_out"; fi

	out_bad1=$(verify_units "$T/bad" undulated@.service)
	out_bad2=$(verify_units "$T/bad" undulate-sim.service)
	if [ -n "$out_bad1" ] && [ -n "$out_bad2" ]; then
		tap_ok "systemd-analyze verify complains about a misspelt key and a missing binary"
	else
		tap_fail "systemd-analyze verify catches broken units" "typo: '$out_bad1' missing binary: '$out_bad2'"
	fi
fi

# ---- what the service must be (issue: notify, watchdog, user, RT, hardening) ---------
unit="$R$P/lib/systemd/system/undulated@.service"
want=(Type=notify NotifyAccess=main WatchdogSec=2s Restart=on-failure RestartPreventExitStatus=2 StartLimitIntervalSec=60
	StartLimitBurst=5 User=undulate SupplementaryGroups=dialout LimitRTPRIO=90
	LimitMEMLOCK=infinity DevicePolicy=closed "DeviceAllow=char-ttyUSB rw"
	"DeviceAllow=char-ttyACM rw" ProtectSystem=strict NoNewPrivileges=yes
	"RestrictAddressFamilies=AF_UNIX AF_INET AF_INET6 AF_NETLINK"
	"IPAddressDeny=any" "IPAddressAllow=localhost link-local multicast"
	RuntimeDirectory=undulate RuntimeDirectoryMode=0750 RuntimeDirectoryPreserve=yes)
forbidden=(PrivateNetwork RestrictRealtime DynamicUser PrivateDevices PrivateUsers)
bad=()
for w in "${want[@]}"; do grep -qxF "$w" "$unit" || bad+=("missing: $w"); done
for f in "${forbidden[@]}"; do grep -q "^$f=" "$unit" && bad+=("must not set $f (serial device, multicast or SCHED_FIFO)"); done
# The start limit belongs in [Unit]: in [Service] systemd 252 ignores it with a warning.
awk '/^\[/{s=$0} /^StartLimit/{ if (s != "[Unit]") exit 1 }' "$unit" || bad+=("StartLimit* outside [Unit]")
if [ ${#bad[@]} -eq 0 ]; then
	tap_ok "undulated@.service: notify+watchdog, restart limit, dialout user, RT limits, an address allow-list (multicast out, no other host in), the command socket's directory, hardening without PrivateNetwork/RestrictRealtime"
else
	tap_fail "undulated@.service has the required settings" "$(printf '%s\n' "${bad[@]}")"
fi

# ---- /run/undulate is shared (the daemons' command sockets, the simulator's links):
# a unit that names it without RuntimeDirectoryPreserve=yes has systemd remove the
# whole directory when that unit stops, every other program's sockets with it (the
# audit's finding 9: stopping undulate-sim removed the daemons' command sockets).
bad=()
for u in "${units[@]}"; do
	f="$R$P/lib/systemd/system/$u"
	grep -qxF RuntimeDirectory=undulate "$f" || continue
	grep -qxF RuntimeDirectoryPreserve=yes "$f" || bad+=("$u: RuntimeDirectory=undulate without RuntimeDirectoryPreserve=yes")
done
# the daemon writes the UUCP lock file naming it as the bus's holder (protocol/README.md)
grep -qxF "ReadWritePaths=-/run/lock" "$unit" || bad+=("undulated@.service: /run/lock not writable (ReadWritePaths=-/run/lock)")
if [ ${#bad[@]} -eq 0 ]; then
	tap_ok "no unit removes the shared /run/undulate when it stops; the daemon may write its bus lock file in /run/lock"
else
	tap_fail "the shared run directory outlives each unit" "$(printf '%s\n' "${bad[@]}")"
fi

# ---- re-install keeps an edited config; uninstall removes exactly the rest ------------
conf="$R/etc/undulate/undulated.conf.example"
robot_conf="$R/etc/undulate/robot1.conf"
have_example=0; [ -f "$conf" ] && have_example=1
[ $have_example -eq 1 ] && echo "# operator's edit" >>"$conf"
echo "name = robot1" >"$robot_conf"            # the operator's own file
mkdir -p "$R$P/share/man/man1" && echo keep >"$R$P/share/man/man1/other.1"  # another package's
run_install "$R" "$P" install; rc1=$?
kept=1
[ $have_example -eq 1 ] && { tail -1 "$conf" | grep -q "operator's edit" || kept=0; }
run_install "$R" "$P" uninstall; rc2=$?
left=$(tree "$R")
want_left="./etc
./etc/undulate
./etc/undulate/robot1.conf
./usr
./usr/local
./usr/local/share
./usr/local/share/man
./usr/local/share/man/man1
./usr/local/share/man/man1/other.1"
[ $have_example -eq 1 ] && want_left=$(printf '%s\n./etc/undulate/undulated.conf.example' "$want_left" | sort)
if [ $rc1 -eq 0 ] && [ $rc2 -eq 0 ] && [ $kept -eq 1 ] && [ "$left" = "$want_left" ]; then
	tap_ok "re-install keeps an edited config; uninstall leaves only the operator's files"
else
	tap_fail "re-install/uninstall respect the operator's files" \
		"rc $rc1/$rc2 kept=$kept; left:"$'\n'"$left"$'\n'"$(cat "$T/install.out")"
fi

R2="$T/root2"
run_install "$R2" "$P" install && run_install "$R2" "$P" uninstall
left=$(tree "$R2")
if [ -d "$R2" ] && [ -z "$left" ]; then tap_ok "install then uninstall leaves nothing behind"
else tap_fail "uninstall leaves nothing" "left:"$'\n'"$left"$'\n'"$(cat "$T/install.out")"; fi

# ---- another prefix: units/rules go where systemd and udev look (/etc) ----------------
R3="$T/root3"
P3=/opt/undulate
run_install "$R3" "$P3" install
ok=1
grep -qxF "ExecStart=$P3/bin/undulated --config /etc/undulate/%i.conf" \
	"$R3/etc/systemd/system/undulated@.service" 2>/dev/null || ok=0
[ -f "$R3/etc/udev/rules.d/99-undulate.rules" ] && [ -x "$R3$P3/bin/undulated" ] || ok=0
[ -f "$R3$P3/share/man/man8/undulated.8" ] || ok=0
run_install "$R3" "$P3" uninstall
[ -z "$(tree "$R3")" ] || ok=0
if [ $ok -eq 1 ]; then tap_ok "PREFIX=$P3: units in /etc/systemd/system, rules in /etc/udev/rules.d, clean uninstall"
else tap_fail "PREFIX=$P3 install" "$(tree "$R3")"$'\n'"$(cat "$T/install.out")"; fi

tap_done
