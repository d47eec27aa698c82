#!/usr/bin/env bash
# undulate-analyze from the command line: a log recorded by the real
# lcm-logger from replayed synthetic traffic (known phases and collisions),
# plots, and the exit codes for missing, foreign and truncated logs.
. "$(dirname "$0")/../lib.sh"
port=$(lcm_port 7752)   # the UDP port itself, to find in /proc/net/udp
url=$(lcm_url 7752)
A="$B/undulate-analyze"

tap_check "--synth writes a log" bash -c "'$A' --synth '$T/s.log' --duration 13 >/dev/null"
# record it as a lab would: lcm-logger on the network, lcm-logplayer at the
# log's own speed (at 4x a loaded machine's logger lost messages twice: an
# empty events.csv, a missing return-map point)
spawn logger lcm-logger --lcm-url="$url" --flush-interval=10 -q "$T/rec.log"
hexport=$(printf '%04X' $port)
# ready once its multicast socket is bound (LCM binds it when subscribing)
wait_for 5 grep -q ":$hexport " /proc/net/udp || tap_fail "lcm-logger did not bind port $port"
lcm-logplayer --lcm-url="$url" --speed=1 "$T/s.log" >"$T/player.log" 2>&1
stop logger INT >/dev/null
tap_check "lcm-logger recorded something" test -s "$T/rec.log"

"$A" "$T/rec.log" --out "$T/out" --window 5 --plots >"$T/summary.out" 2>"$T/err.out"
rc=$?
if [ "$rc" = 0 ]; then tap_ok "analysis of an lcm-logger log exits 0"
else tap_fail "analysis of an lcm-logger log exits 0" "rc=$rc: $(cat "$T/err.out")"; fi
for f in states collisions bus events params phase_diff return_map collision_rate; do
	tap_check "$f.csv written with a header and rows" test "$(wc -l <"$T/out/$f.csv")" -gt 1
done
tap_check "summary: r1:r2 compatible" grep -qE '^r1:r2 +compatible' "$T/out/summary.txt"
tap_check "summary: r2:r3 anti-phase" grep -qE '^r2:r3 +anti-phase' "$T/out/summary.txt"
tap_check "summary printed on stdout too" grep -q 'end state' "$T/summary.out"
# r3:r4 collides at 4, 8, 12 s: two return-map points on the d~ = 0 closed form
# delta_n = 2 atan((-r)^n tan(delta0/2)), delta0 = 2, r = 0.67
tap_check "return map r3:r4 follows the closed form" awk -F, '
	$1 == "\"r3:r4\"" { n = $2; e0 = 2 * atan2((-0.67)^n * sin(1) / cos(1), 1);
		e1 = 2 * atan2((-0.67)^(n + 1) * sin(1) / cos(1), 1);
		if (($5 - e0)^2 > 1e-6 || ($6 - e1)^2 > 1e-6) bad = 1; pts++ }
	END { exit !(pts == 2 && !bad) }' "$T/out/return_map.csv"

png_ok() { [ "$(head -c 8 "$1" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ] && [ "$(stat -c %s "$1")" -gt 1000 ]; }
# A plot drawn without its data still has frame, text and key samples: count
# the pixels of the data's own colours (tests/tools/pngdata). An empty
# angles.png (rows of several robots interleaved in states.csv, filtered
# inside `plot with lines`) had 156 coloured pixels; the key samples of a
# panel are about 100.
PNGDATA="$BUILD/tests/tools/pngdata"
# drawn NAME FILE MIN [RGB]: at least MIN data pixels (of colour RGB if given)
drawn() {
	local n
	n=$("$PNGDATA" ${4:+--rgb "$4"} "$2" 2>&1 | sed -n 's/.*\(coloured\|matching\)=\([0-9]*\)$/\2/p')
	if [ "${n:-0}" -ge "$3" ]; then tap_ok "$1 ($n data pixels)"; else tap_fail "$1" "${n:-no count}: $("$PNGDATA" "$2" 2>&1)"; fi
}
if command -v gnuplot >/dev/null; then
	for p in angles portraits phase_diff collision_rate return_map_1 return_map_2; do
		tap_check "$p.png is a PNG" png_ok "$T/out/$p.png"
	done
	drawn "angles.png draws every robot's joints" "$T/out/angles.png" 20000
	drawn "angles.png: joint 1 drawn (its own colour)" "$T/out/angles.png" 2000 b3261e
	drawn "portraits.png draws the portraits" "$T/out/portraits.png" 3000
	drawn "phase_diff.png draws the phase differences" "$T/out/phase_diff.png" 3000 1f4e9c
	drawn "collision_rate.png draws the contact force" "$T/out/collision_rate.png" 1000 b3261e
	# the anti-phase pair r2:r3 is one band at pi, not two at the edges: its
	# deltas near -pi were moved up by 2 pi (cut below -2 asin(d~))
	tap_check "phase_diff.png: anti-phase drawn as one band" grep -q '1:(\$2 <= -1.5' "$T/out/plots.gp"
	# Each big CSV is read once, by the analyser, into blocks of the rows each
	# panel draws (gnuplot filtering states.csv once per joint took two
	# minutes for a demo): the script reads none of them, and each block holds
	# exactly its joint's (its pair's) rows.
	big=$(grep -cE "'(states|phase_diff|collisions)\.csv'" "$T/out/plots.gp")
	if [ "$big" = 0 ]; then tap_ok "plots.gp filters none of the big CSVs (joints.dat, phase.dat, pair_collisions.dat instead)"
	else tap_fail "plots.gp filters none of the big CSVs" "$big plot clauses read them"; fi
	per_key() {   # CSV KEYCOLS...: "key rows" per key, the key's columns named in the header, unquoted
		awk -F, -v keys="${*:2}" 'NR == 1 { n = split(keys, k, " "); for (i = 1; i <= NF; i++) c[$i] = i; next }
			{ key = ""; for (i = 1; i <= n; i++) { v = $c[k[i]]; gsub(/"/, "", v); key = key (i > 1 ? ":" : "") v }; rows[key]++ }
			END { for (key in rows) print key, rows[key] }' "$1" | sort
	}
	per_block() {   # DAT: "key rows" per block, the key from its comment line
		awk '/^# index / { key = $0; next } NF { rows[key]++ } END { for (key in rows) print key, rows[key] }' "$1"
	}
	# each joint's rows (t, angle, speed as states.csv has them, in its order),
	# by robot name and joint, in its own block
	awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
		{ r = $c["robot"]; gsub(/"/, "", r); print r ":" $c["joint"] "\t" $c["t"] "," $c["angle"] "," $c["speed"] }' \
		"$T/out/states.csv" | sort -s -t "$(printf '\t')" -k1,1 >"$T/joints.want"
	awk '/^# index / { r = $5; sub(/,$/, "", r); j = $7; sub(/:$/, "", j); key = r ":" j; next }   # "# index K: robot R, joint J: ..."
		NF { print key "\t" $0 }' "$T/out/joints.dat" | sort -s -t "$(printf '\t')" -k1,1 >"$T/joints.got"
	nj=$(cut -f1 "$T/joints.got" | sort -u | grep -c .)
	if [ "$nj" -ge 4 ] && cmp -s "$T/joints.want" "$T/joints.got"; then
		tap_ok "joints.dat: each joint's rows of states.csv, as written, in its own block ($nj joints)"
	else
		tap_fail "joints.dat: each joint's rows of states.csv in its own block" "$nj blocks; first difference: $(diff "$T/joints.want" "$T/joints.got" | head -3 | tr '\n' ' ')"
	fi
	# (phase_diff.csv also holds each robot's own joint pairs, r1/0:1, which no panel draws)
	got=$(per_block "$T/out/phase.dat" | sed -E 's/^# index [0-9]+: pair ([^:]*:[^:]*): [^ ]* /\1 /' | sort)
	want=$(per_key "$T/out/phase_diff.csv" pair | join - <(echo "$got" | awk '{ print $1 }'))
	if [ -n "$got" ] && [ "$want" = "$got" ]; then tap_ok "phase.dat: each pair's rows of phase_diff.csv in its block ($(echo $got))"
	else tap_fail "phase.dat: each pair's rows of phase_diff.csv" "phase_diff.csv: $(echo $want); phase.dat: $(echo $got)"; fi
	tap_check "phase_diff.png: compatibility bounds and collisions drawn" \
		bash -c "grep -q 'compatible bound' '$T/out/plots.gp' && grep -q \"title 'collision'\" '$T/out/plots.gp'"
	tap_check "return maps: measured points coloured by time" grep -q "lc palette title 'measured (colour: time)'" "$T/out/plots.gp"
else
	tap_fail "gnuplot not installed (gnuplot-nox): plots untested"
fi

# A pair whose joints stopped is not-oscillating, whatever its phases say:
# r3 and r4 stand still from 8 s on (r3:r4 at rest on the same side would
# otherwise be "in-phase"); the swings are in the last two columns.
tap_check "--synth-stop-after writes a log" bash -c "'$A' --synth '$T/stop.log' --duration 20 --synth-stop-after 8 >/dev/null"
"$A" "$T/stop.log" --out "$T/stop" --quiet 2>"$T/stop.err"; rc=$?
tap_check "analysis of a log with stopped robots exits 0" [ "$rc" = 0 ]
# col DIR PAIR COLUMN: a column of a pair's row in summary.txt, found by header name.
col() {
	awk -v pair="$2" -v want="$3" '
		$1 == "pair" && !hdr { for (i = 1; i <= NF; i++) { if ($i == "end" && $(i + 1) == "state") { c["state"] = ++j; i++ } else c[$i] = ++j }; hdr = 1; next }
		hdr && $1 == pair { print $c[want]; exit }' "$1/summary.txt"
}
tap_check "stopped: r1:r2 still compatible" [ "$(col "$T/stop" r1:r2 state)" = compatible ]
tap_check "stopped: r2:r3 (one robot at rest) not-oscillating" [ "$(col "$T/stop" r2:r3 state)" = not-oscillating ]
tap_check "stopped: r3:r4 (both at rest) not-oscillating" [ "$(col "$T/stop" r3:r4 state)" = not-oscillating ]
tap_check "stopped: swing_a of r2:r3 is 1.6 rad p-p, swing_b 0" \
	awk -v a="$(col "$T/stop" r2:r3 swing_a)" -v b="$(col "$T/stop" r2:r3 swing_b)" \
	'BEGIN { exit !(a > 1.59 && a < 1.61 && b == 0) }'
tap_check "stopped: summary.json has the swings and the class" \
	grep -qE '"pair":"r3:r4"[^}]*"class":"not-oscillating"[^}]*"swing_a":0,"swing_b":0}' "$T/stop/summary.json"
"$A" "$T/stop.log" --out "$T/stop0" --quiet --min-swing 0 2>/dev/null
tap_check "--min-swing 0: the phases decide again (r3:r4 in-phase)" [ "$(col "$T/stop0" r3:r4 state)" = in-phase ]
"$A" "$T/stop.log" --out "$T/stop1" --quiet --min-swing -1 2>/dev/null; rc=$?
tap_check "--min-swing -1: exit 1" [ "$rc" = 1 ]
"$A" "$T/stop.log" --synth-stop-after 3 --out "$T/stop2" 2>/dev/null; rc=$?
tap_check "--synth-stop-after without --synth: exit 1" [ "$rc" = 1 ]
"$A" --synth "$T/s3.log" "$T/s.log" 2>"$T/s3.err"; rc=$?
tap_check "--synth with a log to read: exit 1, saying so" bash -c "[ $rc = 1 ] && grep -q 'reads none' '$T/s3.err'"

# --frequency HZ: every joint's phase from the first sample at the given
# frequency. Against --zero-crossings (the analyser's own estimate, known from
# about the fourth cycle): the phase starts at once, and the known phases
# come out (r1:r2 at 0.4 rad); a wrong frequency gives wrong phases.
"$A" "$T/s.log" --out "$T/zc" --window 5 --quiet --zero-crossings
"$A" "$T/s.log" --out "$T/fq" --window 5 --quiet --zero-crossings --frequency 0.8
"$A" "$T/s.log" --out "$T/fq4" --window 5 --quiet --frequency 0.4
first_phase() { awk -F, 'NR == 2 { print $2 }' "$1/phase_diff.csv"; }
tap_check "--zero-crossings: no phase before the third second" awk -v t="$(first_phase "$T/zc")" 'BEGIN { exit !(t > 3) }'
tap_check "--frequency 0.8: a phase from the first sample" awk -v t="$(first_phase "$T/fq")" 'BEGIN { exit !(t < 0.05) }'
tap_check "--frequency 0.8: r1:r2 at its known 0.4 rad" awk -v d="$(col "$T/fq" r1:r2 meanD)" 'BEGIN { exit !(d > 0.39 && d < 0.41) }'
tap_check "--frequency 0.4 (wrong): r1:r2 no longer at 0.4 rad" \
	awk -v d="$(col "$T/fq4" r1:r2 spread)" 'BEGIN { exit !(d > 0.1) }'
"$A" "$T/s.log" --out "$T/fq0" --frequency 0 2>"$T/fq0.err"; rc=$?
tap_check "--frequency 0: exit 1, saying so" bash -c "[ $rc = 1 ] && grep -q 'frequency must be' '$T/fq0.err'"
# --plane-every S: plane.csv's spacing; a negative one is refused (a row
# world's log has no plane.csv: test_analyze_logs checks the files' content)
"$A" "$T/s.log" --out "$T/pe" --plane-every -1 2>"$T/pe.err"; rc=$?
tap_check "--plane-every -1: exit 1, saying so" bash -c "[ $rc = 1 ] && grep -q 'plane-every must be' '$T/pe.err'"

# --theory: the theory's curves as CSV (tools/analyze/theory.c), checked
# against theory.md's formulas at known points.
th() { "$A" --theory "$@"; }
tap_check "--theory critical: d~_c = 0.316 at r = 0.67" \
	bash -c "'$A' --theory critical | awk -F, 'NR == 2 { exit !(\$2 > 0.3150 && \$2 < 0.3160) }'"
tap_check "--theory critical: d~_c = 0.21 at r = 0.9" \
	bash -c "'$A' --theory critical --restitution 0.9 | awk -F, 'NR == 2 { exit !(\$2 > 0.205 && \$2 < 0.21) }'"
th curves --points 101 >"$T/curves.csv"
tap_check "--theory curves: 2 asin(d~), f'(pi) (theory.md), stable only above d~_c, 101 rows" awk -F, '
	NR == 1 { ok = $1 == "dsep" && $2 == "compat_limit" && $3 == "fprime_pi" && $5 == "antiphase_stable"; next }
	{ n++; d = $1; r = 0.67; d2 = d * d
	  if (($2 - 2 * atan2(d, sqrt(1 - d * d)))^2 > 1e-12) ok = 0
	  s = -(r * (d2 - 1) + d2) / (r * r * (d2 - 1) - d2); if (($3 - s)^2 > 1e-12) ok = 0
	  if ($5 != (d > 0.3156 && d < 1)) ok = 0 }
	END { exit !(ok && n == 101) }' "$T/curves.csv"
tap_check "--theory curves: the third fixed point only between d~_c and 1/sqrt(1 + r)" awk -F, '
	NR > 1 { if (($6 != "") != ($1 > 0.3156 && $1 < 0.7738)) bad = 1 } END { exit bad }' "$T/curves.csv"
th sequence --delta0 2.5 --steps 12 --restitution 0.5 >"$T/seq.csv"
tap_check "--theory sequence: the closed form 2 atan((-r)^n tan(D0/2)) is the map iterated" awk -F, '
	NR > 1 { e = 2 * atan2((-0.5)^$1 * sin(1.25) / cos(1.25), 1)
		if (($2 - e)^2 > 1e-14 || ($3 - $2)^2 > 1e-14) bad = 1; n++ } END { exit !(n == 13 && !bad) }' "$T/seq.csv"
printf 'dsep,delta0\n0.7,3.0\n0.2,3.1\n0.5,0.5\n' | th final >"$T/final.csv"
tap_check "--theory final: anti-phase above d~_c, compatible below, no contact inside the set" awk -F, '
	NR == 2 { a = $3 > 3.1415 } NR == 3 { b = ($3 < 0 ? -$3 : $3) < 0.403 } NR == 4 { c = $3 == 0.5 && $4 == 0 }
	END { exit !(a && b && c) }' "$T/final.csv"
th map --points 8 2>"$T/th1.err"; rc=$?
tap_check "--theory map without --separation: exit 1, saying so" bash -c "[ $rc = 1 ] && grep -q 'needs --separation' '$T/th1.err'"
th curves --restitution 0 2>"$T/th2.err"; rc=$?
tap_check "--theory with r = 0: exit 1" [ "$rc" = 1 ]
th nonsense 2>"$T/th3.err"; rc=$?
tap_check "--theory nonsense: exit 1, naming what there is" bash -c "[ $rc = 1 ] && grep -q 'want curves' '$T/th3.err'"
echo '0.5,abc' | th final >/dev/null 2>"$T/th4.err"; rc=$?
tap_check "--theory final with a bad line: exit 1 with its line number" bash -c "[ $rc = 1 ] && grep -q 'line 1' '$T/th4.err'"
"$A" "$T/s.log" --theory curves 2>"$T/th5.err"; rc=$?
tap_check "--theory with a log: exit 1" [ "$rc" = 1 ]

# errors: missing, foreign, truncated, bad options
"$A" "$T/nope.log" --out "$T/e1" 2>"$T/e1.err"; rc=$?
tap_check "missing log: exit 2 and a message" bash -c "[ $rc = 2 ] && grep -q 'No such file' '$T/e1.err'"
printf 'not a log at all\n' >"$T/foreign.log"
"$A" "$T/foreign.log" --out "$T/e2" 2>"$T/e2.err"; rc=$?
tap_check "foreign file: exit 2, 'not an LCM log', nothing written" \
	bash -c "[ $rc = 2 ] && grep -q 'not an LCM log' '$T/e2.err' && [ ! -e '$T/e2/states.csv' ]"
head -c 300000 "$T/s.log" >"$T/cut.log"
"$A" "$T/cut.log" --out "$T/e3" --quiet 2>"$T/e3.err"; rc=$?
tap_check "truncated log: exit 3 with a warning saying where it stopped" \
	bash -c "[ $rc = 3 ] && grep -q 'truncated or damaged at byte' '$T/e3.err'"
tap_check "truncated log: everything before the damage is written" test "$(wc -l <"$T/e3/states.csv")" -gt 100
# an xz-compressed log (as make demo keeps it) reads as the log it holds; one
# whose xz stream was cut short is a truncated log; an xz of something else is foreign
xz -1 -c "$T/s.log" >"$T/s.log.xz"
"$A" "$T/s.log" --out "$T/x0" --quiet 2>/dev/null; "$A" "$T/s.log.xz" --out "$T/x1" --quiet 2>"$T/x1.err"; rc=$?
tap_check "an xz-compressed log: the same states.csv and summary as the log" bash -c "[ $rc = 0 ] &&
	cmp -s '$T/x0/states.csv' '$T/x1/states.csv' && diff <(grep -v '^log:' '$T/x0/summary.txt') <(grep -v '^log:' '$T/x1/summary.txt') >/dev/null"
head -c $(( $(stat -c %s "$T/s.log.xz") / 2 )) "$T/s.log.xz" >"$T/cut.log.xz"
"$A" "$T/cut.log.xz" --out "$T/x2" --quiet 2>"$T/x2.err"; rc=$?
tap_check "an xz log cut short: exit 3, truncated, what came before written" \
	bash -c "[ $rc = 3 ] && grep -q 'truncated or damaged at byte' '$T/x2.err' && [ \$(wc -l <'$T/x2/states.csv') -gt 100 ]"
xz -1 -c "$T/foreign.log" >"$T/foreign.log.xz"
"$A" "$T/foreign.log.xz" --out "$T/x3" 2>"$T/x3.err"; rc=$?
tap_check "an xz of something else: exit 2, not an LCM log inside the xz stream" \
	bash -c "[ $rc = 2 ] && grep -q 'not an LCM log inside the xz stream' '$T/x3.err'"
# --plots-only: the plots without the per-sample CSVs (the plot command make demo prints)
"$A" "$T/s.log.xz" --out "$T/x4" --plots-only --quiet 2>"$T/x4.err"; rc=$?
tap_check "--plots-only: plots and summary, no states.csv or phase_diff.csv" bash -c "[ $rc = 0 ] &&
	[ -f '$T/x4/angles.png' ] && [ -f '$T/x4/summary.txt' ] && [ ! -e '$T/x4/states.csv' ] && [ ! -e '$T/x4/phase_diff.csv' ]"
"$A" "$T/s.log" --window -1 2>/dev/null; rc=$?
tap_check "bad option: exit 1" [ "$rc" = 1 ]

# A log is read in large pieces, with no system call per event: liblcm's
# reader seeks back 4 bytes after every event, and glibc made that an lseek
# (two an event with the analyser's ftello; 151 k for a 10-robot run).
# Counted by strace, where it may trace.
if command -v strace >/dev/null 2>&1 && strace -f -qq -o /dev/null true 2>/dev/null; then
	strace -qq -e trace=lseek,read -o "$T/an.strace" "$A" "$T/s.log" --out "$T/sys" --quiet 2>/dev/null
	events=$(sed -n 's/^log: .* (\([0-9]*\) events)$/\1/p' "$T/sys/summary.txt")
	seeks=$(grep -c '^lseek(' "$T/an.strace") reads=$(grep -c '^read(' "$T/an.strace")
	if [ "${events:-0}" -gt 1000 ] && [ "$seeks" -le 20 ] && [ "$reads" -le $((events / 20)) ]; then
		tap_ok "a log of $events events read with $seeks lseek and $reads read calls"
	else
		tap_fail "a log read with at most 20 lseek calls and a read per 20 events" "$events events, $seeks lseek, $reads read"
	fi
else
	tap_skip "a log read without a system call per event" "strace cannot trace here"
fi
tap_done
