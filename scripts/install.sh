#!/usr/bin/env bash
# scripts/install.sh install|uninstall — `make install` / `make uninstall`.
#
# Environment (the Makefile passes the first three):
#   PREFIX    where programs, man pages and shared data go      (/usr/local)
#   DESTDIR   staging root prepended to every path (packaging)  (empty)
#   BUILD     build directory holding bin/                       (build)
# Optional overrides:
#   BINDIR        $PREFIX/bin
#   MANDIR        $PREFIX/share/man
#   DATADIR       $PREFIX/share/undulate            (scenarios, install manifest)
#   DOCDIR        $PREFIX/share/doc/undulate        (the READMEs and docs, in the source's layout)
#   SYSCONFDIR    /etc                              (robot configs in $SYSCONFDIR/undulate)
#   UNITDIR       systemd units: $PREFIX/lib/systemd/system for PREFIX /usr or
#                 /usr/local (both are on systemd's search path), else /etc/systemd/system
#   UDEVRULESDIR  udev rules: $PREFIX/lib/udev/rules.d for /usr or /usr/local, else
#                 /etc/udev/rules.d
#   SYSUSERSDIR   sysusers.d entry for the `undulate` user, chosen the same way
#
# Every file and directory install creates is listed in a manifest
# ($DATADIR/install-manifest, paths without DESTDIR); uninstall removes exactly
# those, and a config file only if it is unchanged since install wrote it.
set -eu

top=$(cd "$(dirname "$0")/.." && pwd)
PREFIX=${PREFIX:-/usr/local}
PREFIX=${PREFIX%/}
DESTDIR=${DESTDIR:-}
DESTDIR=${DESTDIR%/}
BUILD=${BUILD:-build}
case "$BUILD" in /*) ;; *) BUILD="$top/$BUILD" ;; esac

case "$PREFIX" in
/usr | /usr/local) sys_lib="$PREFIX/lib" sys_etc='' ;;
*) sys_lib='' sys_etc=/etc ;;
esac
BINDIR=${BINDIR:-$PREFIX/bin}
MANDIR=${MANDIR:-$PREFIX/share/man}
DATADIR=${DATADIR:-$PREFIX/share/undulate}
DOCDIR=${DOCDIR:-$PREFIX/share/doc/undulate}
SYSCONFDIR=${SYSCONFDIR:-/etc}
UNITDIR=${UNITDIR:-${sys_lib:-$sys_etc}/systemd/system}
UDEVRULESDIR=${UDEVRULESDIR:-${sys_lib:-$sys_etc}/udev/rules.d}
SYSUSERSDIR=${SYSUSERSDIR:-${sys_lib:-$sys_etc}/sysusers.d}
CONFDIR="$SYSCONFDIR/undulate"
MANIFEST="$DATADIR/install-manifest"

PROGRAMS=(undulated undulate-sim dxl undulate-top undulate-analyze undulate-web undulate-model)
UNITS=(undulated@.service undulate-sim.service undulate-web.service)
DOCS=(README.md daemon/README.md daemon/CONTROL.md sim-bridge/README.md sim-bridge/PHYSICS.md
      protocol/README.md lcmtypes/README.md systemd/README.md tools/dxl/README.md tools/top/README.md
      tools/analyze/README.md tools/web/README.md model/README.md docs/EXPERIMENTS.md docs/ROBOT.md
      docs/SAFETY.md docs/MEASUREMENTS.md docs/LIMITS.md docs/LAYOUT.md docs/CLUSTER.md docs/img/dashboard.png)
SERVICE_USER=undulate

die() { echo "install.sh: $*" >&2; exit 1; }
say() { echo "  $*"; }

# ---- manifest ------------------------------------------------------------------
# One entry a line, tab-separated:  d DIR | f FILE | c CONFFILE SHA256 | u USER
entries=()
declare -A seen=()
record() { # KIND PATH [SHA256]
	local key="$1"$'\t'"$2"
	[ -n "${seen[$key]:-}" ] && return 0
	seen[$key]=1
	entries+=("$key${3:+$'\t'$3}")
}
# The previous install's entries are kept: directories it created stay ours.
load_manifest() {
	local m="$DESTDIR$MANIFEST" kind path rest
	[ -f "$m" ] || return 0
	while IFS=$'\t' read -r kind path rest; do
		[ -n "$kind" ] || continue
		if [ "$kind" = c ]; then
			old_conf_sum[$path]=$rest
			continue # re-recorded by install_conf with its current checksum
		fi
		record "$kind" "$path" "$rest"
	done <"$m"
}
declare -A old_conf_sum=()

# mkdir -p that records every directory it had to create.
make_dir() {
	local dir=$1 missing=() d
	d=$dir
	while [ -n "$d" ] && [ "$d" != / ] && [ ! -d "$DESTDIR$d" ]; do
		missing=("$d" "${missing[@]}")
		d=$(dirname "$d")
	done
	# DESTDIR's own parents are not ours to record, but DESTDIR may not exist yet.
	[ -z "$DESTDIR" ] || [ -d "$DESTDIR" ] || { mkdir -p "$DESTDIR"; }
	for d in "${missing[@]}"; do
		mkdir -m 0755 "$DESTDIR$d"
		record d "$d"
	done
}

install_file() { # MODE SRC DEST
	make_dir "$(dirname "$3")"
	install -m "$1" "$2" "$DESTDIR$3"
	record f "$3"
	say "$3"
}

# Units name the default paths (/usr/local/bin, /etc/undulate); point them at
# this install's.
install_unit() { # SRC DEST
	make_dir "$(dirname "$2")"
	sed -e "s#/usr/local/bin/#$BINDIR/#g" -e "s#/etc/undulate/#$CONFDIR/#g" "$1" >"$DESTDIR$2.tmp"
	chmod 0644 "$DESTDIR$2.tmp"
	mv -f "$DESTDIR$2.tmp" "$DESTDIR$2"
	record f "$2"
	say "$2"
}

sum_of() { sha256sum "$1" | cut -d' ' -f1; }

# A config is the operator's once it exists: never overwritten, unless it is
# still byte-for-byte what a previous install wrote.
install_conf() { # SRC DEST
	local src=$1 dest=$2 target="$DESTDIR$2"
	make_dir "$(dirname "$dest")"
	if [ -e "$target" ]; then
		local cur; cur=$(sum_of "$target")
		if [ "$cur" = "$(sum_of "$src")" ]; then
			[ -n "${old_conf_sum[$dest]:-}" ] && record c "$dest" "$cur"
			say "$dest (unchanged)"
			return 0
		fi
		if [ "${old_conf_sum[$dest]:-}" != "$cur" ]; then
			[ -n "${old_conf_sum[$dest]:-}" ] && record c "$dest" "${old_conf_sum[$dest]}"
			say "$dest exists and was edited: kept (the new example is $src)"
			return 0
		fi
	fi
	install -m 0644 "$src" "$target"
	record c "$dest" "$(sum_of "$target")"
	say "$dest"
}

write_manifest() {
	# Configs from an earlier install that this one did not touch stay listed.
	local c
	for c in "${!old_conf_sum[@]}"; do record c "$c" "${old_conf_sum[$c]}"; done
	make_dir "$(dirname "$MANIFEST")"
	printf '%s\n' "${entries[@]}" >"$DESTDIR$MANIFEST.tmp"
	mv -f "$DESTDIR$MANIFEST.tmp" "$DESTDIR$MANIFEST"
}

# ---- the live system (root, no DESTDIR) --------------------------------------
live_system() { [ -z "$DESTDIR" ] && [ "$(id -u)" -eq 0 ]; }

create_user() {
	# The unit adds dialout itself (SupplementaryGroups=); membership only
	# matters for running the tools as this user, so an existing user is left alone.
	getent passwd "$SERVICE_USER" >/dev/null && return 0
	if command -v systemd-sysusers >/dev/null; then
		systemd-sysusers "$SYSUSERSDIR/undulate.conf"
	else
		local groups=()
		getent group dialout >/dev/null && groups=(--groups dialout)
		useradd --system --user-group --no-create-home --home-dir /nonexistent \
			--shell /usr/sbin/nologin --comment "undulate robot controller" \
			"${groups[@]}" "$SERVICE_USER"
	fi
	record u "$SERVICE_USER"
	say "created system user $SERVICE_USER (group dialout)"
}

reload_services() {
	if [ -d /run/systemd/system ] && command -v systemctl >/dev/null; then
		systemctl daemon-reload || true
	fi
	if command -v udevadm >/dev/null; then
		udevadm control --reload || true
		# Adapters already plugged in get the latency timer and links now.
		udevadm trigger --subsystem-match=tty --sysname-match='ttyUSB*' --sysname-match='ttyACM*' \
			--action=add || true
	fi
}

# Say so up front, rather than stopping half-way on "permission denied".
check_writable() { # DIR...
	local d
	for d in "$@"; do
		d="$DESTDIR$d"
		while [ ! -e "$d" ]; do d=$(dirname "$d"); done
		[ -w "$d" ] || die "cannot write to $d: run as root (sudo make install/uninstall), or set DESTDIR or PREFIX"
	done
}

# ---- install --------------------------------------------------------------------
do_install() {
	local missing=() p
	for p in "${PROGRAMS[@]}"; do [ -x "$BUILD/bin/$p" ] || missing+=("$BUILD/bin/$p"); done
	[ ${#missing[@]} -eq 0 ] || die "not built: ${missing[*]} (run make first)"
	check_writable "$BINDIR" "$UNITDIR" "$UDEVRULESDIR" "$SYSUSERSDIR" "$CONFDIR" "$MANDIR" "$DATADIR" "$DOCDIR"

	echo "installing undulate into ${DESTDIR:+$DESTDIR (staging) }prefix $PREFIX"
	load_manifest
	# Stopped part-way (disk full, a missing source)? Still list what was
	# written, so that uninstall can take it back.
	trap 'rc=$?; [ $rc -eq 0 ] || { write_manifest; echo "install.sh: install incomplete; \`make uninstall\` removes what was written" >&2; }' EXIT
	for p in "${PROGRAMS[@]}"; do install_file 0755 "$BUILD/bin/$p" "$BINDIR/$p"; done
	local u; for u in "${UNITS[@]}"; do install_unit "$top/systemd/$u" "$UNITDIR/$u"; done
	install_file 0644 "$top/systemd/99-undulate.rules" "$UDEVRULESDIR/99-undulate.rules"

	# The service user, for systemd-sysusers (and for the next boot of an image).
	make_dir "$SYSUSERSDIR"
	cat >"$DESTDIR$SYSUSERSDIR/undulate.conf" <<-EOF
		# undulate: the system user undulated@.service runs as, in the serial-port group.
		u $SERVICE_USER - "undulate robot controller" /nonexistent
		m $SERVICE_USER dialout
	EOF
	chmod 0644 "$DESTDIR$SYSUSERSDIR/undulate.conf"
	record f "$SYSUSERSDIR/undulate.conf"
	say "$SYSUSERSDIR/undulate.conf"

	make_dir "$CONFDIR"
	if [ -f "$top/systemd/undulated.conf.example" ]; then
		install_conf "$top/systemd/undulated.conf.example" "$CONFDIR/undulated.conf.example"
	else
		echo "install.sh: warning: systemd/undulated.conf.example not found; no example config installed" >&2
	fi

	local m sec
	for m in "$top"/man/*.[18]; do
		[ -f "$m" ] || continue
		sec=${m##*.}
		install_file 0644 "$m" "$MANDIR/man$sec/$(basename "$m")"
	done
	local s
	for s in "$top"/sim-bridge/scenarios/*.scenario; do
		[ -f "$s" ] || continue
		install_file 0644 "$s" "$DATADIR/scenarios/$(basename "$s")"
	done
	# undulate-web's page (it looks for it in ../share/undulate/web beside itself)
	local w
	for w in "$top"/tools/web/page/*; do
		[ -f "$w" ] || continue
		install_file 0644 "$w" "$DATADIR/web/$(basename "$w")"
	done
	# The documentation, in the source's layout so its links between
	# documents still work (the example config and man pages point here).
	local doc
	for doc in "${DOCS[@]}"; do
		[ -f "$top/$doc" ] && install_file 0644 "$top/$doc" "$DOCDIR/$doc"
	done

	if live_system; then
		create_user
		reload_services
	elif [ -z "$DESTDIR" ]; then
		echo "not root: create the service user yourself:  sudo systemd-sysusers $SYSUSERSDIR/undulate.conf"
	fi
	write_manifest
	say "$MANIFEST (what \`make uninstall\` removes)"
	echo "next: write $CONFDIR/<robot>.conf, then  systemctl enable --now undulated@<robot>"
}

# ---- uninstall ------------------------------------------------------------------
do_uninstall() {
	local m="$DESTDIR$MANIFEST" kind path rest dirs=() users=()
	if [ ! -f "$m" ]; then
		echo "nothing to uninstall: no manifest at $m"
		return 0
	fi
	check_writable "$DATADIR"
	echo "uninstalling undulate from ${DESTDIR:+$DESTDIR (staging) }prefix $PREFIX"
	while IFS=$'\t' read -r kind path rest; do
		case "$kind" in
		f) rm -f "$DESTDIR$path" && say "removed $path" ;;
		c)
			if [ ! -e "$DESTDIR$path" ]; then :
			elif [ "$(sum_of "$DESTDIR$path")" = "$rest" ]; then rm -f "$DESTDIR$path" && say "removed $path"
			else say "kept $path (edited since install)"
			fi ;;
		d) dirs+=("$path") ;;
		u) users+=("$path") ;;
		"") ;;
		*) echo "install.sh: manifest line not understood: $kind $path" >&2 ;;
		esac
	done <"$m"
	rm -f "$m"
	# Deepest first; a directory that holds someone else's files stays.
	local d
	[ ${#dirs[@]} -eq 0 ] || printf '%s\n' "${dirs[@]}" | awk '{ print length($0) "\t" $0 }' | sort -rn | cut -f2- |
		while IFS= read -r d; do
			if rmdir "$DESTDIR$d" 2>/dev/null; then say "removed $d/"; fi
		done
	local u
	for u in "${users[@]}"; do
		if live_system && getent passwd "$u" >/dev/null; then
			userdel "$u" && say "removed system user $u"
		fi
	done
	live_system && reload_services
	return 0
}

case "${1:-}" in
install) do_install ;;
uninstall) do_uninstall ;;
*) echo "usage: PREFIX=... DESTDIR=... BUILD=... $0 install|uninstall" >&2; exit 2 ;;
esac
