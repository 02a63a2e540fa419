#!/usr/bin/python3
r"""Runs the bad-input corpus: tests/bad/cases.json => every case exits with its documented code
and names the problem on stderr, with no control character (a quoted binary byte shows as \xNN);
none crashes, hangs or reports an internal error.

usage: bad_corpus.py TREEANIM CORPUS_DIR
Each case runs in CORPUS_DIR (paths in its args are relative to it; a lone surrogate such as
\udcda in cases.json stands for the byte 0xDA, as os.fsencode maps it); "{tmp}" in an argument is
replaced by a fresh empty folder, which must still be empty afterwards (a refused bake writes
nothing), and "{corpus}" (in arguments and messages) by the corpus folder, which no case may
change (a refused bake replaces nothing). An optional "env" object sets environment variables
for the case ({tmp} and {corpus} replaced as in arguments), e.g. a PATH without sbatch.
"""
import json
import os
import subprocess
import sys
import tempfile


def snapshot(folder):
    """folder => {relative path: (type and mode bits, size, modification time)} of everything below it."""
    found = {}
    for root, dirs, names in os.walk(folder):
        for name in dirs + names:
            path = os.path.join(root, name)
            info = os.lstat(path)
            found[os.path.relpath(path, folder)] = (info.st_mode, info.st_size, info.st_mtime_ns)
    return found


def run_case(binary, corpus, case):
    """case => list of problems (empty when it behaves as documented)."""
    corpus = os.path.abspath(corpus)
    before = snapshot(corpus)
    with tempfile.TemporaryDirectory(prefix="treeanim-bad-") as tmp:
        args = [a.replace("{tmp}", tmp).replace("{corpus}", corpus) for a in case["args"]]
        message = case["message"].replace("{corpus}", corpus)
        env = dict(os.environ)
        for name, value in case.get("env", {}).items():
            env[name] = value.replace("{tmp}", tmp).replace("{corpus}", corpus)
        try:
            done = subprocess.run([binary] + args, cwd=corpus, capture_output=True, text=True,
                                  errors="replace", timeout=120, env=env)
        except subprocess.TimeoutExpired:
            return ["timed out after 120 s"]
        problems = []
        if done.returncode != case["exit"]:
            problems.append("exit %d, expected %d" % (done.returncode, case["exit"]))
        if message not in done.stderr:
            problems.append("stderr lacks %r" % message)
        if any(ord(c) < 0x20 and c not in "\n\t" or ord(c) == 0x7F for c in done.stderr):
            problems.append("a control character on stderr (input quoted without escaping its bytes)")
        if "internal error" in done.stderr:
            problems.append("an internal error (an exception nobody mapped)")
        left = os.listdir(tmp)
        if left:
            problems.append("files left in the output folder: %s" % left)
        if snapshot(corpus) != before:
            problems.append("the corpus folder changed")
        if problems:
            problems.append("stderr was: %s" % done.stderr.strip()[-2000:])
        return problems


def main():
    binary, corpus = os.path.abspath(sys.argv[1]), sys.argv[2]
    with open(os.path.join(corpus, "cases.json")) as f:
        cases = json.load(f)["cases"]
    names = [c["name"] for c in cases]
    if len(set(names)) != len(names):
        sys.exit("cases.json: duplicate case names")
    failed = 0
    for case in cases:
        problems = run_case(binary, corpus, case)
        if problems:
            failed += 1
            print("FAIL %s: %s" % (case["name"], "\n    ".join(problems)))
    print("bad corpus: %d of %d cases as documented" % (len(cases) - failed, len(cases)))
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
