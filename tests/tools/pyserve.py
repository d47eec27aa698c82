#!/usr/bin/env python3
"""pyserve.py SCRIPT — run SCRIPT's main(argv) once per request, in one process.

The tests call their Python clients (tests/integration/sim_client.py,
qa_lcm.py) hundreds of times; a Python start-up costs more than the exchange
it makes (tens of milliseconds of system time on a quiet machine, seconds on a
loaded one), so tests/lib.sh's py_start/py_call keep one interpreter per
client and send it requests instead (py_call says how).

Requests on stdin, one per line: the fields separated by 0x1F, the first
ENV=VALUE;ENV2=... (the environment the call sees: variables named there are
set, a name without '=' is removed) and the rest the arguments after the
script's name. Replies on stdout: each line of what the call printed prefixed
'o ' (stdout) or 'e ' (stderr), then 'x RC', the exit status (SystemExit's
code; 1 and a traceback on stderr for an exception).
"""
import importlib.util, io, os, sys, traceback


def load(path):
    spec = importlib.util.spec_from_file_location("served", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)  # not as __main__: its own main() is not run
    return mod


def status(code):
    if code is None:
        return 0
    if isinstance(code, int):
        return code & 0xFF
    sys.__stderr__.write(str(code) + "\n")  # sys.exit("message")
    return 1


def call(mod, path, fields):
    for item in fields[0].split(";") if fields[0] else []:
        name, eq, value = item.partition("=")
        if eq:
            os.environ[name] = value
        else:
            os.environ.pop(name, None)
    out, err = io.StringIO(), io.StringIO()
    sys.stdout, sys.stderr = out, err
    try:
        rc = status(mod.main([path] + fields[1:]))
    except SystemExit as e:
        if isinstance(e.code, str):
            err.write(e.code + "\n")
            rc = 1
        else:
            rc = status(e.code)
    except Exception:  # the client's own failure: what it would have printed
        traceback.print_exc()
        rc = 1
    finally:
        sys.stdout, sys.stderr = sys.__stdout__, sys.__stderr__
    lines = ["o " + l for l in out.getvalue().splitlines()]
    lines += ["e " + l for l in err.getvalue().splitlines()]
    sys.stdout.write("".join(l + "\n" for l in lines) + "x %d\n" % rc)
    sys.stdout.flush()


def main():
    if len(sys.argv) != 2:
        sys.stderr.write(__doc__)
        return 2
    path = sys.argv[1]
    mod = load(path)
    for line in sys.stdin:
        call(mod, path, line.rstrip("\n").split("\x1f"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
