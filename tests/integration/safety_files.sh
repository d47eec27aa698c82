#!/usr/bin/env bash
# safety_files.sh — files a tool writes go only where it was asked. The
# audit's attacks, prepared here inside the test's directory, against every
# writer of results: undulate-analyze --out (and its --synth and --record
# logs), scripts/demo.sh --out,
# undulated --tune --out, and `make figures` (scripts/figures.sh, its runs
# and its merges):
#   (a) a directory owned by another user (nobody; as root only, else
#       skipped) holding a symbolic link to a file of ours (a "victim") under
#       a name the tool writes, and a FIFO plots.gp fed by a process that, as
#       the audit's other user did, drains what is written into it and hands
#       whoever reads it a gnuplot command: refused at once with a message
#       naming the owner; the victim unchanged; nothing run;
#   (b) a directory of ours with links to victims pre-placed under the names
#       written there: each link replaced by the new file, no victim written;
#   (c) a FIFO plots.gp in our own directory: no hang, never executed;
#   and a directory of ours that other users may write (0777) is refused,
#   a sticky one (1777) of ours is accepted, a link to our directory made by
#   another user is refused, and analysing into a directory analysed before
#   works (the files replaced).
. "$(dirname "$0")/../lib.sh"
A="$B/undulate-analyze" D="$B/undulated" S="$B/undulate-sim"
for p in "$A" "$D" "$S"; do [ -x "$p" ] || tap_skip_all "$p is not built (make)"; done
"$A" --synth "$T/s.log" --duration 13 >/dev/null 2>&1 || { tap_fail "--synth writes a log"; tap_done; exit 1; }
# The analyser and demo.sh may not hang on a FIFO: a hang is a failure, not a stuck test.
LIMIT_S=60
# The modes below are the ones a new file or directory gets under umask 022.
umask 022

root=0
[ "$(id -u)" = 0 ] && getent passwd nobody >/dev/null && root=1
# victim NAME: a file of ours the attacks aim at; intact NAME: unchanged.
victim() { printf 'precious %s\n' "$1" >"$T/victim.$1"; }
intact() { [ "$(cat "$T/victim.$1" 2>/dev/null)" = "precious $1" ]; }
# foreign DIR: hand DIR and everything in it to nobody (links too, -h).
foreign() { chown -hR nobody "$1"; }
# feed FIFO TAG: the audit's other user on a FIFO: drain what the tool
# writes into it, then hand whoever reads it (gnuplot) `system(...)`, which
# leaves $T/pwned.TAG. Under timeout: left blocked when nobody opens the
# FIFO, it ends with the test (spawn's cleanup signals timeout, which passes
# the signal on).
feed() {
	mkfifo "$1"
	spawn "feed_$2" timeout 120 bash -c 'cat "$1" >/dev/null; printf "system(\"touch %s\")\n" "$2" >"$1"' _ "$1" "$T/pwned.$2"
}
pwned() { [ -e "$T/pwned.$1" ]; }
regular() { [ -f "$1" ] && [ ! -L "$1" ]; }
# analyze NAME DIR ARG...: undulate-analyze of the synthetic log into DIR; rc in $rc
analyze() {
	local name=$1 dir=$2; shift 2
	rc=0
	timeout "$LIMIT_S" "$A" "$T/s.log" --out "$dir" --quiet "$@" >"$T/$name.out" 2>"$T/$name.err" || rc=$?
}

# ---- undulate-analyze --out ------------------------------------------------------------
# (a) another user's directory with a link and a FIFO under the names written
if [ "$root" = 1 ]; then
	F="$T/foreign"; mkdir "$F"; victim a
	ln -s "$T/victim.a" "$F/summary.txt"
	feed "$F/plots.gp" a
	foreign "$F"
	analyze a "$F" --plots
	if [ "$rc" != 0 ] && [ "$rc" != 124 ] && grep -q 'owned by nobody' "$T/a.err"; then
		tap_ok "analyze --out another user's directory: refused, exit $rc: $(head -n 1 "$T/a.err")"
	else tap_fail "analyze --out another user's directory: refused, naming the owner" "exit $rc: $(cat "$T/a.err")"; fi
	tap_check "analyze (a): the victim behind the link unchanged" intact a
	tap_check "analyze (a): the FIFO's command never run" bash -c "! test -e '$T/pwned.a'"
	tap_check "analyze (a): nothing written there" test ! -e "$F/states.csv"
	# a link to our own directory, made by another user: it chooses where results land
	mkdir "$T/ours"; ln -s "$T/ours" "$T/theirlink"; chown -h nobody "$T/theirlink"
	analyze alink "$T/theirlink"
	if [ "$rc" != 0 ] && grep -q 'symbolic link .* owned by nobody' "$T/alink.err" && [ ! -e "$T/ours/states.csv" ]; then
		tap_ok "analyze --out through another user's link: refused: $(head -n 1 "$T/alink.err")"
	else tap_fail "analyze --out through another user's link: refused" "exit $rc: $(cat "$T/alink.err")"; fi
else
	tap_skip "analyze --out another user's directory" "not root: cannot give a directory to another user"
	tap_skip "analyze --out through another user's link" "not root"
fi

# (b) our own directory with links to victims under the names written, gnuplot's too
O="$T/own"; mkdir "$O"
for n in b1 b2 b3 b4; do victim "$n"; done
ln -s "$T/victim.b1" "$O/summary.txt"
ln -s "$T/victim.b2" "$O/states.csv"
ln -s "$T/victim.b3" "$O/angles.png"
ln -s "$T/victim.b4" "$O/plots.log"
analyze b "$O" --plots
tap_check "analyze (b): own directory with links in it: exit 0" test "$rc" = 0
tap_check "analyze (b): no victim written through a link" bash -c "$(declare -f intact); T='$T'; intact b1 && intact b2 && intact b3 && intact b4"
if regular "$O/summary.txt" && regular "$O/states.csv" && regular "$O/angles.png" && grep -q 'end state' "$O/summary.txt" &&
	[ "$(wc -l <"$O/states.csv")" -gt 100 ]; then
	tap_ok "analyze (b): the links replaced by the results (summary.txt, states.csv, angles.png)"
else tap_fail "analyze (b): the links replaced by the results" "$(ls -l "$O" | head -20)"; fi
# run again into the directory it wrote: replaced, and nothing of its own left behind
sum1=$(md5sum <"$O/summary.txt")
analyze b2 "$O" --plots
if [ "$rc" = 0 ] && [ "$(md5sum <"$O/summary.txt")" = "$sum1" ] && [ -z "$(ls -A "$O" | grep '^\.')" ]; then
	tap_ok "analyze into its own earlier output: exit 0, the same summary, no temporary left"
else tap_fail "analyze into its own earlier output" "exit $rc: $(cat "$T/b2.err"; ls -A "$O")"; fi

# (c) a FIFO plots.gp in our own directory, fed as in (a)
C="$T/own2"; mkdir "$C"
feed "$C/plots.gp" c
analyze c "$C" --plots
tap_check "analyze (c): a FIFO plots.gp in our directory: no hang (exit $rc)" test "$rc" = 0
tap_check "analyze (c): the FIFO's command never run" bash -c "! test -e '$T/pwned.c'"
if regular "$C/plots.gp" && grep -q 'undulate-analyze plots' "$C/plots.gp" && regular "$C/angles.png"; then
	tap_ok "analyze (c): plots.gp is now our script, and the plots were drawn"
else tap_fail "analyze (c): plots.gp replaced by our script" "$(ls -l "$C")"; fi

# ... and one nobody reads: opening it to write would wait for a reader for ever
C3="$T/own3"; mkdir "$C3"; mkfifo "$C3/plots.gp" "$C3/summary.txt"
rc=0; timeout 20 "$A" "$T/s.log" --out "$C3" --quiet --plots >/dev/null 2>"$T/c3.err" || rc=$?
tap_check "analyze (c): FIFOs plots.gp and summary.txt nobody reads: no hang, exit 0 ($rc), both now files" \
	bash -c "[ $rc = 0 ] && [ -f '$C3/plots.gp' ] && [ -f '$C3/summary.txt' ] && [ ! -p '$C3/summary.txt' ]"

# a directory of ours that everyone may write: refused; sticky: accepted
W="$T/open"; mkdir -m 0777 "$W"; chmod 0777 "$W"
analyze w "$W"
if [ "$rc" != 0 ] && grep -q 'writable by other users (mode 0777)' "$T/w.err" && grep -q 'chmod go-w' "$T/w.err" &&
	[ ! -e "$W/states.csv" ]; then
	tap_ok "analyze --out a directory others may write: refused: $(head -n 1 "$T/w.err")"
else tap_fail "analyze --out a 0777 directory: refused, saying chmod go-w" "exit $rc: $(cat "$T/w.err")"; fi
# said before the logs are read (a long log takes a while): even a missing log
rc=0; "$A" "$T/nope.log" --out "$W" >/dev/null 2>"$T/w2.err" || rc=$?
tap_check "analyze --out refused before reading the logs (exit 5, not 2, for a missing log)" \
	bash -c "[ $rc = 5 ] && grep -q 'writable by other users' '$T/w2.err'"
K="$T/sticky"; mkdir "$K"; chmod 1777 "$K"
analyze k "$K"
tap_check "analyze --out a sticky directory of ours (1777): accepted" bash -c "[ $rc = 0 ] && test -s '$K/summary.txt'"
analyze n "$T/new/sub"
tap_check "analyze --out a path whose parent is missing: exit 5, saying so" bash -c "[ $rc = 5 ] && grep -q 'No such file' '$T/n.err'"
analyze m "$T/made"
tap_check "analyze --out a new directory: made (0755), results in it" \
	bash -c "[ $rc = 0 ] && [ \"\$(stat -c %a '$T/made')\" = 755 ] && test -s '$T/made/summary.json'"

# --synth and --record write a log at the path given: the same rules for its directory,
# and a link at the path is replaced (written in place, a recording is read as it grows)
if [ "$root" = 1 ]; then
	SF="$T/sforeign"; mkdir "$SF"; victim s1; ln -s "$T/victim.s1" "$SF/x.log"; foreign "$SF"
	rc=0; "$A" --synth "$SF/x.log" --duration 2 >"$T/s1.out" 2>&1 || rc=$?
	if [ "$rc" = 5 ] && grep -q 'owned by nobody' "$T/s1.out" && intact s1; then
		tap_ok "--synth into another user's directory: exit 5, the victim unchanged: $(head -n 1 "$T/s1.out")"
	else tap_fail "--synth into another user's directory: refused" "exit $rc: $(cat "$T/s1.out")"; fi
else
	tap_skip "--synth into another user's directory" "not root"
fi
victim s2; ln -s "$T/victim.s2" "$O/synth.log"
rc=0; "$A" --synth "$O/synth.log" --duration 2 >"$T/s2.out" 2>&1 || rc=$?
tap_check "--synth to a link: the link replaced by the log, the victim unchanged" \
	bash -c "[ $rc = 0 ] && $(declare -f intact); T='$T'; intact s2 && [ -f '$O/synth.log' ] && [ ! -L '$O/synth.log' ] && [ \$(stat -c %s '$O/synth.log') -gt 10000 ]"
victim s3; ln -s "$T/victim.s3" "$O/rec.log"
spawn rec "$A" --record "$O/rec.log" --lcm-url "$(lcm_url 7773)"
if wait_log rec 'recording' 10; then
	stop rec INT >/dev/null
	if [ "$stop_rc" = 0 ] && intact s3 && regular "$O/rec.log"; then
		tap_ok "--record to a link: the link replaced by the recording, the victim unchanged"
	else tap_fail "--record to a link: replaced" "exit $stop_rc: $(cat "$T/rec.log"); $(ls -l "$O/rec.log")"; fi
else
	stop rec >/dev/null
	tap_fail "--record to a link: replaced" "$(cat "$T/rec.log"); victim: $(cat "$T/victim.s3" | head -c 100)"
fi

# ---- undulated --tune --out --------------------------------------------------------------
# Refused before any motion (the port is never opened): a directory of another user.
if [ "$root" = 1 ]; then
	TF="$T/tforeign"; mkdir "$TF"; victim t1; ln -s "$T/victim.t1" "$TF/r.conf"; foreign "$TF"
	out=$("$D" --tune --port "$T/none" --ids 1,2 --out "$TF/r.conf" 2>&1); rc=$?
	if [ "$rc" = 2 ] && [[ "$out" == *"owned by nobody"* ]] && intact t1 && [ -L "$TF/r.conf" ] &&
		[ -z "$(ls -A "$TF" | grep -v '^r.conf$')" ]; then
		tap_ok "tune --out in another user's directory: exit 2 before tuning, nothing written: $out"
	else tap_fail "tune --out in another user's directory: exit 2, naming the owner" "exit $rc: $out; $(ls -lA "$TF")"; fi
else
	tap_skip "tune --out in another user's directory" "not root"
fi
TW="$T/topen"; mkdir "$TW"; chmod 0777 "$TW"
out=$("$D" --tune --port "$T/none" --ids 1,2 --out "$TW/r.conf" 2>&1); rc=$?
if [ "$rc" = 2 ] && [[ "$out" == *"writable by other users"* ]] && [ -z "$(ls -A "$TW")" ]; then
	tap_ok "tune --out in a directory others may write: exit 2, nothing written"
else tap_fail "tune --out in a 0777 directory: exit 2" "exit $rc: $out; $(ls -lA "$TW")"; fi
# (b) a link at the --out path: a lockstep tune (fast) replaces it
TO="$T/town"; mkdir "$TO"; victim t2; ln -s "$T/victim.t2" "$TO/r.conf"
url=$(lcm_url 7770)
spawn tsim "$S" --link "$TO/r1" --ids 1,2 --name r1 --lcm-url "$url" --seed 5 --lockstep "$T/tclock" --duration 400
if wait_log tsim 'ready:' 10; then
	out=$(timeout "$LIMIT_S" "$D" --tune --port "$TO/r1" --ids 1,2 --robot r1 --lcm-url "$url" --lockstep "$T/tclock" \
		--out "$TO/r.conf" 2>&1); rc=$?
	if [ "$rc" = 0 ] && intact t2 && regular "$TO/r.conf" && grep -q 'written by undulated --tune' "$TO/r.conf" && grep -q '^\[joint.2\]' "$TO/r.conf" &&
		[ "$(stat -c %a "$TO/r.conf")" = 644 ]; then
		tap_ok "tune --out a link to a victim: the link replaced by the configuration (0644), the victim unchanged"
	else tap_fail "tune --out a link: replaced, victim unchanged" "exit $rc: $(tail -n 3 <<<"$out"); $(ls -l "$TO")"; fi
else
	tap_fail "tune: the lockstep simulator did not start" "$(cat "$T/tsim.log")"
fi
stop tsim >/dev/null

# ---- scripts/demo.sh --out ---------------------------------------------------------------
DEMO="$top/scripts/demo.sh"
demo() { # NAME OUT: a short lockstep run of the pair rig; rc in $rc
	rc=0
	timeout "$LIMIT_S" "$DEMO" --lockstep --scenario "$top/sim-bridge/scenarios/pair-rig.scenario" --seconds 4 \
		--switch-at 2 --lcm-url "$(lcm_url 7771)" --out "$2" >"$T/$1.out" 2>&1 </dev/null || rc=$?
}
if [ "$root" = 1 ]; then
	DF="$T/dforeign"; mkdir "$DF"; victim d1; ln -s "$T/victim.d1" "$DF/demo-summary.txt"; foreign "$DF"
	demo d1 "$DF"
	if [ "$rc" != 0 ] && grep -q 'owned by nobody' "$T/d1.out" && intact d1 && [ ! -e "$DF/demo.lcmlog" ]; then
		tap_ok "demo.sh --out another user's directory: refused (exit $rc), nothing written: $(grep -m1 'owned by' "$T/d1.out")"
	else tap_fail "demo.sh --out another user's directory: refused" "exit $rc: $(tail -n 3 "$T/d1.out"); $(ls -l "$DF")"; fi
	# a link to our own directory, made by another user (scripts/outdir.sh walks the path)
	mkdir "$T/dmine"; ln -s "$T/dmine" "$T/dlink"; chown -h nobody "$T/dlink"
	demo d4 "$T/dlink"
	if [ "$rc" != 0 ] && grep -q 'symbolic link dlink on the way is owned by nobody' "$T/d4.out" && [ -z "$(ls -A "$T/dmine")" ]; then
		tap_ok "demo.sh --out through another user's link: refused, nothing written"
	else tap_fail "demo.sh --out through another user's link: refused" "exit $rc: $(tail -n 3 "$T/d4.out")"; fi
else
	tap_skip "demo.sh --out another user's directory" "not root"
	tap_skip "demo.sh --out through another user's link" "not root"
fi
DO="$T/down"; mkdir -p "$DO" "$T/vdir"
for n in d2 d3 d4 d5 d6; do victim "$n"; done
ln -s "$T/victim.d2" "$DO/demo-summary.txt"
ln -s "$T/victim.d3" "$DO/seed"
ln -s "$T/victim.d4" "$DO/contact.csv"
ln -s "$T/victim.d5" "$DO/summary.txt"
ln -s "$T/victim.d6" "$DO/demo.lcmlog"
ln -s "$T/vdir" "$DO/logs"
demo d2 "$DO"
tap_check "demo.sh (b): own directory with links in it: exit 0 ($rc)" test "$rc" = 0
tap_check "demo.sh (b): no victim written through a link" bash -c "$(declare -f intact); T='$T'; intact d2 && intact d3 && intact d4 && intact d5 && intact d6"
tap_check "demo.sh (b): nothing copied through the link logs -> another directory" test -z "$(ls -A "$T/vdir")"
if regular "$DO/demo-summary.txt" && regular "$DO/seed" && regular "$DO/contact.csv" && regular "$DO/summary.txt" &&
	regular "$DO/demo.lcmlog" && [ -d "$DO/logs" ] && [ ! -L "$DO/logs" ] && [ -f "$DO/logs/sim.log" ] &&
	grep -q 'undulate demo summary' "$DO/demo-summary.txt"; then
	tap_ok "demo.sh (b): the links replaced by the run's files and logs/"
else tap_fail "demo.sh (b): links replaced" "$(ls -lA "$DO")"; fi
DW="$T/dopen"; mkdir "$DW"; chmod 0777 "$DW"
demo d3 "$DW"
if [ "$rc" != 0 ] && grep -q 'writable by other users' "$T/d3.out" && [ -z "$(ls -A "$DW")" ]; then
	tap_ok "demo.sh --out a directory others may write: refused, nothing written"
else tap_fail "demo.sh --out a 0777 directory: refused" "exit $rc: $(tail -n 3 "$T/d3.out")"; fi

# ---- make figures: the driver's run, a module's run, the merge ---------------------------
FIGS="$top/scripts/figures.sh"
export FIG_TINY=1 FIG_PORT_LO FIG_PORT_SPAN=4
FIG_PORT_LO=$(lcm_port 7772)
# (b) one run of the pair rig (FIG_TINY's first) into a run directory with links in it
read -r _ fargs <<<"$("$top/figures/pair/fig.sh" jobs | head -n 1)"
R="$T/runs/pair/r1"; mkdir -p "$R"
for n in f1 f2 f3 f4; do victim "$n"; done
ln -s "$T/victim.f1" "$R/run.log"
ln -s "$T/victim.f2" "$R/run.info"
ln -s "$T/victim.f3" "$R/demo.out"
ln -s "$T/victim.f4" "$R/delta_t.csv"
rc=0; (cd "$top" && timeout "$LIMIT_S" "$FIGS" run pair "$R" $fargs) >"$T/f1.out" 2>&1 || rc=$?
tap_check "figures run (b): a run directory with links in it: exit 0 ($rc)" test "$rc" = 0
tap_check "figures run (b): no victim written through a link" bash -c "$(declare -f intact); T='$T'; intact f1 && intact f2 && intact f3 && intact f4"
if regular "$R/run.log" && regular "$R/run.info" && regular "$R/demo.out" && regular "$R/delta_t.csv" && regular "$R/result.csv"; then
	tap_ok "figures run (b): the links replaced by the run's files"
else tap_fail "figures run (b): links replaced" "$(ls -lA "$R"; cat "$T/f1.out")"; fi
# (b) the merge into a page directory with links in it (the channel's fixed rows)
H="width_cm,nominal_dsep,seed,pair,class,mean_delta,mean_abs_delta,spread,window_collisions,collisions,impulse,distance_m,dsep,compat_limit,swing_a,swing_b,min_swing_rad,wall_s"
mkdir -p "$T/mruns/channel/a"
printf '%s\n' "$H" "16,0.5362,1,r1:r2,compatible,1.0,1.0,0.1,0,30,3,0.16,0.55,1.1645,1.6,1.6,1.5,6" \
	"16,0.5362,1,r2:r3,still-colliding,-1.2,1.2,0.2,3,40,3,0.17,0.57,1.2130,1.6,1.6,1.5,6" >"$T/mruns/channel/a/result.csv"
P="$T/page"; mkdir -p "$P/figures"
for n in m1 m2 m3 m4 m5 m6; do victim "$n"; done
ln -s "$T/victim.m1" "$P/figures/channel.png"
ln -s "$T/victim.m2" "$P/figures/channel.csv"
ln -s "$T/victim.m3" "$P/figures/channel.md"
ln -s "$T/victim.m4" "$P/figures/channel.run"
ln -s "$T/victim.m5" "$P/FIGURES.md"
ln -s "$T/victim.m6" "$P/FIGURES.md.new"
rc=0; timeout "$LIMIT_S" "$FIGS" --merge "$T/mruns" --only channel --out "$P" >"$T/m1.out" 2>&1 || rc=$?
tap_check "figures merge (b): a page directory with links in it: exit 0 ($rc)" test "$rc" = 0
tap_check "figures merge (b): no victim written through a link" \
	bash -c "$(declare -f intact); T='$T'; intact m1 && intact m2 && intact m3 && intact m4 && intact m5 && intact m6"
if regular "$P/figures/channel.png" && regular "$P/figures/channel.csv" && regular "$P/figures/channel.md" &&
	regular "$P/figures/channel.run" && regular "$P/FIGURES.md" && grep -q '<a id="channel">' "$P/FIGURES.md" &&
	[ -z "$(ls -A "$P/figures" | grep '^\.')" ]; then
	tap_ok "figures merge (b): the links replaced by the figure, its data, its section and the page"
else tap_fail "figures merge (b): links replaced" "$(ls -lA "$P" "$P/figures"; cat "$T/m1.out")"; fi
PW="$T/popen"; mkdir -p "$PW"; chmod 0777 "$PW"
rc=0; timeout "$LIMIT_S" "$FIGS" --merge "$T/mruns" --only channel --out "$PW" >"$T/m4.out" 2>&1 || rc=$?
if [ "$rc" != 0 ] && grep -q 'writable by other users (mode 0777)' "$T/m4.out" && [ -z "$(ls -A "$PW")" ]; then
	tap_ok "figures --merge --out a directory others may write: refused, nothing written"
else tap_fail "figures --merge --out a 0777 directory: refused" "exit $rc: $(cat "$T/m4.out")"; fi
# (a) another user's directories: the page's, a run's, a module's merge
if [ "$root" = 1 ]; then
	PF="$T/pforeign"; mkdir -p "$PF/figures"; victim m7; ln -s "$T/victim.m7" "$PF/figures/channel.md"; foreign "$PF"
	rc=0; timeout "$LIMIT_S" "$FIGS" --merge "$T/mruns" --only channel --out "$PF" >"$T/m2.out" 2>&1 || rc=$?
	if [ "$rc" != 0 ] && grep -q 'owned by nobody' "$T/m2.out" && intact m7 && [ ! -e "$PF/figures/channel.png" ]; then
		tap_ok "figures --merge --out another user's directory: refused: $(grep -m1 'owned by' "$T/m2.out")"
	else tap_fail "figures --merge --out another user's directory: refused" "exit $rc: $(cat "$T/m2.out")"; fi
	rc=0; timeout "$LIMIT_S" "$top/figures/channel/fig.sh" merge "$T/mruns/channel" "$PF/figures" >"$T/m3.out" 2>&1 || rc=$?
	if [ "$rc" != 0 ] && grep -q 'owned by nobody' "$T/m3.out" && intact m7; then
		tap_ok "a module's merge into another user's directory: refused"
	else tap_fail "a module's merge into another user's directory: refused" "exit $rc: $(cat "$T/m3.out")"; fi
	RF="$T/rforeign"; mkdir -p "$RF"; victim f5; ln -s "$T/victim.f5" "$RF/run.log"; foreign "$RF"
	rc=0; (cd "$top" && timeout "$LIMIT_S" "$FIGS" run pair "$RF" $fargs) >"$T/f2.out" 2>&1 || rc=$?
	if [ "$rc" != 0 ] && grep -q 'owned by nobody' "$T/f2.out" && intact f5 && [ ! -e "$RF/result.csv" ]; then
		tap_ok "figures run into another user's directory: refused: $(grep -m1 'owned by' "$T/f2.out")"
	else tap_fail "figures run into another user's directory: refused" "exit $rc: $(cat "$T/f2.out")"; fi
	rc=0; timeout "$LIMIT_S" "$top/figures/pair/fig.sh" run "$RF" $fargs >"$T/f3.out" 2>&1 || rc=$?
	if [ "$rc" != 0 ] && grep -q 'owned by nobody' "$T/f3.out" && intact f5 && [ ! -e "$RF/result.csv" ]; then
		tap_ok "a module's run into another user's directory: refused"
	else tap_fail "a module's run into another user's directory: refused" "exit $rc: $(cat "$T/f3.out")"; fi
else
	tap_skip "figures into another user's directories" "not root"
fi
tap_done
