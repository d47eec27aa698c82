#!/usr/bin/env bash
# systemd/99-undulate.rules: syntax and behaviour.
#
# This udev (252) has no `udevadm verify`, and `udevadm test` needs a live
# udevd and real devices, so the rules are checked here by a small reader of
# the rules language: every line parses, every key is a udev key with an
# operator it accepts, GOTOs have labels, substitutions are known. Then the
# rules are *run* by a tiny evaluator of the subset they use against
# described devices (a U2D2, a USB2Dynamixel, a USB2AX, an unrelated FTDI
# chip, a remove event, ...) and the outcome is compared with what the
# adapters need: latency timer 1, the by-serial link, dialout 0660.
# When `udevadm verify` exists, it runs too.
. "$(dirname "$0")/../lib.sh"

rules="$top/systemd/99-undulate.rules"

if ! command -v python3 >/dev/null; then
	tap_skip "udev rules checked" "python3 not installed"
	tap_done; exit
fi

cat >"$T/udevcheck.py" <<'PY'
import fnmatch, re, sys

# Keys udev(7) knows, and whether they match, assign, or both.
MATCH_ONLY = {"ACTION", "DEVPATH", "KERNEL", "KERNELS", "SUBSYSTEM", "SUBSYSTEMS",
              "DRIVER", "DRIVERS", "ATTRS", "TAGS", "TEST", "PROGRAM", "RESULT", "CONST"}
ASSIGN_ONLY = {"OWNER", "GROUP", "MODE", "SECLABEL", "OPTIONS", "RUN", "LABEL", "GOTO",
               "IMPORT", "SYSCTL"}  # SYSCTL/ATTR both match and assign
BOTH = {"NAME", "SYMLINK", "ENV", "TAG", "ATTR", "SYSCTL"}
WITH_ATTR = {"ATTR", "ATTRS", "ENV", "TEST", "IMPORT", "RUN", "SECLABEL", "SYSCTL", "CONST"}
NEEDS_ATTR = {"ATTR", "ATTRS", "ENV", "IMPORT", "SECLABEL", "SYSCTL", "CONST"}
BUILTINS = {"blkid", "btrfs", "hwdb", "input_id", "keyboard", "kmod", "net_id", "net_setup_link",
            "path_id", "uaccess", "usb_id"}
TOKEN = re.compile(r'\s*([A-Z]+)(?:\{([^}]*)\})?\s*(==|!=|\+=|-=|:=|=)\s*"((?:[^"\\]|\\.)*)"\s*(,|$)')
SUBST = re.compile(r'\$(\$|kernel|number|devpath|id|driver|attr\{[^}]+\}|sysfs\{[^}]+\}|env\{[^}]+\}|'
                   r'major|minor|result|parent|name|links|root|sys|devnode|tempnode)'
                   r'|\$([A-Za-z{][^ "/]*)|%([knpbdMmcPNsErSL%])|%(.)')

def logical_lines(path):
    buf, start = "", None
    for no, raw in enumerate(open(path, encoding="utf-8"), 1):
        line = raw.rstrip("\n")
        if start is None:
            start = no
        if line.endswith("\\"):
            buf += line[:-1]
            continue
        buf += line
        s = buf.strip()
        if s and not s.startswith("#"):
            yield start, s
        buf, start = "", None

def parse(path):
    errors, rules, labels, gotos = [], [], set(), []
    for no, text in logical_lines(path):
        pos, toks = 0, []
        while pos < len(text):
            m = TOKEN.match(text, pos)
            if not m:
                errors.append(f"line {no}: cannot parse at: {text[pos:pos+40]!r}")
                break
            key, attr, op, val, sep = m.groups()
            toks.append((key, attr, op, val))
            pos = m.end()
            if sep == "" and pos < len(text):
                errors.append(f"line {no}: missing comma before {text[pos:pos+20]!r}")
                break
        if text.rstrip().endswith(","):
            errors.append(f"line {no}: trailing comma")
        for key, attr, op, val in toks:
            known = MATCH_ONLY | ASSIGN_ONLY | BOTH
            if key not in known:
                errors.append(f"line {no}: unknown key {key}")
                continue
            is_match = op in ("==", "!=")
            if is_match and key in ASSIGN_ONLY and key not in BOTH:
                errors.append(f"line {no}: {key} cannot be matched ({op})")
            if not is_match and key in MATCH_ONLY:
                errors.append(f"line {no}: {key} cannot be assigned ({op})")
            if attr is not None and key not in WITH_ATTR:
                errors.append(f"line {no}: {key} takes no {{attribute}}")
            if attr is None and key in NEEDS_ATTR:
                errors.append(f"line {no}: {key} needs an {{attribute}}")
            if key in ("LABEL", "GOTO") and op != "=":
                errors.append(f"line {no}: {key} takes '='")
            if key == "MODE" and not is_match and not re.fullmatch(r"0?[0-7]{3,4}", val):
                errors.append(f"line {no}: MODE {val!r} is not octal")
            if key == "IMPORT" and attr not in ("program", "builtin", "file", "db", "cmdline", "parent"):
                errors.append(f"line {no}: IMPORT{{{attr}}} unknown")
            if key == "IMPORT" and attr == "builtin" and val.split()[0] not in BUILTINS:
                errors.append(f"line {no}: no udev builtin {val!r}")
            for s in SUBST.finditer(val):
                if s.group(2) is not None or s.group(4) is not None:
                    errors.append(f"line {no}: unknown substitution {s.group(0)!r} in {val!r}")
            if key == "LABEL":
                labels.add(val)
            if key == "GOTO":
                gotos.append((no, val))
        if toks:
            rules.append((no, toks))
    for no, g in gotos:
        if g not in labels:
            errors.append(f"line {no}: GOTO {g!r} has no LABEL")
    return errors, rules

def glob_any(pattern, value):
    return any(fnmatch.fnmatchcase(value, p) for p in pattern.split("|"))

def run(rules, dev):
    """Evaluate the rules for one event. dev: action, subsystem, kernel, attrs
    (of the device), parents (list of attr dicts, nearest first), files
    (sysfs paths relative to the device that exist), builtins (env each
    IMPORT{builtin} adds). Returns the resulting state."""
    env = dict(dev.get("env", {}))
    out = {"attr_writes": {}, "symlinks": [], "group": None, "mode": None, "tags": [], "env": env}
    skip_to = None
    for no, toks in rules:
        if skip_to is not None:
            if any(k == "LABEL" and v == skip_to for k, _, _, v in toks):
                skip_to = None
            continue
        parent = None  # the parent an ATTRS match selected
        def subst(v):
            def one(m):
                s = m.group(1)
                if s.startswith("env{"):
                    return env.get(s[4:-1], "")
                if s.startswith("attr{"):
                    a = s[5:-1]
                    if a in dev.get("attrs", {}):
                        return dev["attrs"][a]
                    return (parent or {}).get(a, "")
                if s == "kernel":
                    return dev["kernel"]
                raise AssertionError(f"evaluator: substitution {s} not modelled")
            return SUBST.sub(one, v)
        matched = True
        # Match keys first (udev evaluates them before assignments).
        attrs_keys = [(a, op, v) for k, a, op, v in toks if k == "ATTRS"]
        if attrs_keys:
            hits = [p for p in dev.get("parents", [])
                    if all((a in p and glob_any(v, p[a])) == (op == "==") for a, op, v in attrs_keys)]
            if hits:
                parent = hits[0]
            else:
                matched = False
        for k, a, op, v in toks:
            if not matched:
                break
            if op not in ("==", "!="):
                continue
            if k == "ATTRS":
                continue
            if k == "ACTION":
                got = dev["action"]
            elif k == "SUBSYSTEM":
                got = dev["subsystem"]
            elif k == "KERNEL":
                got = dev["kernel"]
            elif k == "ENV":
                got = env.get(a, "")
            elif k == "TEST":
                ok = a is None and subst(v) in dev.get("files", set())
                matched = ok == (op == "==")
                continue
            else:
                raise AssertionError(f"evaluator: match key {k} not modelled")
            matched = glob_any(v, got) == (op == "==")
        if not matched:
            continue
        for k, a, op, v in toks:
            if op in ("==", "!="):
                continue
            if k == "GOTO":
                skip_to = v
            elif k == "LABEL":
                pass
            elif k == "ENV":
                env[a] = subst(v)
            elif k == "ATTR":
                if a.startswith("device/") and a not in dev.get("files", set()):
                    raise AssertionError(f"line {no}: writes missing sysfs file {a}")
                out["attr_writes"][a] = subst(v)
            elif k == "SYMLINK":
                links = subst(v).split()
                out["symlinks"] = links if op in ("=", ":=") else out["symlinks"] + links
            elif k == "GROUP":
                out["group"] = subst(v)
            elif k == "MODE":
                out["mode"] = v
            elif k == "TAG":
                out["tags"].append(v)
            elif k == "IMPORT" and a == "builtin":
                env.update(dev.get("builtins", {}).get(v, {}))
            else:
                raise AssertionError(f"evaluator: assignment {k} not modelled")
        if skip_to is not None:
            continue
    return out

def usb_tty(kernel, vid, pid, serial, action="add", latency=True):
    usbdev = {"idVendor": vid, "idProduct": pid, "manufacturer": "FTDI"}
    if serial:
        usbdev["serial"] = serial
    roothub = {"idVendor": "1d6b", "idProduct": "0002", "serial": "0000:00:14.0"}
    usb_id = {"ID_VENDOR_ID": vid, "ID_MODEL_ID": pid}
    if serial:
        usb_id["ID_SERIAL_SHORT"] = serial
    return {"action": action, "subsystem": "tty", "kernel": kernel, "attrs": {"dev": "188:0"},
            "parents": [{}, {}, usbdev, roothub],
            "files": {"device/latency_timer"} if latency else set(),
            "builtins": {"usb_id": usb_id,
                         "path_id": {"ID_PATH": "pci-0000:00:14.0-usb-0:2:1.0"}}}

def check(rules):
    fails = []
    def expect(name, dev, latency, links, managed=True):
        r = run(rules, dev)
        got_lat = r["attr_writes"].get("device/latency_timer")
        if got_lat != latency:
            fails.append(f"{name}: latency_timer write {got_lat!r}, want {latency!r}")
        for l in links:
            if l not in r["symlinks"]:
                fails.append(f"{name}: no link {l} (links {r['symlinks']})")
        if not managed:
            if r["symlinks"] or r["group"] or r["mode"]:
                fails.append(f"{name}: touched by the rules: {r}")
            return
        bad = [l for l in r["symlinks"] if not l.startswith("dynamixel/")]
        if bad:
            fails.append(f"{name}: links outside /dev/dynamixel: {bad}")
        if r["group"] != "dialout" or r["mode"] != "0660":
            fails.append(f"{name}: group/mode {r['group']}/{r['mode']}, want dialout/0660")
        if r["env"].get("ID_MM_DEVICE_IGNORE") != "1":
            fails.append(f"{name}: ModemManager not told to ignore it")
        if "by-serial" not in " ".join(links) and any("by-serial" in l for l in r["symlinks"]):
            fails.append(f"{name}: by-serial link without a serial number: {r['symlinks']}")
    path = "dynamixel/by-path/pci-0000:00:14.0-usb-0:2:1.0"
    expect("U2D2 add", usb_tty("ttyUSB0", "0403", "6014", "FT3M9Y2N"), "1",
           ["dynamixel/by-serial/FT3M9Y2N", path])
    expect("U2D2 change (links kept)", usb_tty("ttyUSB0", "0403", "6014", "FT3M9Y2N", "change"), "1",
           ["dynamixel/by-serial/FT3M9Y2N"])
    expect("USB2Dynamixel add", usb_tty("ttyUSB1", "0403", "6001", "A9ETBXZZ"), "1",
           ["dynamixel/by-serial/A9ETBXZZ"])
    expect("USB2AX add", usb_tty("ttyACM0", "16d0", "06a7", "74031303437351011190", latency=False),
           None, ["dynamixel/by-serial/74031303437351011190", path])
    expect("USB2AX without serial number", usb_tty("ttyACM0", "16d0", "06a7", None, latency=False),
           None, [path])
    expect("U2D2 remove", usb_tty("ttyUSB0", "0403", "6014", "FT3M9Y2N", "remove"), None, [],
           managed=False)
    expect("FT231X (not a Dynamixel adapter)", usb_tty("ttyUSB0", "0403", "6015", "DN01"), None, [],
           managed=False)
    expect("Arduino ACM (not a Dynamixel adapter)",
           usb_tty("ttyACM0", "2341", "0043", "7543", latency=False), None, [], managed=False)
    usbdev = usb_tty("ttyUSB0", "0403", "6014", "FT3M9Y2N")
    usbdev.update(subsystem="usb-serial", kernel="ttyUSB0")
    expect("usb-serial event (not the tty)", usbdev, None, [], managed=False)
    return fails

syntax_only = sys.argv[1] == "--syntax"
errors, rules = parse(sys.argv[-1])
for e in errors:
    print("syntax:", e)
if errors or not rules:
    sys.exit(1)
print(f"parsed {len(rules)} rules")
if syntax_only:
    sys.exit(0)
try:
    fails = check(rules)
except AssertionError as e:
    fails = [str(e)]
for f in fails:
    print("behaviour:", f)
sys.exit(1 if fails else 0)
PY

if out=$(python3 "$T/udevcheck.py" --syntax "$rules" 2>&1); then
	tap_ok "udev rules: every line parses, keys and operators are udev's"
else
	tap_fail "udev rules syntax" "$out"
fi

if out=$(python3 "$T/udevcheck.py" "$rules" 2>&1); then
	tap_ok "udev rules: U2D2/USB2Dynamixel get latency 1, by-serial link, dialout 0660; USB2AX a link; others untouched"
else
	tap_fail "udev rules behave as the adapters need" "$out"
fi

# The checker must itself catch mistakes: each broken copy has to fail.
broken_ok=1
mutate() { # NAME SED-EXPR: the checker must reject this broken copy
	sed -e "$2" "$rules" >"$T/broken.rules"
	if cmp -s "$rules" "$T/broken.rules"; then
		echo "# mutation '$1' changed nothing"; broken_ok=0; return
	fi
	if python3 "$T/udevcheck.py" "$T/broken.rules" >/dev/null 2>&1; then
		echo "# mutation '$1' was not caught"; broken_ok=0
	fi
}
mutate "misspelt key" 's/SUBSYSTEM!=/SUBSYTEM!=/'
mutate "assignment to a match key" 's/KERNEL!=/KERNEL=/'
mutate "missing comma" '0,/", ENV{UNDULATE_ADAPTER}="ftdi"/s//" ENV{UNDULATE_ADAPTER}="ftdi"/'
mutate "GOTO without label" 's/LABEL="undulate_end"/LABEL="undulate_done"/'
mutate "latency not set" 's/ATTR{device\/latency_timer}="1"/ATTR{device\/latency_timer}="16"/'
mutate "U2D2 id wrong" 's/6014|6001/6010|6001/'
mutate "links lost on change" 's/ACTION=="remove"/ACTION!="add"/'
mutate "wrong group" 's/GROUP="dialout"/GROUP="tty"/'
mutate "unknown builtin" 's/"usb_id"/"usbid"/'
mutate "by-serial link without a serial" 's/ID_SERIAL_SHORT}=="?\*"/ID_SERIAL_SHORT}=="*"/'
if [ "$broken_ok" -eq 1 ]; then
	tap_ok "udev checker rejects broken copies (typo, bad operator, lost latency, lost links, ...)"
else
	tap_fail "udev checker rejects broken copies"
fi

if command -v udevadm >/dev/null && udevadm verify --help >/dev/null 2>&1; then
	if out=$(udevadm verify --no-summary "$rules" 2>&1) && [ -z "$out" ]; then
		tap_ok "udevadm verify"
	else
		tap_fail "udevadm verify" "$out"
	fi
fi
tap_done
