# scripts/outdir.sh — where a script writes its results (scripts/demo.sh
# --out, `make figures`' runs and pages): the rules of common/outdir.h, in
# bash, for the scripts. Source it.
#
#   outdir_check DIR PREFIX   DIR made when missing (0755 less the umask; its
#                             parent must exist); else it must be ours and
#                             writable by no other user (its group only when
#                             the group is ours alone; sticky and ours is
#                             fine), reached through symbolic links we or root
#                             made. 0, or 1 with "PREFIX DIR: why: what to do"
#                             on stderr (the C tools' words).
#   outdir_new FILE...        each FILE a new empty file of ours (0666 less
#                             the umask), whatever was there (a link, a FIFO,
#                             an old file) replaced, never followed or opened;
#                             then write it with > or >>. 1 when one cannot be.
#   outdir_put FILE           stdin into FILE the same way, at once (rename).
#   outdir_mv SRC DST         SRC (a file) moved to DST, replacing what is there.
#   outdir_publish SRC DIR    every file under directory SRC moved to the same
#                             name under DIR (a subdirectory checked, or made,
#                             with outdir_check), then SRC removed.
#
# Why: in a directory another user can write, the names about to be written
# may already be symbolic links to our files (`>` writes through them: as
# root, into any file) or FIFOs (`>` blocks; a program run on one reads what
# the other user feeds it). A temporary file made by mktemp (O_EXCL, a name
# no one chose) and renamed over the final name replaces a link or FIFO
# rather than following or opening it. The checks are made by name, as a
# shell can: the C tools (common/outdir.c) hold the directory open instead.

# A symbolic link on the way is followed this many times at most (the kernel's MAXSYMLINKS).
OUTDIR_MAX_LINKS=40

# _outdir_who UID: "name (uid N)" or "uid N".
_outdir_who() {
	local name
	name=$(getent passwd "$1" | cut -d: -f1)
	if [ -n "$name" ]; then echo "$name (uid $1)"; else echo "uid $1"; fi
}

# _outdir_group_private GID: the group is ours alone (our primary group,
# named as we are, no other member listed).
_outdir_group_private() {
	local me name members m
	[ "$1" = "$(id -g)" ] || return 1
	me=$(id -un) || return 1
	IFS=: read -r name _ _ members < <(getent group "$1") || return 1
	[ "$name" = "$me" ] || return 1
	for m in ${members//,/ }; do [ "$m" = "$me" ] || return 1; done
	return 0
}

# _outdir_walk BASE PATH LAST DEPTH: the physical path PATH leads to from
# directory BASE ("" for /), checking every symbolic link on the way; with
# LAST=1 its last name may be missing. Errors name $_outdir_path.
_outdir_walk() {
	local cur=$1 rest=$2 last=$3 depth=$4 comp next owner target
	case "$rest" in /*) cur="" ;; esac
	while [ -n "$rest" ]; do
		comp=${rest%%/*}
		if [ "$comp" = "$rest" ]; then rest=""; else rest=${rest#*/}; fi
		case "$comp" in
		""|.) continue ;;
		..) cur=${cur%/*}; continue ;;
		esac
		next="$cur/$comp"
		if [ -L "$next" ]; then
			owner=$(command stat -c %u -- "$next") || return 1
			if [ "$owner" != 0 ] && [ "$owner" != "$EUID" ]; then
				echo "$_outdir_path: the symbolic link $comp on the way is owned by $(_outdir_who "$owner"), not by you or root: another user chooses where it leads; give the directory itself"
				return 1
			fi
			depth=$((depth + 1))
			[ "$depth" -le "$OUTDIR_MAX_LINKS" ] || { echo "$_outdir_path: Too many levels of symbolic links"; return 1; }
			target=$(readlink -- "$next") || return 1
			cur=$(_outdir_walk "$cur" "$target" "$([ -z "$rest" ] && echo "$last" || echo 0)" "$depth") ||
				{ echo "$cur"; return 1; }
		elif [ -d "$next" ]; then
			cur=$next
		elif [ -e "$next" ]; then
			echo "$_outdir_path: $comp is not a directory"; return 1
		elif [ -z "$rest" ] && [ "$last" = 1 ]; then
			cur=$next
		else
			echo "$_outdir_path: cannot open $comp: No such file or directory"; return 1
		fi
	done
	echo "$cur"
}

outdir_check() {
	local dir=$1 prefix=${2:-} res uid gid mode why="" base dmode
	local _outdir_path=$dir
	[ -n "$dir" ] || { echo "${prefix:+$prefix }an empty directory name" >&2; return 1; }
	# the working directory matters only to a relative DIR (a process fewer
	# for an absolute one: make figures checks a few thousand folders)
	case "$dir" in /*) base="" ;; *) base=$(pwd -P) ;; esac
	res=$(_outdir_walk "$base" "$dir" 1 0) || { echo "${prefix:+$prefix }$res" >&2; return 1; }
	[ -n "$res" ] || res=/
	if [ ! -e "$res" ]; then
		printf -v dmode '%o' $((0755 & ~0$(umask)))
		mkdir -m "$dmode" -- "$res" 2>/dev/null || [ -d "$res" ] ||
			{ echo "${prefix:+$prefix }$dir: cannot create it" >&2; return 1; }
	fi
	read -r uid gid mode < <(command stat -L -c '%u %g %a' -- "$res") || return 1
	mode=$((8#$mode))
	# $EUID: what `id -u` prints, without running it
	if [ "$uid" != "$EUID" ]; then
		why="owned by $(_outdir_who "$uid"), not by you ($(id -un)): another user could put links or FIFOs in it under the names written there; choose a directory of yours (a new one is made)"
	elif [ $((mode & 01000)) = 0 ]; then
		if [ $((mode & 02)) != 0 ]; then
			why="writable by other users (mode $(printf '%04o' "$mode")): another user could put links or FIFOs in it under the names written there; chmod go-w $dir, or choose another directory"
		elif [ $((mode & 020)) != 0 ] && ! _outdir_group_private "$gid"; then
			why="writable by its group, which is not yours alone (mode $(printf '%04o' "$mode")): another user could put links or FIFOs in it under the names written there; chmod g-w $dir, or choose another directory"
		fi
	fi
	[ -z "$why" ] || { echo "${prefix:+$prefix }$dir: $why" >&2; return 1; }
}

# _outdir_tmp VAR FILE: a new file of ours beside FILE (mktemp: O_EXCL), 0666
# less the umask as a file made by > would be; its name in VAR (no
# subshell: a figure run writes a few of these).
_outdir_tmp() {
	local -n _ot_tmp=$1
	local dir base fmode
	case "$2" in */*) dir=${2%/*}; [ -n "$dir" ] || dir=/ ;; *) dir=. ;; esac
	base=${2##*/}
	_ot_tmp=$(mktemp -- "$dir/.$base.XXXXXX") || return 1
	printf -v fmode '%o' $((0666 & ~0$(umask)))
	chmod "$fmode" -- "$_ot_tmp" || { rm -f -- "$_ot_tmp"; return 1; }
}

outdir_new() {
	local f tmp rc=0
	_outdir_new_together "$@" || rc=$?
	[ "$rc" = 2 ] || return "$rc"
	for f in "$@"; do
		_outdir_tmp tmp "$f" || return 1
		mv -f -T -- "$tmp" "$f" || { rm -f -- "$tmp"; return 1; }
	done
}
# _outdir_new_together FILE...: several new files of one folder made in a
# private folder beside them (mktemp -d: no one else can place anything in
# it, and a file the shell creates there has 0666 less the umask) and moved
# in with one mv, each replacing what has its name, never followed: three
# programs for any number of files. 1 when one could not be made; 2, having
# done nothing, for one file, files of several folders or a name given twice.
_outdir_new_together() {
	[ $# -gt 1 ] || return 2
	local f dir d tmp made=()
	local -A seen=()
	case "$1" in */*) dir=${1%/*}; [ -n "$dir" ] || dir=/ ;; *) dir=. ;; esac
	for f in "$@"; do
		case "$f" in */*) d=${f%/*}; [ -n "$d" ] || d=/ ;; *) d=. ;; esac
		[ "$d" = "$dir" ] && [ -n "${f##*/}" ] && [ -z "${seen[${f##*/}]:-}" ] || return 2
		seen[${f##*/}]=1
	done
	tmp=$(mktemp -d -- "$dir/.outdir.XXXXXX") || return 1
	for f in "$@"; do
		made+=("$tmp/${f##*/}")
		: >"$tmp/${f##*/}" || { rm -rf -- "$tmp"; return 1; }
	done
	mv -f -t "$dir" -- "${made[@]}" || { rm -rf -- "$tmp"; return 1; }
	rmdir -- "$tmp"
}

outdir_put() {
	local tmp
	_outdir_tmp tmp "$1" || return 1
	cat >"$tmp" && mv -f -T -- "$tmp" "$1" || { rm -f -- "$tmp"; return 1; }
}

outdir_mv() { mv -f -T -- "$1" "$2"; }

outdir_publish() {
	local src=$1 dir=$2 p name rc=0 files=()
	for p in "$src"/* "$src"/.[!.]*; do
		[ -e "$p" ] || [ -L "$p" ] || continue
		name=${p##*/}
		if [ -d "$p" ] && [ ! -L "$p" ]; then
			# a link or file under a directory's name is replaced too
			if [ -L "$dir/$name" ] || { [ -e "$dir/$name" ] && [ ! -d "$dir/$name" ]; }; then
				rm -f -- "$dir/$name" || rc=1
			fi
			outdir_check "$dir/$name" && outdir_publish "$p" "$dir/$name" || rc=1
		elif [ -f "$p" ]; then
			files+=("$p")
		fi
	done
	# the files in one mv (a run publishes about twenty): each is renamed to
	# its name in DIR as outdir_mv does, replacing a link there, never
	# following it; a directory under that name is refused, as with -T
	if [ ${#files[@]} -gt 0 ]; then mv -f -t "$dir" -- "${files[@]}" || rc=1; fi
	rm -rf -- "$src"
	return "$rc"
}
