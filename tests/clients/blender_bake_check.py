"""What the Blender client checks share: failures collected by check(), and a run() that checks
each file named after a bake against it and leaves Blender with the exit status (Blender ignores
a script's own). Usage inside Blender: blender_bake_check.run("name", doc, check_file)."""
import os
import sys

import h5py

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


def run(name, doc, check_file):
    """argv after "--": BAKE.h5 FILE [FILE ...] => check_file(FILE, bake) for each; exits."""
    argv = sys.argv[sys.argv.index("--") + 1:]
    code = 2
    if len(argv) < 2:
        print(doc)
    else:
        with h5py.File(argv[0], "r") as bake:
            summary = [check_file(path, bake) for path in argv[1:]]
        for failure in failures:
            print(f"{name}: {failure}")
        print(f"{name}: {'FAILED' if failures else 'ok'}: {'; '.join(summary)}")
        code = 1 if failures else 0
    sys.stdout.flush()
    os._exit(code)
