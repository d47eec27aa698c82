#!/usr/bin/env bash
# run.sh: long — started early, so that the run does not end waiting for it (tests/run.sh)
# run.sh: heavy — its lockstep runs keep a core busy (tests/run.sh)
# run.sh: timeout 900
# In make test-long, not make test: its Slurm daemons, sshd and lockstep runs
# took 113 s of a 15-minute suite (and it installs Slurm where it may).
# figures_slurm.sh — docs/CLUSTER.md's two ways of running a sweep elsewhere,
# for real, on this machine: a one-node Slurm (munged with its own key,
# slurmctld and slurmd on a slurm.conf of this test's, all in its folder and
# on ports of its own, stopped at the end) runs an exported tiny sweep as a
# job array through scripts/figures-slurm.sh; GNU parallel runs the same
# lines over ssh (--sshloginfile) to an sshd of this test's on 127.0.0.1.
# Each way's merge must give the same CSVs as the same runs made here by
# GNU parallel (the runs are deterministic): the heatmap module's two tiny
# grids (undulate-model, no daemons) and the returnmap module's two tiny
# lockstep runs (the simulator and two daemons each).
#
# Slurm's packages (slurmctld slurmd slurm-client munge) are installed when
# missing and this runs as root (scripts/deps.sh); otherwise, or when a
# daemon does not start, the Slurm checks are skipped saying why. The ssh
# checks need openssh-server installed (not installed here: Debian's package
# starts the machine's own sshd on port 22).
source "$(dirname "$0")/../lib.sh"

command -v parallel >/dev/null 2>&1 || tap_skip_all "GNU parallel is not installed (scripts/deps.sh installs it)"
command -v gnuplot >/dev/null 2>&1 || tap_skip_all "gnuplot is not installed (scripts/deps.sh installs it)"
for p in undulate-model undulate-sim undulated undulate-analyze; do
	[ -x "$B/$p" ] || tap_skip_all "$B/$p is not built (make)"
done

F="$top/scripts/figures.sh"
export FIG_TINY=1 FIG_PORT_LO FIG_PORT_SPAN=8
ONLY=heatmap,returnmap
# The runs' LCM ports (UDP) and the daemons' (TCP: Slurm's two, sshd's):
# this test's block of the tools' range, moved by TEST_PORT_OFFSET.
FIG_PORT_LO=$(lcm_port 7756)
CTLD_PORT=$(lcm_port 7764) SLURMD_PORT=$(lcm_port 7765) SSHD_PORT=$(lcm_port 7766)
NODE=undulate-test

# ---- the reference: the same jobs here, by GNU parallel ---------------------------------
# export SET: the tiny sweep's lines into $T/jobs-SET.txt, runs under $T/runs-SET
export_set() { "$F" --export-jobs "$T/jobs-$1.txt" --runs "$T/runs-$1" --only "$ONLY" >"$T/export-$1.out" 2>&1; }
# merged SET: the merge of $T/runs-SET into $T/docs-SET
merged() { "$F" --merge "$T/runs-$1" --only "$ONLY" --out "$T/docs-$1" >"$T/merge-$1.out" 2>&1; }
# same_csvs SET: each module's merged CSV as the reference's, byte for byte
same_csvs() {
	local m diffs=""
	for m in heatmap returnmap; do
		cmp -s "$T/docs-local/figures/$m.csv" "$T/docs-$1/figures/$m.csv" || diffs+="$m.csv differs: $(diff "$T/docs-local/figures/$m.csv" "$T/docs-$1/figures/$m.csv" 2>&1 | head -4) "
	done
	[ -z "$diffs" ] && return 0
	echo "$diffs"
	return 1
}

export_set local
n=$(wc -l <"$T/jobs-local.txt" 2>/dev/null || echo 0)
tap_check "--export-jobs: the tiny sweep, 4 lines (2 heatmap, 2 returnmap)" test "$n" = 4
(cd "$top" && parallel --jobs 2 --joblog "$T/joblog-local" <"$T/jobs-local.txt") >"$T/parallel-local.out" 2>&1
if merged local && [ -s "$T/docs-local/figures/heatmap.csv" ] && [ -s "$T/docs-local/figures/returnmap.csv" ]; then
	tap_ok "the reference: the 4 runs here by GNU parallel, merged"
else
	tap_fail "the reference: the 4 runs here by GNU parallel, merged" "$(tail -n 5 "$T/parallel-local.out" "$T/merge-local.out")"
fi

# ---- a one-node Slurm ----------------------------------------------------------------------
S="$T/slurm"
slurm_pids_started=0
# slurm_why: the reason Slurm cannot run here, empty when it can
slurm_why() {
	local p missing=""
	for p in munged munge slurmctld slurmd sbatch sinfo scontrol; do command -v "$p" >/dev/null 2>&1 || missing+=" $p"; done
	[ -z "$missing" ] && return 0
	if [ "$(id -u)" -ne 0 ]; then
		echo "Slurm is not installed (missing:$missing) and this test is not root: apt-get install slurmctld slurmd slurm-client munge"
		return 0
	fi
	if ! "$top/scripts/deps.sh" slurmctld slurmd slurm-client munge >"$T/deps.log" 2>&1; then
		echo "installing Slurm failed: $(tail -n 1 "$T/deps.log")"
		return 0
	fi
	for p in munged slurmctld slurmd sbatch; do command -v "$p" >/dev/null 2>&1 || { echo "installed, yet no $p"; return 0; }; done
}
# port_free PORT: nothing listens on TCP PORT here
port_free() { ! ss -Htln "( sport = :$1 )" 2>/dev/null | grep -q .; }
# slurm_start: munged, slurmctld and slurmd of this test (in this shell:
# their PIDs are lib.sh's to stop); non-zero with the reason in $why when
# they do not come up
slurm_start() {
	local host p
	[ "$(id -u)" -eq 0 ] || { why="slurmd runs as root (it starts each job as its user); this test is not root"; return 1; }
	for p in "$CTLD_PORT" "$SLURMD_PORT"; do port_free "$p" || { why="TCP port $p is taken"; return 1; }; done
	# munged wants every folder above its socket searchable by all, and its
	# key's folder private
	chmod 711 "$T"
	mkdir -p "$S/state" "$S/spool" "$S/log" "$S/out" && mkdir -m 700 "$S/munge" && mkdir -m 755 "$S/sock" || { why="cannot make its folders in $S"; return 1; }
	head -c 1024 /dev/urandom >"$S/munge/munge.key" && chmod 400 "$S/munge/munge.key" || { why="cannot write a munge key"; return 1; }
	spawn munged munged --foreground --key-file="$S/munge/munge.key" --socket="$S/sock/munge.sock" \
		--pid-file="$S/munge/munged.pid" --seed-file="$S/munge/munged.seed" --log-file="$S/log/munged.log"
	wait_for 10 test -S "$S/sock/munge.sock" || { why="munged did not start: $(tail -n 1 "$T/munged.log")"; return 1; }
	host=$(hostname -s)
	cat >"$S/slurm.conf" <<-EOF
		# a one-node Slurm for tests/long/figures_slurm.sh
		ClusterName=undulatetest
		SlurmctldHost=$host(127.0.0.1)
		SlurmctldPort=$CTLD_PORT
		SlurmdPort=$SLURMD_PORT
		SlurmUser=root
		SlurmdUser=root
		AuthType=auth/munge
		CredType=cred/munge
		AuthInfo=socket=$S/sock/munge.sock
		StateSaveLocation=$S/state
		SlurmdSpoolDir=$S/spool
		SlurmctldPidFile=$S/slurmctld.pid
		SlurmdPidFile=$S/slurmd.pid
		SlurmctldLogFile=$S/log/slurmctld.log
		SlurmdLogFile=$S/log/slurmd.log
		MailProg=/bin/true
		ProctrackType=proctrack/linuxproc
		TaskPlugin=task/none
		JobAcctGatherType=jobacct_gather/none
		AccountingStorageType=accounting_storage/none
		SchedulerType=sched/builtin
		SelectType=select/cons_tres
		SelectTypeParameters=CR_CPU
		MpiDefault=none
		ReturnToService=2
		NodeName=$NODE NodeAddr=127.0.0.1 NodeHostname=$host CPUs=2 State=UNKNOWN
		PartitionName=figures Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
	EOF
	export SLURM_CONF="$S/slurm.conf"
	spawn slurmctld slurmctld -D -i -f "$SLURM_CONF"
	spawn slurmd slurmd -D -N "$NODE" -f "$SLURM_CONF"
	slurm_pids_started=1
	if ! wait_for 60 bash -c "sinfo -h -n '$NODE' -o %T 2>/dev/null | grep -qx idle"; then
		why="the node never came up idle: slurmctld: $(grep -i error "$T/slurmctld.log" | grep -v pmix | tail -n 2 | tr '\n' ' ')"
		why+=" slurmd: $(grep -i error "$T/slurmd.log" | grep -v pmix | tail -n 2 | tr '\n' ' ')"
		return 1
	fi
}
# Jobs still queued or running are cancelled before the daemons stop (lib.sh's
# trap then stops them by PID), so that no slurmstepd is left behind.
slurm_stop() {
	[ "$slurm_pids_started" = 1 ] || return 0
	scancel --quiet --user="$(id -un)" 2>/dev/null
	wait_for 20 bash -c '[ -z "$(squeue -h 2>/dev/null)" ]'
	return 0
}
trap 'slurm_stop; _cleanup' EXIT

why=$(slurm_why)
[ -z "$why" ] && slurm_start
if [ -n "$why" ]; then
	for c in "Slurm: the array ran every line, each task exit 0" "Slurm: a task beyond the file fails" "Slurm: no job file: the usage" "Slurm: the merge gives the reference's CSVs"; do
		tap_skip "$c" "$why"
	done
else
	ver=$(sinfo --version 2>&1)
	echo "# $ver, one node ($NODE, 2 CPUs), proctrack/linuxproc"
	export_set slurm
	n=$(wc -l <"$T/jobs-slurm.txt")
	# From the top of the checkout, as docs/CLUSTER.md says; the tasks' output
	# beside the test's files, not in the checkout (the script's default)
	(cd "$top" && timeout 600 sbatch --wait --array="1-$n" --output="$S/out/slurm-%A_%a.out" \
		scripts/figures-slurm.sh "$T/jobs-slurm.txt") >"$T/sbatch.out" 2>&1
	rc=$?
	job=$(sed -n 's/^Submitted batch job \([0-9]*\).*/\1/p' "$T/sbatch.out")
	ok=$(ls "$T"/runs-slurm/*/*/result.csv 2>/dev/null | wc -l)
	# slurmctld's own word that each task ran and ended well
	ended=$(grep -cE "_job_complete: JobId=${job:-none}_[0-9]+\([0-9]+\) WEXITSTATUS 0" "$S/log/slurmctld.log" 2>/dev/null)
	if [ "$rc" = 0 ] && [ -n "$job" ] && [ "$ok" = "$n" ] && [ "$ended" = "$n" ]; then
		tap_ok "Slurm: the array ran every line, each task exit 0 (job $job, $n tasks)"
	else
		tap_fail "Slurm: the array ran every line, each task exit 0" \
			"sbatch exit $rc, $ok of $n results, $ended tasks ended with 0: $(tail -n 3 "$T/sbatch.out"; tail -n 3 "$S"/out/*.out 2>/dev/null)"
	fi
	# a task beyond the file: the task fails, and says why in its output file
	(cd "$top" && timeout 300 sbatch --wait --array="$((n + 1))" --output="$S/out/beyond-%A_%a.out" \
		scripts/figures-slurm.sh "$T/jobs-slurm.txt") >"$T/sbatch-beyond.out" 2>&1
	rc=$?
	tap_check "Slurm: a task beyond the file fails (sbatch --wait: exit $rc), its output saying so" \
		bash -c "[ $rc != 0 ] && grep -q 'has no line $((n + 1))' '$S'/out/beyond-*.out"
	# no job file: the usage names the script as it was submitted (under Slurm
	# $0 is slurmd's copy of it in its spool folder)
	(cd "$top" && timeout 300 sbatch --wait --array=1 --output="$S/out/usage-%A_%a.out" scripts/figures-slurm.sh) >"$T/sbatch-usage.out" 2>&1
	rc=$?
	tap_check "Slurm: no job file: exit 2, the usage naming scripts/figures-slurm.sh ($(cat "$S"/out/usage-*.out 2>/dev/null))" \
		bash -c "[ $rc = 2 ] && grep -qx 'figures-slurm: usage: sbatch --array=1-N scripts/figures-slurm.sh JOBFILE' '$S'/out/usage-*.out"
	merged slurm
	if d=$(same_csvs slurm); then tap_ok "Slurm: the merge gives the reference's CSVs"; else tap_fail "Slurm: the merge gives the reference's CSVs" "$d $(tail -n 3 "$T/merge-slurm.out")"; fi
fi

# ---- GNU parallel over ssh, to an sshd of this test's ---------------------------------------
H="$T/ssh" SSHD=/usr/sbin/sshd
# ssh_start: an sshd on 127.0.0.1:SSHD_PORT that takes only this test's key
# for this user, and an ssh_config naming it "undulate-self"; non-zero with
# the reason in $why
ssh_start() {
	local me
	me=$(id -un)
	[ -x "$SSHD" ] || { why="openssh-server is not installed (not installed by this test: Debian's package starts the machine's sshd on port 22)"; return 1; }
	command -v ssh >/dev/null 2>&1 && command -v ssh-keygen >/dev/null 2>&1 || { why="openssh-client is not installed"; return 1; }
	port_free "$SSHD_PORT" || { why="TCP port $SSHD_PORT is taken"; return 1; }
	# sshd as root wants its privilege separation folder (made by the
	# package's service when it starts; root's own, empty)
	[ "$(id -u)" -ne 0 ] || [ -d /run/sshd ] || mkdir -m 755 /run/sshd || { why="cannot make /run/sshd"; return 1; }
	mkdir -m 700 "$H" && ssh-keygen -q -t ed25519 -N '' -f "$H/host_key" && ssh-keygen -q -t ed25519 -N '' -f "$H/id" &&
		cp "$H/id.pub" "$H/authorized_keys" || { why="ssh-keygen failed"; return 1; }
	cat >"$H/sshd_config" <<-EOF
		ListenAddress 127.0.0.1
		Port $SSHD_PORT
		HostKey $H/host_key
		PidFile $H/sshd.pid
		AuthorizedKeysFile $H/authorized_keys
		AllowUsers $me
		PermitRootLogin prohibit-password
		PubkeyAuthentication yes
		PasswordAuthentication no
		KbdInteractiveAuthentication no
		UsePAM no
		StrictModes no
	EOF
	echo "[127.0.0.1]:$SSHD_PORT $(cat "$H/host_key.pub")" >"$H/known_hosts"
	cat >"$H/ssh_config" <<-EOF
		Host undulate-self
		  HostName 127.0.0.1
		  Port $SSHD_PORT
		  User $me
		  IdentityFile $H/id
		  IdentitiesOnly yes
		  UserKnownHostsFile $H/known_hosts
		  StrictHostKeyChecking yes
		  BatchMode yes
	EOF
	"$SSHD" -t -f "$H/sshd_config" >"$H/check.out" 2>&1 || { why="sshd refused its configuration: $(tail -n 1 "$H/check.out")"; return 1; }
	spawn sshd "$SSHD" -D -e -f "$H/sshd_config"
	wait_for 20 ssh -F "$H/ssh_config" undulate-self true ||
		{ why="ssh to the test's sshd failed: $(ssh -F "$H/ssh_config" undulate-self true 2>&1 | tail -n 1) $(tail -n 2 "$T/sshd.log")"; return 1; }
}
why=""
ssh_start
if [ -n "$why" ]; then
	for c in "ssh: GNU parallel ran every line on undulate-self, each exit 0" "ssh: the merge gives the reference's CSVs"; do
		tap_skip "$c" "$why"
	done
else
	echo "# $(ssh -V 2>&1), GNU parallel $(parallel --version | sed -n '1s/.* //p')"
	export_set ssh
	n=$(wc -l <"$T/jobs-ssh.txt")
	# docs/CLUSTER.md's line, with this test's ssh and the runs' ports passed on
	echo "2/undulate-self" >"$H/hosts"
	parallel --ssh "ssh -F $H/ssh_config" --sshloginfile "$H/hosts" --jobs 2 --workdir "$top" \
		--env FIG_PORT_LO --env FIG_PORT_SPAN --joblog "$T/joblog-ssh" <"$T/jobs-ssh.txt" >"$T/parallel-ssh.out" 2>&1
	rc=$?
	# the joblog's host column: every line ran through ssh, none here
	hosts=$(awk -F'\t' 'NR > 1 { print $2 }' "$T/joblog-ssh" 2>/dev/null | sort | uniq -c | tr -s ' ' | tr '\n' ';')
	bad=$(awk -F'\t' 'NR > 1 && $7 != 0' "$T/joblog-ssh" 2>/dev/null | wc -l)
	if [ "$rc" = 0 ] && [ "$bad" = 0 ] && [ "$hosts" = " $n undulate-self;" ]; then
		tap_ok "ssh: GNU parallel ran every line on undulate-self, each exit 0"
	else
		tap_fail "ssh: GNU parallel ran every line on undulate-self, each exit 0" "exit $rc, $bad failed, hosts:$hosts $(tail -n 3 "$T/parallel-ssh.out")"
	fi
	merged ssh
	if d=$(same_csvs ssh); then tap_ok "ssh: the merge gives the reference's CSVs"; else tap_fail "ssh: the merge gives the reference's CSVs" "$d $(tail -n 3 "$T/merge-ssh.out")"; fi
fi

tap_done
