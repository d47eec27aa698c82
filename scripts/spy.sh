#!/usr/bin/env bash
# scripts/spy.sh JAR [lcm-spy options] — lcm-spy with undulate's message types.
#
# Debian's /usr/bin/lcm-spy passes -Xincgc, which Java 9 and later reject
# ("Unrecognized VM option"), so this runs the same main class itself on the
# installed JRE (OpenJDK 17 on Debian 12). lcm-spy finds message types by
# scanning the jars on its class path; JAR is ours (make spy-jar).
#   LCM_URL=udpm://239.255.76.67:7667?ttl=1 make spy   listen on another URL
#   SPY_JAVA_OPTS="-Xmx512m" make spy                   extra JVM options
set -eu
jar=${1:?usage: scripts/spy.sh TYPES.jar [lcm-spy options]}
shift
share=/usr/share/java

# Packages: a JRE (default-jdk-headless also brings javac for `make spy-jar`),
# lcm.jar (liblcm-java), the charts (libjchart2d-java).
"$(dirname "$0")/deps.sh" default-jdk-headless liblcm-java libjchart2d-java

[ -f "$jar" ] || { echo "spy.sh: $jar not found (make spy-jar builds it)" >&2; exit 1; }
for j in "$share/lcm.jar" "$share/jchart2d.jar"; do
	[ -f "$j" ] || { echo "spy.sh: $j missing" >&2; exit 1; }
done
if [ -z "${DISPLAY:-}" ] && [ -z "${WAYLAND_DISPLAY:-}" ]; then
	echo "spy.sh: no display (DISPLAY is unset); lcm-spy is a Swing window: use ssh -X, or run it on the laptop" >&2
	exit 1
fi

cp="$share/lcm.jar:$share/jchart2d.jar:$(cd "$(dirname "$jar")" && pwd)/$(basename "$jar")"
args=()
[ -n "${LCM_URL:-}" ] && args+=(--lcm-url="$LCM_URL")
# lcm-spy's own JVM options, less -Xincgc; IPv4 because LCM's udpm is IPv4 multicast.
# shellcheck disable=SC2086
exec java -Djava.net.preferIPv4Stack=true -Xmx256m -ea ${SPY_JAVA_OPTS:-} \
	-cp "$cp" lcm.spy.Spy "${args[@]}" "$@"
