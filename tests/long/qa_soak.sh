#!/usr/bin/env bash
# run.sh: alone — it puts one CPU-bound process on every core for minutes: nothing beside it (tests/run.sh)
# run.sh: timeout 900
# qa_soak.sh (make test-long) — a simulated robot (undulate-sim, two AX-12A)
# and its undulated at 100 Hz in real time for QA_SOAK_S seconds (default
# 480, the audit's 8 minutes), beside one CPU-bound process per core, each in
# a session of its own (as a user's programs would be), while
#  - random serial faults come and go through the simulator's control socket:
#    corrupted, late, lost and foreign replies (no-reply, bad-checksum,
#    truncate, garbage, wrong-id, stuck-error, slow; on one servo or both, on
#    a fraction of the replies or the next few), random bytes on the line, a
#    servo's power off and on, the bus disconnected and reconnected; after
#    each, the operator's part: 'clear' while a fault is latched, and the mode
#    wanted put back;
#  - LIMP ('mode limp' or 'torque off'), HOLD ('mode hold' or 'torque on') and
#    OSCILLATOR come at random times through the local command socket
#    (undulated --command).
# Joint limits narrowed to +-0.5 rad so that the 0.8 rad limit cycle presses
# against them (as qa_daemon_hostile).
# Asserted (behaviour only, never timing):
#  - the daemon and the simulator survive, and the daemon publishes to the end;
#  - no published goal outside the limits while its joint's torque is on, and
#    the limits the daemon publishes never change;
#  - every LIMP takes effect: the daemon publishes LIMP with torque off on both
#    joints and both simulated servos have torque off, within LIMP_BOUND_S
#    (3 s; from the command, or from the end of a power loss or disconnection
#    that kept the bus from it) — and torque stays off (no published state
#    wants it on) until the next HOLD or OSCILLATOR;
#  - after the soak the robot runs OSCILLATOR again with torque on;
#  - the daemon's memory is flat: VmRSS (sampled from /proc every 5 s) grows
#    less than 1 MB after the first minute (the first quarter of a shorter soak);
#  - SIGTERM stops it cleanly; no sanitizer report.
# Printed (figures, not asserted): the loop's rate (cycles over wall time),
# its period from robot_state_t.period_us (mean, p99, max), overruns, bus
# errors, how many fault episodes of each kind and commands of each kind ran,
# the LIMPs' latency, the share of the soak spent torqued, memory, and the
# load average the run saw.
# QA_SOAK_S: seconds (20..7200); QA_SOAK_SEED: the random schedule's seed
# (printed; default from the clock). A soak longer than ~13 minutes needs
# TEST_TIMEOUT raised above the 900 s asked for here.
source "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"
[ -x "$D" ] && [ -x "$S" ] || tap_skip_all "undulated or undulate-sim not built"
command -v socat >/dev/null || tap_skip_all "socat missing (the simulator's control socket)"

DUR=${QA_SOAK_S:-480}
if ! [[ "$DUR" =~ ^[0-9]{1,4}$ ]] || [ "$((10#$DUR))" -lt 20 ] || [ "$((10#$DUR))" -gt 7200 ]; then
	echo "qa_soak.sh: QA_SOAK_S must be whole seconds from 20 to 7200, not '$DUR'" >&2
	exit 2
fi
DUR=$((10#$DUR))
SEED=${QA_SOAK_SEED:-$(( ${EPOCHREALTIME//[!0-9]/} % 100000 ))}
[[ "$SEED" =~ ^[0-9]{1,9}$ ]] || { echo "qa_soak.sh: QA_SOAK_SEED must be a whole number, not '$SEED'" >&2; exit 2; }
RANDOM=$SEED
LIM=0.5
LIMP_BOUND_S=3
# memory is judged after the start-up's allocations and the first reconnects
WARM_S=$(( DUR / 4 < 60 ? DUR / 4 : 60 ))
R="soak$$"
URL=$(lcm_url 7960)
CORES=$(getconf _NPROCESSORS_ONLN 2>/dev/null || echo 1)

now_ms() { local t=${EPOCHREALTIME//[!0-9]/}; echo $(( t / 1000 )); }
rnd() { echo $(( $1 + RANDOM % ($2 - $1 + 1) )); }   # a whole number in [$1, $2]
pick() { shift $(( RANDOM % $# )); echo "$1"; }      # one of the arguments
# the last published state, from the end of the watcher's log (it grows by
# ~50 kB a second: never read whole inside the loop)
cur_state() { tail -c 6000 "$T/watch.log" | grep -a "^STATE $R .* dr1=" | tail -n 1; }
load() { cut -d' ' -f1-3 /proc/loadavg; }
rss_kb() { awk '$1 == "VmRSS:" { print $2 }' "/proc/$1/status" 2>/dev/null; }
sim_torque_off() {
	local s1 s2
	s1=$(ctl servo r1 1); s2=$(ctl servo r1 2)
	[[ "$s1" == *" torque=0 "* ]] && [[ "$s2" == *" torque=0 "* ]]
}

load0=$(load)
spawn sim "$S" --link "$T/bus" --ids 1,2 --name r1 --lcm-url "$URL" --control "$T/ctl" --seed "$SEED" --return-delay 0
wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
spawn watch "$D" --watch "$R" --raw --lcm-url "$URL"
spawn d "$D" --port "$T/bus" --ids 1,2 --robot "$R" --lcm-url "$URL" --mode oscillator \
	--set joint.1.limit_min=-$LIM --set joint.1.limit_max=$LIM \
	--set joint.2.limit_min=-$LIM --set joint.2.limit_max=$LIM
if wait_log d "ready: $R.STATE" 10 && wait_for 10 cycle_at_least 100; then
	tap_ok "undulated runs on the simulated AX-12A pair (OSCILLATOR, limits +-$LIM rad)"
else
	tap_fail "undulated runs" "$(tail -5 "$T/d.log")"; tap_done; exit 1
fi
for i in $(seq "$CORES"); do spawn "hog$i" sh -c 'while :; do :; done'; done
echo "# soak: $DUR s, seed $SEED, $CORES CPU-bound process(es) beside it, load average at the start $load0"

# ---- the schedule --------------------------------------------------------------------
declare -A n_kind=()      # fault episodes by kind
n_episodes=0 n_ctl_errors=0 ctl_error=""
episode="" episode_end=0 episode_cuts=0 episode_arg=""
n_limp=0 n_limp_ok=0 limp_lat=() limp_fail=""
n_hold=0 n_osc=0 n_refused=0 n_clear=0 n_restore=0
wanted=3                  # the mode the operator last asked for (robot_state_t.mode)
limp_sent=0 limp_cycle=0 limp_deadline=0   # a LIMP waiting to take effect (limp_sent > 0)
limp_from=0               # the cycle from which torque must stay off (0: not in LIMP)
last_cmd=0 last_clear=0 quiet_since=0
: >"$T/limp_spans"        # "FROM TO": cycles in which no state may want torque on
: >"$T/rss"               # "SECONDS RSS_DAEMON_KB RSS_SIM_KB"
: >"$T/wire_goals"        # "ID ok GOAL_POSITION" of a torqued servo, every 5 s

sim_cmd() {
	local r
	r=$(ctl "$@")
	if [[ "$r" != ok* ]]; then
		n_ctl_errors=$((n_ctl_errors + 1))
		[ -n "$ctl_error" ] || ctl_error="'$*': ${r:-no answer}"
	fi
}

# begin_episode T: one random fault, for a random 0.3-4 s
begin_episode() {
	local t=$1 id kind how
	id=$(pick 1 2 '*')
	how=$(pick "prob=$(printf '0.%02d' "$(rnd 5 60)")" "prob=1" "count=$(rnd 1 20)")
	kind=$(pick no-reply bad-checksum truncate garbage wrong-id stuck-error slow line-garbage power disconnect)
	episode_cuts=0 episode_arg=""
	case $kind in
	truncate) sim_cmd fault r1 "$id" truncate "$(rnd 1 6)" "$how" ;;
	garbage) sim_cmd fault r1 "$id" garbage "$(rnd 1 32)" "$how" ;;
	stuck-error) sim_cmd fault r1 "$id" stuck-error "$(pick overload voltage angle-limit overheating 'overload|range')" "$how" ;;
	slow) sim_cmd fault r1 "$id" slow "$(rnd 1 20)" "$how" ;;
	line-garbage) sim_cmd garbage r1 "$(rnd 1 64)" ;;   # and again at every tick of the episode
	power) episode_arg=$(pick 1 2); sim_cmd power r1 "$episode_arg" off; episode_cuts=1 ;;
	disconnect) sim_cmd disconnect r1; episode_cuts=1 ;;
	*) sim_cmd fault r1 "$id" "$kind" "$how" ;;
	esac
	episode=$kind
	episode_end=$(( t + $(rnd 300 4000) ))
	n_episodes=$((n_episodes + 1))
	n_kind[$kind]=$(( ${n_kind[$kind]:-0} + 1 ))
	# a LIMP sent before the bus went away takes effect once it is back
	if [ "$limp_sent" -gt 0 ] && [ "$episode_cuts" -eq 1 ]; then
		limp_deadline=$(( episode_end + LIMP_BOUND_S * 1000 ))
	fi
}

end_episode() {
	case $episode in
	power) sim_cmd power r1 "$episode_arg" on ;;
	disconnect) sim_cmd reconnect r1 ;;
	line-garbage) ;;
	*) sim_cmd clear r1 ;;
	esac
	[ "$limp_sent" -gt 0 ] && [ "$episode_cuts" -eq 1 ] && limp_deadline=$(( $(now_ms) + LIMP_BOUND_S * 1000 ))
	episode="" episode_cuts=0
}

# send TEXT: one command through the local socket; 0 when accepted
send() {
	local out
	out=$("$D" --command "$1" --robot "$R" --lcm-url "$URL" --timeout 3 2>&1)
	last_cmd=$(now_ms)
	echo "$1 -> $out" >>"$T/commands.log"
	[[ "$out" == *command-accepted* ]]
}

send_limp() {
	limp_cycle=$(cur_state | field cycle)
	limp_cycle=${limp_cycle:-0}
	limp_sent=$(now_ms)
	send "$(pick 'mode limp' 'torque off')" || n_refused=$((n_refused + 1))
	n_limp=$((n_limp + 1)) wanted=0
	limp_deadline=$(( limp_sent + LIMP_BOUND_S * 1000 ))
	[ "$episode_cuts" -eq 1 ] && limp_deadline=$(( episode_end + LIMP_BOUND_S * 1000 ))
}

# torque may come back on from here: the LIMP span ends at the last cycle seen
end_limp_span() {
	[ "$limp_from" -gt 0 ] || return 0
	echo "$limp_from $(cur_state | field cycle)" >>"$T/limp_spans"
	limp_from=0
}

send_other() {
	local text
	end_limp_span
	if [ "$(pick 1 2 3)" = 1 ]; then
		text=$(pick 'mode hold' 'torque on'); wanted=1; n_hold=$((n_hold + 1))
		# 'torque on' is HOLD only from LIMP: elsewhere it is 'mode hold'
		[ "$text" = 'torque on' ] && [ "$(cur_state | field mode)" != 0 ] && text='mode hold'
	else
		text='mode oscillator'; wanted=3; n_osc=$((n_osc + 1))
	fi
	send "$text" || n_refused=$((n_refused + 1))
}

# check_limp T: has the pending LIMP taken effect, published and on the servos?
check_limp() {
	local t=$1 s c
	s=$(cur_state)
	c=$(echo "$s" | field cycle)
	if [ "${c:-0}" -gt "$limp_cycle" ] && [[ "$s" == *" mode=0 "* ]] &&
		[[ "$s" == *" tq0=0 "* ]] && [[ "$s" == *" tq1=0 "* ]] && sim_torque_off; then
		n_limp_ok=$((n_limp_ok + 1))
		limp_lat+=($(( t - limp_sent )))
		limp_from=$c limp_sent=0
	elif [ "$t" -gt "$limp_deadline" ]; then
		[ -n "$limp_fail" ] || limp_fail="LIMP $n_limp (sent at cycle $limp_cycle, episode '${episode:-none}'): $(echo "$s" | cut -c1-200); servos: $(ctl servo r1 1 | cut -c1-40) / $(ctl servo r1 2 | cut -c1-40)"
		limp_from=${c:-0} limp_sent=0
	fi
}

# operator: a latched fault cleared once its episode is over; the mode wanted put back
operator() {
	local t=$1 s
	[ -z "$episode" ] && [ "$limp_sent" -eq 0 ] || return 0
	[ $(( t - quiet_since )) -ge 1000 ] && [ $(( t - last_cmd )) -ge 1000 ] || return 0
	s=$(cur_state)
	if [[ "$s" != *' fault="" '* ]]; then
		send clear && n_clear=$((n_clear + 1))
	elif [ "$(echo "$s" | field mode)" != "$wanted" ]; then
		case $wanted in 0) send 'mode limp' ;; 1) send 'mode hold' ;; 3) send 'mode oscillator' ;; esac
		n_restore=$((n_restore + 1))
	fi
}

t_start=$(now_ms)
t_end=$(( t_start + DUR * 1000 ))
s0=$(cur_state); c0=$(echo "$s0" | field cycle)
next_fault=$(( t_start + $(rnd 500 3000) ))
next_cmd=$(( t_start + $(rnd 2000 8000) ))
next_rss=$t_start
load_max=${load0%% *}
while :; do
	t=$(now_ms)
	[ "$t" -lt "$t_end" ] || break
	if [ "$t" -ge "$next_rss" ]; then
		echo "$(( (t - t_start) / 1000 )) $(rss_kb "$pid_d") $(rss_kb "$pid_sim")" >>"$T/rss"
		# what the servos were told, on the wire: Goal Position, with torque on
		for id in 1 2; do
			[ "$(ctl peek r1 $id torque_enable)" = "ok 1" ] && echo "$id $(ctl peek r1 $id goal)" >>"$T/wire_goals"
		done
		next_rss=$(( next_rss + 5000 ))
		l=$(cut -d' ' -f1 /proc/loadavg)
		awk -v a="$l" -v b="$load_max" 'BEGIN { exit !(a > b) }' && load_max=$l
		alive d && alive sim || break
	fi
	if [ -n "$episode" ] && [ "$t" -ge "$episode_end" ]; then
		end_episode
		quiet_since=$t
		next_fault=$(( t + $(rnd 500 4000) ))
	elif [ -z "$episode" ] && [ "$t" -ge "$next_fault" ]; then
		begin_episode "$t"
	elif [ "$episode" = line-garbage ]; then
		sim_cmd garbage r1 "$(rnd 1 64)"
	fi
	if [ "$limp_sent" -gt 0 ]; then
		check_limp "$t"
		# the next command a little after the LIMP: short LIMP spans, many of them
		[ "$limp_sent" -eq 0 ] && next_cmd=$(( t + $(rnd 1000 4000) ))
	elif [ "$t" -ge "$next_cmd" ]; then
		if [ "$wanted" -ne 0 ] && [ "$(pick 1 2 3 4 5)" -le 3 ]; then send_limp; else send_other; fi
		next_cmd=$(( $(now_ms) + $(rnd 2000 8000) ))
	else
		operator "$t"
	fi
	sleep 0.05
done
t_loop=$(now_ms)
s1=$(cur_state); c1=$(echo "$s1" | field cycle)
load1=$(load)
[ -n "$episode" ] && end_episode
for i in $(seq "$CORES"); do stop "hog$i" >/dev/null; done
# a LIMP still waiting has its time, faults over
while [ "$limp_sent" -gt 0 ]; do check_limp "$(now_ms)"; sleep 0.05; done
end_limp_span
echo "# soak over after $(( (t_loop - t_start) / 1000 )) s; load average at the end $load1 (1-min peak $load_max)"

# ---- after the soak: the operator brings it back to OSCILLATOR -----------------------
ok_back=0
for _ in 1 2 3 4 5; do
	s=$(cur_state)
	[[ "$s" != *' fault="" '* ]] && { send clear || true; }
	send 'mode oscillator' &&
		wait_for 5 bash -c "tail -c 6000 '$T/watch.log' | grep -a '^STATE $R ' | tail -n 1 | grep -q ' mode=3 .* tq0=1 .* tq1=1 '" &&
		{ ok_back=1; break; }
done

if alive d && alive sim; then tap_ok "daemon and simulator survived $DUR s"
else tap_fail "daemon and simulator survived" "$(tail -n 20 "$T/d.log"; tail -n 5 "$T/sim.log")"; fi
if [ -n "$c1" ] && wait_cycles 50; then tap_ok "the daemon published to the end (cycle ${c0:-?} -> $c1, and on)"
else tap_fail "the daemon published to the end" "last state: $(cur_state | cut -c1-200)"; fi
if [ "$n_ctl_errors" -eq 0 ]; then tap_ok "the simulator took all $n_episodes fault episodes"
else tap_fail "the simulator took every fault command" "$n_ctl_errors refused; first: $ctl_error"; fi
if [ "$ok_back" = 1 ]; then tap_ok "after the soak: OSCILLATOR again, torque on"
else tap_fail "after the soak: OSCILLATOR again" "$(cur_state | cut -c1-300); $(tail -n 3 "$T/commands.log")"; fi

# ---- goals and limits ------------------------------------------------------------------
out=$(states | awk -v lim=$LIM '{
	delete v
	for (i = 1; i <= NF; i++) { k = index($i, "="); if (k) v[substr($i, 1, k - 1)] = substr($i, k + 1) }
	n++; torqued = 0
	for (j = 0; j < 2; j++) {
		if (v["tq" j] != "1") continue
		torqued = 1; nt++
		g = v["g" j]
		if (g ~ /nan/) { nan++; continue }
		g += 0
		if (g < -lim - 1e-4 || g > lim + 1e-4) { bad++; if (!eg) eg = $3 "/g" j "=" g }
		if (g > mx) mx = g; if (g < mn) mn = g
	}
	if (torqued) ts++
	if (v["mode"] == "3" && v["tq0"] == "1" && v["tq1"] == "1") osc++
} END { printf "%d %d %d %d %d %d %.4f %.4f %s\n", n, nt, ts, osc, bad, nan, mn, mx, eg ? eg : "-" }')
read -r n_states n_tq n_ts n_osc_states n_bad n_nan g_min g_max g_first <<<"$out"
if [ "$n_tq" -gt 1000 ] && [ "$n_bad" -eq 0 ] && [ "$n_nan" -eq 0 ]; then
	tap_ok "$n_tq goals of torqued joints in $n_states states: all inside +-$LIM rad (min $g_min, max $g_max)"
else
	c=${g_first%%/*}
	tap_fail "goals of torqued joints inside the limits" "$n_tq goals: $n_bad outside (first $g_first), $n_nan NaN; $n_states states"$'\n'"$(
		[ "$c" != - ] && states | grep -a -B2 -A1 " $c " | sed -E 's/ (jitter|bus|control|overruns|bus_errors|bad_commands|amp.|f.|ph.|ld.|st.|tl.|v.|T.|dr.)=[^ ]*//g' | cut -c1-260)"
fi
pl=$(grep -a "^PARAMS $R " "$T/watch.log" | awk -v lim=$LIM '{
	delete v
	for (i = 1; i <= NF; i++) { k = index($i, "="); if (k) v[substr($i, 1, k - 1)] = substr($i, k + 1) }
	n++; if (v["min0"] + lim != 0 || v["max0"] != lim || v["min1"] + lim != 0 || v["max1"] != lim) bad++
} END { print n + 0, bad + 0 }')
read -r np nb <<<"$pl"
if [ "$np" -ge 2 ] && [ "$nb" -eq 0 ]; then tap_ok "limits unchanged in all $np PARAMS"
else tap_fail "limits unchanged" "$nb of $np PARAMS differ"; fi

# ---- LIMP ----------------------------------------------------------------------------
lat=$(printf '%s\n' "${limp_lat[@]}" | sort -n | awk '{ v[NR] = $1 } END { if (NR) printf "median %.2f s, max %.2f s", v[int((NR + 1) / 2)] / 1000, v[NR] / 1000; else printf "none" }')
if [ "$n_limp" -ge 1 ] && [ "$n_limp_ok" -eq "$n_limp" ]; then
	tap_ok "$n_limp_ok of $n_limp LIMPs took effect within $LIMP_BOUND_S s (published and on both servos; $lat)"
else tap_fail "every LIMP took effect" "$n_limp_ok of $n_limp; ${limp_fail:-no LIMP sent}"; fi
# no state wanted torque on between a LIMP taking effect and the next HOLD/OSCILLATOR
spans=$(wc -l <"$T/limp_spans")
viol=$(states | awk 'NR == FNR { from[NR] = $1; to[NR] = $2; n = NR; next }
	{ c = $3; sub("cycle=", "", c); c += 0
	  for (i = 1; i <= n; i++) if (c >= from[i] && c <= to[i] && ($0 ~ / tq0=1 / || $0 ~ / tq1=1 /)) { bad++; if (!first) first = $3; break } }
	END { print bad + 0, first ? first : "-" }' "$T/limp_spans" -)
read -r n_viol first_viol <<<"$viol"
if [ "$spans" -ge 1 ] && [ "$n_viol" -eq 0 ]; then tap_ok "torque stayed off through all $spans LIMP spans until the next command"
else tap_fail "torque stayed off in LIMP" "$n_viol states want torque on inside $spans LIMP spans (first at $first_viol)"; fi

# ---- memory --------------------------------------------------------------------------
mem=$(awk -v w="$WARM_S" '$2 == "" { next }
	NR == 1 { first = $2 }
	$1 >= w { if (base == "") base = $2; if ($2 > mx) mx = $2; last = $2; sb = (sb == "" ? $3 : sb); ls = $3 }
	END { printf "%d %d %d %d %d %d\n", first, base, mx, last, sb, ls }' "$T/rss")
read -r rss_first rss_base rss_max rss_last sim_base sim_last <<<"$mem"
growth=$(( rss_max - rss_base ))
if [ "$rss_base" -gt 0 ] && [ "$growth" -lt 1024 ]; then
	tap_ok "daemon memory flat after ${WARM_S} s: VmRSS $rss_base -> $rss_last kB (peak +$growth kB)"
else tap_fail "daemon memory flat" "VmRSS at ${WARM_S} s $rss_base kB, peak $rss_max kB, last $rss_last kB"$'\n'"$(tail -n 20 "$T/rss")"; fi

# ---- the figures ---------------------------------------------------------------------
per=$(states | awk '{ p = $0; sub(/.* period=/, "", p); sub(/ .*/, "", p); print p + 0 }' | sort -n |
	awk '{ v[NR] = $1; s += $1 } END { if (!NR) exit; k = int(NR * 0.99); if (k < 1) k = 1
		printf "mean %.0f us, p99 %d us, max %d us (%d states)", s / NR, v[k], v[NR], NR }')
hz=$(awk -v c0="$c0" -v c1="$c1" -v t0="$t_start" -v t1="$t_loop" 'BEGIN { printf "%.2f", (c1 - c0) / ((t1 - t0) / 1000) }')
kinds=""; for k in $(printf '%s\n' "${!n_kind[@]}" | sort); do kinds+="${kinds:+, }$k ${n_kind[$k]}"; done
bus=$(grep -a "^BUS $R " "$T/watch.log" | tail -n 1)
echo "# loop: $hz Hz over the soak (cycles $c0 -> $c1); period $per; overruns $(echo "$s1" | field overruns); bus errors $(echo "$s1" | field bus_errors); BUS: p99 $(echo "$bus" | field p99) us, reconnects $(echo "$bus" | field reconnects), cpu $(echo "$bus" | field cpu) %"
echo "# faults: $n_episodes episodes ($kinds)"
echo "# commands: $n_limp LIMP, $n_hold HOLD, $n_osc OSCILLATOR ($n_refused refused), $n_clear 'clear' after latched faults, $n_restore modes put back"
echo "# torqued in $n_ts of $n_states states, OSCILLATOR with torque on in $n_osc_states"
echo "# memory: undulated VmRSS $rss_first kB at start, $rss_base at ${WARM_S} s, $rss_last at the end (peak $rss_max); undulate-sim $sim_base -> $sim_last kB"
echo "# sim: $(ctl stats)"
# the goal registers sampled on the simulated servos (AX-12A: 512 is 0 rad,
# 300/1023 degree a step): printed, not asserted — the published goal above
# is the clamped one, before it is rounded to a step
awk -v lim=$LIM '{ n++; r = ($3 - 512) * 300 / 1023 * 3.14159265358979 / 180
	if (r > lim + 1e-9 || r < -lim - 1e-9) { out++; d = (r > 0 ? r - lim : -lim - r); if (d > dmax) dmax = d } }
	END { printf "# wire: %d Goal Position registers of torqued servos sampled; %d beyond +-%s rad (by up to %.4f rad)\n", n, out, lim, dmax }' "$T/wire_goals"

stop d >/dev/null; rc=$stop_rc
if [ "$rc" = 0 ]; then tap_ok "SIGTERM: clean stop"; else tap_fail "SIGTERM: clean stop" "exit $rc: $(tail -n 5 "$T/d.log")"; fi
if grep -aqE "Sanitizer|runtime error" "$T/d.log" "$T/sim.log"; then
	tap_fail "no sanitizer report" "$(grep -aE -A5 "Sanitizer|runtime error" "$T/d.log" "$T/sim.log" | head -n 20)"
else tap_ok "no sanitizer report"; fi
# after a failure, what it needs: the programs' logs, the commands and their
# answers, the memory samples, the LIMP spans and every state (compressed)
if [ "$_tap_failed" -gt 0 ]; then
	keep="$BUILD/test-logs/qa_soak.d"
	rm -rf "$keep" && mkdir -p "$keep"
	cp "$T"/{d.log,sim.log,commands.log,rss,limp_spans,wire_goals} "$keep/" 2>/dev/null
	gzip -c "$T/watch.log" >"$keep/watch.log.gz"
	echo "# logs kept in $keep"
fi
tap_done
